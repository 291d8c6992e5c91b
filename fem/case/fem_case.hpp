#pragma once
// fem's sections of a case file, one reader per section (keys in docs/case-file.md). Each reads
// and range-checks its keys once, into ctx.model; called in this order by the case orchestration
// (workflow/case), a module's own sections in between (drape/case: [[mesh.fabric]]).
#include <array>
#include <cstdint>
#include <string_view>
#include <vector>

#include "fem/case/case_context.hpp"

namespace ncfsim::fem {

/// [mesh].resolution, [[mesh.block]], [[mesh.line]], [[mesh.plate]] (`m` is the [mesh] table).
void read_mesh_blocks(CaseReadContext& ctx, const TableReader& m);
/// After every module made its elements: renumbers for locality (returns new-from-old node map)
/// and sets the default user ids. Modules remap their node lists with the map.
std::vector<std::int32_t> finish_mesh(CaseReadContext& ctx);
/// [[material]] (through the registry), [[bar_law]].
void read_materials(CaseReadContext& ctx);
void read_bar_laws(CaseReadContext& ctx);
/// [[membrane_law]] (through the registry).
void read_membrane_laws(CaseReadContext& ctx);
/// [[part]]; then, after the modules gave their generated parts, check_parts_defined.
void read_parts(CaseReadContext& ctx);
void check_parts_defined(const CaseReadContext& ctx);
/// [boundary] (fixed, velocity, picture_frame), [load], [damping], [initial].
void read_boundary(CaseReadContext& ctx);
void read_loads(CaseReadContext& ctx);
/// [[tool]] (rigid tools), [[contact]] (deformable contacts).
void read_tools(CaseReadContext& ctx);
void read_contacts(CaseReadContext& ctx);
/// The geometry keys of a [[tool]] (shape, point, axis, radius, minor_radius, body_inside, file,
/// scale, search_radius): also the surfaces of a kinematic drape.
void read_rigid_surface(const TableReader& t, RigidSurface& s);
/// [time] (needs the picture frames: their rate follows from end_time).
void read_time(CaseReadContext& ctx);

/// A node selection `key = { ... }` of table `owner` (docs/case-file.md, "Node selections").
std::vector<std::int32_t> select_nodes(const CaseReadContext& ctx, const TableReader& owner,
                                       std::string_view key);
/// A direction `key` (default `fallback`), normalised; zero is bad input.
V3 read_unit_vector(const TableReader& t, std::string_view key, std::array<double, 3> fallback);
/// `[case] name` (`case_table` is the [case] table): non-empty, no spaces or slashes (it names
/// the output folder). Every stage's case has one.
std::string read_case_name(const TableReader& case_table);
/// The [case] table of a stage's case: its name (read_case_name), its kind (must be `kind`) and
/// its description ("" when absent).
struct StageCaseHeader {
  std::string name, description;
};
StageCaseHeader read_stage_case_header(const TableReader& root, const std::string& kind);
/// Part names under `key` as indices into mesh.part_names (at least one).
std::vector<int> part_indices(const TableReader& t, std::string_view key, const Mesh& mesh);

/// The two places that know the mesh's element sets: per node, 1 if an element of
/// part `part` holds it; and a bar appended to the mesh.
std::vector<char> part_node_mask(const Mesh& mesh, int part);
void append_bar(Mesh& mesh, std::int32_t n0, std::int32_t n1, int part);

}  // namespace ncfsim::fem

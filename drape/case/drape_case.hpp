#pragma once
// drape's sections of a case file (keys in docs/case-file.md): the [[mesh.fabric]] blankets, the
// tow_biphase material type, and the fabric-test probes of [output] (shear angle, D1388 bending
// length, the bias-extension analytic curve). Called by the case orchestration (workflow/case)
// between fem's readers (fem/case/fem_case.hpp), with the same reading context.
#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "drape/fabric_generator.hpp"
#include "drape/probe_specs.hpp"
#include "drape/shell_stitch.hpp"
#include "drape/shell_stitch_connection.hpp"
#include "drape/stitch_connection.hpp"
#include "fem/case/case_context.hpp"

namespace ncfsim::drape {

/// Registers the material type `tow_biphase` (drape/tow_material.hpp).
void register_drape_case_types(fem::CaseTypeRegistry& registry);

/// One [[mesh.fabric]] between its generation and its parts' properties.
struct FabricEntry {
  std::string name, path;  // path: its table, "mesh.fabric[0]"
  std::string fabric;      // the [fabric.NAME] it reads its fabric keys from ("": its own)
  std::string tow_material, law_I, law_Lambda, law_legs;
  std::map<std::string, std::string> key_paths;  // "tow_material", "stitch_law_I", ... -> path
  std::vector<double> angles;
  int elements_through_thickness = 1;
  FabricModel model;
  StitchConnectionSettings connection;
};

/// [[mesh.fabric]] of the [mesh] table `m`: generates the blankets into ctx.model.mesh (after fem's
/// blocks and lines, before fem::finish_mesh); its parts are marked generated.
std::vector<FabricEntry> read_fabrics(fem::CaseReadContext& ctx, const fem::TableReader& m);
/// After fem::finish_mesh: renumbers the fabrics' node lists and registers their tow-end pins as
/// the node selector `tow_end_pins = "<fabric name>"`.
void renumber_fabrics(fem::CaseReadContext& ctx, std::vector<FabricEntry>& fabrics,
                      const std::vector<std::int32_t>& new_of_old);
/// After fem::read_parts: the properties of the fabrics' parts (tow material, ply axes, stitch
/// laws) and their stitch-to-tow connections (into ctx.model.contacts).
std::vector<FabricSummary> assign_fabric_parts(fem::CaseReadContext& ctx,
                                               const std::vector<FabricEntry>& fabrics);

/// One [[mesh.shell_stitch]] between its generation and its bar law and sliders.
struct ShellStitchEntry {
  std::string name, path, law;
  int bar_part = -1;
  ShellStitchModel model;
  ShellStitchSliderSettings slider;  // sliding_force per penetration of the fabric
  double added_mass_per_area = 0;    // kg/m^2 carried by the stitch nodes on top of the yarn's
};

/// [[mesh.shell_stitch]] of the [mesh] table `m`: lays the stitch lines over their shell parts
/// (after fem's plates, before fem::finish_mesh); the bar parts are marked generated.
std::vector<ShellStitchEntry> read_shell_stitches(fem::CaseReadContext& ctx,
                                                  const fem::TableReader& m);
/// After fem::finish_mesh: renumbers the links and registers the lines' end nodes as the node
/// selector `shell_stitch_ends = "<name>"` (a frame or a clamp holds them).
void renumber_shell_stitches(fem::CaseReadContext& ctx, std::vector<ShellStitchEntry>& stitches,
                             const std::vector<std::int32_t>& new_of_old);
/// After fem::read_bar_laws and fem::read_parts: each line's bar law (the pillar law scaled by
/// the pillars a line stands for) and its sliders (into ctx.model.contacts).
void assign_shell_stitch_parts(fem::CaseReadContext& ctx,
                               const std::vector<ShellStitchEntry>& stitches);

/// [[output.shear_probe]] and [[output.bending_length]] of the [output] table `o`.
std::vector<ShearProbe> read_shear_probes(const fem::CaseReadContext& ctx,
                                          const fem::TableReader& o);
/// The ring keys (centre, axis, zero_direction, height, step_deg) of a table: the ring measure
/// of [[output.ring_shear]] and of a kinematic drape's [ring].
void read_ring(const fem::TableReader& t, RingSpec& ring);
/// [[output.ring_shear]] (at most one).
std::vector<RingShearProbe> read_ring_shear_probes(const fem::CaseReadContext& ctx,
                                                   const fem::TableReader& o);
std::vector<BendingLengthProbe> read_bending_probes(const fem::CaseReadContext& ctx,
                                                    const fem::TableReader& o);

/// The bias-extension coupon of an [[output.sample]] with analytic = "bias_extension" (else none).
struct BiasExtensionCoupon {
  double length = 0, width = 0;  // m: free length H, width W
};
std::optional<BiasExtensionCoupon> read_bias_extension_analytic(const fem::TableReader& sample);

}  // namespace ncfsim::drape

#pragma once
// Builds a meso model of a rectangular NCF blanket: each ply as distinct rows of hexahedra, one row
// per tow (the paper's Fig. 3), tows placed so that the stitch penetration points fall into the
// gaps between tows; the stitch as bar elements ('I' pillar segments on the top face, 'Lambda'
// zig-zag underlaps on the bottom face for tricot, legs through the thickness at the penetration
// points, one bar per ply, with a stitch node on every ply boundary); each stitch node joined by a
// connection to the nearest node of each tow beside its gap on that boundary, sliding along that
// tow past a sliding force and across it past a transverse force (on an interface:
// the tows of both plies, which pins the plies to each other at the stitch points; on meshes with
// elements longer than the tow pitch the search also reaches the next tows over).
#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "drape/fabric.hpp"
#include "fem/mesh.hpp"

namespace ncfsim::drape {

struct BlanketSpec {
  std::array<double, 2> origin{0, 0};  // m, lower-left corner in x-y
  std::array<double, 2> size{0, 0};    // m, along x (machine direction) and y
  double z0 = 0;                       // m, bottom face
};

/// A stitch node joined to a tow node (elastic, sliding along the tow past a sliding force and
/// across it past a transverse force). The tow's axis there is that of a hexahedron holding the
/// tow node and its next node along the tow (same tow, same face).
struct StitchConnection {
  std::int32_t stitch_node = -1, tow_node = -1;
  std::int32_t tow_axis_node = -1;  // next node along the tow (fibre direction)
};

struct FabricModel {
  std::vector<int> ply_parts;          // part index per ply (hexahedra)
  int stitch_I_part = -1, stitch_Lambda_part = -1, stitch_leg_part = -1;  // bar parts (-1: none)
  std::vector<std::int32_t> tow_of_hex;   // per hexahedron added: global tow index
  std::vector<int> ply_of_tow;            // per tow
  std::vector<StitchConnection> connections;
  std::vector<std::int32_t> stitch_nodes;
  /// The two end lines of every tow on its centre line (through the thickness): pins about which a
  /// tow end may rotate (a picture frame holds tows by these). Centred for an even
  /// elements_across_tow.
  std::vector<std::int32_t> tow_end_pins;
  /// The stitch nodes (all ply boundaries) of the penetrations on the outline of the stitch
  /// lattice (one of their eight lattice neighbours lies outside the blanket): where every stitch
  /// line of the blanket ends. A picture frame that holds them (`anchored_nodes`) makes its cell
  /// the interior of a large specimen, whose stitch is held by the fabric around (issue #19).
  std::vector<std::int32_t> stitch_end_pins;
  std::size_t n_tows = 0, n_dropped_tows = 0;
  std::size_t n_penetrations = 0;
  double tow_thickness = 0;
};

/// Appends the blanket to `mesh` (parts "<prefix>ply<k>", "<prefix>stitch_I", "<prefix>stitch_Lambda",
/// "<prefix>stitch_legs"). Tows shorter than two elements at the corners are dropped (counted).
/// Throws InputError for an inconsistent fabric or a blanket smaller than one tow pitch, naming
/// `key_path` + ".<key>" (the case file's table, "mesh.fabric[0]"; empty: "<prefix>" + key).
FabricModel generate_blanket(fem::Mesh& mesh, const FabricSpec& fabric, const BlanketSpec& blanket,
                             const std::string& file = "", const std::string& prefix = "",
                             const std::string& key_path = "");

}  // namespace ncfsim::drape

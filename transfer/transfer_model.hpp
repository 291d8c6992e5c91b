#pragma once
// The impregnated composite model of a formed part, built from a drape result's frame (issue #20):
// the draped tow hexahedra, in their draped shape (the new stress-free reference), each with its
// material frame, its fibre volume fraction raised by its compaction during the drape, its
// impregnated-tow properties (micromechanics at that Vf, in Vf classes), trimmed at a radius, and
// the tied pairs of faces the resin bonds: between plies (delamination) and between tows of a ply
// (intra-ply debond). Plain data; the transfer stage (workflow/stages) writes it, the crush reads
// it back through the stage hand-off, `ncfsim export` turns that file into an Abaqus or LS-DYNA
// deck.
#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "fem/io/stage_handoff.hpp"
#include "fem/vec3.hpp"
#include "transfer/impregnation.hpp"
#include "transfer/micromechanics.hpp"

namespace ncfsim::transfer {

struct TrimSpec {
  double radius = 0;  // m; 0: keep the whole part
  fem::V3 centre{};   // a point of the part's axis
  fem::V3 axis{0, 0, 1};
};

struct TieSpec {
  bool interply = true;  // faces of one ply on faces of the other
  bool intraply = true;  // side faces of neighbouring tows of a ply
  double distance =
      0;  // m, the most resin between two bonded faces (0: the thinnest tow's thickness)
  double normal_strength = 0, shear_strength = 0;  // Pa, the resin's bond (0: the resin's own)
};

/// The stitches in the cured part (dropped by default, docs/case-file.md "Transfer"). Kept, a
/// stitch bar whose two ends lie within `capture_distance` of kept tow hexahedra stays a bar with
/// its nodes where the drape left them; the crush ties each of its nodes to the nearest tow face
/// (the resin locks the yarn in place: the stitch-to-tow joints no longer slide).
/// The yarn's datasheet values (docs/case-file.md): polyester, 76 dtex as the drape's stitch.
struct StitchSpec {
  bool keep = false;
  double capture_distance = 0;     // m; 0: the thinnest tow's thickness
  double modulus = 10e9;           // Pa, high-tenacity polyester yarn
  double linear_density = 7.6e-6;  // kg/m (76 dtex)
  double density = 1380;           // kg/m^3
  double area() const { return linear_density / density; }
};

struct TransferSpec {
  std::vector<int> parts;  // part ids of the tow hexahedra to take (empty: every tow hexahedron)
  /// A draped hexahedron whose smallest scaled corner Jacobian is below this is not mapped: a
  /// dry tow folded over a tool edge carries it, an impregnated one (a hundred times stiffer)
  /// makes the one-point hexahedron unstable at once. [0, 0.5]; 0 keeps every unfolded one.
  double min_corner_jacobian = 0.1;
  FibreData fibre;
  ResinData resin;
  double compressive_ratio = 0.6;
  MappingSpec mapping;
  TrimSpec trim;
  TieSpec ties;
  StitchSpec stitches;
};

/// The tied face pairs of one interface: faces as (element, face 0..5, VTK hexahedron faces -z,
/// +z, -y, +x, +y, -x of the reference cube), slave and master sides pair by pair.
struct TiePairs {
  std::string name;  // "interply" or "intraply"
  std::vector<std::pair<std::int32_t, int>> slave, master;
};

struct ImpregnatedModel {
  std::vector<double> points;                    // [3 n] the draped positions
  std::vector<std::int64_t> point_user_id;       // per point (the drape's node ids)
  std::vector<std::array<std::int32_t, 8>> hex;  // into points, VTK order
  std::vector<std::int64_t> hex_user_id;         // the drape's hexahedron ids
  std::vector<std::int32_t> hex_part, hex_ply, hex_tow;
  std::vector<std::string> part_names;
  std::vector<std::array<double, 9>> frame;  // per element: row-major, axes as columns
  std::vector<double> vf, volume_ratio;      // per element
  std::vector<std::int32_t> vf_class;        // per element, into classes
  std::vector<ImpregnatedTow> classes;       // one impregnated tow per Vf class
  std::vector<TiePairs> ties;
  std::size_t n_candidates = 0;  // tow hexahedra in the source frame (selected parts)
  std::size_t n_trimmed = 0;     // left out by the trim
  std::size_t n_lost = 0;        // not mapped: eroded in the drape, a non-positive volume, a fibre
                                 // along the thickness
  std::size_t n_eroded = 0;      // of those, eroded in the drape
  std::size_t n_distorted = 0;   // of those, folded or distorted past spec.min_corner_jacobian
  std::size_t n_capped = 0;      // Vf capped at the locking value
  std::size_t n_floored = 0;     // Vf raised to the undeformed value (a tow the drape spread)
  std::size_t n_stitches = 0;    // stitch bars in the source frame
  /// Kept stitch bars (spec.stitches.keep): their two points (the stitch nodes, appended to
  /// `points` after the tows' at their draped positions), the drape's bar id and part.
  std::vector<std::array<std::int32_t, 2>> stitch;
  std::vector<std::int64_t> stitch_user_id;
  std::vector<std::int32_t> stitch_part;
  std::size_t n_stitch_nodes = 0;         // points of the kept stitches (the last ones)
  std::size_t n_stitches_uncaptured = 0;  // an end beside no kept tow hexahedron: dropped
  double stitch_capture = 0;              // m, the capture distance used

  std::size_t n_elements() const { return hex.size(); }
  std::size_t n_tie_pairs() const;
};

/// Throws std::invalid_argument naming the spec's field for a bad spec, std::runtime_error when the
/// frame holds no tow hexahedra or no fibre_direction field.
ImpregnatedModel build_impregnated_model(const fem::io::StageFrame& frame,
                                         const TransferSpec& spec);

}  // namespace ncfsim::transfer

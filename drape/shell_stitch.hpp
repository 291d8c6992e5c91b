#pragma once
// The stitch of a macro (shell) fabric as bars: the 'I' pillars of a tricot stitch, lines along the
// wale sewn onto a flat part of four-node shells. Each stitch node is tied to a point of a shell
// (bilinear weights of its host quadrilateral) by a slider of StitchToShellConnection: the stitch
// yarn can slide through the fabric along its own length, which a membrane law cannot do (a local
// law makes the stitch follow the fabric exactly, as in a picture frame). A line stands for the
// pillars of the width it covers (line_spacing / gauge of them): its bars' forces and masses are
// scaled by that share, so the overlay's stiffness per unit width does not depend on its spacing.
#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "fem/mesh.hpp"

namespace ncfsim::drape {

struct ShellStitchSpec {
  int shell_part = -1;                       // the part whose quadrilaterals carry the stitch
  std::array<double, 3> direction{1, 0, 0};  // the wale (projected onto the shells' plane)
  double gauge = 0;                          // m between wales in the fabric (> 0)
  double stitch_length = 0;  // m between penetrations along a wale in the fabric (> 0)
  double line_spacing = 0;   // m between the overlay's lines (> 0)
  double point_spacing = 0;  // m between the overlay's stitch nodes along a line (> 0)
};

/// One stitch node and the shell point it is sewn to.
struct ShellStitchLink {
  std::int32_t stitch_node = -1;
  std::array<std::int32_t, 4> host{};  // the host quadrilateral's nodes
  std::array<double, 4> weight{};      // bilinear weights of the point in it (sum 1)
  // d(weight)/dS, S the reference length along the line: the point a slip s along the line
  // reaches is sum (weight + s slide) x (the host's map, to first order: slips stay far below a
  // shell's size).
  std::array<double, 4> slide{};
  std::int32_t prev = -1, next = -1;  // neighbouring stitch nodes on the line (-1: line end)
  // The fabric's penetrations this node stands for: pillar_share x its length of line (half a
  // step at a line's end) / stitch_length. Its slider slides at this times the force of one.
  double penetrations = 0;
};

struct ShellStitchModel {
  std::vector<ShellStitchLink> links;
  std::size_t n_lines = 0;
  double line_spacing = 0;       // m, as laid (the part's width over the number of lines)
  double pillar_share = 0;       // pillars per line: line_spacing / gauge (scales the bar law)
  double penetrations = 0;  // sum over the links: the fabric's penetrations the lines stand for
};

/// Lays the lines over the shell part (flat at set-up) and appends their nodes and bars (part
/// `bar_part`) to `mesh`. Lines run across the whole part; where the part has a hole a line is cut
/// into several. Throws InputError (file, key) when the part has no quadrilateral, is not flat,
/// or the direction is normal to it.
ShellStitchModel sew_shell_stitch(fem::Mesh& mesh, const ShellStitchSpec& spec, int bar_part,
                                  const std::string& file, const std::string& key);

}  // namespace ncfsim::drape

#pragma once
// Element fields of a two-ply fabric in the result frames (issue #18's results): at every frame,
// for each tow hexahedron of the two plies,
//  * shear_angle_deg: the inter-ply shear angle, 90 deg minus the angle between its convected
//    fibre direction and that of the nearest element (current centroids) of the other ply: what
//    an engineer reads off a formed part (the paper's Fig. 18 measure, everywhere);
//  * interply_slip_m: the slip of the ply over the other (cross-over sliding) at that place: the
//    material point of the other ply now under the element's centre (found in the nearest element
//    of the other ply by inverting its bilinear mid-surface) is taken back to its reference
//    position, and its distance in the ply plane from the element centre's reference position is
//    the slip. Exact under an affine deformation of the two plies; otherwise to the accuracy of a
//    bilinear field over one element.
//  * wrinkle_angle_deg: out-of-plane waviness, the angle between the element's mid-surface normal
//    and the mean normal of its own ply's elements within three element lengths (centroids). A
//    smooth surface of curvature radius rho reads about R / (2 rho) (R the radius of that
//    neighbourhood: 3 deg for the CI mesh on the 78 mm punch); a wrinkle of shorter wavelength
//    than 2R reads its slope.
// summary.json: fabrics.<name>.max_shear_deg, fabrics.<name>.max_interply_slip_m (final state),
// and the draw-in of the blank's outline (the nodes of the plies on the edge of the blank's
// rectangle in its plane): how much nearer to the blank's centre, in that plane, each has come:
// draw_in_max_m, draw_in_mid_edge_m (mean at the four edge mid-points), draw_in_corner_m (mean
// at the four corners).
#include <array>
#include <string>
#include <utility>
#include <vector>

#include "drape/probes/ply_elements.hpp"
#include "fem/run_measure.hpp"

namespace ncfsim::drape {

class FabricFields final : public fem::RunMeasure {
 public:
  /// The fabric `name` whose plies are the parts ply_a, ply_b (hexahedra).
  FabricFields(std::string name, int ply_a, int ply_b, const fem::ExplicitSolver& s);
  void add_frame_fields(const fem::ExplicitSolver& s,
                        std::vector<fem::MeasureCellField>& fields) const override;
  void add_summary(const fem::ExplicitSolver& s, nlohmann::json& summary) const override;

  struct Values {
    std::vector<double> shear_deg, slip_m, wrinkle_deg;  // per element of the plies (ply a, then b)
  };
  Values values(const fem::ExplicitSolver& s) const;

 private:
  std::string name_;
  PlyElements plies_;
  double reach_ = 0;
  double wrinkle_radius_ = 0;  // m, the neighbourhood of the wrinkle indicator
  // Draw-in: the blank's plane (centre, normal), its outline nodes, and which of them are nearest
  // to the four edge mid-points and the four corners.
  fem::V3 centre_, normal_;
  std::vector<std::int32_t> outline_;
  std::array<std::int32_t, 4> mid_edge_{}, corner_{};
};

}  // namespace ncfsim::drape

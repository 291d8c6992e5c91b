// The broad phase's contract: a node is a candidate of a flat segment when it lies within reach
// of it measured in the segment's own frame (in front of it or beside its extended edge by at
// most `far`, a little over the margin; behind it within its depth plus the margin), so the
// candidates do not depend on how a part lies relative to the coordinate axes. The bucket grid's
// boxes are axis-aligned: the box of a wide tow's face at 45 deg to the axes covers about twice
// the face, and on a +-45 fabric the other ply's nodes over the neighbouring faces fall inside it
// (on the CI hemisphere 2.75 candidates per node, 1.28 with the frame's test; the forming results
// the same byte for byte, fem/contact/README.md).
//  * Two crossed plies (tows at +45 and -45 deg, 2 mm wide, one hexahedron across, 0.05 mm apart:
//    within the margin) have the same candidates whether their tows lie at +-45 deg to the axes
//    or along them, and when the upper ply is driven onto the lower the same number of nodes
//    come into contact.
#include "tests/contact/contact_test_support.hpp"

using namespace ncfsim;

namespace {

constexpr double kT = 0.25e-3;       // ply thickness, m
constexpr double kW = 2e-3;          // tow width, m (one hexahedron across)
constexpr double kL = 12e-3;         // tow length, m (24 hexahedra along)
constexpr double kTowGap = 0.02e-3;  // between tows side by side
constexpr double kPlyGap = 0.05e-3;  // between the plies: within the margin (0.5 kT), apart
constexpr int kTows = 3;

struct PlyCandidates {
  std::int64_t candidates = 0;
  std::int64_t contacts = 0;  // active at the end
};

// Two plies of three tows (one part each) centred on the z axis, the lower ply's tows at
// turn + 45 deg to x, the upper's at turn - 45 deg, kPlyGap apart, in one self-contact group. The
// lower ply held, the upper one driven onto it at 1 m/s: the gap closes at 50 us, and at 60 us
// the plies' facing nodes are in contact.
PlyCandidates ply_candidates(double turn_deg) {
  fem::Model m;
  std::vector<int> tows;
  for (int ply = 0; ply < 2; ++ply) {
    const double a = (turn_deg + (ply == 0 ? 45.0 : -45.0)) * M_PI / 180;
    const double c = std::cos(a), s = std::sin(a);
    for (int k = 0; k < kTows; ++k) {
      const int part = static_cast<int>(tows.size());
      tows.push_back(part);
      const double y0 = (k - 0.5 * kTows) * (kW + kTowGap);
      test::add_elastic_block(m, "tow" + std::to_string(part),
                              {-0.5 * kL, y0, ply * (kT + kPlyGap)}, {kL, kW, kT}, {24, 1, 1}, 1500,
                              1e8, 0.3);
      for (auto i : test::part_nodes(m.mesh, part)) {
        double* p = &m.mesh.coords[3 * static_cast<std::size_t>(i)];
        const double x = c * p[0] - s * p[1], y = s * p[0] + c * p[1];
        p[0] = x, p[1] = y;
      }
    }
  }
  fem::PenaltyContactConfig cfg;
  cfg.name = "plies";
  cfg.groups = {{"tows", tows}};
  cfg.pairs = {{0, 0, 0.3}};
  auto* contact = test::add_contact<fem::PenaltyContact>(m, cfg);
  std::vector<std::int32_t> held, driven;
  for (int k = 0; k < 2 * kTows; ++k)
    for (auto i : test::part_nodes(m.mesh, k)) (k < kTows ? held : driven).push_back(i);
  m.fixed.push_back({"held", held, {true, true, true}});
  fem::PrescribedVelocity push;
  push.name = "push";
  push.nodes = driven;
  push.dofs = {true, true, true};
  push.velocity = {0, 0, -1};
  m.velocities.push_back(push);
  m.time.end_time = 1;
  fem::ExplicitSolver solver(m);
  while (solver.time() < 60e-6) solver.step();
  return {contact->stats().n_candidates, contact->active_contacts()};
}

}  // namespace

TEST(ContactBroadPhase, CandidatesDoNotDependOnHowThePliesLieToTheAxes) {
  const PlyCandidates along = ply_candidates(45), diagonal = ply_candidates(0);
  std::printf(
      "candidates: tows along the axes %lld, at +-45 deg to them %lld; contacts %lld / "
      "%lld\n",
      static_cast<long long>(along.candidates), static_cast<long long>(diagonal.candidates),
      static_cast<long long>(along.contacts), static_cast<long long>(diagonal.contacts));
  EXPECT_GT(along.candidates, 0);
  EXPECT_EQ(diagonal.candidates, along.candidates);
  EXPECT_GT(along.contacts, 0);
  EXPECT_EQ(diagonal.contacts, along.contacts);
}

// Stacks of thin plies in self-contact (one contact group holding every ply, mu = 0.3), the
// bottom ply's base fixed, the top pressed (force ramped in over 1 ms) and then sheared (its top
// nodes driven sideways at 0.5 m/s).
//  * 20 strips (ordering, no analytic value): no strip passes through another (at the end every
//    bottom node of strip k that lies over strip k - 1 is above its top face, to within 10 % of
//    the thickness, and each strip's mean height is above the one below), all positions finite,
//    penetration below 10 % of the strip thickness at every cycle, energy balance within 1 %.
//  * 12 plies, stable step (the penalty k = s m / dt0^2 adds at most ~2 s to (omega dt)^2): the
//    smallest step of the pressed and sheared stack with contact, at the default and at the
//    largest allowed penalty scale (0.5), stays within 10 % of the step of the same stack
//    without contact, and the run stays stable (energy balance within 1 %, penetration below
//    25 % of the ply thickness: the largest is at the plies' corners, where the sheared stack's
//    corner nodes dig into the face of the next ply; on the faces it is about 1 %).
#include "fem/contact/segment_frame.hpp"
#include "tests/contact/contact_test_support.hpp"

using namespace ncfsim;

namespace {

constexpr double kT = 0.25e-3;  // ply thickness, m

struct Stack {
  fem::Model model;
  std::vector<int> plies;
  fem::PenaltyContact* contact = nullptr;
};

// n plies of nx x ny x 1 hexahedra (size a x b x kT) stacked in z, touching, nodes renumbered.
void build_stack(Stack& s, int n, int nx, int ny, double a, double b, bool with_contact,
                 double penalty_scale, bool loaded) {
  fem::Model& m = s.model;
  for (int k = 0; k < n; ++k) {
    test::add_elastic_block(m, "ply" + std::to_string(k), {0, 0, k * kT}, {a, b, kT}, {nx, ny, 1},
                            1500, 1e8, 0.3);
    s.plies.push_back(k);
  }
  fem::renumber_for_locality(m.mesh);
  m.fixed.push_back({"base", test::nodes_at(m.mesh, 2, 0.0), {true, true, true}});
  const auto top = test::nodes_at(m.mesh, 2, n * kT);
  if (loaded) {
    fem::NodalLoad press;
    press.name = "press";
    press.nodes = top;
    press.force_per_node = {0, 0, -10.0 / static_cast<double>(top.size())};  // 10 N in all
    press.ramp_time = 1e-3;
    m.loads.push_back(press);
    fem::PrescribedVelocity shear;
    shear.name = "shear";
    shear.nodes = top;
    shear.dofs = {true, false, false};
    shear.velocity = {0.5, 0, 0};
    shear.start_time = 1e-3;
    shear.ramp_time = 0.5e-3;
    m.velocities.push_back(shear);
  }
  if (with_contact) {
    fem::PenaltyContactConfig cfg;
    cfg.name = "stack";
    cfg.groups = {{"plies", s.plies}};
    cfg.pairs = {{0, 0, 0.3}};
    cfg.penalty_scale = penalty_scale;
    s.contact = test::add_contact<fem::PenaltyContact>(m, cfg);
  }
}

}  // namespace

TEST(ContactStack, TwentyStripsPressedAndShearedNeverPassThroughEachOther) {
  Stack s;
  const int n = 20;
  build_stack(s, n, 8, 2, 20e-3, 5e-3, true, 0.1, true);
  s.model.time.end_time = 3e-3;
  fem::ExplicitSolver solver(s.model);
  std::vector<std::vector<std::int32_t>> nodes(n);
  for (int k = 0; k < n; ++k)
    nodes[static_cast<std::size_t>(k)] = test::part_nodes(s.model.mesh, k);
  double worst_pen = 0;
  while (solver.time() < s.model.time.end_time) {
    solver.step();
    worst_pen = std::max(worst_pen, s.contact->stats().max_penetration);
  }
  auto X = solver.x.view();
  for (std::size_t d = 0; d < 3 * s.model.mesh.n_nodes(); ++d) ASSERT_TRUE(std::isfinite(X[d]));
  // Height of every bottom node of strip k over the top face of strip k - 1 below it.
  const fem::Mesh& mesh = s.model.mesh;
  double lowest = 1e300;
  int n_checked = 0;
  for (int k = 1; k < n; ++k) {
    for (auto i : test::part_nodes_at(mesh, k, 2, k * kT)) {
      const double* p = &X[3 * static_cast<std::size_t>(i)];
      bool over = false;
      const fem::ElementSet& hexes = mesh.elements(fem::ElementKind::Hex8);
      for (std::size_t e = 0; e < hexes.size(); ++e) {
        if (hexes.part[e] != k - 1) continue;
        const auto h = hexes.nodes(e);
        const std::int32_t top_face[4] = {h[4], h[5], h[6], h[7]};
        double q[4][3];
        fem::gather_segment(X.data(), top_face, q);
        fem::SegmentFrame f;
        fem::segment_frame(q, 0, f);
        const auto pr = fem::project_on_segment(f, p[0], p[1], p[2]);
        if (std::abs(pr.xi) > 1 || std::abs(pr.eta) > 1) continue;
        lowest = std::min(lowest, pr.gap);
        over = true;
      }
      n_checked += over;
    }
    EXPECT_GT(test::mean_of(solver, nodes[static_cast<std::size_t>(k)], 2, 0),
              test::mean_of(solver, nodes[static_cast<std::size_t>(k) - 1], 2, 0))
        << "strip " << k << " is no longer above strip " << k - 1;
  }
  const double top_shift = test::mean_of(solver, nodes[n - 1], 0, 0) - 10e-3;
  std::printf(
      "stack of %d: top strip moved %.3g m in x, worst penetration %.3g of the thickness "
      "(%.3g at the end, over %d nodes), %lld sorts, energy error %.3g\n",
      n, top_shift, worst_pen / kT, -lowest / kT, n_checked,
      static_cast<long long>(s.contact->stats().n_sorts), solver.energy().error());
  // 27 bottom nodes per strip; those at the leading end overhang the strip below once sheared.
  EXPECT_GT(n_checked, 19 * 20) << "most bottom nodes should lie over the strip below";
  EXPECT_GT(lowest, -0.1 * kT) << "a bottom node lies below the top face of the strip beneath (m)";
  EXPECT_GT(top_shift, 0.2e-3) << "the top strip should have been sheared along (m)";
  EXPECT_LT(worst_pen, 0.1 * kT) << "largest penetration (m)";
  EXPECT_LT(solver.energy().error(), 0.01);
}

TEST(ContactStack, PenaltyDoesNotLowerTheStableStepOfTwelvePlies) {
  auto smallest_step = [](bool with_contact, double scale, double& error, double& pen) {
    Stack s;
    build_stack(s, 12, 8, 8, 8e-3, 8e-3, with_contact, scale, with_contact);
    s.model.time.end_time = 2.5e-3;
    fem::ExplicitSolver solver(s.model);
    double dt_min = solver.time_step();
    pen = 0;
    while (solver.time() < s.model.time.end_time) {
      solver.step();
      dt_min = std::min(dt_min, solver.time_step());
      if (s.contact) pen = std::max(pen, s.contact->stats().max_penetration);
    }
    error = solver.energy().error();
    return dt_min;
  };
  double err = 0, pen = 0;
  // Without contact the plies cannot be loaded (they would pass through): the step of the
  // unloaded stack is the reference.
  const double dt_free = smallest_step(false, 0.1, err, pen);
  for (double scale : {0.1, 0.5}) {
    const double dt = smallest_step(true, scale, err, pen);
    std::printf(
        "12 plies, penalty scale %.1f: smallest step %.4g s vs %.4g s without contact, "
        "energy error %.3g, penetration %.3g of the thickness\n",
        scale, dt, dt_free, err, pen / kT);
    EXPECT_GT(dt, 0.9 * dt_free) << "penalty scale " << scale;
    EXPECT_LT(err, 0.01) << "penalty scale " << scale;
    EXPECT_LT(pen, 0.25 * kT) << "penalty scale " << scale;
  }
}

// Plies meshed alike put each interface node on the corner of four facets of the ply beyond, all
// at the same gap up to round-off and the plies' vibration. The node keeps the segment it had
// unless another is nearer by more than 1e-4 of the segment's depth: pressed (no sliding, so no
// node crosses a facet edge) the contacts keep their segments; before this rule a quarter of
// them changed segment every cycle in such a stack (fem/contact/README.md, Method).
TEST(ContactStack, PliesMeshedAlikeKeepTheirSegmentsWhilePressed) {
  Stack s;
  build_stack(s, 4, 8, 8, 8e-3, 8e-3, true, 0.1, true);
  s.model.time.end_time = 1e-3;  // the press ramp; the shear starts after it
  fem::ExplicitSolver solver(s.model);
  std::int64_t contact_cycles = 0, changes = 0;
  while (solver.time() < s.model.time.end_time) {
    solver.step();
    if (solver.cycle() == 100) {  // after the first touch
      contact_cycles = s.contact->stats().n_contact_cycles;
      changes = s.contact->stats().n_segment_changes;
    }
  }
  contact_cycles = s.contact->stats().n_contact_cycles - contact_cycles;
  changes = s.contact->stats().n_segment_changes - changes;
  const double rate = static_cast<double>(changes) / static_cast<double>(contact_cycles);
  std::printf(
      "4 plies pressed: %lld contact-cycles, %lld segment changes (%.3g per contact-cycle), "
      "energy error %.3g\n",
      static_cast<long long>(contact_cycles), static_cast<long long>(changes), rate,
      solver.energy().error());
  EXPECT_GT(s.contact->active_contacts(), 3 * 81 / 2) << "the pressed interfaces should touch";
  EXPECT_LT(rate, 1e-3);
  EXPECT_LT(solver.energy().error(), 0.01);
}

namespace {

// The penalty contact as it was before the solver's travel bound: every call of
// set_node_travel is dropped, so the displacement check runs every cycle.
class WithoutTravelBound final : public fem::ContactAlgorithm {
 public:
  explicit WithoutTravelBound(std::unique_ptr<fem::ContactAlgorithm> c) : c_(std::move(c)) {}
  const std::string& name() const override { return c_->name(); }
  void initialise(const fem::ContactSetup& setup) override { c_->initialise(setup); }
  double estimated_bytes(const fem::Mesh& mesh, bool erosion) const override {
    return c_->estimated_bytes(mesh, erosion);
  }
  void add_forces(const double* x, const double* v, const double* m, double dt,
                  double* f) override {
    c_->add_forces(x, v, m, dt, f);
  }
  double friction_dissipation() const override { return c_->friction_dissipation(); }
  std::vector<fem::ContactResultant> resultants() const override { return c_->resultants(); }
  double stable_step_limit() const override { return c_->stable_step_limit(); }
  std::int64_t active_contacts() const override { return c_->active_contacts(); }
  double max_penetration() const override { return c_->max_penetration(); }
  void save_state(fem::CheckpointWriter& w) const override { c_->save_state(w); }
  void load_state(fem::CheckpointReader& r) override { c_->load_state(r); }

 private:
  std::unique_ptr<fem::ContactAlgorithm> c_;
};

}  // namespace

// The displacement check of the broad phase skipped while the solver's bound on the nodes'
// travel (3.5 dt v_max summed over the cycles) cannot have taken a node to the search margin:
// the stack of six pressed and sheared strips gives the same positions, velocities and contact
// energy to the last bit as with the check made every cycle, with the same sorts, and the check
// is made in fewer than half of the cycles.
TEST(ContactStack, TravelBoundSkipsDisplacementChecksAndChangesNothing) {
  std::vector<double> x[2], v[2];
  std::int64_t sorts[2] = {}, checks[2] = {}, cycles[2] = {};
  double friction[2] = {};
  for (int run = 0; run < 2; ++run) {
    Stack s;
    build_stack(s, 6, 8, 2, 20e-3, 5e-3, true, 0.1, true);
    s.model.time.end_time = 2.5e-3;
    if (run == 1) {
      auto c = std::move(s.model.contacts.back());
      s.model.contacts.back() = std::make_unique<WithoutTravelBound>(std::move(c));
    }
    fem::ExplicitSolver solver(s.model);
    while (solver.time() < s.model.time.end_time) solver.step();
    auto X = solver.x.view();
    auto V = solver.v.view();
    x[run].assign(X.data(), X.data() + 3 * s.model.mesh.n_nodes());
    v[run].assign(V.data(), V.data() + 3 * s.model.mesh.n_nodes());
    sorts[run] = s.contact->stats().n_sorts;
    checks[run] = s.contact->stats().n_checks;
    cycles[run] = s.contact->stats().n_cycles;
    friction[run] = s.contact->friction_dissipation();
  }
  EXPECT_TRUE(x[0] == x[1]) << "positions differ";
  EXPECT_TRUE(v[0] == v[1]) << "velocities differ";
  EXPECT_EQ(friction[0], friction[1]);
  EXPECT_EQ(sorts[0], sorts[1]);
  EXPECT_GT(sorts[0], 1) << "the strips should have slid far enough to be sorted again";
  EXPECT_EQ(checks[1], cycles[1]) << "without the bound every cycle checks";
  EXPECT_LT(2 * checks[0], cycles[0]) << checks[0] << " checks in " << cycles[0] << " cycles";
}

// Stitch-to-tow joint cost per joint and cycle: a +-45 blanket of the default fabric, meshed as the
// bias-extension cases' CI mesh (0: 1 element across a tow, 2 tow pitches long, so about 8 joints
// share a tow hexahedron) or as the generator's default (1: 2 across, 1 pitch long, the cases'
// coarse resolution), its stitch nodes joined to the tows, every node moved by a smooth shear and
// rotation field so that every joint's tow axis has turned and some joints slide. Counter
// ns_per_joint_cycle: time per (joint x cycle) of add_forces.
//   bench_stitch_joints                  a 100 x 100 mm blanket, CI mesh (0) and default (1)
// And the sliders that sew a macro fabric's stitch onto its shells (drape/shell_stitch_connection):
// a 290 mm blank of 2.5 mm shells (the macro hemisphere's), a line per row of shells, a stitch node
// per shell node along it, the same shear, turn and bulge, a third of the stitch nodes displaced
// along their lines (they slide in the first call; the timed calls, at the same positions, find
// every link sticking: the common case in a drape). Counter ns_per_link_cycle.
//   BM_ShellStitchSliders/116            116 x 116 shells: 13 456 links
#include <benchmark/benchmark.h>

#include <cmath>
#include <vector>

#include "drape/fabric_generator.hpp"
#include "drape/shell_stitch.hpp"
#include "drape/shell_stitch_connection.hpp"
#include "drape/stitch_connection.hpp"

using namespace ncfsim;

namespace {

// Positions x of the reference X (a square of side `size` in x-y): a shear of 0.2 rad and a turn
// of 0.1 rad in the plane, and a bulge out of it: every tow axis and stitch line turns, the
// connections load across and along.
void sheared_turned_bulged(const std::vector<double>& X, double size, std::vector<double>& x) {
  x = X;
  const double c = std::cos(0.1), s = std::sin(0.1);
  for (std::size_t i = 0; i < X.size() / 3; ++i) {
    const double px = X[3 * i], py = X[3 * i + 1], xs = px + 0.2 * py;
    x[3 * i] = c * xs - s * py;
    x[3 * i + 1] = s * xs + c * py;
    x[3 * i + 2] += 0.05 * size * std::sin(3.14159 * px / size) * std::sin(3.14159 * py / size);
  }
}

// The timed loop: one add_forces per iteration at fixed positions.
void time_add_forces(benchmark::State& state, fem::ContactAlgorithm& contact,
                     const std::vector<double>& x, const std::vector<double>& mass, double dt,
                     std::vector<double>& f) {
  for (auto _ : state) {
    contact.add_forces(x.data(), nullptr, mass.data(), dt, f.data());
    benchmark::DoNotOptimize(f.data());
  }
}

void BM_StitchJoints(benchmark::State& state) {
  const double size = 1e-3 * static_cast<double>(state.range(0));
  fem::Mesh mesh;
  drape::FabricSpec fabric;
  if (state.range(1) == 0) {  // the bias cases' CI mesh
    fabric.elements_across_tow = 1;
    fabric.element_length = 2 * fabric.tow_pitch();
  }
  drape::BlanketSpec blanket;
  blanket.size = {size, size};
  const drape::FabricModel fm = drape::generate_blanket(mesh, fabric, blanket);
  const std::size_t nn = mesh.n_nodes();
  std::vector<double> mass(3 * nn, 1e-6), f(3 * nn, 0.0), x = mesh.coords;
  sheared_turned_bulged(mesh.coords, size, x);
  drape::StitchConnectionSettings settings;
  drape::StitchToTowConnection joints("stitch_tow", fm.connections, settings);
  const double dt = 1e-7;
  fem::ContactSetup setup{&mesh, mesh.coords.data(), mass.data(), dt};
  joints.initialise(setup);
  time_add_forces(state, joints, x, mass, dt, f);
  const double n = static_cast<double>(joints.size());
  state.counters["joints"] = n;
  state.counters["hexahedra"] = static_cast<double>(mesh.n_elements(fem::ElementKind::Hex8));
  state.counters["axis_hexahedra"] = static_cast<double>(joints.axis_hexahedra());
  state.counters["ns_per_joint_cycle"] = benchmark::Counter(
      n, benchmark::Counter::kIsIterationInvariantRate | benchmark::Counter::kInvert);
}

void BM_ShellStitchSliders(benchmark::State& state) {
  const int n = static_cast<int>(state.range(0));
  const double size = 0.29, h = size / n;
  fem::Mesh mesh;
  mesh.add_part("blank");
  mesh.add_part("stitch");
  for (int j = 0; j <= n; ++j)
    for (int i = 0; i <= n; ++i) mesh.coords.insert(mesh.coords.end(), {i * h, j * h, 0.0});
  auto id = [&](int i, int j) { return static_cast<std::int32_t>(i + (n + 1) * j); };
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i)
      mesh.elements(fem::ElementKind::Quad4)
          .add({id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1)}, 0);
  drape::ShellStitchSpec spec;
  spec.shell_part = 0;
  spec.gauge = spec.stitch_length = 4.7e-3;
  spec.line_spacing = spec.point_spacing = h;
  const drape::ShellStitchModel st = drape::sew_shell_stitch(mesh, spec, 1, "bench", "bench");
  const std::size_t nn = mesh.n_nodes();
  std::vector<double> mass(3 * nn, 1e-6), f(3 * nn, 0.0), x = mesh.coords;
  sheared_turned_bulged(mesh.coords, size, x);
  for (std::size_t k = 0; k < st.links.size(); k += 3)  // a third pulled along their line
    x[3 * static_cast<std::size_t>(st.links[k].stitch_node)] += 1e-4;
  drape::ShellStitchSliderSettings settings;
  drape::StitchToShellConnection sliders("stitch_slider", st.links, settings);
  const double dt = 1e-6;
  fem::ContactSetup setup{&mesh, mesh.coords.data(), mass.data(), dt};
  sliders.initialise(setup);
  time_add_forces(state, sliders, x, mass, dt, f);
  const double links = static_cast<double>(sliders.size());
  state.counters["links"] = links;
  state.counters["sliding"] = static_cast<double>(sliders.active_contacts());
  state.counters["ns_per_link_cycle"] = benchmark::Counter(
      links, benchmark::Counter::kIsIterationInvariantRate | benchmark::Counter::kInvert);
}

}  // namespace

BENCHMARK(BM_ShellStitchSliders)->Arg(116)->Repetitions(3)->Unit(benchmark::kMillisecond);

BENCHMARK(BM_StitchJoints)
    ->Args({100, 0})
    ->Args({100, 1})
    ->Repetitions(3)
    ->Unit(benchmark::kMillisecond);

BENCHMARK_MAIN();

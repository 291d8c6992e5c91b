// Stitch-to-tow joint cost per joint and cycle: a +-45 blanket of the default fabric, meshed as the
// bias-extension cases' CI mesh (0: 1 element across a tow, 2 tow pitches long, so about 8 joints
// share a tow hexahedron) or as the generator's default (1: 2 across, 1 pitch long, the cases'
// coarse resolution), its stitch nodes joined to the tows, every node moved by a smooth shear and
// rotation field so that every joint's tow axis has turned and some joints slide. Counter
// ns_per_joint_cycle: time per (joint x cycle) of add_forces.
//   bench_stitch_joints                  a 100 x 100 mm blanket, CI mesh (0) and default (1)
#include <benchmark/benchmark.h>

#include <cmath>
#include <vector>

#include "drape/fabric_generator.hpp"
#include "drape/stitch_connection.hpp"

using namespace ncfsim;

namespace {

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
  // A shear of 0.2 rad and a turn of 0.1 rad in the plane, and a bulge out of it: every tow axis
  // turns, the joints load across and along their tows.
  for (std::size_t i = 0; i < nn; ++i) {
    const double X = mesh.coords[3 * i], Y = mesh.coords[3 * i + 1];
    const double c = std::cos(0.1), s = std::sin(0.1);
    const double xs = X + 0.2 * Y;
    x[3 * i] = c * xs - s * Y;
    x[3 * i + 1] = s * xs + c * Y;
    x[3 * i + 2] += 0.05 * size * std::sin(3.14159 * X / size) * std::sin(3.14159 * Y / size);
  }
  drape::StitchConnectionSettings settings;
  drape::StitchToTowConnection joints("stitch_tow", fm.connections, settings);
  const double dt = 1e-7;
  fem::ContactSetup setup{&mesh, mesh.coords.data(), mass.data(), dt};
  joints.initialise(setup);
  for (auto _ : state) {
    joints.add_forces(x.data(), nullptr, mass.data(), dt, f.data());
    benchmark::DoNotOptimize(f.data());
  }
  const double n = static_cast<double>(joints.size());
  state.counters["joints"] = n;
  state.counters["hexahedra"] = static_cast<double>(mesh.n_elements(fem::ElementKind::Hex8));
  state.counters["axis_hexahedra"] = static_cast<double>(joints.axis_hexahedra());
  state.counters["ns_per_joint_cycle"] = benchmark::Counter(
      n, benchmark::Counter::kIsIterationInvariantRate | benchmark::Counter::kInvert);
}

}  // namespace

BENCHMARK(BM_StitchJoints)
    ->Args({100, 0})
    ->Args({100, 1})
    ->Repetitions(3)
    ->Unit(benchmark::kMillisecond);

BENCHMARK_MAIN();

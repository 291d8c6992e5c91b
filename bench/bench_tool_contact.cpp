// Rigid-tool contact cost per contact node and cycle, with and without the proximity cull: a
// 290 x 290 mm sheet of nodes (1.66 mm apart, about 30 000 nodes, the CI hemisphere's count)
// formed over a rising 156 mm sphere (the hemisphere punch), each node swaying a little every
// cycle so the near list is rebuilt as in a run. Arguments: punch height above the sheet's
// lowest point in mm (its cap under the sheet: 0 = just touching, 40 = a third of the sheet on
// it) and the cull (0: every node tested, margin 1 km; 1: the automatic margin). Counter
// ns_per_node_cycle: time per (contact node x cycle) of tool_contact_forces.
//   bench_tool_contact
#include <benchmark/benchmark.h>

#include <cmath>
#include <vector>

#include "fem/rigid_tool.hpp"

using namespace ncfsim;

namespace {

void BM_ToolContact(benchmark::State& state) {
  const double rise = 1e-3 * static_cast<double>(state.range(0));
  const bool cull = state.range(1) != 0;
  const double R = 0.078, pitch = 1.66e-3, half = 0.145;
  std::vector<double> x0;
  for (double y = -half; y <= half; y += pitch)
    for (double x = -half; x <= half; x += pitch) {
      // The sheet already draped on the cap where the punch has risen through it.
      const double r2 = x * x + y * y, zc = rise - R;
      const double z = r2 < R * R ? std::max(0.0, zc + std::sqrt(R * R - r2)) : 0.0;
      x0.insert(x0.end(), {x, y, z});
    }
  const std::size_t n = x0.size() / 3;
  std::vector<double> x = x0, v(3 * n, 0.0), m(3 * n, 1e-6), f(3 * n, 0.0);
  fem::RigidTool punch;
  punch.surface.shape = fem::ToolShape::Sphere;
  punch.surface.point = {0, 0, rise - R - 1e-5};  // in contact with the draped nodes
  punch.surface.radius = R;
  punch.friction = 0.2;
  punch.search_margin = cull ? 0.0 : 1e3;
  for (std::size_t i = 0; i < n; ++i) punch.contact_nodes.push_back(static_cast<std::int32_t>(i));
  const double dt = 4e-7;
  std::int64_t cycle = 0;
  for (auto _ : state) {
    const double t = static_cast<double>(cycle++) * dt;
    punch.displacement = {0, 0, 1.0 * t};  // 1 m/s
    punch.velocity = {0, 0, 1.0};
    for (std::size_t i = 0; i < n; ++i)
      x[3 * i + 2] = x0[3 * i + 2] + 1.0 * t;  // the sheet follows
    fem::tool_contact_forces(punch, x.data(), v.data(), m.data(), dt, f.data());
    benchmark::DoNotOptimize(f.data());
  }
  state.counters["ns_per_node_cycle"] =
      benchmark::Counter(static_cast<double>(state.iterations()) * static_cast<double>(n),
                         benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
  state.counters["contact_nodes"] = static_cast<double>(n);
  state.counters["near_nodes"] = static_cast<double>(punch.proximity.near.size());
  state.counters["rebuilds"] = static_cast<double>(punch.proximity.n_rebuilds);
}

}  // namespace

BENCHMARK(BM_ToolContact)
    ->Args({0, 0})
    ->Args({0, 1})
    ->Args({40, 0})
    ->Args({40, 1})
    ->Unit(benchmark::kMicrosecond);
BENCHMARK_MAIN();

// Four-node shells (fem/elements/shell4_block.hpp): ns per shell element-cycle on a 200 x 200
// plate (40 000 shells) with a smooth bending and stretching velocity field, elastic
// (2 Gauss points through the thickness) and with the macro fabric membrane law
// (drape/fabric_membrane.hpp). Target (issue #19): under 60 ns per shell element-cycle, one core.
#include <benchmark/benchmark.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <ctime>
#include <memory>
#include <numbers>

#include "drape/fabric_membrane.hpp"
#include "fem/elements/shell4_block.hpp"
#include "fem/petsc_vector.hpp"
#include "fem/solver.hpp"

using namespace ncfsim;

namespace {

constexpr int kN = 200;  // shells per side

struct Fixture {
  std::string key;
  fem::Model model;
  std::unique_ptr<fem::ExplicitSolver> solver;
};
std::unique_ptr<Fixture> g_fixture;

Fixture& plate(bool fabric) {
  const std::string key = fabric ? "fabric" : "elastic";
  if (g_fixture && g_fixture->key == key) return *g_fixture;
  g_fixture.reset();
  auto fx = std::make_unique<Fixture>();
  fx->key = key;
  fem::Model& model = fx->model;
  const int p = model.mesh.add_part("plate");
  const double h = 2.5e-3;
  for (int j = 0; j <= kN; ++j)
    for (int i = 0; i <= kN; ++i)
      for (double c : {h * i, h * j, 0.0}) model.mesh.coords.push_back(c);
  auto id = [](int i, int j) { return static_cast<std::int32_t>(i + (kN + 1) * j); };
  auto& shells = model.mesh.elements(fem::ElementKind::Quad4);
  for (int j = 0; j < kN; ++j)
    for (int i = 0; i < kN; ++i) shells.add({id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1)}, p);
  fem::renumber_for_locality(model.mesh);
  model.mesh.fill_default_user_ids();
  model.parts.resize(1);
  auto& pp = model.parts[0];
  pp.shell_thickness = fabric ? 4.6e-4 : 1e-3;
  if (fabric) {
    drape::FabricMembraneConstants c;
    c.areal_density = 0.5;
    c.fibre_angles = {std::numbers::pi / 4, -std::numbers::pi / 4};
    c.fibre_tension_stiffness = 1.56e4;
    c.bending_stiffness = 3e-4;
    const double d = std::numbers::pi / 180;
    c.positive = drape::ShearCurve({10 * d, 20 * d, 30 * d, 40 * d, 50 * d},
                                   {6.0, 14.0, 31.0, 105.0, 550.0});
    model.membrane_laws.push_back(std::make_unique<drape::FabricMembraneLaw>("ncf", c));
    pp.membrane_law = 0;
  } else {
    model.materials.push_back(std::make_unique<fem::ElasticIsotropic>("steel", 7850, 210e9, 0.3));
    pp.material = 0;
  }
  model.time.end_time = 1.0;
  fx->solver = std::make_unique<fem::ExplicitSolver>(model);
  {
    auto V = fx->solver->v.view();
    auto X = fx->solver->x.view();
    const double L = h * kN, pi = std::numbers::pi;
    for (std::size_t i = 0; i < model.mesh.n_nodes(); ++i) {
      const double x = X[3 * i] / L, y = X[3 * i + 1] / L;
      V[3 * i] = 0.2 * (x - 0.5) + 0.05 * std::sin(pi * y);
      V[3 * i + 1] = -0.1 * (y - 0.5);
      V[3 * i + 2] = std::sin(pi * x) * std::sin(pi * y);
    }
  }
  for (int k = 0; k < 20; ++k) fx->solver->step();  // stressed, rotating state
  g_fixture = std::move(fx);
  return *g_fixture;
}

double cpu_now() {
  timespec t{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
  return static_cast<double>(t.tv_sec) + 1e-9 * static_cast<double>(t.tv_nsec);
}

void report(benchmark::State& state, double c0, std::size_t per_iteration) {
  const double ec = static_cast<double>(state.iterations()) * static_cast<double>(per_iteration);
  state.counters["ns_per_shell_cycle"] = benchmark::Counter(1e9 * (cpu_now() - c0) / ec);
}

void BM_ShellFullCycle(benchmark::State& state, bool fabric) {
  auto& s = *plate(fabric).solver;
  const double c0 = cpu_now();
  for (auto _ : state) s.step();
  benchmark::DoNotOptimize(s.energy().internal);
  report(state, c0, s.n_elements(fem::ElementKind::Quad4));
}

void BM_ShellInternalForceOnly(benchmark::State& state, bool fabric) {
  auto& s = *plate(fabric).solver;
  auto& blk = s.blocks<fem::Shell4Block>().at(0);
  auto X = s.x.view();
  auto V = s.v.view();
  auto F = s.f_int.view();
  std::vector<double> w(F.size(), 0.0), m(F.size(), 0.0);
  for (std::size_t i = 0; i < w.size(); ++i) w[i] = 0.1 * std::sin(0.01 * static_cast<double>(i));
  const double dt = s.time_step();
  fem::ElementEnergyIncrement inc;
  const double c0 = cpu_now();
  for (auto _ : state) {
    fem::StableStep st;
    std::fill(F.data(), F.data() + F.size(), 0.0);
    std::fill(m.begin(), m.end(), 0.0);
    fem::shell4_internal_forces(blk, X.data(), V.data(), w.data(), dt, F.data(), m.data(), inc,
                                st);
    benchmark::DoNotOptimize(st.dt);
  }
  benchmark::DoNotOptimize(inc.internal);
  report(state, c0, blk.n);
}

double min_of(const std::vector<double>& v) { return *std::min_element(v.begin(), v.end()); }

void common(benchmark::internal::Benchmark* b) {
  b->Iterations(40)->Repetitions(3)->ReportAggregatesOnly(true)->Unit(benchmark::kMillisecond);
  b->ComputeStatistics("min", min_of);
}

}  // namespace

int main(int argc, char** argv) {
  using benchmark::RegisterBenchmark;
  common(RegisterBenchmark("ShellFullCycle/elastic", BM_ShellFullCycle, false));
  common(RegisterBenchmark("ShellInternalForceOnly/elastic", BM_ShellInternalForceOnly, false));
  common(RegisterBenchmark("ShellFullCycle/fabric", BM_ShellFullCycle, true));
  common(RegisterBenchmark("ShellInternalForceOnly/fabric", BM_ShellInternalForceOnly, true));
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  {
    fem::PetscSession petsc(&argc, &argv);
    benchmark::RunSpecifiedBenchmarks();
    g_fixture.reset();
  }
  benchmark::Shutdown();
  return 0;
}

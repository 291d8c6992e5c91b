// Deformable contact cost per contact node and cycle (bucket sorts amortised + narrow phase +
// forces), on a stack of 12 plies of n x n x 1 hexahedra (1 x 1 x 0.25 mm) in self-contact: one
// contact group holds every ply, so every node is a contact node. The plies are pressed into each
// other by 2 % of their thickness (every interface node in contact) and sheared: ply p slides at
// p * 0.1 m/s with a step of 0.5 us, so the bucket sort is redone every ~110 cycles, as in a
// draping run. Counter ns_per_node_cycle: wall time per (contact node x cycle).
//   bench_contact                      12 plies of 20^2 (10k nodes), 64^2 (100k), 100^2 (245k);
//                                      AfterElements/100: 245k with the cache cleared per cycle
//                                      Vibrating/100/A: 245k, nodes vibrating A nm normal to the
//                                      plies (as a run's do: segment changes)
#include <benchmark/benchmark.h>

#include <cmath>
#include <numbers>
#include <vector>

#include "fem/contact/penalty_contact.hpp"
#include "fem/mesh.hpp"

using namespace ncfsim::fem;

namespace {

constexpr int kPlies = 12;
constexpr double kH = 1e-3, kT = 0.25e-3, kRho = 1500, kDt = 5e-7;

struct PlyStack {
  Mesh mesh;
  std::vector<double> x, v, mass, f;
  std::vector<int> ply_of_node;
};

PlyStack make_stack(int n) {
  PlyStack s;
  for (int p = 0; p < kPlies; ++p) {
    const int part = s.mesh.add_part("ply" + std::to_string(p));
    // 2 % overlap between neighbouring plies: every interface node is in contact.
    add_hex_block(s.mesh, part, {0, 0, p * 0.98 * kT}, {n * kH, n * kH, kT}, {n, n, 1});
  }
  renumber_for_locality(s.mesh);
  const std::size_t nn = s.mesh.n_nodes();
  s.x = s.mesh.coords;
  s.v.assign(3 * nn, 0.0);
  s.mass.assign(3 * nn, 0.0);
  s.f.assign(3 * nn, 0.0);
  s.ply_of_node.assign(nn, 0);
  const double m8 = kRho * kH * kH * kT / 8;
  const ElementSet& hexes = s.mesh.elements(ElementKind::Hex8);
  for (std::size_t e = 0; e < hexes.size(); ++e)
    for (auto node : hexes.nodes(e)) {
      for (int c = 0; c < 3; ++c) s.mass[3 * static_cast<std::size_t>(node) + c] += m8;
      s.ply_of_node[static_cast<std::size_t>(node)] = hexes.part[e];
    }
  for (std::size_t i = 0; i < nn; ++i) s.v[3 * i] = 0.1 * s.ply_of_node[i];  // shear, m/s
  return s;
}

// Between two cycles a run's element pass streams the element state (~48 MB for the 120k
// hexahedra of bench/cases/ply_stack_12_contact.toml), more than the 32 MB L3 of the
// development machine, so the contact starts each cycle from memory, not from the cache the
// previous cycle left (docs/performance.md, "Runs against the benchmark"). `evict` does the
// same outside the timing: the /after_elements variant.
void run_stack_self_contact(benchmark::State& state, bool evict, double vibration = 0);

void BM_StackSelfContact(benchmark::State& state) { run_stack_self_contact(state, false); }
void BM_StackSelfContactAfterElements(benchmark::State& state) {
  run_stack_self_contact(state, true);
}

// The plies of a run vibrate: each node's z oscillates about the rigid motion (amplitude
// range(1) nm, a period of 14 cycles, phases spread over the nodes), so the plies' faces wrinkle
// at the node scale. Where the plies are meshed alike a node lies at the corner of four facets
// of equal gap, and which one is nearest changes with the wrinkles: in the run of
// bench/cases/ply_stack_12_contact.toml a quarter of the contacts changed segment every cycle
// (the rigid stack: 0.4 %), and that cost the run ~35 % more per node than the rigid benchmark.
void BM_StackSelfContactVibrating(benchmark::State& state) {
  run_stack_self_contact(state, false, 1e-9 * static_cast<double>(state.range(1)));
}

void run_stack_self_contact(benchmark::State& state, bool evict, double vibration) {
  static std::vector<double> element_state;
  if (evict) element_state.assign(std::size_t{8} << 20, 1.0);  // 64 MB
  const int n = static_cast<int>(state.range(0));
  PlyStack s = make_stack(n);
  PenaltyContactConfig cfg;
  cfg.name = "stack";
  std::vector<int> parts(kPlies);
  for (int p = 0; p < kPlies; ++p) parts[static_cast<std::size_t>(p)] = p;
  cfg.groups = {{"plies", parts}};
  cfg.pairs = {{0, 0, 0.3}};
  PenaltyContact contact(cfg);
  ContactSetup setup{&s.mesh, s.mesh.coords.data(), s.mass.data(), kDt};
  contact.initialise(setup);
  const std::size_t nd = s.x.size();
  const auto sorts0 = contact.stats().n_sorts;
  const PenaltyContactStats st0 = contact.stats();
  const double sort_s0 = st0.sort_seconds;
  const std::vector<double> z0 = s.x;
  int cycle = 0;
  for (auto _ : state) {
    state.PauseTiming();
    for (std::size_t d = 0; d < nd; ++d) s.x[d] += kDt * s.v[d], s.f[d] = 0.0;
    if (vibration > 0) {
      ++cycle;
      for (std::size_t i = 0; i < nd / 3; ++i) {
        const double phase =
            2 * std::numbers::pi * std::fmod(0.6180339887 * static_cast<double>(i), 1.0);
        s.x[3 * i + 2] =
            z0[3 * i + 2] + vibration * std::sin(2 * std::numbers::pi * cycle / 14.0 + phase);
      }
    }
    if (evict) {
      for (double& e : element_state) e += 1.0;
      benchmark::DoNotOptimize(element_state.data());
    }
    state.ResumeTiming();
    contact.add_forces(s.x.data(), s.v.data(), s.mass.data(), kDt, s.f.data());
    benchmark::DoNotOptimize(s.f.data());
  }
  const double n_nodes = static_cast<double>(contact.n_contact_nodes());
  const double cycles = static_cast<double>(state.iterations());
  state.counters["contact_nodes"] = n_nodes;
  state.counters["ns_per_node_cycle"] = benchmark::Counter(
      n_nodes, benchmark::Counter::kIsIterationInvariantRate | benchmark::Counter::kInvert);
  state.counters["sorts"] = static_cast<double>(contact.stats().n_sorts - sorts0);
  state.counters["sort_ns"] = 1e9 * (contact.stats().sort_seconds - sort_s0) / (n_nodes * cycles);
  auto per_node_cycle = [&](double s1, double s0) { return 1e9 * (s1 - s0) / (n_nodes * cycles); };
  state.counters["check_ns"] = per_node_cycle(contact.stats().check_seconds, st0.check_seconds);
  state.counters["narrow_ns"] = per_node_cycle(contact.stats().narrow_seconds, st0.narrow_seconds);
  state.counters["active_per_node"] = static_cast<double>(contact.active_contacts()) / n_nodes;
  state.counters["changes_per_contact"] =
      static_cast<double>(contact.stats().n_segment_changes - st0.n_segment_changes) /
      static_cast<double>(
          std::max<std::int64_t>(contact.stats().n_contact_cycles - st0.n_contact_cycles, 1));
  state.counters["candidates_per_node"] =
      static_cast<double>(contact.stats().n_candidates) / n_nodes;
}

}  // namespace

// The same 600 cycles at every size (same kinematics, 5 bucket sorts, same candidates per node),
// so the sizes compare; repeated 3 times (the minimum is the figure to quote on a busy machine).
BENCHMARK(BM_StackSelfContact)
    ->Arg(20)
    ->Arg(64)
    ->Arg(100)
    ->Iterations(600)
    ->Repetitions(3)
    ->Unit(benchmark::kMillisecond);

// The same at 245k contact nodes with the cache cleared between cycles as a run's element pass
// clears it: the figure a run's contact timer gives.
BENCHMARK(BM_StackSelfContactAfterElements)
    ->Arg(100)
    ->Iterations(600)
    ->Repetitions(3)
    ->Unit(benchmark::kMillisecond);

// The same 245k stack vibrating by 0.5 and 2 um (of 5 um overlap: every contact stays closed).
BENCHMARK(BM_StackSelfContactVibrating)
    ->Args({100, 500})
    ->Args({100, 2000})
    ->Iterations(600)
    ->Repetitions(3)
    ->Unit(benchmark::kMillisecond);

BENCHMARK_MAIN();

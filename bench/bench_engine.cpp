// Engine throughput (issue #2, item 8): ns per element-cycle on one core.
//
//   HexFullCycle/<material>/<numbering>  full ExplicitSolver::step() cycles on a 60x50x40 block of
//                                        120,000 hexahedra (base fixed, non-uniform velocity
//                                        field): internal force (geometry, strain, material, Cauchy
//                                        stress, hourglass, scatter), loads, nodal update,
//                                        positions
//   HexInternalForceOnly/<material>      hex8_internal_forces alone on the same block;
//                                        ".../l2_resident": a 2,048-element block whose state stays
//                                        in L2 (the compute-bound figure, for reference)
//   HexFullCycle/isotropic/ply_stack     the same on bench/cases/ply_stack_12.toml's mesh: 12 plies
//                                        (parts) of 100x100x1 hexahedra of 1 x 1 x 0.25 mm, 120,000
//                                        in all, 244,824 nodes (2.04 per hexahedron, the block
//                                        1.06); x = 0 edge held; HexInternalForceOnly/.../ply_stack
//                                        the kernel alone over its 12 blocks (issue #24)
//   BarFullCycle                         full cycles of a 40x40x26-node lattice of 121,120
//                                        tension-only bars, tabulated law, pre-stretched so that
//                                        every segment of the table and slack bars occur
//   BarInternalForceOnly                 bar_internal_forces alone
//
// Numbering: "local" = renumber_for_locality (what the engine does on input); "random_nodes" =
// node ids shuffled, elements in generation order; "random_all" = nodes and elements shuffled.
// Counters: ns_per_hex_cycle / ns_per_bar_cycle = thread CPU time / (cycles x elements), so time
// descheduled on a shared machine is not counted; wall_* the same from wall time. Each benchmark
// runs a fixed number of cycles, 3 repetitions; mean, median, min are reported. < 1 min in all.
#include <benchmark/benchmark.h>
#include <time.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <memory>
#include <numbers>
#include <numeric>
#include <random>
#include <string>

#include "fem/elements/hex8_block.hpp"
#include "fem/model.hpp"
#include "fem/petsc_vector.hpp"
#include "fem/solver.hpp"
#include "impact/tow_damage_material.hpp"

using namespace ncfsim;

namespace {

enum class Mat { Isotropic, Orthotropic, TowDamage };
enum class Numbering { Local, RandomNodes, RandomAll };
enum class Shape { Block, Small, PlyStack };

constexpr std::array<int, 3> kHexDiv{60, 50, 40};        // 120,000 hexahedra, h = 10 mm
constexpr std::array<int, 3> kSmallHexDiv{16, 16, 8};    // 2,048 hexahedra: state stays in L2
constexpr std::array<int, 3> kLatticeNodes{40, 40, 26};  // 121,120 bars, 10 mm apart

struct Fixture {
  fem::Model model;
  std::unique_ptr<fem::ExplicitSolver> solver;
  std::string key;
};

// One model alive at a time: repetitions of a benchmark reuse it, the next benchmark replaces it
// (released before PETSc finalises).
std::unique_ptr<Fixture> g_fixture;

// Shuffles node ids (and optionally element order) of a mesh built in structured order.
void shuffle_numbering(fem::Mesh& mesh, bool elements, std::mt19937_64& rng) {
  const std::size_t n = mesh.n_nodes();
  std::vector<std::int32_t> new_of_old(n);
  std::iota(new_of_old.begin(), new_of_old.end(), 0);
  std::shuffle(new_of_old.begin(), new_of_old.end(), rng);
  std::vector<double> coords(mesh.coords.size());
  for (std::size_t i = 0; i < n; ++i)
    for (int k = 0; k < 3; ++k)
      coords[3 * static_cast<std::size_t>(new_of_old[i]) + k] = mesh.coords[3 * i + k];
  mesh.coords.swap(coords);
  for (auto& set : mesh.sets)
    for (auto& v : set.conn) v = new_of_old[static_cast<std::size_t>(v)];
  if (elements)
    for (auto kind : {fem::ElementKind::Hex8, fem::ElementKind::Bar2}) {  // the old shuffle order
      fem::ElementSet& set = mesh.elements(kind);
      std::vector<std::size_t> order(set.size());
      std::iota(order.begin(), order.end(), 0);
      std::shuffle(order.begin(), order.end(), rng);  // one part: part tags unchanged
      const auto nn = static_cast<std::size_t>(set.nodes_per_element);
      std::vector<std::int32_t> conn(set.conn.size());
      for (std::size_t e = 0; e < order.size(); ++e)
        for (std::size_t I = 0; I < nn; ++I) conn[nn * e + I] = set.conn[nn * order[e] + I];
      set.conn.swap(conn);
    }
  mesh.node_user_id.clear();
  for (auto& set : mesh.sets) set.user_id.clear();
  mesh.fill_default_user_ids();
}

void apply_numbering(fem::Mesh& mesh, Numbering num) {
  std::mt19937_64 rng(12345);
  if (num == Numbering::Local)
    fem::renumber_for_locality(mesh);
  else
    shuffle_numbering(mesh, num == Numbering::RandomAll, rng);
}

// A smooth, non-uniform velocity field (bending, shear and stretching) with 2 % node noise, so
// that strains, stresses and hourglass forces are all non-trivial. Fixed DOFs stay at zero.
void set_velocity_field(fem::ExplicitSolver& s, double v0, bool noise) {
  const auto& m = s.model().mesh;
  std::array<double, 3> lo{1e300, 1e300, 1e300}, hi{-1e300, -1e300, -1e300};
  for (std::size_t i = 0; i < m.n_nodes(); ++i)
    for (int k = 0; k < 3; ++k)
      lo[k] = std::min(lo[k], m.coords[3 * i + k]), hi[k] = std::max(hi[k], m.coords[3 * i + k]);
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  auto V = s.v.view();
  auto X = s.x.view();
  constexpr double pi = std::numbers::pi;
  for (std::size_t i = 0; i < m.n_nodes(); ++i) {
    const double x = (X[3 * i] - lo[0]) / (hi[0] - lo[0]),
                 y = (X[3 * i + 1] - lo[1]) / (hi[1] - lo[1]),
                 z = (X[3 * i + 2] - lo[2]) / (hi[2] - lo[2]);
    const double r = noise ? 0.02 : 0.0;
    V[3 * i] = v0 * (std::sin(pi * z) * std::cos(pi * y) + 0.3 * x + r * u(rng));
    V[3 * i + 1] = v0 * (0.5 * std::sin(pi * x) * z + 0.2 * y + r * u(rng));
    V[3 * i + 2] = v0 * (z * std::sin(0.5 * pi * x) - 0.1 * z + r * u(rng));
  }
  // Fixed DOFs of the model are zeroed again by the first step.
}

Fixture& hex_fixture(Mat mat, Numbering num, Shape shape = Shape::Block) {
  const std::string key = "hex" + std::to_string(int(mat)) + std::to_string(int(num)) + "/" +
                          std::to_string(int(shape));
  if (g_fixture && g_fixture->key == key) return *g_fixture;
  g_fixture.reset();
  auto fx = std::make_unique<Fixture>();
  fx->key = key;
  fem::Model& model = fx->model;
  if (shape == Shape::PlyStack) {
    for (int ply = 0; ply < 12; ++ply) {
      const int p = model.mesh.add_part("ply" + std::to_string(ply));
      fem::add_hex_block(model.mesh, p, {0, 0, ply * 0.25e-3}, {0.1, 0.1, 0.25e-3}, {100, 100, 1});
    }
  } else {
    const int p = model.mesh.add_part("block");
    const auto div = shape == Shape::Small ? kSmallHexDiv : kHexDiv;
    fem::add_hex_block(model.mesh, p, {0, 0, 0}, {0.01 * div[0], 0.01 * div[1], 0.01 * div[2]},
                       div);
  }
  model.parts.resize(model.mesh.part_names.size());
  for (auto& part : model.parts) part.material = 0;
  if (mat == Mat::Isotropic) {
    model.materials.push_back(std::make_unique<fem::ElasticIsotropic>("steel", 7850.0, 210e9, 0.3));
  } else {
    // Carbon/epoxy-like, fibre axes turned 30 degrees about z.
    const fem::OrthotropicConstants c{135e9, 10e9, 10e9, 0.3, 0.3, 0.45, 5e9, 5e9, 3.5e9};
    if (mat == Mat::Orthotropic) {
      model.materials.push_back(std::make_unique<fem::ElasticOrthotropic>("cfrp", 1550.0, c));
    } else {
      // The same tow with the impregnated-tow damage law (issue #21): initiation per mode and
      // crack-band softening evaluated for every element every cycle.
      impact::TowDamageConstants d;
      d.density = 1550.0;
      d.elastic = c;
      d.strength = {2.3e9, 1.4e9, 60e6, 36e6, 80e6, 60e6};
      d.fracture_energy = {9e5, 8e5, 3e3, 8e3, 8e3, 5e3};  // J/m^2: no snap-back at h = 10 mm
      d.default_length = 0.01;
      model.materials.push_back(std::make_unique<impact::TowDamageMaterial>("cfrp_damage", d));
    }
    const double a = std::numbers::pi / 6, ca = std::cos(a), sa = std::sin(a);
    for (auto& part : model.parts) part.material_axes = {ca, -sa, 0, sa, ca, 0, 0, 0, 1};
  }
  apply_numbering(model.mesh, num);
  std::vector<std::int32_t> base;
  const int held_axis = shape == Shape::PlyStack ? 0 : 2;  // the stack: its x = 0 edge
  for (std::size_t i = 0; i < model.mesh.n_nodes(); ++i)
    if (model.mesh.coords[3 * i + held_axis] < 1e-9) base.push_back(static_cast<std::int32_t>(i));
  model.fixed.push_back({"base", base, {true, true, true}});
  model.time.end_time = 1.0;
  fx->solver = std::make_unique<fem::ExplicitSolver>(model);
  set_velocity_field(*fx->solver, 1.0, true);
  for (int k = 0; k < 3; ++k) fx->solver->step();  // warm caches, non-zero stress state
  g_fixture = std::move(fx);
  return *g_fixture;
}

// `use` keeps the two bar benchmarks on separate, fresh fixtures: the kernel-only figure must not
// depend on the state the full cycles left behind.
Fixture& bar_fixture(const std::string& use) {
  const std::string key = "bar/" + use;
  if (g_fixture && g_fixture->key == key) return *g_fixture;
  g_fixture.reset();
  auto fx = std::make_unique<Fixture>();
  fx->key = key;
  fem::Model& model = fx->model;
  auto& mesh = model.mesh;
  const int p = mesh.add_part("stitches");
  fem::ElementSet& bars = mesh.elements(fem::ElementKind::Bar2);
  const auto [a, b, c] = kLatticeNodes;
  const double h = 0.01;
  auto id = [&](int i, int j, int k) { return static_cast<std::int32_t>(i + a * (j + b * k)); };
  for (int k = 0; k < c; ++k)
    for (int j = 0; j < b; ++j)
      for (int i = 0; i < a; ++i) {
        mesh.coords.push_back(h * i);
        mesh.coords.push_back(h * j);
        mesh.coords.push_back(h * k);
      }
  for (int k = 0; k < c; ++k)
    for (int j = 0; j < b; ++j)
      for (int i = 0; i < a; ++i) {
        if (i + 1 < a) bars.add({id(i, j, k), id(i + 1, j, k)}, p);
        if (j + 1 < b) bars.add({id(i, j, k), id(i, j + 1, k)}, p);
        if (k + 1 < c) bars.add({id(i, j, k), id(i, j, k + 1)}, p);
      }
  // Polyester-yarn-like tabulated law, tension only: toe, linear, stiffening.
  model.bar_laws.emplace_back("yarn", std::vector<double>{0.0, 0.005, 0.02, 0.05, 0.1},
                              std::vector<double>{0.0, 0.5, 4.0, 15.0, 40.0}, true, 1e-5);
  model.parts.resize(1);
  model.parts[0].bar_law = 0;
  fem::renumber_for_locality(mesh);
  // The boundary nodes are held, so that the stretch below stays in the lattice.
  std::vector<std::int32_t> boundary;
  for (std::size_t i = 0; i < mesh.n_nodes(); ++i) {
    bool on = false;
    for (int k = 0; k < 3; ++k) {
      const double xk = mesh.coords[3 * i + k],
                   hi = h * (kLatticeNodes[static_cast<std::size_t>(k)] - 1);
      on = on || xk < 1e-9 || xk > hi - 1e-9;
    }
    if (on) boundary.push_back(static_cast<std::int32_t>(i));
  }
  model.fixed.push_back({"boundary", boundary, {true, true, true}});
  model.time.end_time = 1.0;
  fx->solver = std::make_unique<fem::ExplicitSolver>(model);
  // Loaded state: 3 % mean stretch with node noise puts the bars in every segment of the table,
  // a few percent slack; a small random velocity keeps it moving.
  {
    auto V = fx->solver->v.view();
    auto X = fx->solver->x.view();
    std::mt19937_64 rng(3);
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    for (std::size_t i = 0; i < 3 * mesh.n_nodes(); ++i) {
      X[i] = 1.03 * X[i] + 0.0005 * u(rng);
      V[i] = 0.1 * u(rng);
    }
  }
  for (int k = 0; k < 3; ++k) fx->solver->step();
  g_fixture = std::move(fx);
  return *g_fixture;
}

// Thread CPU time: on a shared machine, time spent descheduled is not charged to the engine.
struct Timer {
  static double cpu() {
    timespec ts{};
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
    return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
  }
  static double wall() {
    return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch())
        .count();
  }
  double c0 = cpu(), w0 = wall();
};

// ns_per_*_cycle from thread CPU time, wall_ns_per_*_cycle from wall time.
void report(benchmark::State& state, const std::string& name, const Timer& t,
            std::size_t element_cycles_per_iteration) {
  const double cpu = Timer::cpu() - t.c0, wall = Timer::wall() - t.w0;
  const double ec =
      static_cast<double>(state.iterations()) * static_cast<double>(element_cycles_per_iteration);
  state.counters[name] = benchmark::Counter(1e9 * cpu / ec);
  state.counters["wall_" + name] = benchmark::Counter(1e9 * wall / ec);
  state.SetItemsProcessed(state.iterations() *
                          static_cast<std::int64_t>(element_cycles_per_iteration));
}

void BM_HexFullCycle(benchmark::State& state, Mat mat, Numbering num, Shape shape) {
  auto& fx = hex_fixture(mat, num, shape);
  auto& s = *fx.solver;
  const Timer t;
  for (auto _ : state) s.step();
  benchmark::DoNotOptimize(s.energy().internal);
  report(state, "ns_per_hex_cycle", t, s.n_elements(fem::ElementKind::Hex8));
}

void BM_HexInternalForceOnly(benchmark::State& state, Mat mat, Shape shape) {
  auto& fx = hex_fixture(mat, Numbering::Local, shape);
  auto& s = *fx.solver;
  const auto blocks = s.blocks<fem::Hex8Block>();
  auto X = s.x.view();
  auto V = s.v.view();
  auto F = s.f_int.view();
  const double dt = s.time_step();
  const int reps = shape == Shape::Small ? 50 : 1;  // the small block: 50 calls per iteration
  fem::ElementEnergyIncrement inc;
  const Timer t;
  for (auto _ : state) {
    for (int r = 0; r < reps; ++r) {
      fem::StableStep st;
      std::fill(F.data(), F.data() + F.size(), 0.0);
      for (auto& blk : blocks)
        fem::hex8_internal_forces(blk, X.data(), V.data(), dt, F.data(), inc, st);
      benchmark::DoNotOptimize(st.dt);
    }
  }
  benchmark::DoNotOptimize(inc.internal);
  report(state, "ns_per_hex_cycle", t,
         s.n_elements(fem::ElementKind::Hex8) * static_cast<std::size_t>(reps));
}

void BM_BarFullCycle(benchmark::State& state) {
  auto& s = *bar_fixture("full").solver;
  const Timer t;
  for (auto _ : state) s.step();
  benchmark::DoNotOptimize(s.energy().internal);
  report(state, "ns_per_bar_cycle", t, s.n_elements(fem::ElementKind::Bar2));
}

void BM_BarInternalForceOnly(benchmark::State& state) {
  auto& s = *bar_fixture("kernel").solver;
  auto& blk = s.blocks<fem::BarBlock>().at(0);
  auto X = s.x.view();
  auto F = s.f_int.view();
  fem::ElementEnergyIncrement inc;
  const Timer t;
  for (auto _ : state) {
    fem::StableStep st;
    std::fill(F.data(), F.data() + F.size(), 0.0);
    fem::bar_internal_forces(blk, X.data(), F.data(), inc, st);
    benchmark::DoNotOptimize(st.dt);
  }
  benchmark::DoNotOptimize(inc.internal);
  report(state, "ns_per_bar_cycle", t, blk.n);
}

double min_of(const std::vector<double>& v) { return *std::min_element(v.begin(), v.end()); }

void common(benchmark::internal::Benchmark* b, int iterations) {
  b->Iterations(iterations)
      ->Repetitions(3)
      ->ReportAggregatesOnly(true)
      ->Unit(benchmark::kMillisecond);
  b->ComputeStatistics("min", min_of);
}

void register_all() {
  using benchmark::RegisterBenchmark;
  common(RegisterBenchmark("HexFullCycle/isotropic/local", BM_HexFullCycle, Mat::Isotropic,
                           Numbering::Local, Shape::Block),
         40);
  common(RegisterBenchmark("HexFullCycle/isotropic/ply_stack", BM_HexFullCycle, Mat::Isotropic,
                           Numbering::Local, Shape::PlyStack),
         40);
  common(RegisterBenchmark("HexFullCycle/orthotropic/local", BM_HexFullCycle, Mat::Orthotropic,
                           Numbering::Local, Shape::Block),
         40);
  common(RegisterBenchmark("HexFullCycle/tow_damage/local", BM_HexFullCycle, Mat::TowDamage,
                           Numbering::Local, Shape::Block),
         40);
  common(RegisterBenchmark("HexFullCycle/isotropic/random_nodes", BM_HexFullCycle, Mat::Isotropic,
                           Numbering::RandomNodes, Shape::Block),
         40);
  common(RegisterBenchmark("HexFullCycle/isotropic/random_all", BM_HexFullCycle, Mat::Isotropic,
                           Numbering::RandomAll, Shape::Block),
         40);
  common(RegisterBenchmark("HexInternalForceOnly/isotropic", BM_HexInternalForceOnly,
                           Mat::Isotropic, Shape::Block),
         40);
  common(RegisterBenchmark("HexInternalForceOnly/isotropic/ply_stack", BM_HexInternalForceOnly,
                           Mat::Isotropic, Shape::PlyStack),
         40);
  common(RegisterBenchmark("HexInternalForceOnly/orthotropic", BM_HexInternalForceOnly,
                           Mat::Orthotropic, Shape::Block),
         40);
  common(RegisterBenchmark("HexInternalForceOnly/tow_damage", BM_HexInternalForceOnly,
                           Mat::TowDamage, Shape::Block),
         40);
  common(RegisterBenchmark("HexInternalForceOnly/isotropic/l2_resident", BM_HexInternalForceOnly,
                           Mat::Isotropic, Shape::Small),
         40);
  common(RegisterBenchmark("BarFullCycle", BM_BarFullCycle), 200);
  common(RegisterBenchmark("BarInternalForceOnly", BM_BarInternalForceOnly), 200);
}

}  // namespace

int main(int argc, char** argv) {
  register_all();
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  {
    fem::PetscSession petsc(&argc, &argv);
    benchmark::RunSpecifiedBenchmarks();
    g_fixture.reset();  // PETSc vectors die before PetscFinalize
  }
  benchmark::Shutdown();
  return 0;
}

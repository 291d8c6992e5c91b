// The forming cycle as a run does it: the whole model of a forming case (rigid tools, the fabric's
// self-contact, stitch bars and stitch-to-tow joints), read by the same case reader as
// `ncfsim run` and stepped by the same solver, without output. Counters, all in thread CPU time:
//   ns_per_hex_cycle   per (hexahedron x cycle), all in: the run's log line "cycle in ns of CPU
//                      per hexahedron-cycle" summed (docs/performance.md, "Forming")
//   <phase>            the same per phase (element kinds, each tool, each contact, update), from
//                      the solver's phase timers scaled to the CPU time
// Environment:
//   NCFSIM_FORMING_CASE        case file (default cases/hemisphere/drape.toml: the paper's model)
//   NCFSIM_FORMING_SET         --set items separated by ';' (e.g. "mesh.resolution=coarse")
//   NCFSIM_FORMING_CHECKPOINT  checkpoint.h5 of a 1-rank run of the same case and items (stopped
//                              with time.max_cycles, or interrupted): the state that is timed, e.g.
//                              at 40 or 75 ms of the stroke; without it the model starts at rest
//   NCFSIM_FORMING_WARMUP      cycles stepped before timing (default 100)
//   bench_forming --benchmark_min_time=... ; each iteration is one cycle.
#include <benchmark/benchmark.h>
#include <time.h>

#include <cstdlib>
#include <filesystem>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include "fem/io/hdf5_checkpoint.hpp"
#include "fem/petsc_vector.hpp"
#include "fem/solver.hpp"
#include "workflow/case/engine_case.hpp"
#include "workflow/run/run_summary.hpp"

using namespace ncfsim;

namespace {

double thread_cpu() {
  timespec ts{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}

std::string env_or(const char* name, const std::string& fallback) {
  const char* v = std::getenv(name);
  return v && *v ? std::string(v) : fallback;
}

struct Forming {
  workflow::EngineCase ec;
  std::unique_ptr<fem::ExplicitSolver> solver;
};

std::unique_ptr<Forming> g_forming;

void BM_FormingCycle(benchmark::State& state) {
  if (!g_forming) {
    std::filesystem::path file = env_or("NCFSIM_FORMING_CASE", "cases/hemisphere/drape.toml");
    if (file.is_relative() && !std::filesystem::exists(file))
      file = std::filesystem::path(NCFSIM_SOURCE_DIR) / file;
    std::vector<std::string> items;
    std::stringstream ss(env_or("NCFSIM_FORMING_SET", ""));
    for (std::string item; std::getline(ss, item, ';');)
      if (!item.empty()) items.push_back(item);
    g_forming = std::make_unique<Forming>();
    g_forming->ec = workflow::load_engine_case(file, items);
    g_forming->solver = std::make_unique<fem::ExplicitSolver>(g_forming->ec.model);
    const std::string ck = env_or("NCFSIM_FORMING_CHECKPOINT", "");
    if (!ck.empty()) {
      fem::CheckpointTree t = fem::io::read_checkpoint_file(ck);
      g_forming->solver->load_state(t);
    }
    const int warmup = std::atoi(env_or("NCFSIM_FORMING_WARMUP", "100").c_str());
    for (int k = 0; k < warmup; ++k) g_forming->solver->step({}, false);
  }
  fem::ExplicitSolver& s = *g_forming->solver;
  const auto phases0 = workflow::cycle_phases(s);
  const auto t0 = s.timers();
  double wall0 = t0.internal_force + t0.contact + t0.update + t0.exchange;
  const double cpu0 = thread_cpu();
  std::int64_t cycles = 0;
  for (auto _ : state) {
    s.step({}, false);
    ++cycles;
  }
  const double cpu = thread_cpu() - cpu0;
  const auto t1 = s.timers();
  const double wall = t1.internal_force + t1.contact + t1.update + t1.exchange - wall0;
  const double n_hex = static_cast<double>(s.n_elements(fem::ElementKind::Hex8));
  const double per = 1e9 / (n_hex * static_cast<double>(cycles));
  state.counters["ns_per_hex_cycle"] = cpu * per;
  state.counters["t_ms"] = 1e3 * s.time();
  const double share = wall > 0 ? cpu / wall : 1.0;
  const auto phases1 = workflow::cycle_phases(s);
  for (std::size_t k = 0; k < phases1.size() && k < phases0.size(); ++k)
    state.counters[phases1[k].first] = share * per * (phases1[k].second - phases0[k].second);
}

}  // namespace

int main(int argc, char** argv) {
  benchmark::RegisterBenchmark("FormingCycle", BM_FormingCycle)
      ->Unit(benchmark::kMillisecond)
      ->Iterations(100)
      ->Repetitions(3);
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  {
    fem::PetscSession petsc(&argc, &argv);
    benchmark::RunSpecifiedBenchmarks();
    g_forming.reset();  // PETSc vectors die before PetscFinalize
  }
  benchmark::Shutdown();
  return 0;
}

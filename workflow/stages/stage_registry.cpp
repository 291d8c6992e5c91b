#include "workflow/stages/stage_registry.hpp"

#include <algorithm>
#include <cstdio>
#include <cstdlib>

#include "drape/case/kinematic_case.hpp"
#include "fem/case/model_size.hpp"
#include "fem/case/stage_kinds.hpp"
#include "fem/case/toml_reader.hpp"
#include "fem/errors.hpp"
#include "fem/memory_estimate.hpp"
#include "fem/petsc_vector.hpp"
#include "fem/solver.hpp"
#include "workflow/calibrate/calibration_stage.hpp"
#include "workflow/run/run_summary.hpp"
#include "workflow/stages/kinematic_drape_stage.hpp"
#include "workflow/stages/transfer_stage.hpp"
#include "workflow/stages/workflow_stage.hpp"
#include "workflow/version.hpp"

namespace ncfsim::workflow {

namespace {

int run_engine_stage(const StageCall& call) {
  EngineCase ec = load_engine_case(call.case_file, call.overrides);
  fem::PetscSession petsc;  // after the case: bad input is reported without starting MPI
  // Several ranks (docs/parallel.md): the root runs the case and writes its files, the others
  // integrate their share.
  if (fem::PetscSession::rank() != 0) return run_engine_worker(ec, call.options);
  return run_engine_case(ec, call.options);
}

int check_engine_stage(const StageCall& call) {
  auto ec = load_engine_case(call.case_file, call.overrides);
  // Building the solver checks what only the assembled model can show (massless nodes, steps).
  fem::PetscSession petsc;
  if (const int code = refuse_many_ranks()) return code;
  const fem::MemoryEstimate memory = fem::estimate_memory(ec.model, 1, ec.output.memory());
  fem::ExplicitSolver probe(ec.model);
  std::printf(
      "%s: OK (case '%s', %zu nodes, %s, stable step %.4g s, about %.3g cycles; memory %s of %s "
      "available)\n",
      call.case_file.c_str(), ec.name.c_str(), ec.model.mesh.n_nodes(),
      element_counts(probe).c_str(), probe.time_step(), ec.model.time.end_time / probe.time_step(),
      memory.describe().c_str(), fem::bytes_text(fem::available_memory_bytes()).c_str());
  // What the case's laws will change (a crush's crack band raising energies), as the run warns.
  for (const auto& line : ec.crush.crack_band.warnings())
    std::printf("warning: %s\n", line.c_str());
  return kSuccess;
}

int check_kinematic_drape_stage(const StageCall& call) {
  const auto kc = drape::load_kinematic_drape_case(call.case_file, call.overrides);
  std::printf(
      "%s: OK (case '%s', kinematic drape, %zu surfaces, net of %d x %d joints at %.4g m)\n",
      call.case_file.c_str(), kc.name.c_str(), kc.surface.bodies.size(), 2 * kc.net.half_nodes + 1,
      2 * kc.net.half_nodes + 1, kc.net.spacing);
  return kSuccess;
}

}  // namespace

nlohmann::json stage_summary_header(const std::string& case_name, const StageCall& call,
                                    const std::string& stage) {
  nlohmann::json s;
  s["case"] = case_name;
  s["case_file"] = call.case_file.string();
  s["stage"] = stage;
  s["ncfsim_version"] = kVersion;
  s["overrides"] = call.overrides;
  s["status"] = "completed";
  return s;
}

namespace {
// What the launchers (Open MPI, MPICH/Hydra, Slurm's PMI) put in a rank's environment: the
// world size.
constexpr const char* kLauncherSizeVars[] = {"OMPI_COMM_WORLD_SIZE", "PMI_SIZE", "MPI_LOCALNRANKS"};
}  // namespace

bool started_by_mpi_launcher() {
  for (const char* v : kLauncherSizeVars)
    if (std::getenv(v)) return true;
  return false;
}

int launcher_world_size() {
  for (const char* v : kLauncherSizeVars)
    if (const char* n = std::getenv(v)) return std::max(1, std::atoi(n));
  return 1;
}

int refuse_many_ranks() {
  const int n = fem::PetscSession::size();
  if (n <= 1) return 0;
  if (fem::PetscSession::rank() == 0)
    std::fprintf(stderr,
                 "ncfsim: bad input: started on %d MPI ranks: this command runs on one rank "
                 "(only `ncfsim run` of engine and crush cases is split over ranks, "
                 "docs/parallel.md): start it without --np / mpirun\n",
                 n);
  return kBadInput;
}

const std::vector<Stage>& stages() {
  static const std::vector<Stage> registry{
      {fem::stage_kind::kEngine,
       "explicit finite-element run (virtual tests, forming, crush)",
       &run_engine_stage,
       &check_engine_stage,
       true,
       false,
       {{"formed_shear_iso.png", "the formed part by shear angle"}},
       "",
       ""},
      {fem::stage_kind::kCrush,
       "explicit crush of an impregnated part from a transfer (tow damage per mode, cohesive "
       "resin bonds, punch force filtered at a CFC class)",
       &run_engine_stage,
       &check_engine_stage,
       true,
       false,
       {{"crush_force.png", "punch force against stroke"},
        {"failed_mode.png", "failed mode per tow element"}},
       "",
       ""},
      {fem::stage_kind::kKinematicDrape,
       "pin-jointed net (fishnet) drape on rigid tool surfaces, ring shear measure",
       &run_kinematic_drape_stage,
       &check_kinematic_drape_stage,
       false,
       false,
       {},
       "kinematic_shear_deg",
       " (pin-jointed net)"},
      {fem::stage_kind::kTransfer,
       "draped tows to the impregnated composite model (micromechanics, Vf from compaction, ties)",
       &run_transfer_stage,
       &check_transfer_stage,
       false,
       false,
       {},
       "",
       ""},
      {fem::stage_kind::kCalibration,
       "a law from virtual tests (macro membrane law from the picture frames, tow E11f from the "
       "cantilever, stitch law from bias-extension data), handed on as laws.toml",
       &run_calibration_stage,
       &check_calibration_stage,
       false,
       false,
       {},
       "",
       "",
       kLawsFile},
      {fem::stage_kind::kWorkflow,
       "stages (drape, fishnet, transfer, crush, ...) from case files of their own into one "
       "folder, unchanged stages skipped, one report",
       &run_workflow_stage,
       &check_workflow_stage,
       false,
       true,
       {},
       "",
       ""},
  };
  return registry;
}

const Stage* stage_of_kind(const std::string& kind) {
  for (const auto& s : stages())
    if (s.kind == kind) return &s;
  return nullptr;
}

const Stage& find_stage(const std::string& kind, const std::filesystem::path& file) {
  for (const auto& s : stages())
    if (s.kind == kind) return s;
  std::string allowed;
  for (const auto& s : stages()) allowed += (allowed.empty() ? "" : ", ") + s.kind;
  throw InputError(file.string(), "case.kind",
                   "'" + kind + "' is not a stage kind; allowed: " + allowed);
}

std::string case_kind(const std::filesystem::path& file,
                      const std::vector<std::string>& overrides) {
  const fem::CaseDocument doc = fem::CaseDocument::load(file, overrides);
  const auto* c = doc.root()["case"].as_table();
  if (!c || !c->contains("kind")) return fem::stage_kind::kEngine;
  const auto kind = (*c)["kind"].value<std::string>();
  if (!kind)
    throw InputError(file.string(), "case.kind",
                     "must be a string (allowed: a stage kind, e.g. engine)");
  return *kind;
}

std::filesystem::path run_output_folder(const std::filesystem::path& file,
                                        const std::vector<std::string>& overrides,
                                        const std::string& out_dir) {
  if (!out_dir.empty()) return out_dir;
  const fem::CaseDocument doc = fem::CaseDocument::load(file, overrides);
  const auto name = doc.root()["case"]["name"].value<std::string>();
  return name ? std::filesystem::path("results") / *name : std::filesystem::path();
}

namespace {
// "engine and crush": the kinds split over ranks, for messages.
std::string time_loop_kinds() {
  std::vector<std::string> k;
  for (const auto& s : stages())
    if (s.time_loop) k.push_back(s.kind);
  std::string out;
  for (std::size_t i = 0; i < k.size(); ++i)
    out += (i == 0 ? "" : i + 1 == k.size() ? " and " : ", ") + k[i];
  return out;
}
}  // namespace

int run_stage(const StageCall& call) {
  const std::string kind = case_kind(call.case_file, call.overrides);
  const Stage& stage = find_stage(kind, call.case_file);
  // Only time-loop runs write checkpoints (a workflow passes --resume on to its stages); the
  // other stages are short and rerun.
  if (call.options.resume && !stage.time_loop && !stage.holds_stages)
    throw InputError(
        call.case_file.string(), "--resume",
        "a '" + kind + "' stage keeps no checkpoint (it is short): run it without --resume");
  // Several ranks (docs/parallel.md): the time-loop runs only. Read from the launcher's
  // environment: the other stages never start MPI.
  if (stage.holds_stages && launcher_world_size() > 1)
    throw InputError(call.case_file.string(), "--np",
                     "a " + kind + " runs on one MPI rank: start it without mpirun; `ncfsim run " +
                         "CASE --np N` runs its " + time_loop_kinds() + " stages on N ranks each");
  if (!stage.time_loop && launcher_world_size() > 1)
    throw InputError(call.case_file.string(), "--np",
                     "a '" + kind + "' stage runs on one MPI rank (only " + time_loop_kinds() +
                         " cases are split over ranks): run it without --np / mpirun, or give "
                         "--np to the stage cases themselves");
  return stage.run(call);
}

int check_stage(const StageCall& call) {
  return find_stage(case_kind(call.case_file, call.overrides), call.case_file).check(call);
}

}  // namespace ncfsim::workflow

// The kinematic (pin-jointed net) drape as a stage: the net on the case's surfaces, the ring shear
// measure (ring_shear.csv), the quadrant maxima (summary.json kinematic_max_shear_deg_q1..q4) and
// the net itself (net.csv: joint, position, shear). docs/output.md, "Kinematic drape".
#include "workflow/stages/kinematic_drape_stage.hpp"

#include <fmt/format.h>
#include <spdlog/logger.h>

#include <chrono>
#include <nlohmann/json.hpp>

#include "drape/case/kinematic_case.hpp"
#include "fem/case/stage_kinds.hpp"
#include "workflow/output/output_files.hpp"
#include "workflow/version.hpp"

namespace ncfsim::workflow {

namespace {

std::string net_csv(const drape::KinematicNet& net) {
  std::string s = "i,j,x_m,y_m,z_m,shear_deg\n";
  for (int j = -net.n; j <= net.n; ++j)
    for (int i = -net.n; i <= net.n; ++i) {
      if (!net.has(i, j)) continue;
      const auto& p = net.x[net.index(i, j)];
      s += fmt::format("{},{},{:.9g},{:.9g},{:.9g},{:.6g}\n", i, j, p.x, p.y, p.z,
                       net.shear_deg[net.index(i, j)]);
    }
  return s;
}

}  // namespace

int run_kinematic_drape_stage(const StageCall& call) {
  const auto kc = drape::load_kinematic_drape_case(call.case_file, call.overrides);
  const auto t0 = std::chrono::steady_clock::now();
  const std::filesystem::path dir = output_folder(kc.name, call.options);
  const OutputFolder folder =
      OutputFolder::claim(dir, call.options.overwrite, {}, "kinematic drape");
  auto log = make_run_logger(dir, call.options.verbosity);
  log->info("ncfsim {} | case '{}' ({}) | kinematic drape", kVersion, kc.name,
            call.case_file.string());
  if (!kc.description.empty()) log->info("  {}", kc.description);
  for (const auto& o : call.overrides) log->info("  --set {}", o);

  const auto net = drape::kinematic_drape(kc.surface, kc.net);
  const std::size_t joints =
      static_cast<std::size_t>(net.side()) * static_cast<std::size_t>(net.side());
  log->info(
      "net: {} x {} joints, spacing {:.4g} m, fibres at {:.4g} / {:.4g} deg, {} joints not placed "
      "(where the net locks)",
      net.side(), net.side(), net.spacing, kc.fibre_angles_deg[0], kc.fibre_angles_deg[1],
      net.n_locked);
  const auto ring = drape::ring_shear(net.x, net.triangles(), net.shear_deg, kc.ring);
  const auto q = drape::quadrant_maxima(ring);
  std::size_t missed = 0;
  for (const auto& r : ring) missed += r.hit ? 0 : 1;
  if (missed)
    log->warn("ring: {} of {} azimuths do not meet the net (reach too short?)", missed,
              ring.size());
  log->info("ring at {:.4g} m: max shear q1 {:.2f}, q2 {:.2f}, q3 {:.2f}, q4 {:.2f} deg",
            kc.ring.height, q.max_shear_deg[0], q.max_shear_deg[1], q.max_shear_deg[2],
            q.max_shear_deg[3]);

  write_file_atomically(dir / "ring_shear.csv", drape::ring_csv(ring, "kinematic_shear_deg"));
  write_file_atomically(dir / "net.csv", net_csv(net));
  nlohmann::json s = stage_summary_header(kc.name, call, fem::stage_kind::kKinematicDrape);
  s["net_joints"] = joints;
  s["net_joints_not_placed"] = net.n_locked;
  s["net_spacing_m"] = net.spacing;
  s["ring_height_m"] = kc.ring.height;
  s["ring_samples"] = ring.size();
  s["ring_samples_missed"] = missed;
  for (int k = 0; k < 4; ++k) {
    const auto kk = static_cast<std::size_t>(k);
    if (q.samples[kk] > 0)
      s[fmt::format("kinematic_max_shear_deg_q{}", k + 1)] = q.max_shear_deg[kk];
    else
      s[fmt::format("kinematic_max_shear_deg_q{}", k + 1)] = nullptr;
  }
  s["wall_seconds"] = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  write_file_atomically(dir / "summary.json", s.dump(2) + "\n");
  log->info("wrote {}", (dir / "summary.json").string());
  folder.finish();
  return missed == ring.size() ? kNumericalFailure : kSuccess;
}

}  // namespace ncfsim::workflow

#include "workflow/run/engine_run.hpp"

#include <fmt/format.h>
#include <spdlog/logger.h>

#include <chrono>
#include <cmath>
#include <fstream>
#include <limits>
#include <sstream>

#include "drape/stitch_calibration.hpp"
#include "drape/stitch_connection.hpp"
#include "fem/elements/element_fields.hpp"
#include "fem/errors.hpp"
#include "fem/io/result_writers.hpp"
#include "fem/solver.hpp"
#include "workflow/figures/figures.hpp"
#include "workflow/report/report.hpp"
#include "workflow/version.hpp"

namespace ncfsim::workflow {

namespace {

using Clock = std::chrono::steady_clock;
using fem::V3;
using json = nlohmann::json;

std::string hms(double seconds) {
  if (!std::isfinite(seconds) || seconds < 0) return "--:--";
  const auto s = static_cast<long>(seconds + 0.5);
  if (s >= 3600) return fmt::format("{}:{:02}:{:02}", s / 3600, (s / 60) % 60, s % 60);
  return fmt::format("{:02}:{:02}", s / 60, s % 60);
}

// Axis a tool reports its scalar force and displacement along: its motion direction.
V3 tool_axis(const fem::RigidTool& t) {
  if (t.motion.kind == fem::ToolMotion::Kind::Velocity && norm(t.motion.velocity) > 0) return normalized(t.motion.velocity);
  if (t.motion.kind == fem::ToolMotion::Kind::Force) return t.motion.axis;
  return t.surface.axis;
}

struct HistoryColumns {
  std::vector<std::string> names;
  /// Index of a column, -1 when absent.
  int index(const std::string& name) const {
    for (std::size_t c = 0; c < names.size(); ++c)
      if (names[c] == name) return static_cast<int>(c);
    return -1;
  }
  void add(std::string n) { names.push_back(std::move(n)); }
  void add_xyz(const std::string& prefix, const std::string& unit) {
    for (const char* c : {"x", "y", "z"}) add(prefix + "_" + c + "_" + unit);
  }
};

// Output mesh in the solver's block order, so element fields map one to one.
fem::io::ResultMesh result_mesh(const fem::ExplicitSolver& s) {
  fem::io::ResultMesh m;
  m.points = s.model().mesh.coords;
  m.part_names = s.model().mesh.part_names;
  for (const auto& b : s.blocks<fem::Hex8Block>())
    for (std::size_t e = 0; e < b.n; ++e) {
      for (int I = 0; I < 8; ++I) m.hex8.push_back(b.conn[static_cast<std::size_t>(I) * b.n + e]);
      m.hex_part.push_back(b.part);
    }
  for (const auto& b : s.blocks<fem::BarBlock>())
    for (std::size_t e = 0; e < b.n; ++e) {
      m.bar2.push_back(b.conn[e]);
      m.bar2.push_back(b.conn[b.n + e]);
      m.bar_part.push_back(b.part);
    }
  return m;
}

fem::io::Frame make_frame(const fem::ExplicitSolver& s) {
  fem::io::Frame fr;
  fr.time = s.time();
  fr.cycle = static_cast<int>(s.cycle());
  const std::size_t nn = s.model().mesh.n_nodes();
  auto X = s.x.view();
  auto X0 = s.x0.view();
  auto Vv = s.v.view();
  fr.displacement.resize(3 * nn);
  for (std::size_t d = 0; d < 3 * nn; ++d) fr.displacement[d] = X[d] - X0[d];
  fr.fields.push_back({"velocity", false, 3, std::vector<double>(Vv.data(), Vv.data() + 3 * nn)});
  const std::size_t nh = s.n_elements(fem::ElementKind::Hex8), nb = s.n_elements(fem::ElementKind::Bar2);
  const double nan = std::numeric_limits<double>::quiet_NaN();
  fem::io::FrameField stress{"stress", true, 6, std::vector<double>(6 * (nh + nb), nan)};
  fem::io::FrameField vm{"von_mises_stress", true, 1, std::vector<double>(nh + nb, nan)};
  fem::io::FrameField fibre{"fibre_direction", true, 3, std::vector<double>(3 * (nh + nb), nan)};
  fem::io::FrameField axial{"axial_force", true, 1, std::vector<double>(nh + nb, nan)};
  fem::io::FrameField bstrain{"axial_strain", true, 1, std::vector<double>(nh + nb, nan)};
  std::size_t off = 0;
  for (const auto& b : s.blocks<fem::Hex8Block>()) {
    fem::hex8_output_fields(b, X.data(), stress.values.data() + 6 * off, vm.values.data() + off,
                            fibre.values.data() + 3 * off);
    off += b.n;
  }
  for (const auto& b : s.blocks<fem::BarBlock>()) {
    for (std::size_t e = 0; e < b.n; ++e) {
      axial.values[off + e] = b.force[e];
      bstrain.values[off + e] = b.strain[e];
    }
    off += b.n;
  }
  if (nh) {
    fr.fields.push_back(std::move(stress));
    fr.fields.push_back(std::move(vm));
    fr.fields.push_back(std::move(fibre));
  }
  if (nh && s.model().time.erosion_step_ratio > 0) {
    // 1 where a hexahedron was eroded (ParaView: threshold it away)
    fem::io::FrameField eroded{"eroded", true, 1, std::vector<double>(nh + nb, 0.0)};
    std::size_t o = 0;
    for (const auto& b : s.blocks<fem::Hex8Block>()) {
      if (b.n_eroded)
        for (std::size_t e = 0; e < b.n; ++e) eroded.values[o + e] = b.eroded[e];
      o += b.n;
    }
    fr.fields.push_back(std::move(eroded));
  }
  if (nb) {
    fr.fields.push_back(std::move(axial));
    fr.fields.push_back(std::move(bstrain));
  }
  return fr;
}

void clean_previous_results(const std::filesystem::path& dir) {
  for (const char* f : {"results.h5", "results.xdmf", "results.pvd", "history.csv", "summary.json",
                        "report.html", "figures.json", "case.toml", "log.txt"})
    std::filesystem::remove(dir / f);
  std::filesystem::remove_all(dir / "frames");
  std::filesystem::remove_all(dir / "figures");
}

}  // namespace

std::filesystem::path output_folder(const EngineCase& ec, const RunOptions& o) {
  return o.out_dir.empty() ? std::filesystem::path("results") / ec.name : o.out_dir;
}

int run_engine_case(EngineCase& ec, const RunOptions& options) {
  const auto wall0 = Clock::now();
  const std::filesystem::path dir = output_folder(ec, options);
  std::filesystem::create_directories(dir);
  clean_previous_results(dir);
  auto log = make_run_logger(dir, options.verbosity);
  std::filesystem::copy_file(ec.file, dir / "case.toml", std::filesystem::copy_options::overwrite_existing);
  write_figure_specs(dir, ec);

  log->info("ncfsim {} | case '{}' ({}) | resolution {}", kVersion, ec.name, ec.file.string(), ec.resolution);
  if (!ec.description.empty()) log->info("  {}", ec.description);
  for (const auto& ov : options.overrides) log->info("  --set {}", ov);
  if (options.ranks > 1)
    log->warn("--np {}: this build runs the engine on one rank; the state is laid out for MPI "
              "(ghosted PETSc vectors) but the domain decomposition is not implemented yet",
              options.ranks);

  json summary;
  summary["case"] = ec.name;
  summary["stage"] = "engine";
  summary["ncfsim_version"] = kVersion;
  summary["case_file"] = ec.file.string();
  summary["overrides"] = options.overrides;
  summary["resolution"] = ec.resolution;
  summary["status"] = "starting";
  auto write_summary = [&] { write_file_atomically(dir / "summary.json", summary.dump(2) + "\n"); };

  std::unique_ptr<fem::ExplicitSolver> solver_ptr;
  try {
    solver_ptr = std::make_unique<fem::ExplicitSolver>(ec.model);
  } catch (const InputError& e) {
    summary["status"] = "bad_input";
    summary["error"] = e.what();
    write_summary();
    throw InputError(ec.file.string(), e.key(), std::string(e.what()));
  }
  fem::ExplicitSolver& solver = *solver_ptr;
  const fem::Model& model = solver.model();

  log->info("mesh: {} nodes, {} hexahedra, {} bars, {} parts, {} tools", model.mesh.n_nodes(),
            solver.n_elements(fem::ElementKind::Hex8), solver.n_elements(fem::ElementKind::Bar2), model.mesh.part_names.size(), model.tools.size());
  json fabrics = json::object();
  for (const auto& f : ec.fabric_summaries) {
    log->info("fabric {}: {} tows ({} dropped at the corners), tow thickness {:.4g} mm, {} stitch penetrations, "
              "{} stitch-to-tow connections", f.name, f.tows, f.dropped_tows, 1e3 * f.tow_thickness, f.penetrations,
              f.connections);
    fabrics[f.name] = {{"tows", f.tows}, {"dropped_tows", f.dropped_tows}, {"tow_thickness_m", f.tow_thickness},
                       {"stitch_penetrations", f.penetrations}, {"stitch_connections", f.connections}};
  }
  if (!ec.fabric_summaries.empty()) summary["fabrics"] = fabrics;
  // Stitch-to-tow joints released when the tow hexahedron that gives their axis erodes (per
  // fabric; null where it has none).
  std::vector<const drape::StitchToTowConnection*> fabric_joints;
  for (const auto& f : ec.fabric_summaries)
    fabric_joints.push_back(
        f.connection_contact < 0
            ? nullptr
            : dynamic_cast<const drape::StitchToTowConnection*>(
                  model.contacts[static_cast<std::size_t>(f.connection_contact)].get()));
  auto joints_released = [&](std::size_t k) -> std::size_t {
    return fabric_joints[k] ? fabric_joints[k]->released() : 0;
  };
  std::vector<std::size_t> joints_released_logged(ec.fabric_summaries.size(), 0);
  const auto& st = solver.controlling_element();
  log->info("stable step {:.4g} s (safety factor {}), controlled by {} {}", solver.time_step(),
            model.time.safety_factor, fem::element_noun(st.kind), st.element);
  json parts = json::object();
  for (const auto& pm : solver.part_masses()) {
    const double pct = pm.mass > 0 ? 100.0 * pm.added_mass / pm.mass : 0.0;
    log->info("  part {:<16} mass {:.5g} kg, added by mass scaling {:.5g} kg ({:.3g} %)", pm.part, pm.mass,
              pm.added_mass, pct);
    parts[pm.part] = {{"mass_kg", pm.mass}, {"added_mass_kg", pm.added_mass}, {"added_mass_percent", pct}};
  }
  const double est_cycles = model.time.end_time / solver.time_step();
  log->info("end time {:.4g} s: about {:.3g} cycles", model.time.end_time, est_cycles);

  summary["elements"] = {{"hex8", solver.n_elements(fem::ElementKind::Hex8)}, {"bar2", solver.n_elements(fem::ElementKind::Bar2)}};
  summary["nodes"] = model.mesh.n_nodes();
  summary["parts"] = parts;
  summary["end_time_s"] = model.time.end_time;
  summary["time_step_initial_s"] = solver.time_step();
  summary["energy_balance_limit"] = model.time.energy_balance_limit;

  // History columns.
  HistoryColumns hc;
  for (const char* c : {"time", "cycle", "time_step_s", "kinetic_energy_J", "internal_energy_J",
                        "stabilisation_energy_J", "hourglass_energy_J", "contact_energy_J",
                        "friction_energy_J", "damping_energy_J", "external_work_J", "total_energy_J",
                        "energy_balance_error"})
    hc.add(c);
  const bool erosion = model.time.erosion_step_ratio > 0;
  if (erosion) {
    hc.add("eroded_elements");
    hc.add("eroded_internal_energy_J");
  }
  for (const auto& t : model.tools) {
    hc.add(t.name + "_force_N");
    hc.add(t.name + "_displacement_m");
    hc.add_xyz(t.name + "_force", "N");
    hc.add_xyz(t.name + "_displacement", "m");
  }
  for (const auto& r : ec.reactions) hc.add_xyz(r.name + "_reaction", "N");
  for (const auto& pf : model.picture_frames) {
    hc.add(pf.name + "_shear_angle_deg");
    hc.add(pf.name + "_force_N");
    hc.add(pf.name + "_shear_force_N");
    hc.add(pf.name + "_normalised_shear_force_N_per_m");
  }
  for (const auto& p : ec.probes) hc.add_xyz(p.name + "_displacement", "m");
  // Contact resultants are named by the contacts once they have run a cycle: the header is
  // written with the first row.
  std::unique_ptr<HistoryWriter> history;

  auto probe_disp = [&](const std::vector<std::int32_t>& nodes) {
    auto X = solver.x.view();
    auto X0 = solver.x0.view();
    V3 s;
    for (auto i : nodes) {
      const auto k = 3 * static_cast<std::size_t>(i);
      s += V3{X[k] - X0[k], X[k + 1] - X0[k + 1], X[k + 2] - X0[k + 2]};
    }
    return (1.0 / static_cast<double>(nodes.size())) * s;
  };
  // Shear probes: the hexahedra (block, element) of each ply whose reference centroid is in the box.
  struct ProbeElements {
    std::vector<std::pair<std::size_t, std::size_t>> a, b;
  };
  std::vector<ProbeElements> shear_sets;
  {
    auto X0 = solver.x0.view();
    for (const auto& sp : ec.shear_probes) {
      ProbeElements pe;
      for (std::size_t k = 0; k < solver.blocks<fem::Hex8Block>().size(); ++k) {
        const auto& b = solver.blocks<fem::Hex8Block>()[k];
        if (b.part != sp.part_a && b.part != sp.part_b) continue;
        for (std::size_t e = 0; e < b.n; ++e) {
          double c[3] = {0, 0, 0};
          for (int I = 0; I < 8; ++I)
            for (int r = 0; r < 3; ++r)
              c[r] += 0.125 * X0[3 * static_cast<std::size_t>(b.conn[static_cast<std::size_t>(I) * b.n + e]) + static_cast<std::size_t>(r)];
          bool in = true;
          for (int r = 0; r < 3; ++r) in &= c[r] >= sp.box_min[static_cast<std::size_t>(r)] && c[r] <= sp.box_max[static_cast<std::size_t>(r)];
          if (in) (b.part == sp.part_a ? pe.a : pe.b).emplace_back(k, e);
        }
      }
      if (pe.a.empty() || pe.b.empty())
        throw InputError(ec.file.string(), "output.shear_probe." + sp.name,
                         "the box holds no element of one of the two parts");
      log->info("shear probe {}: {} + {} elements", sp.name, pe.a.size(), pe.b.size());
      shear_sets.push_back(std::move(pe));
      hc.add(sp.name + "_shear_angle_deg");
    }
  }
  auto shear_angle = [&](const ProbeElements& pe) {
    auto X = solver.x.view();
    auto mean = [&](const std::vector<std::pair<std::size_t, std::size_t>>& set) {
      V3 s, first;
      for (const auto& [k, e] : set) {
        const auto& b = solver.blocks<fem::Hex8Block>()[k];
        if (b.n_eroded && b.eroded[e]) continue;  // no longer part of the fabric
        double d[3];
        fem::hex8_fibre_direction(b, X.data(), e, d);
        V3 v{d[0], d[1], d[2]};
        if (norm(first) == 0) first = v;
        s += dot(v, first) < 0 ? -1.0 * v : v;  // a fibre direction has no sign
      }
      const double nan = std::numeric_limits<double>::quiet_NaN();
      return norm(s) > 0 ? normalized(s) : V3{nan, nan, nan};  // all eroded: nothing to measure
    };
    const double c = std::abs(dot(mean(pe.a), mean(pe.b)));
    if (std::isnan(c)) return c;
    return 90.0 - std::acos(std::min(1.0, c)) * 180.0 / M_PI;
  };
  // Cantilever bending (ASTM D1388) probes.
  struct BendingState {
    double overhang = 0, thickness = 0, width = 0, areal_mass = 0, E1 = 0;
  };
  std::vector<BendingState> bending_state;
  {
    auto X0 = solver.x0.view();
    for (const auto& bp : ec.bending) {
      BendingState bs;
      double lo[3] = {1e300, 1e300, 1e300}, hi[3] = {-1e300, -1e300, -1e300};
      const auto& hexes = model.mesh.elements(fem::ElementKind::Hex8);
      for (std::size_t e = 0; e < hexes.size(); ++e)
        if (hexes.part[e] == bp.part)
          for (auto nd : hexes.nodes(e))
            for (int r = 0; r < 3; ++r) {
              lo[r] = std::min(lo[r], X0[3 * static_cast<std::size_t>(nd) + static_cast<std::size_t>(r)]);
              hi[r] = std::max(hi[r], X0[3 * static_cast<std::size_t>(nd) + static_cast<std::size_t>(r)]);
            }
      bs.overhang = hi[0] - lo[0], bs.width = hi[1] - lo[1], bs.thickness = hi[2] - lo[2];
      bs.areal_mass = solver.part_masses()[static_cast<std::size_t>(bp.part)].mass / (bs.overhang * bs.width);
      const auto& pp = model.parts[static_cast<std::size_t>(bp.part)];
      const auto moduli = fem::directional_moduli(
          model.materials[static_cast<std::size_t>(pp.material)]->bending_stiffness(),
          {1, 0, 0, 0, 1, 0, 0, 0, 1});
      bs.E1 = moduli[0];  // bending modulus along material axis 1 (beam theory)
      bending_state.push_back(bs);
      hc.add(bp.name + "_tip_angle_deg");
    }
  }
  auto tip_angle = [&](const BendingLengthProbe& bp) {
    const V3 r = probe_disp(bp.root), t = probe_disp(bp.tip);
    auto X0 = solver.x0.view();
    V3 r0, t0;
    for (auto i : bp.root) r0 += V3::at(X0.data() + 3 * static_cast<std::size_t>(i));
    for (auto i : bp.tip) t0 += V3::at(X0.data() + 3 * static_cast<std::size_t>(i));
    r0 = (1.0 / static_cast<double>(bp.root.size())) * r0 + r;
    t0 = (1.0 / static_cast<double>(bp.tip.size())) * t0 + t;
    return std::atan2(-(t0.z - r0.z), t0.x - r0.x);  // rad below the horizontal
  };
  std::vector<std::vector<double>> kept_rows;  // for summary samples
  // Eq. 2 beside the simulated shear angle, as a history column, when a sample asks for it.
  const SummarySamples* analytic = nullptr;
  for (const auto& ss : ec.samples)
    if (ss.bias_extension_analytic) analytic = &ss;
  int analytic_x = -1;
  if (analytic) {
    analytic_x = hc.index(analytic->x);
    if (analytic_x < 0)
      throw InputError(ec.file.string(), "output.sample.x", "no history column '" + analytic->x + "' (probes: <name>_displacement_x_m)");
    hc.add("analytic_shear_angle_deg");
  }

  double max_error = 0;
  auto history_row = [&] {
    const auto& en = solver.energy();
    std::vector<double> row{solver.time(), static_cast<double>(solver.cycle()), solver.time_step(),
                            en.kinetic, en.internal, en.stabilisation, en.hourglass, en.contact,
                            en.friction, en.damping, en.external_work, en.total(), en.error()};
    if (erosion) {
      row.push_back(static_cast<double>(solver.erosions().size()));
      row.push_back(en.eroded_internal);
    }
    for (const auto& t : model.tools) {
      const V3 ax = tool_axis(t);
      row.push_back(-dot(t.force, ax));  // resistance of the part, positive against the motion
      row.push_back(dot(t.displacement, ax));
      for (double v : t.force.arr()) row.push_back(v);
      for (double v : t.displacement.arr()) row.push_back(v);
    }
    for (const auto& r : ec.reactions)
      for (double v : solver.reaction_force(r.nodes).arr()) row.push_back(v);
    for (std::size_t k = 0; k < model.picture_frames.size(); ++k) {
      // Crosshead force from the power the frame puts in: F = sum R.v / (dd/dt), d the crosshead
      // travel, d = 2 L cos(theta) - sqrt(2) L, theta = 45 deg - gamma/2; shear force F / (2 cos theta).
      const auto& pf = model.picture_frames[k];
      const double g = fem::picture_frame_angle(pf, solver.time()), gd = fem::picture_frame_rate(pf, solver.time());
      const double theta = 0.25 * M_PI - 0.5 * g, ddot = pf.arm_length * std::sin(theta) * gd;
      double power = solver.frame_wall_power(k);  // the arms as walls push the edge tows
      {
        auto R = solver.reaction.view();
        auto Vn = solver.v.view();
        for (auto node : pf.nodes)
          for (int c = 0; c < 3; ++c) {
            const auto d = 3 * static_cast<std::size_t>(node) + static_cast<std::size_t>(c);
            power += R[d] * Vn[d];
          }
      }
      const double F = ddot > 0 ? power / ddot : 0.0, Fs = F / (2 * std::cos(theta));
      const double Lf = ec.frame_fabric_length[k];
      row.push_back(g * 180.0 / M_PI);
      row.push_back(F);
      row.push_back(Fs);
      row.push_back(Fs * pf.arm_length / (Lf * Lf));
    }
    for (const auto& p : ec.probes)
      for (double v : probe_disp(p.nodes).arr()) row.push_back(v);
    for (const auto& pe : shear_sets) row.push_back(shear_angle(pe));
    for (const auto& bp : ec.bending) row.push_back(tip_angle(bp) * 180.0 / M_PI);
    if (analytic) {
      drape::BiasExtensionCoupon coupon;
      coupon.length = analytic->coupon_length, coupon.width = analytic->coupon_width;
      row.push_back(drape::central_shear_angle(coupon, std::max(0.0, row[static_cast<std::size_t>(analytic_x)])) * 180.0 / M_PI);
    }
    for (const auto& c : model.contacts)
      for (const auto& r : c->resultants()) {
        for (double v : r.force.arr()) row.push_back(v);
        if (!history) hc.add_xyz(r.name + "_force", "N");
      }
    if (!history) history = std::make_unique<HistoryWriter>(dir / "history.csv", hc.names);
    row.resize(hc.names.size(), std::numeric_limits<double>::quiet_NaN());  // a resultant that came later
    history->write_row(row);
    if (!ec.samples.empty() || !ec.means.empty()) kept_rows.push_back(row);
  };

  // Frames.
  std::unique_ptr<fem::io::XdmfResultWriter> xdmf;
  std::unique_ptr<fem::io::VtuSeriesWriter> vtu;
  const fem::io::ResultMesh rmesh = result_mesh(solver);
  if (ec.output.xdmf) xdmf = std::make_unique<fem::io::XdmfResultWriter>(dir, rmesh);
  if (ec.output.vtu) vtu = std::make_unique<fem::io::VtuSeriesWriter>(dir, rmesh);
  std::size_t frames = 0, frame_errors = 0;
  auto write_frame = [&] {  // a frame that cannot be written is reported, the run goes on
    if (!xdmf && !vtu) return;
    const fem::io::Frame fr = make_frame(solver);
    try {
      if (xdmf) xdmf->write_frame(fr);
      if (vtu) vtu->write_frame(fr);
      ++frames;
    } catch (const std::runtime_error& e) {
      ++frame_errors;
      log->error("frame at t = {:.6g} s not written: {}", solver.time(), e.what());
    }
  };

  // The loop.
  const auto& tc = model.time;
  double next_history = 0, next_frame = 0;
  auto last_progress = Clock::now();
  std::string status = "completed";
  std::string failure;
  bool exceeded_reported = false;
  std::size_t erosions_logged = 0;
  StopRequest::install();
  summary["status"] = "running";
  write_summary();

  auto fill_summary = [&] {
    const auto& en = solver.energy();
    summary["status"] = status;
    summary["wall_seconds"] = std::chrono::duration<double>(Clock::now() - wall0).count();
    summary["cycles"] = solver.cycle();
    summary["time_reached_s"] = solver.time();
    summary["time_step_final_s"] = solver.time_step();
    summary["frames"] = frames;
    summary["frame_write_errors"] = frame_errors;
    summary["energy_balance_error"] = en.error();
    summary["energy_balance_error_max"] = max_error;
    summary["kinetic_energy_J"] = en.kinetic;
    summary["internal_energy_J"] = en.internal;
    summary["stabilisation_energy_J"] = en.stabilisation;
    summary["hourglass_energy_J"] = en.hourglass;
    summary["contact_energy_J"] = en.contact;
    summary["friction_energy_J"] = en.friction;
    summary["damping_energy_J"] = en.damping;
    summary["external_work_J"] = en.external_work;
    summary["hourglass_to_internal_ratio"] = en.internal != 0 ? en.hourglass / std::abs(en.internal) : 0.0;
    summary["eroded_elements"] = solver.erosions().size();
    for (std::size_t k = 0; k < ec.fabric_summaries.size(); ++k)
      summary["fabrics"][ec.fabric_summaries[k].name]["stitch_connections_released"] =
          joints_released(k);
    summary["eroded_internal_energy_J"] = en.eroded_internal;
    for (const auto& t : model.tools) {
      summary[t.name + "_force_N"] = -dot(t.force, tool_axis(t));
      summary[t.name + "_displacement_m"] = dot(t.displacement, tool_axis(t));
    }
    for (const auto& p : ec.probes) {
      const V3 d = probe_disp(p.nodes);
      summary[p.name + "_displacement_m"] = {d.x, d.y, d.z};
    }
    for (std::size_t k = 0; k < ec.bending.size(); ++k) {
      const auto& bp = ec.bending[k];
      const auto& bs = bending_state[k];
      const double theta = tip_angle(bp), g = norm(model.gravity);
      const double c = theta > 0 ? bs.overhang * std::cbrt(std::cos(theta / 2) / (8 * std::tan(theta))) : std::nan("");
      summary[bp.name + "_overhang_m"] = bs.overhang;
      summary[bp.name + "_tip_angle_deg"] = theta * 180.0 / M_PI;
      summary[bp.name + "_bending_length_m"] = std::isfinite(c) ? nlohmann::json(c) : nlohmann::json(nullptr);
      summary[bp.name + "_flexural_rigidity_Nm"] = std::isfinite(c) ? nlohmann::json(bs.areal_mass * g * c * c * c) : nlohmann::json(nullptr);
      summary[bp.name + "_beam_theory_bending_length_m"] =
          std::cbrt(bs.E1 * bs.thickness * bs.thickness * bs.thickness / 12.0 / (bs.areal_mass * g));
      summary[bp.name + "_axial_modulus_Pa"] = bs.E1;
    }
    for (const auto& sm : ec.means) {
      const int c = hc.index(sm.column), cp = hc.index(sm.per_column);
      double sum = 0;
      std::size_t n = 0;
      const std::vector<double>*first = nullptr, *last = nullptr;
      for (const auto& r : kept_rows)
        if (c >= 0 && r[0] >= sm.from_time && r[0] <= sm.to_time) {
          sum += r[static_cast<std::size_t>(c)], ++n;
          if (!first) first = &r;
          last = &r;
        }
      double value = n ? sm.scale * sum / static_cast<double>(n) : std::nan("");
      if (!sm.per_column.empty()) {  // ratio of increments over the window
        value = std::nan("");
        if (cp >= 0 && first && last && (*last)[static_cast<std::size_t>(cp)] != (*first)[static_cast<std::size_t>(cp)])
          value = sm.scale * ((*last)[static_cast<std::size_t>(c)] - (*first)[static_cast<std::size_t>(c)]) /
                  ((*last)[static_cast<std::size_t>(cp)] - (*first)[static_cast<std::size_t>(cp)]);
      }
      summary[sm.name] = std::isfinite(value) ? nlohmann::json(value) : nlohmann::json(nullptr);
      if ((c < 0 || (!sm.per_column.empty() && cp < 0)) && !hc.names.empty())
        summary[sm.name + "_error"] = "no history column '" + (c < 0 ? sm.column : sm.per_column) + "'";
    }
    for (const auto& ss : ec.samples) {
      const int cx = hc.index(ss.x);
      for (double at : ss.at) {
        const std::string tag = fmt::format("_at_{:g}{}", at, ss.x_unit);
        const double xv = at / ss.x_display_scale;
        for (const auto& [label, column] : ss.columns) {
          const int cy = hc.index(column);
          double val = std::numeric_limits<double>::quiet_NaN();
          for (std::size_t r = 1; cx >= 0 && cy >= 0 && r < kept_rows.size(); ++r) {
            const double x0 = kept_rows[r - 1][static_cast<std::size_t>(cx)], x1 = kept_rows[r][static_cast<std::size_t>(cx)];
            if ((x0 - xv) * (x1 - xv) <= 0 && x1 != x0) {
              const double w = (xv - x0) / (x1 - x0);
              val = (1 - w) * kept_rows[r - 1][static_cast<std::size_t>(cy)] + w * kept_rows[r][static_cast<std::size_t>(cy)];
              break;
            }
          }
          summary[label + tag] = std::isfinite(val) ? nlohmann::json(val) : nlohmann::json(nullptr);
        }
        if (ss.bias_extension_analytic) {
          drape::BiasExtensionCoupon coupon;
          coupon.length = ss.coupon_length, coupon.width = ss.coupon_width;
          summary["analytic_shear_angle_deg" + tag] = drape::central_shear_angle(coupon, xv) * 180.0 / M_PI;
        }
      }
    }
    const auto& tm = solver.timers();
    summary["timers_s"] = {{"internal_force", tm.internal_force}, {"contact", tm.contact},
                           {"update", tm.update}, {"output", tm.output}};
    if (!failure.empty()) summary["error"] = failure;
  };

  int exit_code = kSuccess;
  try {
    while (solver.time() < tc.end_time * (1 - 1e-12)) {
      if (tc.max_cycles > 0 && solver.cycle() >= tc.max_cycles) {
        status = "max_cycles";
        log->warn("stopped at the cycle limit time.max_cycles = {}", tc.max_cycles);
        break;
      }
      if (StopRequest::requested()) {
        status = "interrupted";
        log->warn("interrupted at t = {:.6g} s, cycle {}: writing the last frame and summary", solver.time(),
                  solver.cycle());
        break;
      }
      solver.step([&] {
        const double t = solver.time();
        const std::size_t erosions_before = erosions_logged;
        for (; erosions_logged < solver.erosions().size(); ++erosions_logged) {
          const auto& ev = solver.erosions()[erosions_logged];
          const std::string why = ev.cause == fem::ErosionEvent::Cause::InvertedCorner
                                      ? "a corner folded over (corner Jacobian <= 0)"
                                      : fmt::format(
                                            "its step {:.3g} s fell below time.erosion_step_ratio "
                                            "= {:g} of the initial one",
                                            ev.step, tc.erosion_step_ratio);
          log->warn(
              "hexahedron {} (part {}) eroded at t = {:.6g} s, cycle {}, at ({:.6g}, {:.6g}, "
              "{:.6g}) m: {}",
              ev.element, model.mesh.part_names[static_cast<std::size_t>(ev.part)], ev.time,
              ev.cycle, ev.centroid.x, ev.centroid.y, ev.centroid.z, why);
        }
        if (erosions_logged > erosions_before)  // joints go only with an eroded hexahedron
          for (std::size_t k = 0; k < fabric_joints.size(); ++k) {
            const std::size_t n = joints_released(k);
            if (n == joints_released_logged[k]) continue;
            log->warn(
                "fabric {}: {} stitch-to-tow connections released at t = {:.6g} s (their tow "
                "hexahedron eroded), {} of {} in all",
                ec.fabric_summaries[k].name, n - joints_released_logged[k], t, n,
                ec.fabric_summaries[k].connections);
            joints_released_logged[k] = n;
          }
        const double err = solver.energy().error();
        if (t > 0.05 * tc.end_time) max_error = std::max(max_error, err);  // skip the start, when little energy is in play
        if (t >= next_history) {
          history_row();
          next_history += tc.history_interval;
          if (!exceeded_reported && err > tc.energy_balance_limit && t > 0.05 * tc.end_time) {
            log->warn("energy balance error {:.3g} % passed its limit {:.3g} % at t = {:.6g} s", 100 * err,
                      100 * tc.energy_balance_limit, t);
            exceeded_reported = true;
          }
        }
        if (t >= next_frame) {
          write_frame();
          fill_summary();
          summary["status"] = "running";
          write_summary();
          next_frame += tc.frame_interval;
        }
        const auto now = Clock::now();
        if (std::chrono::duration<double>(now - last_progress).count() >= options.progress_interval_s) {
          last_progress = now;
          const double wall = std::chrono::duration<double>(now - wall0).count();
          const double frac = t / tc.end_time;
          log->info("t = {:.4e} / {:.4e} s ({:4.1f} %) | cycle {} | dt {:.3e} s | wall {} | ETA {} | "
                    "energy balance {:.3f} %",
                    t, tc.end_time, 100 * frac, solver.cycle(), solver.time_step(), hms(wall),
                    frac > 0 ? hms(wall * (1 - frac) / frac) : "--:--", 100 * err);
        }
      });
    }
    // Final state (positions at the end time; forces of the last cycle).
    history_row();
    write_frame();
  } catch (const NumericalError& e) {
    status = "numerical_failure";
    failure = e.what();
    log->error("{}", e.what());
    exit_code = kNumericalFailure;
  }
  if (xdmf) xdmf->close();
  if (vtu) vtu->close();

  const double err = solver.energy().error();
  if (exit_code == kSuccess && err > tc.energy_balance_limit) {
    status = "energy_balance_exceeded";
    failure = fmt::format("energy balance error {:.3g} % is past its limit {:.3g} % (time.energy_balance_limit)",
                          100 * err, 100 * tc.energy_balance_limit);
    log->error("{}", failure);
    exit_code = kNumericalFailure;
  }
  if (exit_code == kSuccess && status == "interrupted") exit_code = kOtherError;
  fill_summary();
  write_summary();

  const auto& en = solver.energy();
  log->info("energy balance at t = {:.6g} s: kinetic {:.5g} J, internal {:.5g} J (stabilisation {:.5g} J), "
            "hourglass {:.5g} J, contact {:.5g} J (friction {:.5g} J), damping {:.5g} J, external work "
            "{:.5g} J, error {:.3g} % (limit {:.3g} %)",
            en.time, en.kinetic, en.internal, en.stabilisation, en.hourglass, en.contact, en.friction, en.damping,
            en.external_work, 100 * err, 100 * tc.energy_balance_limit);
  const auto& tm = solver.timers();
  const double elem_cycles = static_cast<double>(solver.cycle()) * static_cast<double>(solver.n_elements(fem::ElementKind::Hex8) + solver.n_elements(fem::ElementKind::Bar2));
  log->info("{} cycles in {} | internal force {:.3g} s ({:.0f} ns per element-cycle), contact {:.3g} s, "
            "update {:.3g} s, output {:.3g} s",
            solver.cycle(), hms(summary["wall_seconds"].get<double>()), tm.internal_force,
            elem_cycles > 0 ? 1e9 * tm.internal_force / elem_cycles : 0.0, tm.contact, tm.update, tm.output);

  if (ec.output.figures) {
    try {
      const auto written = render_figures(dir, *log);
      log->info("{} figures in {}", written.size(), (dir / "figures").string());
    } catch (const std::exception& e) {
      log->warn("figures not drawn: {}", e.what());
    }
  }
  if (ec.output.report) {
    try {
      write_report(dir);
      log->info("report: {}", (dir / "report.html").string());
    } catch (const std::exception& e) {
      log->warn("report not written: {}", e.what());
    }
  }
  log->info("results in {} (status: {})", dir.string(), status);
  return exit_code;
}

}  // namespace ncfsim::workflow

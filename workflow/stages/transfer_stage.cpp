#include "workflow/stages/transfer_stage.hpp"

#include <fmt/format.h>
#include <spdlog/logger.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <limits>
#include <nlohmann/json.hpp>

#include "fem/case/stage_kinds.hpp"
#include "fem/errors.hpp"
#include "fem/io/result_writers.hpp"
#include "fem/io/stage_handoff.hpp"
#include "fem/memory_estimate.hpp"
#include "transfer/case/transfer_case.hpp"
#include "workflow/figures/figures.hpp"
#include "workflow/output/output_files.hpp"
#include "workflow/report/report.hpp"
#include "workflow/version.hpp"

namespace ncfsim::workflow {

namespace {

using transfer::ImpregnatedModel;

fem::io::StageFrame read_source(const transfer::TransferCase& tc) {
  const std::string file = tc.file.string();
  try {
    return tc.frame < 0 ? fem::io::read_last_frame(tc.results)
                        : fem::io::read_frame(tc.results, static_cast<std::size_t>(tc.frame));
  } catch (const std::out_of_range& e) {
    throw InputError(file, "source.frame", e.what());
  } catch (const std::runtime_error& e) {
    throw InputError(file, "source.results", e.what());
  }
}

// What a transfer holds, from its source frame's size (docs/performance.md, "Memory"): the frame
// read (the drape's mesh, positions, nodal and cell fields), the impregnated model (frames,
// classes) with the tie search's face maps (~1.1 kB per mapped hexahedron; 600 B per source
// hexahedron, as a dome is trimmed out of its blank), the result writer's mesh, the figures
// (measured: 185 MB, as a run's).
fem::MemoryEstimate transfer_memory(const fem::io::StageFrame& frame, bool figures) {
  constexpr double kFramePerNode = 32 + 24 + 48, kFramePerCell = 88 + 200;
  constexpr double kModelPerHex = 600, kWriterPerNode = 32, kWriterPerHex = 88;
  const double nodes = static_cast<double>(frame.n_points());
  const double hex = static_cast<double>(frame.mesh.hex().conn.size() / 8);
  const double cells = hex + static_cast<double>(frame.mesh.bars().conn.size() / 2);
  fem::MemoryEstimate est;
  est.shares.push_back({"program", fem::kProgramBytes});
  est.shares.push_back({"source frame", kFramePerNode * nodes + kFramePerCell * cells});
  est.shares.push_back({"impregnated model and ties", kModelPerHex * hex});
  est.shares.push_back({"output", kWriterPerNode * nodes + kWriterPerHex * hex +
                                      (figures ? fem::kFiguresBytes : 0.0)});
  return est;
}

ImpregnatedModel build(transfer::TransferCase& tc, const fem::io::StageFrame& frame) {
  const std::string file = tc.file.string();
  for (const auto& name : tc.parts) {
    const auto& names = frame.mesh.part_names;
    const auto it = std::find(names.begin(), names.end(), name);
    if (it == names.end())
      throw InputError(file, "source.parts", "the drape result has no part '" + name + "'");
    tc.spec.parts.push_back(static_cast<int>(it - names.begin()));
  }
  ImpregnatedModel m;
  try {
    m = transfer::build_impregnated_model(frame, tc.spec);
  } catch (const std::invalid_argument& e) {
    throw InputError(file, "impregnation", e.what());
  } catch (const std::runtime_error& e) {
    throw InputError(file, "source.results", e.what());
  }
  if (m.n_elements() == 0) {
    if (m.n_trimmed > 0 && m.n_trimmed + m.n_lost == m.n_candidates)
      throw InputError(
          file, "trim.radius",
          fmt::format("keeps nothing: all {} tow hexahedra lie farther from the axis than {} m",
                      m.n_candidates, tc.spec.trim.radius));
    throw InputError(file, "source.results",
                     fmt::format("none of its {} tow hexahedra can be mapped", m.n_candidates));
  }
  return m;
}

void write_results(const std::filesystem::path& dir, const ImpregnatedModel& m,
                   const transfer::StitchSpec& stitch) {
  // The kept stitches' nodes are the last points: the tows' node fields are unchanged.
  fem::io::ResultMesh rm;
  rm.points = m.points;
  for (const auto& h : m.hex)
    for (auto n : h) rm.hex().conn.push_back(n);
  rm.hex().part = m.hex_part;
  rm.part_names = m.part_names;
  rm.node_user_id = m.point_user_id;
  rm.hex().user_id = m.hex_user_id;
  rm.hex().material = m.vf_class;
  for (const auto& c : m.classes)
    rm.material_names.push_back(fmt::format("tow_vf_{:.3f}", c.fibre_volume_fraction));
  rm.hex_ply = m.hex_ply;
  rm.hex_tow = m.hex_tow;
  for (const auto& b : m.stitch) rm.bars().conn.insert(rm.bars().conn.end(), {b[0], b[1]});
  rm.bars().part = m.stitch_part;
  rm.bars().user_id = m.stitch_user_id;
  rm.bars().material.assign(m.stitch.size(), -1);
  fem::io::Frame fr;
  fr.displacement.assign(m.points.size(), 0.0);
  // Cell fields hold the hexahedra, then the kept stitch bars (NaN where a kind lacks one).
  const std::size_t n = m.n_elements(), nb = m.stitch.size();
  const double nan = std::numeric_limits<double>::quiet_NaN();
  auto scalar = [&](const std::string& name, auto value_of) {
    fem::io::FrameField f{name, true, 1, std::vector<double>(n + nb, nan)};
    for (std::size_t e = 0; e < n; ++e) f.values[e] = value_of(e);
    fr.fields.push_back(std::move(f));
  };
  auto axis = [&](const std::string& name, int col) {
    fem::io::FrameField f{name, true, 3, std::vector<double>(3 * (n + nb), nan)};
    for (std::size_t e = 0; e < n; ++e)
      for (int r = 0; r < 3; ++r)
        f.values[3 * e + static_cast<std::size_t>(r)] =
            m.frame[e][static_cast<std::size_t>(3 * r + col)];
    fr.fields.push_back(std::move(f));
  };
  axis("fibre_direction", 0);
  axis("material_axis_2", 1);
  axis("material_axis_3", 2);
  scalar("vf", [&](std::size_t e) { return m.vf[e]; });
  scalar("volume_ratio", [&](std::size_t e) { return m.volume_ratio[e]; });
  auto cls = [&](std::size_t e) -> const transfer::ImpregnatedTow& {
    return m.classes[static_cast<std::size_t>(m.vf_class[e])];
  };
  scalar("vf_class", [&](std::size_t e) { return static_cast<double>(m.vf_class[e]); });
  scalar("E1_Pa", [&](std::size_t e) { return cls(e).elastic.E1; });
  scalar("E2_Pa", [&](std::size_t e) { return cls(e).elastic.E2; });
  scalar("G12_Pa", [&](std::size_t e) { return cls(e).elastic.G12; });
  // The rest of the impregnated tow's constants, so that the crush builds its materials from
  // this file alone (docs/output.md).
  scalar("density_kg_m3", [&](std::size_t e) { return cls(e).density; });
  scalar("E3_Pa", [&](std::size_t e) { return cls(e).elastic.E3; });
  scalar("nu12", [&](std::size_t e) { return cls(e).elastic.nu12; });
  scalar("nu13", [&](std::size_t e) { return cls(e).elastic.nu13; });
  scalar("nu23", [&](std::size_t e) { return cls(e).elastic.nu23; });
  scalar("G13_Pa", [&](std::size_t e) { return cls(e).elastic.G13; });
  scalar("G23_Pa", [&](std::size_t e) { return cls(e).elastic.G23; });
  scalar("Xt_Pa", [&](std::size_t e) { return cls(e).strength.Xt; });
  scalar("Xc_Pa", [&](std::size_t e) { return cls(e).strength.Xc; });
  scalar("Yt_Pa", [&](std::size_t e) { return cls(e).strength.Yt; });
  scalar("Yc_Pa", [&](std::size_t e) { return cls(e).strength.Yc; });
  scalar("S12_Pa", [&](std::size_t e) { return cls(e).strength.S12; });
  scalar("S23_Pa", [&](std::size_t e) { return cls(e).strength.S23; });
  if (nb > 0) {  // the cured yarn: the crush and the decks take its law from here
    auto bar = [&](const std::string& name, double value) {
      auto it = std::find_if(fr.fields.begin(), fr.fields.end(),
                             [&](const auto& f) { return f.name == name; });
      if (it == fr.fields.end()) {
        fr.fields.push_back({name, true, 1, std::vector<double>(n + nb, nan)});
        it = fr.fields.end() - 1;
      }
      std::fill(it->values.begin() + static_cast<std::ptrdiff_t>(n), it->values.end(), value);
    };
    bar("density_kg_m3", stitch.density);
    bar("stitch_modulus_Pa", stitch.modulus);
    bar("stitch_area_m2", stitch.area());
    bar("stitch_capture_m", m.stitch_capture);
  }
  fem::io::XdmfResultWriter w(dir, rm);
  w.write_frame(fr);
  w.close();
}

std::string materials_csv(const ImpregnatedModel& m) {
  std::string s =
      "class,vf,density_kg_m3,E1_Pa,E2_Pa,E3_Pa,nu12,nu13,nu23,G12_Pa,G13_Pa,G23_Pa,Xt_Pa,Xc_Pa,Yt_"
      "Pa,"
      "Yc_Pa,S12_Pa,S23_Pa,elements\n";
  std::vector<std::size_t> count(m.classes.size(), 0);
  for (auto c : m.vf_class) ++count[static_cast<std::size_t>(c)];
  for (std::size_t k = 0; k < m.classes.size(); ++k) {
    const auto& t = m.classes[k];
    const auto& c = t.elastic;
    s += fmt::format(
        "{},{:.4f},{:.6g},{:.6g},{:.6g},{:.6g},{:.6g},{:.6g},{:.6g},{:.6g},{:.6g},{:.6g},{:.6g},{:."
        "6g},{:.6g},{:.6g},{:.6g},{:.6g},{}\n",
        k, t.fibre_volume_fraction, t.density, c.E1, c.E2, c.E3, c.nu12, c.nu13, c.nu23, c.G12,
        c.G13, c.G23, t.strength.Xt, t.strength.Xc, t.strength.Yt, t.strength.Yc, t.strength.S12,
        t.strength.S23, count[k]);
  }
  return s;
}

std::string ties_csv(const ImpregnatedModel& m) {
  std::string s = "interface,slave_element_id,slave_face,master_element_id,master_face\n";
  for (const auto& t : m.ties)
    for (std::size_t k = 0; k < t.slave.size(); ++k)
      s += fmt::format("{},{},{},{},{}\n", t.name,
                       m.hex_user_id[static_cast<std::size_t>(t.slave[k].first)], t.slave[k].second,
                       m.hex_user_id[static_cast<std::size_t>(t.master[k].first)],
                       t.master[k].second);
  return s;
}

// Elements per Vf bin of the mapping's width, from the undeformed to the locking value.
std::string vf_histogram_csv(const ImpregnatedModel& m, const transfer::MappingSpec& spec) {
  const int bins = std::max(
      1,
      static_cast<int>(std::ceil((spec.vf_locking - spec.vf_undeformed) / spec.vf_bin - 1e-9)) + 1);
  std::vector<std::size_t> count(static_cast<std::size_t>(bins), 0);
  for (double vf : m.vf) {
    const int b = std::clamp(static_cast<int>(std::floor((vf - spec.vf_undeformed) / spec.vf_bin)),
                             0, bins - 1);
    ++count[static_cast<std::size_t>(b)];
  }
  std::string s = "vf,elements\n";
  for (int b = 0; b < bins; ++b)
    s += fmt::format("{:.4f},{}\n", spec.vf_undeformed + (b + 0.5) * spec.vf_bin,
                     count[static_cast<std::size_t>(b)]);
  return s;
}

void write_figures(const std::filesystem::path& dir, const std::string& name, spdlog::logger& log) {
  using json = nlohmann::json;
  json spec;
  spec["plots"] = json::array({json{{"name", "vf_histogram"},
                                    {"source", "vf_histogram.csv"},
                                    {"title", name + ": fibre volume fraction of the tows"},
                                    {"x", "vf"},
                                    {"y", json::array({"elements"})},
                                    {"x_scale", 1.0},
                                    {"y_scale", 1.0},
                                    {"x_label", "fibre volume fraction"},
                                    {"y_label", "elements"}}});
  spec["pictures"] = json::array();
  for (const char* camera : {"iso", "top"})
    spec["pictures"].push_back({{"name", std::string("vf_") + camera},
                                {"field", "vf"},
                                {"camera", camera},
                                {"title", name + ": fibre volume fraction"}});
  write_file_atomically(dir / "figures.json", spec.dump(2) + "\n");
  try {
    render_figures(dir, log);
  } catch (const std::exception& e) {
    log.warn("figures not drawn: {}", e.what());
  }
}

}  // namespace

int check_transfer_stage(const StageCall& call) {
  auto tc = transfer::load_transfer_case(call.case_file, call.overrides);
  const auto frame = read_source(tc);
  const auto m = build(tc, frame);
  std::printf(
      "%s: OK (case '%s', transfer of %s, frame at t = %.4g s: %zu of %zu tow hexahedra mapped, "
      "%zu Vf classes, %zu tie pairs)\n",
      call.case_file.c_str(), tc.name.c_str(), tc.results.c_str(), frame.time, m.n_elements(),
      m.n_candidates, m.classes.size(), m.n_tie_pairs());
  return kSuccess;
}

int run_transfer_stage(const StageCall& call) {
  const auto t0 = std::chrono::steady_clock::now();
  auto tc = transfer::load_transfer_case(call.case_file, call.overrides);
  const auto frame = read_source(tc);
  const fem::MemoryEstimate memory = transfer_memory(frame, tc.figures && tc.frames_xdmf);
  fem::require_memory_fits(memory, tc.file.string());
  const ImpregnatedModel m = build(tc, frame);

  const std::filesystem::path dir = output_folder(tc.name, call.options);
  const OutputFolder folder =
      OutputFolder::claim(dir, call.options.overwrite, {}, fem::stage_kind::kTransfer);
  auto log = make_run_logger(dir, call.options.verbosity);
  log->info("ncfsim {} | case '{}' ({}) | transfer", kVersion, tc.name, call.case_file.string());
  if (!tc.description.empty()) log->info("  {}", tc.description);
  for (const auto& o : call.overrides) log->info("  --set {}", o);
  log->info("drape result {}: frame {} of {} at t = {:.6g} s", tc.results.string(), frame.index + 1,
            frame.n_frames, frame.time);
  log->info("memory: {:.0f} MB resident with the model built; estimated {}", fem::resident_mb(),
            memory.describe());
  double vf_min = 1, vf_max = 0, vf_sum = 0;
  for (double vf : m.vf) vf_min = std::min(vf_min, vf), vf_max = std::max(vf_max, vf), vf_sum += vf;
  const double vf_mean = vf_sum / static_cast<double>(m.vf.size());
  log->info("{} of {} tow hexahedra mapped ({} trimmed at {} m, {} lost)", m.n_elements(),
            m.n_candidates, m.n_trimmed, tc.spec.trim.radius, m.n_lost);
  if (tc.spec.stitches.keep)
    log->info(
        "stitches kept: {} of {} bars with {} nodes, to be tied to the tow faces within {:.4g} m "
        "({} with an end beside no kept tow: dropped); yarn E {:.4g} Pa, area {:.4g} m^2",
        m.stitch.size(), m.n_stitches, m.n_stitch_nodes, m.stitch_capture, m.n_stitches_uncaptured,
        tc.spec.stitches.modulus, tc.spec.stitches.area());
  else
    log->info("{} stitch bars dropped (stitches.keep = false)", m.n_stitches);
  log->info(
      "Vf {:.4f} .. {:.4f}, mean {:.4f} ({} capped at the locking value {:.4f}, {} spread tows "
      "raised to "
      "the undeformed {:.4f}); {} material classes",
      vf_min, vf_max, vf_mean, m.n_capped, tc.spec.mapping.vf_locking, m.n_floored,
      tc.spec.mapping.vf_undeformed, m.classes.size());
  for (const auto& t : m.ties) log->info("tied {}: {} face pairs", t.name, t.slave.size());
  if (m.n_lost)
    log->warn(
        "{} tow hexahedra not mapped: {} eroded in the drape, {} folded or distorted (smallest "
        "scaled corner Jacobian below impregnation.min_corner_jacobian = {:g}), {} with a "
        "non-positive volume or the fibre along the thickness",
        m.n_lost, m.n_eroded, m.n_distorted, tc.spec.min_corner_jacobian,
        m.n_lost - m.n_eroded - m.n_distorted);

  if (tc.frames_xdmf) write_results(dir, m, tc.spec.stitches);
  write_file_atomically(dir / "materials.csv", materials_csv(m));
  write_file_atomically(dir / "ties.csv", ties_csv(m));
  write_file_atomically(dir / "vf_histogram.csv", vf_histogram_csv(m, tc.spec.mapping));

  nlohmann::json s = stage_summary_header(tc.name, call, fem::stage_kind::kTransfer);
  s["source_results"] = tc.results.string();
  s["source_frame"] = frame.index;
  s["source_time_s"] = frame.time;
  s["elements_mapped"] = m.n_elements();
  s["elements_lost"] = m.n_lost;
  s["elements_lost_eroded"] = m.n_eroded;
  s["elements_lost_distorted"] = m.n_distorted;
  s["elements_trimmed"] = m.n_trimmed;
  s["vf_min"] = vf_min;
  s["vf_max"] = vf_max;
  s["vf_mean"] = vf_mean;
  s["vf_capped"] = m.n_capped;
  s["vf_floored"] = m.n_floored;
  s["material_classes"] = m.classes.size();
  s["tie_pairs"] = m.n_tie_pairs();
  for (const auto& t : m.ties) s["tie_pairs_" + t.name] = t.slave.size();
  s["tie_normal_strength_Pa"] = tc.spec.ties.normal_strength;
  s["tie_shear_strength_Pa"] = tc.spec.ties.shear_strength;
  s["stitches_kept"] = m.stitch.size();
  s["stitches_dropped"] = m.n_stitches - m.stitch.size();
  s["compressive_ratio"] = tc.spec.compressive_ratio;
  s["wall_seconds"] = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  s["memory_estimate_MB"] = memory.per_rank() / 1e6;
  s["peak_memory_MB"] = fem::peak_resident_mb();
  write_file_atomically(dir / "summary.json", s.dump(2) + "\n");
  if (tc.figures && tc.frames_xdmf) {
    write_figures(dir, tc.name, *log);
    s["peak_memory_MB"] = fem::peak_resident_mb();  // the figures are drawn in this process
    write_file_atomically(dir / "summary.json", s.dump(2) + "\n");
  }
  try {
    write_report(dir);
  } catch (const std::exception& e) {
    log->warn("report not written: {}", e.what());
  }
  log->info("results in {}", dir.string());
  folder.finish();
  return kSuccess;
}

}  // namespace ncfsim::workflow

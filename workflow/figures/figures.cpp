#include "workflow/figures/figures.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>

#include "fem/io/result_reader.hpp"
#include "impact/tow_damage_material.hpp"
#include "render.hpp"
#include "workflow/output/output_files.hpp"

namespace ncfsim::workflow {

namespace {
using json = nlohmann::json;

json plot_json(const PlotSpec& p) {
  json imports = json::array(), refs = json::array();
  for (const auto& i : p.imports)
    imports.push_back({{"label", i.label},
                       {"file", i.file.string()},
                       {"x", i.x},
                       {"y", i.y},
                       {"x_scale", i.x_scale},
                       {"y_scale", i.y_scale}});
  for (const auto& r : p.references) refs.push_back({{"label", r.label}, {"y", r.y}});
  return {{"name", p.name},
          {"title", p.title},
          {"x", p.x},
          {"y", p.y},
          {"x_scale", p.x_scale},
          {"y_scale", p.y_scale},
          {"x_label", p.x_label},
          {"y_label", p.y_label},
          {"imports", imports},
          {"source", p.source},
          {"references", refs}};
}

std::string unit_of(const std::string& field) {
  if (field == "stress" || field == "von_mises_stress") return "Pa";
  if (field == "displacement" || field == "displacement_magnitude") return "m";
  if (field == "velocity") return "m/s";
  if (field == "axial_force") return "N";
  if (field == "membrane_force") return "N/m";    // shells: force per unit length of the section
  if (field == "bending_moment") return "N m/m";  // shells: moment per unit length
  if (field == "shear_angle_deg" || field == "wrinkle_angle_deg") return "deg";
  if (field == "interply_slip_m") return "m";
  return "-";
}

std::string fmt_time(double t) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.4g", t);
  return buf;
}

render::CameraPreset camera(const std::string& c) {
  if (c == "top") return render::CameraPreset::Top;
  if (c == "front") return render::CameraPreset::Front;
  return render::CameraPreset::Iso;
}
}  // namespace

void write_figure_specs(const std::filesystem::path& dir, const EngineCase& ec) {
  json plots = json::array(), pictures = json::array();
  for (const auto& p : ec.plots) plots.push_back(plot_json(p));
  // Defaults, unless the case declares a figure of the same name.
  auto add_default = [&](const PlotSpec& p) {
    for (const auto& q : ec.plots)
      if (q.name == p.name) return;
    plots.push_back(plot_json(p));
  };
  add_default(
      PlotSpec{"energy_balance",
               ec.name + ": energy balance",
               "time",
               {"kinetic_energy_J", "internal_energy_J", "hourglass_energy_J", "contact_energy_J",
                "damping_energy_J", "external_work_J", "total_energy_J"},
               1.0,
               1.0,
               "time [s]",
               "energy [J]",
               {},
               {}});
  for (const auto& t : ec.model.tools)
    add_default(PlotSpec{t.name + "_force_displacement",
                         ec.name + ": " + t.name + " force",
                         t.name + "_displacement_m",
                         {t.name + "_force_N"},
                         1e3,
                         1.0,
                         t.name + " displacement [mm]",
                         t.name + " force [N]",
                         {},
                         {}});
  for (const auto& p : ec.probes)
    add_default(PlotSpec{
        p.name + "_displacement",
        ec.name + ": " + p.name + " displacement",
        "time",
        {p.name + "_displacement_x_m", p.name + "_displacement_y_m", p.name + "_displacement_z_m"},
        1.0,
        1e3,
        "time [s]",
        "displacement [mm]",
        {},
        {}});
  for (const auto& p : ec.pictures)
    pictures.push_back({{"name", p.name},
                        {"field", p.field},
                        {"component", p.component},
                        {"camera", p.camera},
                        {"title", p.title},
                        {"follow_part", p.follow_part},
                        {"deformation_scale", p.deformation_scale}});
  if (ec.pictures.empty()) {
    bool solids = false;  // elements that bound a volume have a stress tensor to picture
    for (const auto& set : ec.model.mesh.sets)
      solids = solids || (!set.empty() && !fem::element_faces(set.kind).empty());
    if (solids)
      pictures.push_back({{"name", "final_von_mises"},
                          {"field", "von_mises_stress"},
                          {"camera", "iso"},
                          {"title", ec.name + ": von Mises stress, final state"}});
    pictures.push_back({{"name", "final_displacement"},
                        {"field", "displacement_magnitude"},
                        {"camera", "iso"},
                        {"title", ec.name + ": displacement, final state"}});
  }
  write_file_atomically(dir / "figures.json",
                        json{{"plots", plots}, {"pictures", pictures}}.dump(2) + "\n");
}

std::vector<std::filesystem::path> render_figures(const std::filesystem::path& dir,
                                                  spdlog::logger& log) {
  std::ifstream in(dir / "figures.json");
  if (!in)
    throw std::runtime_error((dir / "figures.json").string() +
                             " not found (is this a run's output folder?)");
  const json spec = json::parse(in);
  std::string why;
  if (!render::offscreen_rendering_available(&why))
    throw std::runtime_error("no off-screen rendering: " + why);
  log.debug("off-screen rendering: {}", why);  // the back end (OSMesa, EGL) and its GL
  std::vector<std::filesystem::path> out;
  std::filesystem::create_directories(dir / "figures");

  {
    std::map<std::string, CsvTable> sources;  // the run's CSV files, read once each
    for (const auto& p : spec.at("plots")) {
      const std::string name = p.at("name");
      const std::string source = p.value("source", std::string("history.csv"));
      if (!sources.count(source)) {
        if (!std::filesystem::exists(dir / source)) continue;
        sources.emplace(source, read_csv(dir / source));
      }
      const CsvTable& h = sources.at(source);
      try {
        render::CurvePlot plot;
        plot.title = p.at("title");
        plot.x_label = p.at("x_label");
        plot.y_label = p.at("y_label");
        const double xs = p.at("x_scale"), ys = p.at("y_scale");
        auto x = h.column(p.at("x"));
        for (double& v : x) v *= xs;
        for (const auto& yname : p.at("y")) {
          auto y = h.column(yname);
          for (double& v : y) v *= ys;
          plot.series.push_back({yname.get<std::string>(), x, y});
        }
        if (h.rows.size() < 2) throw std::runtime_error("fewer than 2 rows in " + source);
        for (const auto& im : p.value("imports", json::array())) {
          const CsvTable t = read_csv(im.at("file").get<std::string>());
          auto ix = t.column(im.at("x")), iy = t.column(im.at("y"));
          for (double& v : ix) v *= im.at("x_scale").get<double>();
          for (double& v : iy) v *= im.at("y_scale").get<double>();
          render::CurveSeries cs{im.at("label"), ix, iy};
          cs.dashed = true;
          plot.series.push_back(std::move(cs));
        }
        for (const auto& r : p.value("references", json::array())) {
          const double y = r.at("y");
          render::CurveSeries cs{r.at("label"), {x.front(), x.back()}, {y, y}};
          cs.dashed = true;
          plot.series.push_back(std::move(cs));
        }
        const auto png = dir / "figures" / (name + ".png");
        render::plot_curves_png(plot, png);
        out.push_back(png);
      } catch (const std::exception& e) {
        log.warn("figure {} skipped: {}", name, e.what());
      }
    }
  }

  const auto h5 = dir / "results.h5";
  if (!spec.at("pictures").empty() && std::filesystem::exists(h5)) {
    fem::io::ResultReader reader(h5);
    if (reader.n_frames() > 0) {
      const auto frame = reader.frame(reader.n_frames() - 1);
      const auto& m = reader.mesh();
      render::RenderMesh rm;
      for (fem::ElementKind k : fem::kElementKinds) rm.of(k) = m.of(k).conn;
      for (const auto& f : frame.fields) {
        if (f.name == "displacement") {
          render::MeshField mag{"displacement_magnitude", "m", false, 1, {}};
          for (std::size_t i = 0; i + 2 < f.values.size(); i += 3)
            mag.values.push_back(std::sqrt(f.values[i] * f.values[i] +
                                           f.values[i + 1] * f.values[i + 1] +
                                           f.values[i + 2] * f.values[i + 2]));
          rm.fields.push_back(std::move(mag));
        }
        rm.fields.push_back({f.name, unit_of(f.name), f.on_cells, f.n_components, f.values});
      }
      // Eroded elements are not drawn: nothing holds their lone nodes, which fly off. One flag
      // per cell (hexes, bars, shells, as the field); NaN (a kind without the field) is kept.
      std::vector<char> eroded(m.n_cells(), 0);
      for (const auto& f : frame.fields)
        if (f.name == "eroded" && f.on_cells && f.n_components == 1)
          for (std::size_t c = 0; c < eroded.size() && c < f.values.size(); ++c)
            eroded[c] = f.values[c] > 0.5;
      if (std::find(eroded.begin(), eroded.end(), 1) != eroded.end())
        rm = render::without_cells(rm, eroded);
      for (const auto& p : spec.at("pictures")) {
        const std::string name = p.at("name");
        try {
          // Deformed shape, displacements scaled for visibility where asked.
          const double scale = p.value("deformation_scale", 1.0);
          rm.points.resize(m.points.size());
          for (std::size_t i = 0; i < m.points.size(); ++i)
            rm.points[i] = m.points[i] + scale * (frame.coordinates[i] - m.points[i]);
          render::MeshFigure fig;
          fig.field = p.at("field") == "none" ? "" : p.at("field").get<std::string>();
          fig.component = p.value("component", -1);
          if (fig.field == "failed_mode") {  // impact/crush_measure.hpp: 0 none, 1 + FailureMode
            fig.categories = {"none"};
            for (const char* mode : impact::kModeNames) fig.categories.push_back(mode);
            for (auto& c : fig.categories) std::replace(c.begin(), c.end(), '_', ' ');
          }
          const std::string follow = p.value("follow_part", "");
          if (!follow.empty()) {
            int part = -1;
            for (std::size_t k = 0; k < m.part_names.size(); ++k)
              if (m.part_names[k] == follow) part = static_cast<int>(k);
            std::array<double, 6> b{1e300, -1e300, 1e300, -1e300, 1e300, -1e300};
            auto grow = [&](std::int64_t node) {
              for (int c = 0; c < 3; ++c) {
                const double v =
                    rm.points[3 * static_cast<std::size_t>(node) + static_cast<std::size_t>(c)];
                b[2 * c] = std::min(b[2 * c], v), b[2 * c + 1] = std::max(b[2 * c + 1], v);
              }
            };
            for (fem::ElementKind k : fem::kElementKinds) {
              const auto& c = m.of(k);
              const auto nodes = static_cast<std::size_t>(fem::nodes_per_element(k));
              const std::size_t first = m.first_cell(k);
              for (std::size_t e = 0; e < c.part.size(); ++e)
                if (c.part[e] == part && !eroded[first + e])
                  for (std::size_t I = 0; I < nodes; ++I) grow(c.conn[nodes * e + I]);
            }
            if (b[0] <= b[1]) fig.focus_bounds = b;
          }
          fig.title = p.at("title").get<std::string>() + " (t = " + fmt_time(frame.time) + " s" +
                      (scale != 1.0 ? ", displacements x" + fmt_time(scale) : std::string()) + ")";
          fig.camera = camera(p.at("camera"));
          const auto png = dir / "figures" / (name + ".png");
          render::render_mesh_png(rm, fig, png);
          out.push_back(png);
        } catch (const std::exception& e) {
          log.warn("figure {} skipped: {}", name, e.what());
        }
      }
    }
  }
  return out;
}

}  // namespace ncfsim::workflow

#include "workflow/stages/transfer_export.hpp"

#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <sstream>

#include "fem/case/stage_kinds.hpp"
#include "fem/errors.hpp"
#include "fem/io/stage_handoff.hpp"
#include "transfer/deck_export.hpp"
#include "workflow/output/output_files.hpp"

namespace ncfsim::workflow {

namespace {

void require_transfer_run(const std::filesystem::path& dir) {
  const auto summary = dir / "summary.json";
  if (!std::filesystem::is_regular_file(summary))
    throw InputError(dir.string(), "", "no summary.json: not the output folder of a run");
  const nlohmann::json j = read_json_file(summary);
  if (!j.is_object()) throw InputError(dir.string(), "", "summary.json cannot be read");
  if (j.value("stage", std::string()) != fem::stage_kind::kTransfer ||
      j.value("status", std::string()) != "completed")
    throw InputError(dir.string(), "",
                     "not a completed transfer run (stage '" + j.value("stage", std::string("?")) +
                         "', status '" + j.value("status", std::string("?")) +
                         "'): run a kind = \"transfer\" case first");
  for (const char* f : {"results.h5", "materials.csv", "ties.csv"})
    if (!std::filesystem::is_regular_file(dir / f))
      throw InputError(dir.string(), "",
                       std::string("the transfer run has no ") + f +
                           " (written with output.frames = \"none\"?)");
}

}  // namespace

ExportResult export_impregnated(const std::filesystem::path& dir, const std::string& format) {
  if (format != "abaqus" && format != "lsdyna")
    throw InputError(dir.string(), "--format",
                     "'" + format + "' is not allowed; one of 'abaqus', 'lsdyna'");
  require_transfer_run(dir);
  const fem::io::StageFrame frame = fem::io::read_last_frame(dir / "results.h5");
  const auto& mesh = frame.mesh;
  transfer::ExportModel m;
  for (std::size_t i = 0; i < frame.n_points(); ++i)
    m.nodes.push_back(
        {frame.coordinates[3 * i], frame.coordinates[3 * i + 1], frame.coordinates[3 * i + 2]});
  const std::size_t n = mesh.n_hex();
  const fem::io::FrameField* axes[3] = {frame.field("fibre_direction"),
                                        frame.field("material_axis_2"),
                                        frame.field("material_axis_3")};
  for (const auto* a : axes)
    if (!a)
      throw InputError(dir.string(), "", "results.h5 has no material axes (not a transfer result)");
  std::map<std::int64_t, std::int32_t> element_of;
  for (std::size_t e = 0; e < n; ++e) {
    std::array<std::int32_t, 8> h{};
    for (std::size_t k = 0; k < 8; ++k) h[k] = static_cast<std::int32_t>(mesh.hex8[8 * e + k]);
    m.hex.push_back(h);
    std::array<double, 9> f{};
    for (int col = 0; col < 3; ++col)
      for (int row = 0; row < 3; ++row)
        f[static_cast<std::size_t>(3 * row + col)] =
            axes[col]->values[3 * e + static_cast<std::size_t>(row)];
    m.frame.push_back(f);
    m.material.push_back(mesh.hex_material.empty() ? 0 : mesh.hex_material[e]);
    element_of[mesh.hex_user_id.empty() ? static_cast<std::int64_t>(e + 1) : mesh.hex_user_id[e]] =
        static_cast<std::int32_t>(e);
  }
  // Kept stitches: bars with the yarn's constants as cell fields (after the hexahedra).
  if (const std::size_t nb = mesh.n_bar(); nb > 0) {
    const fem::io::FrameField* f[3] = {frame.field("stitch_modulus_Pa"),
                                       frame.field("stitch_area_m2"), frame.field("density_kg_m3")};
    for (const auto* x : f)
      if (!x || x->n_components != 1 || x->values.size() != n + nb)
        throw InputError(dir.string(), "",
                         "results.h5 has stitch bars without the yarn's constants");
    auto& st = m.stitches;
    st.modulus = f[0]->values[n], st.area = f[1]->values[n], st.density = f[2]->values[n];
    for (std::size_t b = 0; b < nb; ++b)
      st.bars.push_back({static_cast<std::int32_t>(mesh.bar2[2 * b]),
                         static_cast<std::int32_t>(mesh.bar2[2 * b + 1])});
  }
  const CsvTable mat = read_csv(dir / "materials.csv");
  const auto vf = mat.column("vf"), rho = mat.column("density_kg_m3");
  const char* names[9] = {"E1_Pa", "E2_Pa",  "E3_Pa",  "nu12",  "nu13",
                          "nu23",  "G12_Pa", "G13_Pa", "G23_Pa"};
  std::vector<std::vector<double>> c;
  for (const char* name : names) c.push_back(mat.column(name));
  for (std::size_t k = 0; k < vf.size(); ++k) {
    transfer::ExportMaterial em;
    em.name = "TOW_VF" + std::to_string(static_cast<int>(std::lround(1000 * vf[k])));
    em.density = rho[k];
    em.elastic = {c[0][k], c[1][k], c[2][k], c[3][k], c[4][k], c[5][k], c[6][k], c[7][k], c[8][k]};
    m.materials.push_back(em);
  }
  // ties.csv: interface, slave element id, slave face, master element id, master face.
  std::ifstream in(dir / "ties.csv");
  std::string line;
  std::getline(in, line);
  std::map<std::string, std::size_t> tie_of;
  std::size_t pairs = 0;
  while (std::getline(in, line)) {
    std::stringstream ss(line);
    std::string name, a, b, cc, d;
    if (!std::getline(ss, name, ',') || !std::getline(ss, a, ',') || !std::getline(ss, b, ',') ||
        !std::getline(ss, cc, ',') || !std::getline(ss, d, ','))
      throw InputError((dir / "ties.csv").string(), "", "malformed row: " + line);
    if (!tie_of.count(name)) {
      tie_of[name] = m.ties.size();
      m.ties.push_back({name, {}, {}});
    }
    auto& t = m.ties[tie_of[name]];
    const auto s = element_of.find(std::stoll(a)), ms = element_of.find(std::stoll(cc));
    if (s == element_of.end() || ms == element_of.end())
      throw InputError((dir / "ties.csv").string(), "", "element id not in results.h5: " + line);
    t.slave.emplace_back(s->second, std::stoi(b));
    t.master.emplace_back(ms->second, std::stoi(d));
    ++pairs;
  }
  ExportResult r;
  r.file = dir / (format == "abaqus" ? "impregnated.inp" : "impregnated.k");
  if (format == "abaqus")
    transfer::write_abaqus_inp(r.file, m);
  else
    transfer::write_lsdyna_keyword(r.file, m);
  r.nodes = m.nodes.size();
  r.elements = m.hex.size();
  r.bars = m.stitches.bars.size();
  r.materials = m.materials.size();
  r.tie_pairs = pairs;
  return r;
}

}  // namespace ncfsim::workflow

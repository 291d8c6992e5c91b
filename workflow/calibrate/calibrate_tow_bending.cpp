#include "workflow/calibrate/calibrate_tow_bending.hpp"

#include <cmath>
#include <fstream>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "drape/tow_material.hpp"
#include "fem/errors.hpp"
#include "workflow/case/engine_case.hpp"

namespace ncfsim::workflow {

TowBendingResult calibrate_tow_bending(const TowBendingCalibration& cal) {
  const std::string file = cal.case_file.string();
  if (!(cal.target_bending_length > 0)) throw InputError(file, "--target-bending-length", "must be > 0 m");
  // Which material: the one of the bending probe's part.
  std::size_t mat_index = 0;
  double E11f = 0;
  {
    EngineCase ec = load_engine_case(cal.case_file, cal.overrides);
    if (ec.bending.empty())
      throw InputError(file, "output.bending_length", "the case has no [[output.bending_length]] probe to calibrate against");
    const auto& pp = ec.model.parts[static_cast<std::size_t>(ec.bending.front().part)];
    mat_index = static_cast<std::size_t>(pp.material);
    const auto* tow = dynamic_cast<const drape::TowMaterial*>(ec.model.materials[mat_index].get());
    if (!tow)
      throw InputError(file, fmt::format("material[{}].type", mat_index), "the bent part's material must be tow_biphase");
    E11f = tow->constants().E11f;
  }
  std::filesystem::create_directories(cal.out_dir);
  nlohmann::json runs = nlohmann::json::array();
  TowBendingResult res;
  const std::string probe_key = [&] {
    EngineCase ec = load_engine_case(cal.case_file, cal.overrides);
    return ec.bending.front().name;
  }();
  for (int k = 0; k < cal.max_runs; ++k) {
    std::vector<std::string> ov = cal.overrides;
    ov.push_back(fmt::format("material[{}].E11f={:.9g}", mat_index, E11f));
    ov.push_back("output.figures=false");
    EngineCase ec = load_engine_case(cal.case_file, ov);
    RunOptions o;
    o.out_dir = cal.out_dir / fmt::format("run_{}", k);
    o.verbosity = Verbosity::Quiet;
    o.overrides = ov;
    const int code = run_engine_case(ec, o);
    std::ifstream in(o.out_dir / "summary.json");
    const auto s = nlohmann::json::parse(in);
    if (code != kSuccess || s[probe_key + "_bending_length_m"].is_null())
      throw NumericalError(fmt::format("calibration run {} (E11f = {:.4g} Pa) failed: see {}", k, E11f, o.out_dir.string()));
    const double c = s[probe_key + "_bending_length_m"].get<double>();
    const double E1 = s[probe_key + "_axial_modulus_Pa"].get<double>();
    runs.push_back({{"run", k}, {"E11f_Pa", E11f}, {"axial_modulus_Pa", E1}, {"bending_length_m", c},
                    {"beam_theory_bending_length_m", s[probe_key + "_beam_theory_bending_length_m"]}});
    res = {E11f, c, k + 1, std::abs(c / cal.target_bending_length - 1) <= cal.tolerance, mat_index};
    if (res.converged) break;
    // c ~ E1^(1/3): scale the axial modulus by the cube of the length ratio; the matrix phase
    // keeps its share (E1 = E11f + matrix part).
    const double E1_new = E1 * std::pow(cal.target_bending_length / c, 3);
    E11f = std::max(0.0, E11f + (E1_new - E1));
  }
  nlohmann::json out{{"case_file", file},
                     {"target_bending_length_m", cal.target_bending_length},
                     {"tolerance", cal.tolerance},
                     {"converged", res.converged},
                     {"E11f_Pa", res.E11f},
                     {"bending_length_m", res.bending_length},
                     {"runs", runs}};
  write_file_atomically(cal.out_dir / "calibration.json", out.dump(2) + "\n");
  return res;
}

}  // namespace ncfsim::workflow

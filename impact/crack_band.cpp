#include "impact/crack_band.hpp"

#include <fmt/format.h>

#include <nlohmann/json.hpp>

namespace ncfsim::impact {

void CrackBandRaise::add(int mode, double factor, std::int64_t element) {
  const auto k = static_cast<std::size_t>(mode);
  ++elements[k];
  sum_factor[k] += factor;
  if (factor > max_factor[k]) max_factor[k] = factor, worst_element[k] = element;
}

std::vector<std::string> CrackBandRaise::warnings() const {
  std::vector<std::string> out;
  for (std::size_t k = 0; k < elements.size(); ++k) {
    if (elements[k] == 0) continue;
    out.push_back(fmt::format(
        "crack band: {} of {} tow elements are too long across a {} crack for its fracture "
        "energy: raised to the smallest free of snap-back, {:.3g} times on average, {:.3g} at "
        "most (element {}); refine the mesh to crush with the energy as given",
        elements[k], elements_checked, kModeNames[k],
        sum_factor[k] / static_cast<double>(elements[k]), max_factor[k], worst_element[k]));
  }
  return out;
}

nlohmann::json CrackBandRaise::to_json() const {
  nlohmann::json j = nlohmann::json::object();
  for (std::size_t k = 0; k < elements.size(); ++k) {
    if (elements[k] == 0) continue;
    j[kModeNames[k]] = {{"elements", elements[k]},
                        {"mean_factor", sum_factor[k] / static_cast<double>(elements[k])},
                        {"max_factor", max_factor[k]}};
  }
  return j;
}

}  // namespace ncfsim::impact

#include "fem/energy.hpp"

#include <algorithm>
#include <cmath>

namespace ncfsim::fem {

double EnergyBalance::scale() const {
  return std::max(std::abs(initial_total) + std::abs(external_work),
                  std::abs(kinetic) + std::abs(internal) + std::abs(hourglass) + std::abs(contact) +
                      std::abs(damping) + std::abs(eroded_kinetic));
}

double EnergyBalance::error() const {
  const double residual = total() - initial_total - external_work;
  return std::abs(residual) / std::max({scale(), scale_max, kEnergyScaleFloor});
}

}  // namespace ncfsim::fem

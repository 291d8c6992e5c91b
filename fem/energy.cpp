#include "fem/energy.hpp"

#include <algorithm>
#include <cmath>

namespace ncfsim::fem {

double EnergyBalance::error() const {
  const double residual = total() - initial_total - external_work;
  const double scale =
      std::max({std::abs(initial_total) + std::abs(external_work),
                std::abs(kinetic) + std::abs(internal) + std::abs(hourglass) + std::abs(contact) +
                    std::abs(damping) + std::abs(eroded_kinetic),
                1e-30});
  return std::abs(residual) / scale;
}

}  // namespace ncfsim::fem

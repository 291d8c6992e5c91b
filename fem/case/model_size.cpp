#include "fem/case/model_size.hpp"

#include <cmath>
#include <sstream>

#include "fem/errors.hpp"

namespace ncfsim::fem {

double estimated_model_bytes(double n_nodes, double n_hex, double n_bars) {
  // Per node: 12 nodal vectors of 3 doubles (state, forces, masses), contact and tool arrays.
  // Per hexahedron: ~130 doubles of element state (stress, strain, history, hourglass, frames,
  // volumes) and six contact faces with their frames and candidates. Per bar: ~20 doubles.
  return 450.0 * n_nodes + 2500.0 * n_hex + 300.0 * n_bars;
}

void require_model_fits(const std::string& file, const std::string& key, double n_nodes,
                        double n_hex, double n_bars) {
  const double need = estimated_model_bytes(n_nodes, n_hex, n_bars);
  const double have = available_memory_bytes();
  if (std::isfinite(need) && need <= 0.8 * have) return;
  std::ostringstream os;
  os.precision(3);
  os << "makes a model too large for this machine: about " << n_hex << " hexahedra, " << n_bars
     << " bars and " << n_nodes << " nodes need about " << bytes_text(need) << ", and "
     << bytes_text(have) << " of memory is available (at most 80 % of it may be used): use a "
     << "coarser mesh (mesh.resolution = \"coarse\", larger elements) or a smaller part";
  throw InputError(file, key, os.str());
}

}  // namespace ncfsim::fem

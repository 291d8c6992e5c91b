#include "fem/case/model_size.hpp"

#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <fstream>
#include <sstream>

#include "fem/errors.hpp"

namespace ncfsim::fem {

double estimated_model_bytes(double n_nodes, double n_hex, double n_bars) {
  // Per node: 12 nodal vectors of 3 doubles (state, forces, masses), contact and tool arrays.
  // Per hexahedron: ~130 doubles of element state (stress, strain, history, hourglass, frames,
  // volumes) and six contact faces with their frames and candidates. Per bar: ~20 doubles.
  return 450.0 * n_nodes + 2500.0 * n_hex + 300.0 * n_bars;
}

double available_memory_bytes() {
  std::ifstream in("/proc/meminfo");
  std::string key;
  double kb = 0;
  std::string unit;
  while (in >> key >> kb >> unit)
    if (key == "MemAvailable:") return kb * 1024.0;
  const long pages = sysconf(_SC_PHYS_PAGES), page = sysconf(_SC_PAGE_SIZE);
  return pages > 0 && page > 0 ? static_cast<double>(pages) * static_cast<double>(page) : 1e300;
}

std::string bytes_text(double bytes) {
  char buf[64];
  if (bytes >= 1e9)
    std::snprintf(buf, sizeof buf, "%.3g GB", bytes / 1e9);
  else
    std::snprintf(buf, sizeof buf, "%.3g MB", bytes / 1e6);
  return buf;
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

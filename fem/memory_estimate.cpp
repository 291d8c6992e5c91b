#include "fem/memory_estimate.hpp"

#include <sys/resource.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <sstream>

#include "fem/contact_interface.hpp"
#include "fem/errors.hpp"
#include "fem/model.hpp"

namespace ncfsim::fem {

namespace {

// Bytes per unit, counted from the engine's arrays (docs/performance.md, "Memory", lists them).
// Measured, not counted: the program's own resident set, and what the run adds after its set-up
// when it draws its figures in this process (VTK, OSMesa, the results read back; the contact's
// growth over the run and the frames are inside it): 185 MB and 490 B per node and 1.77 kB per
// hexahedron, fitted to the CI, coarse and paper-density hemispheres (1 rank, 6 December 2026).
constexpr double kPerNode = 323;            // 9 PETSc nodal vectors, solver masks, mesh coordinates
constexpr double kPerNodeErosion = 5;       // node-to-element map, freed flags
constexpr double kPerNodeDynamicMass = 24;  // the mass-scaling scratch
constexpr double kPerNodeParallel = 64;     // ownership, halo positions, star-forest buffers
constexpr double kToolPerNode = 56;         // contact node, friction state, proximity reference
constexpr double kToolPerTriangle = 120;    // STL tools: triangles, normals, buckets
constexpr double kSetupPerElement = 24;  // renumbering keys, sort buffers (set-up, kept by malloc)
// Per element, by kind: element_memory (fem/elements/element_kind.hpp).

// Output on the root: each result writer's copy of the mesh, then the largest of one frame in the
// making (all cell arrays are sized to every cell), the checkpoint's copy of the state, and the
// figures drawn at the end (measured, above).
constexpr double kWriterPerNode = 32;
constexpr double kFramePerCell = 200, kFramePerNode = 72, kVtuPerNode = 72;
constexpr double kCheckpointPerNode = 72;
constexpr double kFiguresPerNode = 490;

double n_of(const Mesh& m, ElementKind k) { return static_cast<double>(m.elements(k).size()); }

}  // namespace

double MemoryEstimate::per_rank() const {
  double s = 0;
  for (const auto& sh : shares) s += sh.bytes;
  return s;
}

std::string MemoryEstimate::describe() const {
  std::ostringstream os;
  os << "about " << bytes_text(per_rank()) << (ranks > 1 ? " a rank" : "") << " (";
  bool first = true;
  for (const auto& sh : shares) {
    if (sh.bytes < 0.5e6) continue;
    os << (first ? "" : ", ") << sh.what << " " << std::lround(sh.bytes / 1e6);
    first = false;
  }
  os << " MB)";
  if (ranks > 1) os << ", " << bytes_text(total()) << " on " << ranks << " ranks";
  return os.str();
}

MemoryEstimate estimate_memory(const Model& model, int ranks, const OutputMemory& output) {
  const Mesh& mesh = model.mesh;
  MemoryEstimate est;
  est.ranks = std::max(1, ranks);
  const double nodes = static_cast<double>(mesh.n_nodes());
  std::array<double, kElementKinds.size()> n{};  // elements of each kind
  double cells = 0;
  for (ElementKind k : kElementKinds) cells += n[static_cast<std::size_t>(k)] = n_of(mesh, k);
  // Sum of a per-element figure of the kinds' rows, over the model's elements.
  const auto per_element = [&](double ElementMemory::*field) {
    double s = 0;
    for (ElementKind k : kElementKinds)
      s += element_memory(k).*field * n[static_cast<std::size_t>(k)];
    return s;
  };
  bool material_failure = false;
  for (const auto& m : model.materials) material_failure |= m->failure_history_row() >= 0;
  const bool erosion =
      model.time.erosion_step_ratio > 0 || model.time.mass_scaling_erode_at_cap || material_failure;

  est.shares.push_back({"program", kProgramBytes});
  // Nodes: a kind whose every part is a group of its own keeps arrays over every node per part.
  double per_node = kPerNode + (erosion ? kPerNodeErosion : 0) +
                    (model.time.mass_scaling_dynamic ? kPerNodeDynamicMass : 0) +
                    (est.ranks > 1 ? kPerNodeParallel : 0);
  for (ElementKind k : kElementKinds) {
    if (element_memory(k).node_arrays_per_part == 0) continue;
    std::vector<char> has(mesh.part_names.size(), 0);
    for (auto p : mesh.elements(k).part) has[static_cast<std::size_t>(p)] = 1;
    per_node += element_memory(k).node_arrays_per_part *
                static_cast<double>(std::count(has.begin(), has.end(), 1));
  }
  est.shares.push_back({"nodes", per_node * nodes});

  // Elements, kind by kind: a group's doubles grow with its material law's history.
  for (ElementKind k : kElementKinds) {
    const ElementSet& set = mesh.elements(k);
    if (set.size() == 0) continue;
    const ElementMemory em = element_memory(k);
    double bytes = (em.fixed + 8 * em.doubles) * static_cast<double>(set.size());
    if (em.law_history)
      for (std::size_t e = 0; e < set.size(); ++e) {
        int mat = set.material.empty() ? -1 : set.material[e];
        if (mat < 0) mat = model.parts[static_cast<std::size_t>(set.part[e])].material;
        if (mat >= 0 && static_cast<std::size_t>(mat) < model.materials.size())
          bytes += 8.0 * model.materials[static_cast<std::size_t>(mat)]->n_history();
      }
    if (!set.material_axes.empty()) bytes += em.own_axes * static_cast<double>(set.size());
    est.shares.push_back({em.share, bytes});
  }
  est.shares.push_back({"set-up", kSetupPerElement * cells});

  for (const auto& c : model.contacts)
    est.shares.push_back({"contact '" + c->name() + "'", c->estimated_bytes(mesh, erosion)});
  double tools = 0;
  for (const auto& t : model.tools) {
    tools += kToolPerNode * static_cast<double>(t.contact_nodes.size());
    if (t.surface.triangles)
      tools += kToolPerTriangle * static_cast<double>(t.surface.triangles->triangles().size());
  }
  if (tools > 0) est.shares.push_back({"tools", tools});

  // The root's output: writers' meshes, then the largest of a frame, a checkpoint, the figures.
  double out = 0, transient = 0;
  if (output.frames) {
    const double writers = output.vtu ? 2.0 : 1.0;
    out += writers * (kWriterPerNode * nodes + per_element(&ElementMemory::writer));
    if (output.vtu) out += per_element(&ElementMemory::vtu);
    transient =
        kFramePerCell * cells + kFramePerNode * nodes + (output.vtu ? kVtuPerNode * nodes : 0.0);
  }
  if (output.checkpoints)
    transient =
        std::max(transient, kCheckpointPerNode * nodes + per_element(&ElementMemory::checkpoint));
  if (output.figures)
    transient = std::max(
        transient, kFiguresBytes + kFiguresPerNode * nodes + per_element(&ElementMemory::figures));
  if (out + transient > 0) est.shares.push_back({"output", out + transient});
  est.root_only = out + transient;
  return est;
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

double peak_resident_mb() {
  rusage u{};
  return getrusage(RUSAGE_SELF, &u) == 0 ? static_cast<double>(u.ru_maxrss) / 1024.0 : 0.0;
}

double resident_mb() {
  std::ifstream in("/proc/self/status");
  for (std::string line; std::getline(in, line);)
    if (line.rfind("VmRSS:", 0) == 0) return std::atof(line.c_str() + 6) / 1024.0;
  return 0.0;
}

void require_memory_fits(const MemoryEstimate& estimate, const std::string& file) {
  const double need = estimate.total(), have = available_memory_bytes();
  if (std::isfinite(need) && need <= 0.8 * have) return;
  throw InputError(file, "mesh",
                   "makes a model too large for this machine: it needs " + estimate.describe() +
                       ", and " + bytes_text(have) +
                       " of memory is available (at most 80 % of it may be used): use a coarser "
                       "mesh (mesh.resolution = \"coarse\"), a smaller part, fewer ranks, or a "
                       "machine with more memory");
}

}  // namespace ncfsim::fem

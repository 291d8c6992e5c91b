#pragma once
// How much memory a model will take on one rank, from what each part of the engine allocates for
// it (docs/performance.md, "Memory"), before the solver is built: a model too large for the
// machine is refused as bad input naming the estimate, and the run's log and summary.json put the
// estimate beside the measured peak.
//
// Every rank keeps the whole model's arrays (docs/parallel.md): a run on N ranks needs about N
// times one rank's memory, the root a little more for the output.
#include <string>
#include <vector>

namespace ncfsim::fem {

struct Model;

/// What the model will hold, by share (bytes), one rank's.
struct MemoryEstimate {
  struct Share {
    std::string what;  // "nodes", "hexahedra", "contact 'fabric'", ...
    double bytes = 0;
  };
  std::vector<Share> shares;
  int ranks = 1;
  double root_only = 0;  // of the shares, what only the root holds (the output), bytes

  /// The root's: the largest of the ranks.
  double per_rank() const;
  /// Every rank the model, the root also the output.
  double total() const { return per_rank() * ranks - root_only * (ranks - 1); }
  /// "about 880 MB a rank (program 60, nodes 115, hexahedra 93, contact 'fabric' 350, ...)".
  std::string describe() const;
};

/// What the root also holds for the output: the result writers' copies of the mesh and a frame
/// in the making (xdmf and/or vtu frames), the checkpoint's copy of the state, the figures.
struct OutputMemory {
  bool frames = true;       // results.h5 / frames/*.vtu written during the run
  bool vtu = false;         // the VTU series keeps its own topology and copies each field
  bool figures = true;      // figures rendered in this process at the end
  bool checkpoints = true;  // checkpoint.h5 (a copy of the state while it is written)
};

/// What the program itself holds (libraries: PETSc, MPI, HDF5, VTK), one rank, and what drawing
/// figures in the process adds at the least (VTK, OSMesa), bytes: measured (docs/performance.md).
inline constexpr double kProgramBytes = 64e6;
inline constexpr double kFiguresBytes = 185e6;

/// The estimate for `model` (as read from its case: mesh, materials, contacts, tools), on `ranks`
/// ranks, with the root's output.
MemoryEstimate estimate_memory(const Model& model, int ranks, const OutputMemory& output);

/// Memory available to this process now (MemAvailable of /proc/meminfo; the physical memory when
/// that cannot be read), bytes.
double available_memory_bytes();

/// "1.2 GB", "350 MB".
std::string bytes_text(double bytes);

/// The process's largest resident set so far (getrusage) and its resident set now (VmRSS of
/// /proc/self/status), MB; 0 where they cannot be read.
double peak_resident_mb();
double resident_mb();

/// Throws InputError(file, "mesh") when the estimate, on all its ranks, needs more than 80 % of
/// the memory available now, naming the estimate and what to change.
void require_memory_fits(const MemoryEstimate& estimate, const std::string& file);

}  // namespace ncfsim::fem

#pragma once
// Stop requests of a running case (SIGINT/SIGTERM). The output folder's files are in
// workflow/output/output_files.hpp.
#include "workflow/output/output_files.hpp"

namespace ncfsim::workflow {

/// SIGINT handling for long runs: the first Ctrl-C asks the run to stop after the current cycle,
/// a second one terminates the process at once.
class StopRequest {
 public:
  static void install();
  static bool requested();
  static void reset();
};

}  // namespace ncfsim::workflow

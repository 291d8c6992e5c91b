#pragma once
// Stop requests of a running case (SIGINT/SIGTERM). The output folder's files are in
// workflow/output/output_files.hpp.
#include "workflow/output/output_files.hpp"

namespace ncfsim::workflow {

/// Signal handling for long runs: the first SIGINT, SIGTERM, SIGHUP or SIGQUIT asks the run to stop
/// after the current cycle (or stage step), a second one more than a second later terminates the
/// process at once (one within the second is the same request, sent to every process of a job);
/// SIGPIPE is ignored. Installed first thing in main(), so a signal at any time leaves consistent
/// files.
class StopRequest {
 public:
  static void install();
  static bool requested();
  static void reset();
};

}  // namespace ncfsim::workflow

#pragma once
// Helpers of the tests that stop and resume runs: a run folder's summary.json, and waiting until
// its log.txt shows a number of checkpoints.
#include <chrono>
#include <nlohmann/json.hpp>
#include <string>
#include <thread>

#include "tests/workflow/cli_test_support.hpp"

namespace ncfsim::test {

inline nlohmann::json summary(const fs::path& out) {
  return nlohmann::json::parse(slurp(out / "summary.json"));
}

/// summary.json keys that describe the process, not the results: a stopped and resumed run
/// differs from an uninterrupted one in them (the pages the kernel gave, the clock, the memory,
/// the command line), so the comparisons of results skip them.
inline bool is_process_fact(const std::string& key) {
  return key == "wall_seconds" || key == "peak_memory_MB" || key == "huge_pages_MB" ||
         key == "timers_s" || key == "overrides" || key == "mpi_per_rank";
}

/// How many times `what` occurs in `text`.
inline int count(const std::string& text, const std::string& what) {
  int n = 0;
  for (auto p = text.find(what); p != std::string::npos; p = text.find(what, p + 1)) ++n;
  return n;
}

/// Waits until log.txt of `out` holds `n` checkpoint lines (false after `seconds`).
inline bool wait_for_checkpoints(const fs::path& out, int n, double seconds = 60) {
  const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(seconds);
  while (std::chrono::steady_clock::now() < end) {
    if (fs::exists(out / "log.txt") && count(slurp(out / "log.txt"), "checkpoint at t =") >= n)
      return true;
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  return false;
}

}  // namespace ncfsim::test

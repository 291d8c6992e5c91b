#include "workflow/run/run_output.hpp"

#include <unistd.h>

#include <atomic>
#include <csignal>
#include <cstdint>
#include <cstdlib>
#include <ctime>

namespace ncfsim::workflow {

namespace {
std::atomic<int> g_stop{0};
std::atomic<std::int64_t> g_first_ns{0};  // when the first request came (CLOCK_MONOTONIC)

// A batch system's or `pkill`'s signal reaches every process of a job, and `ncfsim run --np`
// passes the user's Ctrl-C on to its ranks as well: a rank may see one request twice within
// moments. Only a second signal after this long aborts.
constexpr std::int64_t kSameRequestNs = 1'000'000'000;

std::int64_t monotonic_ns() {  // clock_gettime is async-signal-safe
  timespec ts{};
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return static_cast<std::int64_t>(ts.tv_sec) * 1'000'000'000 + ts.tv_nsec;
}

extern "C" void on_sigint(int) {
  const std::int64_t now = monotonic_ns();
  if (g_stop.load() >= 1) {
    if (now - g_first_ns.load() < kSameRequestNs) return;
    std::_Exit(130);
  }
  g_first_ns.store(now);
  g_stop.store(1);
  static const char msg[] =
      "\n[ncfsim] interrupt: stopping at the end of this cycle or step, keeping what is written "
      "(Ctrl-C again, a second later, to abort)\n";
  [[maybe_unused]] auto r = ::write(2, msg, sizeof msg - 1);
}
}  // namespace

void StopRequest::install() {
  struct sigaction sa {};
  sa.sa_handler = on_sigint;
  sigemptyset(&sa.sa_mask);
  sa.sa_flags = SA_RESTART;
  // Every termination signal that can be caught ends the run like Ctrl-C (status interrupted,
  // files consistent); a closed stdout (ncfsim run ... | head) must not kill it: writes to it
  // fail instead and log.txt keeps the lines.
  for (int sig : {SIGINT, SIGTERM, SIGHUP, SIGQUIT}) sigaction(sig, &sa, nullptr);
  struct sigaction ignore {};
  ignore.sa_handler = SIG_IGN;
  sigemptyset(&ignore.sa_mask);
  sigaction(SIGPIPE, &ignore, nullptr);
}
bool StopRequest::requested() { return g_stop.load(std::memory_order_relaxed) > 0; }
void StopRequest::reset() { g_stop = 0; }

}  // namespace ncfsim::workflow

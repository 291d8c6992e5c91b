#include "workflow/run/run_output.hpp"

#include <unistd.h>

#include <atomic>
#include <csignal>
#include <cstdlib>

namespace ncfsim::workflow {

namespace {
std::atomic<int> g_stop{0};
extern "C" void on_sigint(int) {
  if (g_stop.fetch_add(1) >= 1) std::_Exit(130);
  static const char msg[] =
      "\n[ncfsim] interrupt: stopping at the end of this cycle or step, keeping what is written "
      "(Ctrl-C again to abort)\n";
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

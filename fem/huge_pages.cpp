#include "fem/huge_pages.hpp"

#include <sys/mman.h>

#include <cstdint>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <utility>
#include <vector>

#ifndef MADV_COLLAPSE
#define MADV_COLLAPSE 25  // Linux 6.1
#endif

namespace ncfsim::fem {

namespace {

constexpr std::uintptr_t kHuge = std::uintptr_t{2} << 20;

std::size_t anon_huge_bytes() {
  std::ifstream in("/proc/self/smaps_rollup");
  std::size_t kb = 0;
  for (std::string line; std::getline(in, line);)
    if (line.rfind("AnonHugePages:", 0) == 0) {
      std::istringstream(line.substr(14)) >> kb;
      return kb * 1024;
    }
  return 0;
}

}  // namespace

std::string HugePageAdvice::describe() const {
  std::ostringstream os;
  if (switched_off) return "2 MB pages: not asked for (NCFSIM_HUGE_PAGES=0)";
  if (!available) return "2 MB pages: not available (transparent huge pages off)";
  os << "2 MB pages: " << huge_bytes / (1 << 20) << " MB of " << advised_bytes / (1 << 20)
     << " MB of large arrays";
  if (failed_regions > 0) os << " (" << failed_regions << " regions of 2 MB refused)";
  return os.str();
}

HugePageAdvice advise_huge_pages(std::size_t min_bytes) {
  HugePageAdvice r;
  if (const char* e = std::getenv("NCFSIM_HUGE_PAGES"); e && std::string(e) == "0") {
    r.switched_off = true;
    return r;
  }
  {
    std::ifstream in("/sys/kernel/mm/transparent_hugepage/enabled");
    std::string modes;
    std::getline(in, modes);
    if (modes.empty() || modes.find("[never]") != std::string::npos) return r;
  }
  r.available = true;
  // start-end perms offset dev inode [path]: private, writable, no file behind it ("[heap]" or
  // no name). Read whole before any advice splits the mappings it lists.
  std::vector<std::pair<std::uintptr_t, std::uintptr_t>> ranges;
  std::ifstream maps("/proc/self/maps");
  for (std::string line; std::getline(maps, line);) {
    std::istringstream is(line);
    std::string range, perms, offset, dev, path;
    unsigned long inode = 1;
    is >> range >> perms >> offset >> dev >> inode;
    std::getline(is >> std::ws, path);
    if (perms.size() < 4 || perms[0] != 'r' || perms[1] != 'w' || perms[3] != 'p' || inode != 0)
      continue;
    if (!path.empty() && path != "[heap]") continue;  // [stack], [vvar], ...
    const auto dash = range.find('-');
    if (dash == std::string::npos) continue;
    const std::uintptr_t lo = std::stoull(range.substr(0, dash), nullptr, 16);
    const std::uintptr_t hi = std::stoull(range.substr(dash + 1), nullptr, 16);
    const std::uintptr_t a = (lo + kHuge - 1) & ~(kHuge - 1), b = hi & ~(kHuge - 1);
    if (hi - lo >= min_bytes && b > a) ranges.emplace_back(a, b);
  }
  // One 2 MB region at a time, each failure tried once more: over a whole range the kernel stops
  // at the first region whose huge page it cannot get at once (both ranks asking at the same
  // moment), and the rest stayed on 4 KB pages (half the paper model's 620 MB; khugepaged did
  // not catch up within the run).
  std::vector<std::uintptr_t> failed;
  for (const auto& [a, b] : ranges) {
    if (madvise(reinterpret_cast<void*>(a), b - a, MADV_HUGEPAGE) != 0) continue;
    r.advised_bytes += b - a;
    for (std::uintptr_t q = a; q < b; q += kHuge)
      if (madvise(reinterpret_cast<void*>(q), kHuge, MADV_COLLAPSE) != 0) failed.push_back(q);
  }
  for (const std::uintptr_t q : failed)
    if (madvise(reinterpret_cast<void*>(q), kHuge, MADV_COLLAPSE) != 0) ++r.failed_regions;
  r.huge_bytes = anon_huge_bytes();
  return r;
}

}  // namespace ncfsim::fem

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

// Under AddressSanitizer the pages are not what is measured, and its shadow mappings are many.
#if defined(__SANITIZE_ADDRESS__)
constexpr bool kSanitized = true;
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
constexpr bool kSanitized = true;
#else
constexpr bool kSanitized = false;
#endif
#else
constexpr bool kSanitized = false;
#endif

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
  if (sanitized) return "2 MB pages: not asked for (a sanitizer build)";
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
  if (kSanitized) {
    r.sanitized = true;
    return r;
  }
  {
    std::ifstream in("/sys/kernel/mm/transparent_hugepage/enabled");
    std::string modes;
    std::getline(in, modes);
    if (modes.empty() || modes.find("[never]") != std::string::npos) return r;
  }
  r.available = true;
  // smaps: a header per mapping (start-end perms offset dev inode [path]) then its fields, Rss
  // among them. Private, writable, no file behind it ("[heap]" or no name), and mostly resident:
  // a reservation that is mostly untouched (a sanitizer's shadow, terabytes; a thread's arena)
  // would be made resident by MADV_COLLAPSE, which allocates every region it is given. Read
  // whole before any advice splits the mappings it lists.
  std::vector<std::pair<std::uintptr_t, std::uintptr_t>> ranges;
  std::ifstream maps("/proc/self/smaps");
  std::uintptr_t lo = 0, hi = 0;
  bool candidate = false;
  for (std::string line; std::getline(maps, line);) {
    if (line.rfind("Rss:", 0) == 0) {
      if (!candidate) continue;
      std::size_t rss_kb = 0;
      std::istringstream(line.substr(4)) >> rss_kb;
      const std::uintptr_t a = (lo + kHuge - 1) & ~(kHuge - 1), b = hi & ~(kHuge - 1);
      if (hi - lo >= min_bytes && b > a && 2 * rss_kb * 1024 >= hi - lo) ranges.emplace_back(a, b);
      candidate = false;
      continue;
    }
    // A header starts with a hexadecimal range; the field lines with a capitalised name.
    const auto dash = line.find('-');
    const auto space = line.find(' ');
    if (dash == std::string::npos || space == std::string::npos || dash > space ||
        line.find(':') < dash)
      continue;
    std::istringstream is(line);
    std::string range, perms, offset, dev, path;
    unsigned long inode = 1;
    is >> range >> perms >> offset >> dev >> inode;
    std::getline(is >> std::ws, path);
    candidate = perms.size() >= 4 && perms[0] == 'r' && perms[1] == 'w' && perms[3] == 'p' &&
                inode == 0 && (path.empty() || path == "[heap]");  // not [stack], [vvar], ...
    if (candidate) {
      lo = std::stoull(range.substr(0, dash), nullptr, 16);
      hi = std::stoull(range.substr(dash + 1), nullptr, 16);
    }
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

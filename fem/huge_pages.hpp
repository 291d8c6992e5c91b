#pragma once
// Large arrays on 2 MB pages. An element kernel reads ~50 separate [component][n] streams per
// element, each on its own 4 KB page, and the contact and node passes scatter over arrays of
// megabytes: with 4 KB pages most of a forming cycle's page translations miss the TLB. Debian's
// default (transparent huge pages "madvise") gives 2 MB pages only to memory that asks for them.
#include <cstddef>
#include <string>

namespace ncfsim::fem {

struct HugePageAdvice {
  bool switched_off = false;      // NCFSIM_HUGE_PAGES=0
  bool sanitized = false;         // an AddressSanitizer build: not asked for
  bool available = false;         // the kernel has transparent huge pages (not "never")
  std::size_t advised_bytes = 0;  // in mappings asked to use them
  std::size_t huge_bytes = 0;     // on 2 MB pages afterwards (AnonHugePages of the process)
  std::size_t failed_regions = 0; // 2 MB regions the kernel would not collapse (twice asked)
  std::string describe() const;   // for the log
};

/// Asks the kernel to back this process's large private anonymous mappings (each at least
/// min_bytes and at least half resident: the heap and malloc's own mappings, where the model's
/// arrays are) with 2 MB
/// pages: MADV_HUGEPAGE for what is touched later, MADV_COLLAPSE for what is there now (region
/// by region). Called again, it covers what was allocated since (a new mapping). Changes
/// no value in memory; errors (an older kernel, no THP) leave the pages as they are.
/// NCFSIM_HUGE_PAGES=0 in the environment turns it off (for A/B timings).
HugePageAdvice advise_huge_pages(std::size_t min_bytes = std::size_t{8} << 20);

}  // namespace ncfsim::fem

// 2 MB pages for the model's arrays (fem/huge_pages.hpp): asking for them changes no value in
// memory, covers a large array where the kernel offers them, leaves a sparsely touched reservation
// sparse (MADV_COLLAPSE would make it resident: a sanitizer's terabytes of shadow took minutes),
// and is off with NCFSIM_HUGE_PAGES=0.
#include <gtest/gtest.h>
#include <sys/mman.h>
#include <unistd.h>

#include <cstdlib>
#include <vector>

#include "fem/huge_pages.hpp"

using namespace ncfsim;

TEST(HugePages, LargeArraysKeepTheirValues) {
  std::vector<double> a(std::size_t{8} << 20);  // 64 MB: malloc maps it on its own
  for (std::size_t i = 0; i < a.size(); ++i) a[i] = 0.5 * static_cast<double>(i) + 1e-3;
  const fem::HugePageAdvice r = fem::advise_huge_pages();
  for (std::size_t i = 0; i < a.size(); ++i)
    ASSERT_EQ(a[i], 0.5 * static_cast<double>(i) + 1e-3) << "at " << i;
  if (!r.available) GTEST_SKIP() << r.describe();
  // The array's mapping, less its 2 MB-unaligned ends.
  EXPECT_GE(r.advised_bytes, a.size() * sizeof(double) - (std::size_t{4} << 20)) << r.describe();
  EXPECT_NE(r.describe().find("2 MB pages"), std::string::npos);
}

TEST(HugePages, SparselyTouchedReservationStaysSparse) {
  const std::size_t bytes = std::size_t{512} << 20, stride = std::size_t{2} << 20;
  void* p = mmap(nullptr, bytes, PROT_READ | PROT_WRITE,
                 MAP_PRIVATE | MAP_ANONYMOUS | MAP_NORESERVE, -1, 0);
  ASSERT_NE(p, MAP_FAILED);
  // One byte every 2 MB, as a sanitizer's shadow is written.
  for (std::size_t i = 0; i < bytes; i += stride) static_cast<char*>(p)[i] = 1;
  const fem::HugePageAdvice r = fem::advise_huge_pages();
  const std::size_t page = static_cast<std::size_t>(sysconf(_SC_PAGESIZE));
  std::vector<unsigned char> resident(bytes / page);
  ASSERT_EQ(mincore(p, bytes, resident.data()), 0);
  std::size_t n = 0;
  for (const unsigned char c : resident) n += c & 1;
  munmap(p, bytes);
  EXPECT_LE(n, bytes / stride) << r.describe();  // the touched 4 KB pages, no more
}

TEST(HugePages, OffWithTheEnvironmentSwitch) {
  setenv("NCFSIM_HUGE_PAGES", "0", 1);
  const fem::HugePageAdvice r = fem::advise_huge_pages();
  unsetenv("NCFSIM_HUGE_PAGES");
  EXPECT_TRUE(r.switched_off);
  EXPECT_EQ(r.advised_bytes, 0u);
  EXPECT_NE(r.describe().find("NCFSIM_HUGE_PAGES=0"), std::string::npos);
}

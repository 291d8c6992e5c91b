// 2 MB pages for the model's arrays (fem/huge_pages.hpp): asking for them changes no value in
// memory, covers a large array where the kernel offers them, and is off with NCFSIM_HUGE_PAGES=0.
#include <gtest/gtest.h>

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

TEST(HugePages, OffWithTheEnvironmentSwitch) {
  setenv("NCFSIM_HUGE_PAGES", "0", 1);
  const fem::HugePageAdvice r = fem::advise_huge_pages();
  unsetenv("NCFSIM_HUGE_PAGES");
  EXPECT_TRUE(r.switched_off);
  EXPECT_EQ(r.advised_bytes, 0u);
  EXPECT_NE(r.describe().find("NCFSIM_HUGE_PAGES=0"), std::string::npos);
}

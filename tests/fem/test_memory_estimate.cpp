// The memory estimate's arithmetic (fem/memory_estimate.hpp) on a block counted by hand, and the
// refusal of a model too large for the machine. What it is measured against (the shipped cases'
// resident sets): tests/workflow/test_memory_estimate.cpp, docs/performance.md "Memory".
#include "fem/errors.hpp"
#include "fem/memory_estimate.hpp"
#include "tests/test_support.hpp"

using namespace ncfsim;

namespace {

double share(const fem::MemoryEstimate& e, const std::string& what) {
  for (const auto& s : e.shares)
    if (s.what == what) return s.bytes;
  return -1;
}

fem::Model block() {
  fem::Model model;
  test::add_elastic_block(model, "block", {0, 0, 0}, {0.04, 0.04, 0.04}, {4, 4, 4}, 7850, 200e9,
                          0.3);
  return model;
}

}  // namespace

// 125 nodes at 323 B (9 nodal vectors, masks, coordinates), 64 elastic hexahedra at 116 B of
// integers and 75 doubles, 24 B each at set-up, the program's 64 MB; no contact, tool or output.
TEST(MemoryEstimate, ABlockOfElasticHexahedraCountsItsNodesAndElements) {
  const fem::Model model = block();
  const auto e = fem::estimate_memory(model, 1, {false, false, false, false});
  EXPECT_DOUBLE_EQ(share(e, "program"), 64e6);
  EXPECT_DOUBLE_EQ(share(e, "nodes"), 323.0 * 125);
  EXPECT_DOUBLE_EQ(share(e, "hexahedra"), (116.0 + 8 * 75) * 64);
  EXPECT_DOUBLE_EQ(share(e, "set-up"), 24.0 * 64);
  EXPECT_EQ(share(e, "output"), -1);
  EXPECT_DOUBLE_EQ(e.per_rank(), 64e6 + 323.0 * 125 + 716.0 * 64 + 24.0 * 64);
  EXPECT_DOUBLE_EQ(e.total(), e.per_rank());
}

// Each rank holds the whole model (and its ownership arrays, 64 B a node); the output (here the
// figures: 185 MB and their share per node and hexahedron) is the root's only.
TEST(MemoryEstimate, OnTwoRanksEachHoldsTheModelAndTheRootTheOutput) {
  const fem::Model model = block();
  const auto e = fem::estimate_memory(model, 2, {false, false, true, false});
  EXPECT_DOUBLE_EQ(share(e, "nodes"), (323.0 + 64) * 125);
  const double output = 185e6 + 490.0 * 125 + 1770.0 * 64;
  EXPECT_DOUBLE_EQ(share(e, "output"), output);
  EXPECT_DOUBLE_EQ(e.total(), 2 * e.per_rank() - output);
  EXPECT_NE(e.describe().find("on 2 ranks"), std::string::npos) << e.describe();
}

TEST(MemoryEstimate, AModelTooLargeForTheMachineIsBadInputNamingTheEstimate) {
  fem::MemoryEstimate huge;
  huge.shares = {{"program", 64e6}, {"hexahedra", 1e18}};
  try {
    fem::require_memory_fits(huge, "case.toml");
    FAIL() << "an exabyte model was accepted";
  } catch (const InputError& err) {
    EXPECT_EQ(err.file(), "case.toml");
    EXPECT_EQ(err.key(), "mesh");
    EXPECT_NE(err.message().find("too large for this machine"), std::string::npos) << err.what();
    EXPECT_NE(err.message().find("hexahedra"), std::string::npos) << err.what();
  }
  fem::MemoryEstimate small;
  small.shares = {{"program", 64e6}};
  EXPECT_NO_THROW(fem::require_memory_fits(small, "case.toml"));
}

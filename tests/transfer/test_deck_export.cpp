// Abaqus and LS-DYNA export of an impregnated model, read back: node, element, orientation,
// material and tie counts, and one element's local axes round-trip.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>

#include "transfer/deck_export.hpp"

namespace ncfsim {
namespace {

transfer::ExportModel two_tows() {
  transfer::ExportModel m;
  for (int k = 0; k < 2; ++k)
    for (int j = 0; j < 2; ++j)
      for (int i = 0; i < 3; ++i) m.nodes.push_back({1e-3 * i, 1e-3 * j, 0.23e-3 * k});
  auto id = [](int i, int j, int k) { return static_cast<std::int32_t>(i + 3 * j + 6 * k); };
  for (int i = 0; i < 2; ++i)
    m.hex.push_back({id(i, 0, 0), id(i + 1, 0, 0), id(i + 1, 1, 0), id(i, 1, 0), id(i, 0, 1),
                     id(i + 1, 0, 1), id(i + 1, 1, 1), id(i, 1, 1)});
  const double c = std::sqrt(0.5);
  m.frame = {{c, -c, 0, c, c, 0, 0, 0, 1}, {c, c, 0, -c, c, 0, 0, 0, 1}};  // +45 and -45 fibres
  m.material = {0, 1};
  m.materials = {
      {"tow_vf0600", 1548, {139e9, 8.5e9, 8.5e9, 0.26, 0.26, 0.36, 4.8e9, 4.8e9, 3.1e9}},
      {"tow_vf0650", 1580, {150e9, 9.5e9, 9.5e9, 0.25, 0.25, 0.35, 5.2e9, 5.2e9, 3.4e9}}};
  m.ties.push_back({"tow_tow", {{0, 3}}, {{1, 5}}});
  return m;
}

TEST(DeckExport, AbaqusAndLsDynaDecksReadBackWithTheirCountsAndAxes) {
  const auto m = two_tows();
  const auto dir = std::filesystem::temp_directory_path() / "ncfsim_deck_export";
  std::filesystem::create_directories(dir);
  transfer::write_abaqus_inp(dir / "model.inp", m);
  transfer::write_lsdyna_keyword(dir / "model.k", m);
  for (const std::string format : {"abaqus", "lsdyna"}) {
    const auto c =
        transfer::read_deck(dir / (format == "abaqus" ? "model.inp" : "model.k"), format);
    EXPECT_EQ(c.nodes, 12u) << format;
    EXPECT_EQ(c.elements, 2u) << format;
    EXPECT_EQ(c.orientations, 2u) << format;
    EXPECT_EQ(c.materials, 2u) << format;
    EXPECT_EQ(c.ties, 1u) << format;
    ASSERT_EQ(c.axes.size(), 2u) << format;
    // element 2: fibre (a1) at -45 deg, a2 at +45 deg (Abaqus: a and b axes; LS-DYNA: a and d)
    const double h = std::sqrt(0.5);
    const double want[6] = {h, -h, 0, h, h, 0};
    for (int k = 0; k < 6; ++k)
      EXPECT_NEAR(c.axes[1][static_cast<std::size_t>(k)], want[k], 1e-9) << format << k;
  }
  EXPECT_FALSE(std::filesystem::exists(dir / "model.inp.tmp"));
  std::filesystem::remove_all(dir);
}

TEST(DeckExport, ElementNamingAMissingMaterialIsRefused) {
  auto m = two_tows();
  m.material[1] = 7;
  EXPECT_THROW(transfer::write_abaqus_inp(std::filesystem::temp_directory_path() / "bad.inp", m),
               std::invalid_argument);
}

}  // namespace
}  // namespace ncfsim

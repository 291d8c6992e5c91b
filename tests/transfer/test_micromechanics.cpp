// Impregnated-tow micromechanics against hand calculations (T700S / LY556-class epoxy at Vf 0.6),
// and the fibre volume fraction of a compacted tow (constant fibre content).
#include <gtest/gtest.h>

#include "tests/test_support.hpp"
#include "transfer/micromechanics.hpp"

namespace ncfsim {
namespace {

using transfer::FibreData;
using transfer::ResinData;

TEST(Micromechanics, T700EpoxyAtVf60MatchesAHandCalculation) {
  const FibreData f;  // T700S: 230 / 15 GPa, G12 27, G23 5.5 GPa, nu12 0.2, 4.9 GPa, 1800 kg/m^3
  const ResinData r;  // epoxy: 3.4 GPa, nu 0.36, 80 / 52 MPa, 1170 kg/m^3
  const auto t = transfer::impregnated_tow(f, r, 0.6);
  // By hand: sqrt(0.6) = 0.774597, Gm = 3.4 / 2.72 = 1.25 GPa
  //   E1 = 0.6 230 + 0.4 3.4 = 139.36 GPa; nu12 = 0.6 0.2 + 0.4 0.36 = 0.264
  //   E2 = 3.4 / (1 - 0.774597 (1 - 3.4/15)) = 3.4 / 0.400978 = 8.4793 GPa
  //   G12 = 1.25 / (1 - 0.774597 (1 - 1.25/27)) = 1.25 / 0.261264 = 4.7844 GPa
  //   G23 = 1.25 / (1 - 0.774597 (1 - 1.25/5.5)) = 1.25 / 0.401445 = 3.1138 GPa
  //   rho = 0.6 1800 + 0.4 1170 = 1548 kg/m^3
  //   Xt = 0.6 4.9 + 0.4 3.4 (4.9/230) = 2.94 + 0.028974 = 2.96897 GPa; Xc = 0.6 Xt = 1.78138 GPa
  //   Yt = (1 - (0.774597 - 0.6)(1 - 3.4/15)) 80 = (1 - 0.135022) 80 = 69.198 MPa; Yc = 41.519 MPa
  //   S12 = (1 - 0.174597 (1 - 1.25/27)) 52 = (1 - 0.166514) 52 = 43.341 MPa
  EXPECT_TRUE(test::near_rel(t.elastic.E1, 139.36e9, 0.01));
  EXPECT_TRUE(test::near_rel(t.elastic.nu12, 0.264, 0.01));
  EXPECT_TRUE(test::near_rel(t.elastic.E2, 8.4793e9, 0.01));
  EXPECT_TRUE(test::near_rel(t.elastic.E3, 8.4793e9, 0.01));
  EXPECT_TRUE(test::near_rel(t.elastic.G12, 4.7844e9, 0.01));
  EXPECT_TRUE(test::near_rel(t.elastic.G23, 3.1138e9, 0.01));
  EXPECT_TRUE(test::near_rel(t.elastic.nu23, 8.4793 / (2 * 3.1138) - 1, 0.01));
  EXPECT_TRUE(test::near_rel(t.density, 1548.0, 0.01));
  EXPECT_TRUE(test::near_rel(t.strength.Xt, 2.96897e9, 0.01));
  EXPECT_TRUE(test::near_rel(t.strength.Xc, 1.78138e9, 0.01));
  EXPECT_TRUE(test::near_rel(t.strength.Yt, 69.198e6, 0.01));
  EXPECT_TRUE(test::near_rel(t.strength.Yc, 41.519e6, 0.01));
  EXPECT_TRUE(test::near_rel(t.strength.S12, 43.341e6, 0.01));
  // The constants make a positive-definite orthotropic stiffness.
  EXPECT_NO_THROW(fem::orthotropic_stiffness(t.elastic));
}

TEST(Micromechanics, LimitsAreTheConstituents) {
  const FibreData f;
  const ResinData r;
  // Vf -> 0: the resin; the compressive ratio is a key.
  const auto t = transfer::impregnated_tow(f, r, 1e-10, 0.8);
  EXPECT_TRUE(test::near_rel(t.elastic.E1, r.E, 1e-6));
  EXPECT_TRUE(test::near_rel(t.elastic.E2, r.E, 1e-4));
  EXPECT_TRUE(test::near_rel(t.strength.Yt, r.tensile_strength, 1e-4));
  EXPECT_TRUE(test::near_rel(t.strength.Yc, 0.8 * r.tensile_strength, 1e-4));
}

TEST(Micromechanics, CompactedTowGainsFibreVolumeFraction) {
  // A tow compressed to 90 % of its cross-section (fibres unstretched): Vf x 1 / 0.9.
  EXPECT_DOUBLE_EQ(transfer::compacted_fibre_volume_fraction(0.6, 0.9), 0.6 / 0.9);
  // Stretched 2 % along the fibres at constant volume: the section shrinks by 1/1.02.
  EXPECT_DOUBLE_EQ(transfer::compacted_fibre_volume_fraction(0.6, 1.0, 1.02), 0.612);
}

TEST(Micromechanics, BadDataNamesTheQuantity) {
  FibreData f;
  f.E1 = 0;
  try {
    transfer::impregnated_tow(f, ResinData{}, 0.6);
    FAIL() << "a zero fibre modulus was accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("fibre E1"), std::string::npos) << e.what();
  }
  try {
    transfer::impregnated_tow(FibreData{}, ResinData{}, 0.95);
    FAIL() << "Vf above hexagonal packing was accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("0.9069"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace ncfsim

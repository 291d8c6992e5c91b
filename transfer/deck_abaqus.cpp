// The Abaqus input file (transfer/deck_export.hpp): the impregnated model, elastic. Abaqus/Explicit
// has no built-in per-mode damage for solids: with a crush, the tows' strengths and energies and
// the bonds' cohesive data are written as comments beside what they belong to, and the file says
// what it leaves out (docs/export.md).
#include <fmt/format.h>

#include "fem/io/atomic_file.hpp"
#include "transfer/deck_common.hpp"

namespace ncfsim::transfer {

namespace {

// Abaqus C3D8 face labels S1..S6 for the faces of fem::kHex8Faces (S1: 1-2-3-4, S2: 5-8-7-6,
// S3: 1-5-6-2, S4: 2-6-7-3, S5: 3-7-8-4, S6: 4-8-5-1).
constexpr int kAbaqusFace[6] = {1, 2, 3, 4, 5, 6};

std::string failure_comment(const ExportFailure& f) {
  const auto& G = f.fracture_energy;
  return fmt::format(
      "** the crush's tow failure (not carried: elastic here): Xt {:.6g}, Xc {:.6g}, Yt {:.6g}, "
      "Yc {:.6g}, S12 {:.6g}, S23 {:.6g} Pa; fracture energies per mode (fibre tension, fibre "
      "compression, matrix tension, matrix compression, in-plane shear, transverse shear) "
      "{:.6g}, {:.6g}, {:.6g}, {:.6g}, {:.6g}, {:.6g} J/m^2; residual compression {:.6g}\n",
      f.Xt, f.Xc, f.Yt, f.Yc, f.S12, f.S23, G[0], G[1], G[2], G[3], G[4], G[5],
      f.residual_compression);
}

}  // namespace

void write_abaqus_inp(const std::filesystem::path& file, const ExportModel& m) {
  deck::check(m);
  std::string s = "*HEADING\nncfsim impregnated model (units: m, kg, s, N, Pa)\n";
  const auto contents = deck_contents(m, "abaqus");
  for (const auto& line : contents.carried) s += "** carried: " + line + "\n";
  for (const auto& line : contents.left_out) s += "** left out: " + line + "\n";
  s += "*NODE\n";
  for (std::size_t i = 0; i < m.nodes.size(); ++i)
    s += fmt::format("{}, {:.12e}, {:.12e}, {:.12e}\n", i + 1, m.nodes[i][0], m.nodes[i][1],
                     m.nodes[i][2]);
  // Local axes per element: a distribution read by one orientation.
  s += "*DISTRIBUTION TABLE, NAME=tow_axes_table\nCOORD3D, COORD3D\n";
  s += "*DISTRIBUTION, NAME=tow_axes, LOCATION=ELEMENT, TABLE=tow_axes_table\n, 1., 0., 0., 0., "
       "1., 0.\n";
  for (std::size_t e = 0; e < m.hex.size(); ++e) {
    const auto& R = m.frame[e];
    s += fmt::format("{}, {:.15g}, {:.15g}, {:.15g}, {:.15g}, {:.15g}, {:.15g}\n", e + 1, R[0],
                     R[3], R[6], R[1], R[4], R[7]);
  }
  s += "*ORIENTATION, NAME=tow_orientation, DEFINITION=COORDINATES, "
       "SYSTEM=RECTANGULAR\ntow_axes\n3, 0.\n";
  for (std::size_t k = 0; k < m.materials.size(); ++k) {
    s += fmt::format("*ELEMENT, TYPE=C3D8R, ELSET=class_{}\n", k);
    for (std::size_t e = 0; e < m.hex.size(); ++e) {
      if (static_cast<std::size_t>(m.material[e]) != k) continue;
      const auto& h = m.hex[e];
      s += fmt::format("{}, {}, {}, {}, {}, {}, {}, {}, {}\n", e + 1, h[0] + 1, h[1] + 1, h[2] + 1,
                       h[3] + 1, h[4] + 1, h[5] + 1, h[6] + 1, h[7] + 1);
    }
    const auto& mat = m.materials[k];
    const auto& c = mat.elastic;
    s +=
        fmt::format("*SOLID SECTION, ELSET=class_{}, MATERIAL={}, ORIENTATION=tow_orientation\n,\n",
                    k, mat.name);
    s += fmt::format("*MATERIAL, NAME={}\n*DENSITY\n{:.6g}\n*ELASTIC, TYPE=ENGINEERING CONSTANTS\n",
                     mat.name, mat.density);
    s += fmt::format("{:.6g}, {:.6g}, {:.6g}, {:.6g}, {:.6g}, {:.6g}, {:.6g}, {:.6g}\n{:.6g}\n",
                     c.E1, c.E2, c.E3, c.nu12, c.nu13, c.nu23, c.G12, c.G13, c.G23);
    if (m.crush.enabled) s += failure_comment(m.crush.failure[k]);
  }
  if (const auto& st = m.stitches; !st.bars.empty()) {
    s += "*ELEMENT, TYPE=T3D2, ELSET=stitch\n";
    for (std::size_t b = 0; b < st.bars.size(); ++b)
      s += fmt::format("{}, {}, {}\n", m.hex.size() + b + 1, st.bars[b][0] + 1, st.bars[b][1] + 1);
    s += fmt::format("*SOLID SECTION, ELSET=stitch, MATERIAL=STITCH\n{:.6g},\n", st.area);
    s += fmt::format(
        "*MATERIAL, NAME=STITCH\n*DENSITY\n{:.6g}\n*ELASTIC\n{:.6g}, 0.\n"
        "** the yarn carries tension only (*NO COMPRESSION: Abaqus/Standard)\n*NO COMPRESSION\n",
        st.density, st.modulus);
  }
  for (const auto& t : m.ties) {
    for (const char* side : {"slave", "master"}) {
      const auto& faces = std::string(side) == "slave" ? t.slave : t.master;
      s += fmt::format("*SURFACE, TYPE=ELEMENT, NAME={}_{}\n", t.name, side);
      for (auto [e, f] : faces) s += fmt::format("{}, S{}\n", e + 1, kAbaqusFace[f]);
    }
    s += fmt::format("*TIE, NAME={}, ADJUST=NO\n{}_slave, {}_master\n", t.name, t.name, t.name);
    if (m.crush.enabled) {
      const auto& b = m.crush.bonds[static_cast<std::size_t>(&t - m.ties.data())];
      s += fmt::format(
          "** the crush's resin bond (not carried by *TIE): strengths N {:.6g} Pa, S {:.6g} Pa; "
          "energies GIc {:.6g}, GIIc {:.6g} J/m^2; B-K exponent {:.6g}\n",
          b.normal_strength, b.shear_strength, b.mode_i_energy, b.mode_ii_energy, b.bk_exponent);
    }
  }
  fem::io::atomic_write_text(file, s);
}

}  // namespace ncfsim::transfer

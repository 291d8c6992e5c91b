#include "transfer/deck_export.hpp"

#include <fmt/format.h>

#include <fstream>
#include <sstream>
#include <stdexcept>

#include "fem/elements/element_kind.hpp"
#include "fem/io/atomic_file.hpp"

namespace ncfsim::transfer {

namespace {

// Hexahedron faces in VTK corner numbers (0-based), outward, the order ExportTie uses.
constexpr const auto& kFace = fem::kHex8Faces;
// Abaqus C3D8 face labels S1..S6 for the same faces (S1: 1-2-3-4, S2: 5-8-7-6, S3: 1-5-6-2,
// S4: 2-6-7-3, S5: 3-7-8-4, S6: 4-8-5-1).
constexpr int kAbaqusFace[6] = {1, 2, 3, 4, 5, 6};

void check(const ExportModel& m) {
  const std::size_t n = m.hex.size();
  if (m.frame.size() != n || m.material.size() != n)
    throw std::invalid_argument("export: one frame and one material per element expected");
  for (auto k : m.material)
    if (k < 0 || static_cast<std::size_t>(k) >= m.materials.size())
      throw std::invalid_argument("export: an element names a material that does not exist");
  const auto& st = m.stitches;
  for (const auto& b : st.bars)
    for (auto n : b)
      if (n < 0 || static_cast<std::size_t>(n) >= m.nodes.size())
        throw std::invalid_argument("export: a stitch bar names a node that does not exist");
  if (!st.bars.empty() && !(st.modulus > 0 && st.area > 0 && st.density > 0))
    throw std::invalid_argument("export: stitch bars need a positive modulus, area and density");
}

}  // namespace

void write_abaqus_inp(const std::filesystem::path& file, const ExportModel& m) {
  check(m);
  std::string s = "*HEADING\nncfsim impregnated model (units: m, kg, s, N, Pa)\n*NODE\n";
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
  }
  fem::io::atomic_write_text(file, s);
}

void write_lsdyna_keyword(const std::filesystem::path& file, const ExportModel& m) {
  check(m);
  std::string s = "*KEYWORD\n*TITLE\nncfsim impregnated model (units: m, kg, s, N, Pa)\n*NODE\n";
  for (std::size_t i = 0; i < m.nodes.size(); ++i)
    s += fmt::format("{:>8}{:>16.9e}{:>16.9e}{:>16.9e}\n", i + 1, m.nodes[i][0], m.nodes[i][1],
                     m.nodes[i][2]);
  for (std::size_t k = 0; k < m.materials.size(); ++k) {
    const auto& c = m.materials[k].elastic;
    s += fmt::format("*PART\n{}\n{:>10}{:>10}{:>10}\n", m.materials[k].name, k + 1, k + 1, k + 1);
    s += fmt::format("*SECTION_SOLID\n{:>10}{:>10}\n", k + 1, 1);
    s += fmt::format(
        "*MAT_ORTHOTROPIC_ELASTIC\n{:>10}{:>10.4g}{:>10.4g}{:>10.4g}{:>10.4g}{:>10.4g}{:>10.4g}{:>"
        "10.4g}\n",
        k + 1, m.materials[k].density, c.E1, c.E2, c.E3, c.nu12 * c.E2 / c.E1, c.nu13 * c.E3 / c.E1,
        c.nu23 * c.E3 / c.E2);
    // AOPT = 2 (axes from vectors a and d); *ELEMENT_SOLID_ORTHO gives them per element.
    s += fmt::format("{:>10.4g}{:>10.4g}{:>10.4g}{:>10.1f}\n", c.G12, c.G23, c.G13, 2.0);
    s += fmt::format("{:>10}{:>10}{:>10}{:>10.1f}{:>10.1f}{:>10.1f}\n", 0, 0, 0, 1.0, 0.0, 0.0);
    s += fmt::format("{:>10}{:>10}{:>10}{:>10.1f}{:>10.1f}{:>10.1f}\n", 0, 0, 0, 0.0, 1.0, 0.0);
  }
  s += "*ELEMENT_SOLID_ORTHO\n";
  for (std::size_t e = 0; e < m.hex.size(); ++e) {
    const auto& h = m.hex[e];
    const auto& R = m.frame[e];
    s += fmt::format("{:>8}{:>8}{:>8}{:>8}{:>8}{:>8}{:>8}{:>8}{:>8}{:>8}\n", e + 1,
                     m.material[e] + 1, h[0] + 1, h[1] + 1, h[2] + 1, h[3] + 1, h[4] + 1, h[5] + 1,
                     h[6] + 1, h[7] + 1);
    s += fmt::format("{:>16.9e}{:>16.9e}{:>16.9e}\n{:>16.9e}{:>16.9e}{:>16.9e}\n", R[0], R[3], R[6],
                     R[1], R[4], R[7]);
  }
  if (const auto& st = m.stitches; !st.bars.empty()) {
    const std::size_t id = m.materials.size() + 1;
    s += fmt::format("*PART\nstitch\n{:>10}{:>10}{:>10}\n", id, id, id);
    // A discrete beam with a cable area CA is a cable: its mass from the density and CA.
    s += fmt::format("*SECTION_BEAM\n{:>10}{:>10}\n{:>10.4g}{:>10.4g}{:>10}{:>10.4g}\n", id, 6, 0.0,
                     0.0, 0, st.area);
    s += fmt::format("*MAT_CABLE_DISCRETE_BEAM\n{:>10}{:>10.4g}{:>10.4g}\n", id, st.density,
                     st.modulus);
    s += "*ELEMENT_BEAM\n";
    for (std::size_t b = 0; b < st.bars.size(); ++b)
      s += fmt::format("{:>8}{:>8}{:>8}{:>8}\n", m.hex.size() + b + 1, id, st.bars[b][0] + 1,
                       st.bars[b][1] + 1);
  }
  int set = 0;
  for (const auto& t : m.ties) {
    int ids[2];
    for (int side = 0; side < 2; ++side) {
      ids[side] = ++set;
      s += fmt::format("*SET_SEGMENT\n{:>10}\n", ids[side]);
      for (auto [e, f] : side == 0 ? t.slave : t.master) {
        const auto& h = m.hex[static_cast<std::size_t>(e)];
        s += fmt::format("{:>10}{:>10}{:>10}{:>10}\n", h[kFace[f].corner[0]] + 1,
                         h[kFace[f].corner[1]] + 1, h[kFace[f].corner[2]] + 1,
                         h[kFace[f].corner[3]] + 1);
      }
    }
    s += fmt::format(
        "*CONTACT_TIED_SURFACE_TO_SURFACE_ID\n{:>10}{:>10}\n{:>10}{:>10}{:>10}{:>10}\n\n\n",
        set / 2, t.name, ids[0], ids[1], 0, 0);
  }
  s += "*END\n";
  fem::io::atomic_write_text(file, s);
}

DeckCounts read_deck(const std::filesystem::path& file, const std::string& format) {
  std::ifstream in(file);
  if (!in) throw std::runtime_error(file.string() + ": cannot be read");
  DeckCounts c;
  std::string line, block;
  std::vector<std::string> pending;  // LS-DYNA: the two lines of an element
  auto numbers = [](const std::string& l) {
    std::vector<double> v;
    std::string t = l;
    for (char& ch : t)
      if (ch == ',') ch = ' ';
    std::istringstream is(t);
    double x;
    while (is >> x) v.push_back(x);
    return v;
  };
  auto fixed = [](const std::string& l, std::size_t width) {
    std::vector<double> v;
    for (std::size_t p = 0; p + width <= l.size(); p += width)
      v.push_back(std::stod(l.substr(p, width)));
    return v;
  };
  int ortho_line = 0;
  while (std::getline(in, line)) {
    if (line.empty()) continue;
    if (line[0] == '*') {
      block = line;
      ortho_line = 0;
      if (format == "abaqus") {
        if (block.rfind("*ORIENTATION", 0) == 0) ++c.orientations;
        if (block.rfind("*MATERIAL", 0) == 0) ++c.materials;
        if (block.rfind("*TIE", 0) == 0) ++c.ties;
      } else {
        if (block.rfind("*MAT_", 0) == 0) ++c.materials;
        if (block.rfind("*CONTACT_TIED", 0) == 0) ++c.ties;
      }
      continue;
    }
    if (format == "abaqus") {
      if (block == "*NODE")
        ++c.nodes;
      else if (block.rfind("*ELEMENT", 0) == 0) {
        ++c.elements;
        if (block.find("TYPE=T3D2") != std::string::npos) ++c.bars;
      } else if (block.rfind("*DISTRIBUTION,", 0) == 0) {
        const auto v = numbers(line);
        if (v.size() == 7)
          c.axes.push_back({v[1], v[2], v[3], v[4], v[5], v[6]});
        else if (line[0] != ',')
          throw std::runtime_error(file.string() + ": bad distribution line '" + line + "'");
      }
    } else {
      if (block == "*NODE")
        ++c.nodes;
      else if (block == "*ELEMENT_BEAM")
        ++c.elements, ++c.bars;
      else if (block == "*ELEMENT_SOLID_ORTHO") {
        if (ortho_line % 3 == 0) {
          ++c.elements;
          ++c.orientations;
          c.axes.emplace_back();
        } else {
          const auto v = fixed(line, 16);
          if (v.size() != 3)
            throw std::runtime_error(file.string() + ": bad axis line '" + line + "'");
          for (int k = 0; k < 3; ++k)
            c.axes.back()[static_cast<std::size_t>(3 * (ortho_line % 3 - 1) + k)] =
                v[static_cast<std::size_t>(k)];
        }
        ++ortho_line;
      }
    }
  }
  if (format == "abaqus" && c.orientations == 1 && !c.axes.empty()) c.orientations = c.axes.size();
  return c;
}

}  // namespace ncfsim::transfer

#include "transfer/deck_export.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <map>
#include <numbers>
#include <set>
#include <sstream>
#include <stdexcept>

#include "fem/elements/element_kind.hpp"
#include "transfer/deck_common.hpp"

namespace ncfsim::transfer {

namespace deck {

void check(const ExportModel& m) {
  const std::size_t n = m.hex.size();
  if (m.frame.size() != n || m.material.size() != n)
    throw std::invalid_argument("export: one frame and one material per element expected");
  for (auto k : m.material)
    if (k < 0 || static_cast<std::size_t>(k) >= m.materials.size())
      throw std::invalid_argument("export: an element names a material that does not exist");
  if (!m.group.empty()) {
    if (m.group.size() != n)
      throw std::invalid_argument("export: one group per element expected (or none)");
    for (auto g : m.group)
      if (g < 0 || static_cast<std::size_t>(g) >= m.group_names.size())
        throw std::invalid_argument("export: an element names a group that does not exist");
  }
  const auto& st = m.stitches;
  for (const auto& b : st.bars)
    for (auto n : b)
      if (n < 0 || static_cast<std::size_t>(n) >= m.nodes.size())
        throw std::invalid_argument("export: a stitch bar names a node that does not exist");
  if (!st.bars.empty() && !(st.modulus > 0 && st.area > 0 && st.density > 0))
    throw std::invalid_argument("export: stitch bars need a positive modulus, area and density");
  const auto& c = m.crush;
  if (!c.enabled) return;
  if (c.failure.size() != m.materials.size())
    throw std::invalid_argument("export: a crush needs the failure data of every material");
  if (c.bonds.size() != m.ties.size())
    throw std::invalid_argument("export: a crush needs the cohesive law of every tie");
  if (c.punch < 0 || static_cast<std::size_t>(c.punch) >= c.tools.size())
    throw std::invalid_argument("export: a crush needs its punch among its tools");
  if (!(c.end_time > 0)) throw std::invalid_argument("export: a crush needs a positive end time");
  for (const auto& t : c.tools)
    if ((t.sphere && !(t.radius > 0)) || (!t.sphere && !(t.half_size > 0)))
      throw std::invalid_argument("export: tool '" + t.name + "' has no size");
}

std::vector<DeckPart> tow_parts(const ExportModel& m, std::vector<std::int32_t>& part_of) {
  std::map<std::pair<std::int32_t, std::int32_t>, std::int32_t> index;
  for (std::size_t e = 0; e < m.hex.size(); ++e)
    index[{m.group.empty() ? 0 : m.group[e], m.material[e]}] = 0;
  std::vector<DeckPart> parts;
  for (auto& [key, i] : index) {
    i = static_cast<std::int32_t>(parts.size());
    const std::string& mat = m.materials[static_cast<std::size_t>(key.second)].name;
    parts.push_back({key.first, key.second,
                     m.group_names.empty()
                         ? mat
                         : m.group_names[static_cast<std::size_t>(key.first)] + "_" + mat});
  }
  part_of.resize(m.hex.size());
  for (std::size_t e = 0; e < m.hex.size(); ++e)
    part_of[e] = index[{m.group.empty() ? 0 : m.group[e], m.material[e]}];
  return parts;
}

double hex_volume(const ExportModel& m, std::size_t e) {
  const auto& h = m.hex[e];
  auto p = [&](int k) { return m.nodes[static_cast<std::size_t>(h[static_cast<std::size_t>(k)])]; };
  const int tet[6][3] = {{1, 2, 5}, {2, 6, 5}, {2, 3, 6}, {3, 7, 6}, {3, 0, 7}, {0, 4, 7}};
  double v = 0;
  for (const auto& t : tet) {
    const auto a = p(0), b = p(t[0]), c = p(t[1]), d = p(t[2]);
    const double u[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]};
    const double w[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]};
    const double z[3] = {d[0] - a[0], d[1] - a[1], d[2] - a[2]};
    v += (u[0] * (w[1] * z[2] - w[2] * z[1]) - u[1] * (w[0] * z[2] - w[2] * z[0]) +
          u[2] * (w[0] * z[1] - w[1] * z[0])) /
         6.0;
  }
  return std::abs(v);
}

std::vector<double> mean_element_length(const ExportModel& m) {
  std::vector<double> volume(m.materials.size(), 0.0), count(m.materials.size(), 0.0);
  for (std::size_t e = 0; e < m.hex.size(); ++e) {
    const auto k = static_cast<std::size_t>(m.material[e]);
    volume[k] += hex_volume(m, e), count[k] += 1;
  }
  std::vector<double> length(m.materials.size(), 0.0);
  for (std::size_t k = 0; k < length.size(); ++k)
    if (count[k] > 0) length[k] = std::cbrt(volume[k] / count[k]);
  return length;
}

ToolMesh tool_mesh(const ExportTool& t) {
  ToolMesh mesh;
  auto add = [&](const std::array<double, 3>& p) {
    mesh.nodes.push_back(p);
    return static_cast<std::int32_t>(mesh.nodes.size() - 1);
  };
  auto unit = [](std::array<double, 3> v) {
    const double n = std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
    for (auto& x : v) x /= n;
    return v;
  };
  // Two unit vectors normal to d and to each other.
  auto frame = [&](const std::array<double, 3>& d, std::array<double, 3>& e1,
                   std::array<double, 3>& e2) {
    const std::array<double, 3> r =
        std::abs(d[0]) < 0.9 ? std::array<double, 3>{1, 0, 0} : std::array<double, 3>{0, 1, 0};
    e1 = unit({r[1] * d[2] - r[2] * d[1], r[2] * d[0] - r[0] * d[2], r[0] * d[1] - r[1] * d[0]});
    e2 = {d[1] * e1[2] - d[2] * e1[1], d[2] * e1[0] - d[0] * e1[2], d[0] * e1[1] - d[1] * e1[0]};
  };
  std::array<double, 3> e1, e2;
  if (t.sphere) {
    // The half facing the motion (the tip): pole along the velocity, or -axis when fixed.
    const double vn = std::hypot(t.velocity[0], t.velocity[1], t.velocity[2]);
    const std::array<double, 3> d =
        vn > 0 ? unit(t.velocity) : std::array<double, 3>{-t.axis[0], -t.axis[1], -t.axis[2]};
    frame(d, e1, e2);
    constexpr int kRings = 16, kAround = 64;  // 5.6 deg facets: a 25 mm sphere within 0.03 mm
    auto at = [&](double theta, double phi) {
      std::array<double, 3> p;
      for (int k = 0; k < 3; ++k)
        p[static_cast<std::size_t>(k)] =
            t.point[static_cast<std::size_t>(k)] +
            t.radius * (std::cos(theta) * d[static_cast<std::size_t>(k)] +
                        std::sin(theta) * (std::cos(phi) * e1[static_cast<std::size_t>(k)] +
                                           std::sin(phi) * e2[static_cast<std::size_t>(k)]));
      return p;
    };
    const std::int32_t pole = add(at(0, 0));
    std::vector<std::int32_t> prev;
    for (int i = 1; i <= kRings; ++i) {
      std::vector<std::int32_t> ring;
      for (int j = 0; j < kAround; ++j)
        ring.push_back(
            add(at(0.5 * std::numbers::pi * i / kRings, 2 * std::numbers::pi * j / kAround)));
      for (int j = 0; j < kAround; ++j) {
        const int jn = (j + 1) % kAround;
        if (i == 1)
          mesh.quads.push_back({pole, ring[static_cast<std::size_t>(j)],
                                ring[static_cast<std::size_t>(jn)],
                                ring[static_cast<std::size_t>(jn)]});
        else
          mesh.quads.push_back(
              {prev[static_cast<std::size_t>(j)], ring[static_cast<std::size_t>(j)],
               ring[static_cast<std::size_t>(jn)], prev[static_cast<std::size_t>(jn)]});
      }
      prev = ring;
    }
  } else {
    frame(unit(t.axis), e1, e2);
    constexpr int kSide = 8;
    for (int j = 0; j <= kSide; ++j)
      for (int i = 0; i <= kSide; ++i) {
        const double a = t.half_size * (2.0 * i / kSide - 1),
                     b = t.half_size * (2.0 * j / kSide - 1);
        add({t.point[0] + a * e1[0] + b * e2[0], t.point[1] + a * e1[1] + b * e2[1],
             t.point[2] + a * e1[2] + b * e2[2]});
      }
    for (int j = 0; j < kSide; ++j)
      for (int i = 0; i < kSide; ++i) {
        const std::int32_t n0 = j * (kSide + 1) + i;
        mesh.quads.push_back({n0, n0 + 1, n0 + kSide + 2, n0 + kSide + 1});
      }
  }
  // Outward: a sphere's facets away from its centre, a plane's along its normal (the body's side).
  for (auto& q : mesh.quads) {
    const auto& a = mesh.nodes[static_cast<std::size_t>(q[0])];
    const auto& b = mesh.nodes[static_cast<std::size_t>(q[1])];
    const auto& c = mesh.nodes[static_cast<std::size_t>(q[2])];
    const double u[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]};
    const double w[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]};
    const double nrm[3] = {u[1] * w[2] - u[2] * w[1], u[2] * w[0] - u[0] * w[2],
                           u[0] * w[1] - u[1] * w[0]};
    double out[3];
    for (int k = 0; k < 3; ++k)
      out[k] = t.sphere ? a[static_cast<std::size_t>(k)] - t.point[static_cast<std::size_t>(k)]
                        : t.axis[static_cast<std::size_t>(k)];
    if (nrm[0] * out[0] + nrm[1] * out[1] + nrm[2] * out[2] < 0) {
      if (q[2] == q[3])
        std::swap(q[1], q[2]), q[3] = q[2];
      else
        std::swap(q[1], q[3]);
    }
  }
  return mesh;
}

std::vector<std::array<double, 2>> ramp_curve(double ramp_time, double end_time) {
  std::vector<std::array<double, 2>> c;
  if (ramp_time > 0) {
    for (int k = 0; k <= 10; ++k) {
      const double s = k / 10.0;
      c.push_back({ramp_time * s, s * s * (3 - 2 * s)});
    }
  } else {
    c.push_back({0, 1});
  }
  c.push_back({std::max(10 * end_time, 2 * ramp_time), 1});
  return c;
}

std::string field(double v, int width) {
  // At least one blank before each number: fixed columns read it either way, a reader does too.
  for (int p = 7; p >= 1; --p) {
    std::string s = fmt::format("{:.{}g}", v, p);
    if (static_cast<int>(s.size()) < width) return fmt::format("{:>{}}", s, width);
  }
  throw std::invalid_argument("export: " + fmt::format("{}", v) + " does not fit a deck field");
}

}  // namespace deck

DeckContents deck_contents(const ExportModel& m, const std::string& format) {
  DeckContents d;
  const bool crush = m.crush.enabled;
  d.carried.push_back(
      fmt::format("{} nodes, {} hexahedra with their material axes", m.nodes.size(), m.hex.size()));
  d.carried.push_back(fmt::format("{} orthotropic elastic materials (the transfer's Vf classes)",
                                  m.materials.size()));
  if (!m.stitches.bars.empty())
    d.carried.push_back(fmt::format("{} kept stitch bars (tension only)", m.stitches.bars.size()));
  if (format == "radioss") {
    d.carried.push_back(
        "the tows' per-mode failure: /MAT/LAW123 (Daimler-Pinho: strengths, fracture energies of "
        "fibre tension, kinking, matrix tension, transverse and longitudinal shear, regularised by "
        "V^(1/3)), each brick's axes in /INIBRI/ORTHO");
    std::size_t points = 0;
    for (const auto& t : m.ties) points += t.points.size();
    d.carried.push_back(fmt::format(
        "{} resin-bond interfaces as the crush ties them: {} tied nodes, each a /PROP/TYPE8 spring "
        "of its tie's stiffness to an /RBE3 point of its master face, failing on the bond's "
        "smaller strength times its area",
        m.ties.size(), points));
    d.carried.push_back(fmt::format(
        "{} rigid tools (shell facets on /RBODY), the punch's ramped velocity (/IMPVEL), tows on "
        "tools /INTER/TYPE7 with friction",
        m.crush.tools.size()));
    d.carried.push_back(
        "end time, erosion on the step (/DT/BRICK/DEL, its limit estimated from "
        "the undeformed bricks), time histories of the tools and parts");
    d.left_out.push_back(
        "the plies' contact once debonded (TYPE7 refuses the plies' coincident "
        "nodes; the ties hold them)");
    d.left_out.push_back(
        "a separate matrix-compression energy (LAW123 takes the transverse shear "
        "one), the residual compressive strength, erode_on (LAW123 erodes a "
        "brick when a mode's damage is complete)");
    d.left_out.push_back(
        "the bonds' softening (mode I / II energies, B-K mixed mode): a spring fails at once when "
        "its force reaches the bond's smaller strength, in any direction; the tie's offset turns "
        "with its face in ncfsim, not in the spring");
    return d;
  }
  if (format == "lsdyna") {
    if (crush) {
      d.carried.push_back(
          "the tows' per-mode failure: *MAT_262 (strengths, fracture energies per mode, "
          "transverse shear as strains)");
      d.carried.push_back(fmt::format(
          "{} resin-bond interfaces as tiebreak contacts that soften (OPTION 9: strengths, "
          "mode I / II energies, B-K exponent)",
          m.ties.size()));
      d.carried.push_back(
          fmt::format("{} rigid tools (shell meshes), the punch's prescribed "
                      "velocity with its ramp, friction",
                      m.crush.tools.size()));
      if (m.crush.ply_contact) d.carried.push_back("the plies' contact with friction");
      d.carried.push_back(
          "end time, step safety factor, erosion on the step (DTMIN), energy "
          "and contact-force outputs");
      d.left_out.push_back(
          "the crushed tows' residual compressive strength (MAT_262 has none: its crash front "
          "softening SOFT is left at 1)");
      d.left_out.push_back(
          "the crack band raised per element where an element is too long for a mode's energy "
          "(MAT_262 regularises with its own characteristic length)");
    } else {
      d.carried.push_back(fmt::format("{} tied interfaces (no failure)", m.ties.size()));
      d.left_out.push_back(
          "the failure law, the bonds' softening, tools, loading, controls (export a crush case "
          "for them)");
    }
  } else {
    d.carried.push_back(fmt::format("{} tied interfaces (*TIE, no failure)", m.ties.size()));
    if (crush)
      d.carried.push_back(
          "the tows' strengths and fracture energies and the bonds' cohesive data, as comments");
    d.left_out.push_back(
        "the tows' per-mode damage: Abaqus/Explicit has none built in for solids (a VUMAT would "
        "carry it); the bonds' softening, tools, loading and controls");
  }
  return d;
}

DeckCounts read_radioss_deck(const std::filesystem::path& file);

DeckCounts read_deck(const std::filesystem::path& file, const std::string& format) {
  if (format == "radioss") return read_radioss_deck(file);
  std::ifstream in(file);
  if (!in) throw std::runtime_error(file.string() + ": cannot be read");
  DeckCounts c;
  std::string line, block;
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
  bool first_data = false;  // the block's first data line
  while (std::getline(in, line)) {
    if (line.empty() || line[0] == '$' || line.rfind("**", 0) == 0) continue;  // comments
    if (line[0] == '*') {
      block = line;
      ortho_line = 0;
      first_data = true;
      if (format == "abaqus") {
        if (block.rfind("*ORIENTATION", 0) == 0) ++c.orientations;
        if (block.rfind("*MATERIAL", 0) == 0) ++c.materials;
        if (block.rfind("*TIE", 0) == 0) ++c.ties;
      } else {
        const auto has = [&](const char* key) { return block.find(key) != std::string::npos; };
        if (block == "*MAT_RIGID")
          ++c.rigid_parts;
        else if (block.rfind("*MAT_", 0) == 0)
          ++c.materials;
        if (block == "*MAT_LAMINATED_FRACTURE_DAIMLER_CAMANHO") ++c.failure_materials;
        if (block.rfind("*CONTACT_TIED", 0) == 0) ++c.ties;
        if (block.rfind("*CONTACT_", 0) == 0 && has("_TIEBREAK")) ++c.ties, ++c.softening_ties;
        if (block.rfind("*CONTACT_AUTOMATIC_SURFACE_TO_SURFACE", 0) == 0) ++c.contacts;
        if (block == "*BOUNDARY_PRESCRIBED_MOTION_RIGID") ++c.motions;
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
      else if (block == "*ELEMENT_SHELL")
        ++c.tool_elements;
      else if (block == "*CONTROL_TERMINATION" && first_data)
        c.end_time = fixed(line.substr(0, 10), 10).at(0);
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
    first_data = false;
  }
  if (format == "abaqus" && c.orientations == 1 && !c.axes.empty()) c.orientations = c.axes.size();
  return c;
}

DeckCounts read_radioss_deck(const std::filesystem::path& file) {
  std::ifstream in(file);
  if (!in) throw std::runtime_error(file.string() + ": cannot be read");
  DeckCounts c;
  std::string line, block;
  std::set<std::string> bond_sets, failing_props;
  int line_in_block = 0;
  auto reals = [&](const std::string& l) {
    std::vector<double> v;
    for (std::size_t p = 0; p + 20 <= l.size(); p += 20) v.push_back(std::stod(l.substr(p, 20)));
    return v;
  };
  while (std::getline(in, line)) {
    if (line.empty() || line[0] == '#') continue;
    if (line[0] == '/') {
      block = line;
      line_in_block = 0;
      const auto starts = [&](const char* key) { return line.rfind(key, 0) == 0; };
      if (starts("/MAT/LAW123/")) ++c.materials, ++c.failure_materials;
      if (starts("/RBODY/")) ++c.rigid_parts;  // a tool each
      if (starts("/RBE3/")) ++c.tie_points;
      if (starts("/INTER/TYPE7/")) ++c.contacts;
      if (starts("/IMPVEL/")) ++c.motions;
      continue;
    }
    ++line_in_block;
    if (block.rfind("/PROP/TYPE8/", 0) == 0 && line_in_block == 1) {  // "<interface>_bond_k.."
      const auto at = line.find("_bond_");
      if (at != std::string::npos) bond_sets.insert(line.substr(0, at));
    } else if (block.rfind("/PROP/TYPE8/", 0) == 0 && line_in_block == 2) {
      if (line.size() >= 90 && std::stoi(line.substr(70, 10)) == 1 &&
          std::stoi(line.substr(80, 10)) == 1)
        failing_props.insert(block);  // Ifail 1, Ifail2 1: multi-directional, on force
    } else if (block == "/NODE") {
      ++c.nodes;
    } else if (block.rfind("/BRICK/", 0) == 0) {
      ++c.elements;
    } else if (block.rfind("/SHELL/", 0) == 0 || block.rfind("/SH3N/", 0) == 0) {
      ++c.tool_elements;
    } else if (block == "/INIBRI/ORTHO") {
      if (line_in_block % 3 == 1) {
        ++c.orientations;
        c.axes.emplace_back();
      } else if (line_in_block % 3 == 2) {
        const auto v = reals(line);
        if (v.size() != 5)
          throw std::runtime_error(file.string() + ": bad axes line '" + line + "'");
        for (int k = 0; k < 5; ++k)
          c.axes.back()[static_cast<std::size_t>(k)] = v[static_cast<std::size_t>(k)];
      } else {
        c.axes.back()[5] = reals(line).at(0);
      }
    }
  }
  c.ties = bond_sets.size();
  c.softening_ties = failing_props.empty() ? 0 : c.ties;
  auto engine = file;
  engine.replace_filename(file.stem().string().substr(0, file.stem().string().size() - 5) +
                          "_0001.rad");
  std::ifstream e(engine);
  for (std::string prev; std::getline(e, line); prev = line)
    if (prev.rfind("/RUN/", 0) == 0) c.end_time = std::stod(line);
  return c;
}

}  // namespace ncfsim::transfer

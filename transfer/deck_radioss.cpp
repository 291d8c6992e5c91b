// The OpenRadioss block-format crush (transfer/deck_export.hpp): a starter file (model, laws,
// tools, interfaces, time histories) and an engine file (run, outputs). Card layouts as the
// OpenRadioss 2026 reader takes them (its hm_cfg_files templates); what maps to what and what is
// left out: docs/export.md. Checked by running it (scripts/radioss-check).
#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <set>
#include <tuple>

#include "fem/elements/element_kind.hpp"
#include "fem/io/atomic_file.hpp"
#include "transfer/deck_common.hpp"

namespace ncfsim::transfer {

namespace {

std::string I(long long v) { return fmt::format("{:>10}", v); }
std::string F(double v) { return fmt::format("{:>20.10g}", v); }

// Ids of the starter deck's objects, in one place.
constexpr int kToolMaterial = 9001, kToolProperty = 9001, kTowProperty = 1;
constexpr int kAllTowNodes = 1;   // /GRNOD: every tow node (secondary of the tools' contacts)
constexpr int kTowSurface = 399;  // /SURF/PART/EXT: the tows' outer faces
// Ids of the cards made per tool t and per tie set i: base + t (or + i).
constexpr long long kToolNodes = 100;    // /GRNOD: the tool's facet nodes (its rigid body)
constexpr long long kToolMain = 200;     // /GRNOD: its main node (BCS, IMPVEL)
constexpr long long kToolSurface = 300;  // /SURF/SEG: its facets
// Resin bonds: /GRNOD of one corner node each (base + node id), spring properties from base + 1.
constexpr long long kCornerGroup = 1000000, kBondProperty = 10000;
constexpr double kClassRatio = 1.02;   // spring classes: stiffness and failure force ratio
constexpr double kLeastWeight = 1e-4;  // an /RBE3 corner's smallest weight

struct RadiossDeck {
  const ExportModel& m;
  const ExportCrush& cr;
  std::string s;
  std::vector<deck::DeckPart> parts;
  std::vector<std::int32_t> part_of;
  std::vector<deck::ToolMesh> tools;
  std::vector<std::size_t> tool_first_node, tool_main_node;
  std::size_t next_node = 0, next_elem = 0;

  explicit RadiossDeck(const ExportModel& model) : m(model), cr(model.crush) {}

  void header() {
    s = "#RADIOSS STARTER\n/BEGIN\n" + cr.name + "\n" + I(2026) + "\n";
    s += fmt::format("{:>20}{:>20}{:>20}\n{:>20}{:>20}{:>20}\n", "kg", "m", "s", "kg", "m", "s");
    s += "/TITLE\nncfsim crush " + cr.name + "\n";
    const auto contents = deck_contents(m, "radioss");
    for (const auto& line : contents.carried) s += "# carried: " + line + "\n";
    for (const auto& line : contents.left_out) s += "# left out: " + line + "\n";
  }

  // The model's nodes, the tools' facets' and each tool's rigid-body main node (its centre).
  void nodes() {
    s += "/NODE\n";
    auto node = [&](const std::array<double, 3>& p) {
      s += I(static_cast<long long>(++next_node)) + F(p[0]) + F(p[1]) + F(p[2]) + "\n";
    };
    for (const auto& p : m.nodes) node(p);
    for (const auto& t : cr.tools) {
      tools.push_back(deck::tool_mesh(t));
      tool_first_node.push_back(next_node);
      for (const auto& p : tools.back().nodes) node(p);
      node(t.point);
      tool_main_node.push_back(next_node);
    }
  }

  // LAW123 (Daimler-Pinho) per Vf class: the one per-mode law with fracture energies that has a
  // solid kernel here (LAW132, Daimler-Camanho as LS-DYNA's *MAT_262, has a shell kernel only).
  // Poisson's ratios minor (nu21, nu31, nu32) as LS-DYNA's; energies regularised by V^(1/3).
  void materials() {
    for (std::size_t k = 0; k < m.materials.size(); ++k) {
      const auto& c = m.materials[k].elastic;
      const auto& f = cr.failure[k];
      const auto& G = f.fracture_energy;  // ft, fc, mt, mc, in-plane shear, transverse shear
      s += fmt::format("/MAT/LAW123/{}\n{}\n", k + 1, m.materials[k].name);
      s += "#        Init. dens.\n" + F(m.materials[k].density) + "\n";
      s += "#                 E1                  E2                  E3\n" + F(c.E1) + F(c.E2) +
           F(c.E3) + "\n";
      s += "#                G12                 G13                 G23\n" + F(c.G12) + F(c.G13) +
           F(c.G23) + "\n";
      s += "#               nu21                nu31                nu32\n" +
           F(c.nu12 * c.E2 / c.E1) + F(c.nu13 * c.E3 / c.E1) + F(c.nu23 * c.E3 / c.E2) + "\n";
      s += "#             ENKINK                 ENA                 ENB                 ENT      "
           "           ENL\n" +
           F(G[1]) + F(G[0]) + F(G[2]) + F(G[5]) + F(G[4]) + "\n";
      s += "#                 XC                  XT                  YC                  YT      "
           "            SL\n" +
           F(f.Xc) + F(f.Xt) + F(f.Yc) + F(f.Yt) + F(f.S12) + "\n";
      s += "#                FIO                SIGY      LCSS                          BETA\n" +
           F(53) + F(0) + I(0) + std::string(10, ' ') + F(0) + "\n";
      s += "#                EFS               RATIO                FCUT\n" + F(0) + F(0) + F(0) +
           "\n";
    }
    s += fmt::format("/MAT/ELAST/{}\nrigid_tools\n", kToolMaterial) + F(7850) + "\n" + F(2.1e11) +
         F(0.3) + "\n";
  }

  // One orthotropic solid property (Isolid 24: one point, physical stabilisation, as the
  // engine's hexahedron), each brick's own axes in /INIBRI/ORTHO; the tools' shells.
  void properties() {
    s += fmt::format("/PROP/TYPE6/{}\ntows\n", kTowProperty);
    s += I(24) + I(0) + std::string(10, ' ') + I(0) + I(0) + I(0) + I(0) + I(0) + F(0) + "\n";
    s += F(0) + F(0) + F(0) + "\n" + F(0) + F(0) + F(0) + I(0) + I(0) + I(0) + "\n";
    s += F(0) + F(0) + F(0) + F(0) + "\n" + F(0) + F(0) + F(0) + F(0) + F(0) + "\n";
    s += fmt::format("/PROP/SHELL/{}\nrigid_tool_shell\n", kToolProperty);
    s += I(24) + I(0) + I(0) + I(0) + I(0) + std::string(10, ' ') + F(0) + "\n";
    s += F(0) + F(0) + F(0) + F(0) + F(0) + "\n";
    s += I(1) + std::string(10, ' ') + F(1e-4) + F(0) + std::string(10, ' ') + I(0) + I(0) + I(0) +
         "\n";
  }

  void tows() {
    parts = deck::tow_parts(m, part_of);
    for (std::size_t p = 0; p < parts.size(); ++p)
      s += fmt::format("/PART/{}\n{}\n", p + 1, parts[p].name) + I(kTowProperty) +
           I(parts[p].material + 1) + I(0) + F(0) + "\n";
    for (std::size_t p = 0; p < parts.size(); ++p) {
      s += fmt::format("/BRICK/{}\n", p + 1);
      for (std::size_t e = 0; e < m.hex.size(); ++e) {
        if (static_cast<std::size_t>(part_of[e]) != p) continue;
        s += I(static_cast<long long>(e + 1));
        for (auto n : m.hex[e]) s += I(n + 1);
        s += "\n";
      }
    }
    // Fibre (axis 1) and the second axis per brick, global; the third is their cross product.
    s += "/INIBRI/ORTHO\n";
    for (std::size_t e = 0; e < m.hex.size(); ++e) {
      const auto& R = m.frame[e];
      s += I(static_cast<long long>(e + 1)) + I(1) + I(8) + I(6) + I(24) + "\n";
      s += F(R[0]) + F(R[3]) + F(R[6]) + F(R[1]) + F(R[4]) + "\n" + F(R[7]) + "\n";
    }
    next_elem = m.hex.size();
  }

  // Each tool a rigid body of shell facets (3-node at a sphere's pole) on an extra main node at
  // its centre: held (BCS), the punch driven by its ramped velocity per direction (IMPVEL).
  void rigid_tools() {
    const std::size_t first_part = parts.size() + 1;
    s += "/FUNCT/1\nvelocity_ramp\n";
    for (const auto& [t, f] :
         deck::ramp_curve(cr.tools[static_cast<std::size_t>(cr.punch)].ramp_time, cr.end_time))
      s += F(t) + F(f) + "\n";
    for (std::size_t t = 0; t < tools.size(); ++t) {
      const auto& tool = cr.tools[t];
      const long long pid = static_cast<long long>(first_part + t);
      s += fmt::format("/PART/{}\n{}\n", pid, tool.name) + I(kToolProperty) + I(kToolMaterial) +
           I(0) + F(0) + "\n";
      std::string quads, triangles;
      const auto node = [&](std::int32_t q) {
        return I(static_cast<long long>(tool_first_node[t] + static_cast<std::size_t>(q) + 1));
      };
      for (const auto& q : tools[t].quads) {
        const std::string id = I(static_cast<long long>(++next_elem));
        if (q[2] == q[3])
          triangles += id + node(q[0]) + node(q[1]) + node(q[2]) + "\n";
        else
          quads += id + node(q[0]) + node(q[1]) + node(q[2]) + node(q[3]) + "\n";
      }
      if (!quads.empty()) s += fmt::format("/SHELL/{}\n", pid) + quads;
      if (!triangles.empty()) s += fmt::format("/SH3N/{}\n", pid) + triangles;
      const long long group = kToolNodes + static_cast<long long>(t),
                      main = kToolMain + static_cast<long long>(t);
      s += fmt::format("/GRNOD/NODE/{}\n{}_nodes\n", group, tool.name);
      for (std::size_t k = 0; k < tools[t].nodes.size(); ++k)
        s += I(static_cast<long long>(tool_first_node[t] + k + 1)) +
             (k % 10 == 9 || k + 1 == tools[t].nodes.size() ? "\n" : "");
      s += fmt::format("/GRNOD/NODE/{}\n{}_main\n", main, tool.name) +
           I(static_cast<long long>(tool_main_node[t])) + "\n";
      s += fmt::format("/RBODY/{}\n{}\n", t + 1, tool.name) +
           I(static_cast<long long>(tool_main_node[t])) + I(0) + I(0) + I(0) + F(0) + I(group) +
           I(0) + I(0) + I(0) + "\n" + F(0) + F(0) + F(0) + "\n" + F(0) + F(0) + F(0) + "\n" +
           I(0) + I(0) + I(0) + "\n";
      // Held in every direction it does not move along (held_directions: the BCS), and in
      // rotation.
      const auto held = deck::held_directions(tool);
      std::string flags = "   ";
      for (int d = 0; d < 3; ++d) flags += held[static_cast<std::size_t>(d)] ? '1' : '0';
      s += fmt::format("/BCS/{}\n{}_held\n", t + 1, tool.name) + flags + " 111" + I(0) + I(main) +
           "\n";
      for (int d = 0; d < 3; ++d) {
        if (held[static_cast<std::size_t>(d)]) continue;
        const double v = tool.velocity[static_cast<std::size_t>(d)];
        s += fmt::format("/IMPVEL/{}\n{}_{}\n", 10 * (t + 1) + static_cast<std::size_t>(d),
                         tool.name, "XYZ"[d]) +
             I(1) + fmt::format("{:>10}", "XYZ"[d]) + I(0) + I(0) + I(main) + I(0) + I(0) + "\n" +
             F(1) + F(v) + F(0) + F(10 * cr.end_time) + "\n";
      }
    }
  }

  // A tool's facets as a contact surface.
  void tool_surface(std::size_t t, long long id) {
    s += fmt::format("/SURF/SEG/{}\n{}_surface\n", id, cr.tools[t].name);
    long long k = 0;
    for (const auto& q : tools[t].quads) {
      s += I(++k);
      for (int a = 0; a < 4; ++a)
        s += I(static_cast<long long>(tool_first_node[t] + static_cast<std::size_t>(q[a]) + 1));
      s += "\n";
    }
  }

  // Cards of a TYPE7 (node group on a surface): Istf 4, the smaller of the two sides'
  // stiffnesses (the steel shell's would set the step); Idel 1, eroded bricks' segments out;
  // Irem_i2 3, nodes that resin-bond ties hold stay in.
  void type7(long long id, const std::string& title, long long nodes, long long surf, double mu) {
    s += fmt::format("/INTER/TYPE7/{}\n{}\n", id, title);
    s += I(nodes) + I(surf) + I(4) + I(0) + I(0) + std::string(10, ' ') + I(0) + I(1) + I(0) +
         I(0) + "\n";
    s += F(0) + F(0) + F(0) + std::string(20, ' ') + I(0) + I(0) + "\n";
    s += F(0) + F(0) + F(0) + F(0) + I(0) + I(3) + "\n";
    s += F(0) + F(mu) + F(5e-6) + F(0) + F(0) + "\n";
    s += std::string(7, ' ') + "000" + std::string(20, ' ') + I(0) + F(0) + F(0) + F(0) + "\n";
    s += I(0) + I(0) + F(0) + I(0) + I(0) + I(0) + F(0) + I(0) + "\n";
  }

  // Tows on the tools, both ways for a sphere: the tows' nodes on its facets, and its facets'
  // nodes on the tows' outer surface (a coarse dome has no node under the punch's pole: node on
  // surface alone let the punch 0.26 mm into the CI dome's apex before it touched).
  void tool_contacts() {
    s += fmt::format("/GRNOD/NODE/{}\nall_tow_nodes\n", kAllTowNodes);
    for (std::size_t k = 0; k < m.nodes.size(); ++k)
      s += I(static_cast<long long>(k + 1)) + (k % 10 == 9 || k + 1 == m.nodes.size() ? "\n" : "");
    s += fmt::format("/SURF/PART/EXT/{}\ntows_outer_surface\n", kTowSurface);
    for (std::size_t p = 0; p < parts.size(); ++p)
      s += I(static_cast<long long>(p + 1)) + (p % 10 == 9 || p + 1 == parts.size() ? "\n" : "");
    for (std::size_t t = 0; t < tools.size(); ++t) {
      const long long surf = kToolSurface + static_cast<long long>(t);
      tool_surface(t, surf);
      const auto& tool = cr.tools[t];
      type7(static_cast<long long>(t + 1), tool.name + "_on_tows", kAllTowNodes, surf,
            tool.friction);
      if (tool.sphere)
        type7(static_cast<long long>(tools.size() + t + 1), "tows_on_" + tool.name,
              kToolNodes + static_cast<long long>(t), kTowSurface, tool.friction);
    }
  }

  // Resin bonds, each of the crush's ties as it is: its point on the master face an /RBE3 node
  // (weights N_a, translations) and a /PROP/TYPE8 spring of the tie's stiffness in x, y and z
  // from the slave node to it, failing where the force reaches the bond's smaller strength times
  // the tie's area (multi-directional on force: |F| = cap). OpenRadioss's own ties do not serve:
  // those with rupture are kinematic and refuse the chains a +-45 fabric has (error 556), the
  // penalty ones (TYPE2 Spotflag 25) are 37 times softer than ncfsim's at Stfac 0.1 and drop
  // every secondary projecting beyond 1.5 of its face (docs/export.md). Springs share a property
  // per class of stiffness and failure force (ratio kClassRatio, within 1 % of each tie's).
  void resin_bonds() {
    if (m.ties.empty()) return;
    if (!(cr.first_step > 0))
      throw std::invalid_argument("export: the Radioss deck's ties need the crush's first step");
    struct Spring {
      std::size_t tie, point;
      long long p;                // the /RBE3 node
      std::array<double, 4> w{};  // its corners' weights
    };
    std::vector<Spring> springs;
    double k_min = 1e300, cap_min = 1e300;
    const auto cap = [&](std::size_t i, const ExportTiePoint& q) {
      const auto& b = cr.bonds[i];
      return std::min(b.normal_strength, b.shear_strength) * q.area;
    };
    s += "/NODE\n";
    for (std::size_t i = 0; i < m.ties.size(); ++i) {
      if (m.ties[i].points.empty())
        throw std::invalid_argument("export: tie '" + m.ties[i].name +
                                    "' has no tied points (the crush's ties) for the Radioss deck");
      for (std::size_t j = 0; j < m.ties[i].points.size(); ++j) {
        const auto& q = m.ties[i].points[j];
        const auto w = weights(q);
        std::array<double, 3> x{};
        for (std::size_t a = 0; a < 4; ++a)
          for (std::size_t k = 0; k < 3; ++k)
            x[k] += w[a] * m.nodes[static_cast<std::size_t>(q.corner[a])][k];
        springs.push_back({i, j, static_cast<long long>(++next_node), w});
        s += I(springs.back().p) + F(x[0]) + F(x[1]) + F(x[2]) + "\n";
        k_min = std::min(k_min, q.stiffness), cap_min = std::min(cap_min, cap(i, q));
      }
    }
    std::set<std::int32_t> corners;
    for (const auto& t : m.ties)
      for (const auto& q : t.points) corners.insert(q.corner.begin(), q.corner.end());
    for (auto n : corners)
      s += fmt::format("/GRNOD/NODE/{}\nbond_corner\n", kCornerGroup + n + 1) + I(n + 1) + "\n";
    long long rbe3 = 0;
    for (const auto& sp : springs) {
      const auto& q = m.ties[sp.tie].points[sp.point];
      s += fmt::format("/RBE3/{}\n{}_{}\n", ++rbe3, m.ties[sp.tie].name, q.node + 1) + I(sp.p) +
           "   111 000" + I(4) + I(0) + "\n";
      for (std::size_t a = 0; a < 4; ++a)
        s += F(sp.w[a]) + "   111 000" + I(0) + I(kCornerGroup + q.corner[a] + 1) + "\n";
    }
    // Classes: log bins of stiffness and failure force, each at its bin's geometric centre.
    const auto bin = [](double v, double lo) {
      return static_cast<int>(std::floor(std::log(v / lo) / std::log(kClassRatio)));
    };
    const auto centre = [](int b, double lo) { return lo * std::pow(kClassRatio, b + 0.5); };
    std::map<std::tuple<std::size_t, int, int>, std::vector<std::size_t>> classes;
    for (std::size_t n = 0; n < springs.size(); ++n) {
      const auto& q = m.ties[springs[n].tie].points[springs[n].point];
      classes[{springs[n].tie, bin(q.stiffness, k_min), bin(cap(springs[n].tie, q), cap_min)}]
          .push_back(n);
    }
    // A spring's step in OpenRadioss is 0.9 sqrt(m / k): its mass gives it the crush's first step
    // (the bricks set a smaller one there), a few per cent of the tows' mass.
    const double mass_per_stiffness = std::pow(cr.first_step / 0.9, 2);
    long long pid = kBondProperty, part = static_cast<long long>(parts.size() + tools.size());
    for (const auto& [key, members] : classes) {
      const auto& [tie, kb, cb] = key;
      const double k = centre(kb, k_min), f = centre(cb, cap_min), mass = k * mass_per_stiffness;
      const std::string title = fmt::format("{}_bond_k{}_f{}", m.ties[tie].name, kb, cb);
      ++pid, ++part;
      s += fmt::format("/PROP/TYPE8/{}\n{}\n", pid, title) + F(mass) + F(mass * 1e-8) + I(0) +
           I(0) + I(0) + I(1) + I(1) + I(0) + "\n";
      for (int dof = 0; dof < 6; ++dof) {
        const bool translation = dof < 3;
        s += F(translation ? k : 0) + F(0) + F(1) + F(0) + F(0) + "\n";
        s += I(0) + I(0) + I(0) + I(0) + I(0) + std::string(10, ' ') + F(translation ? -f : 0) +
             F(translation ? f : 0) + "\n";
        s += F(0) + F(0) + F(0) + F(0) + "\n";
      }
      s += I(0) + F(0) + "\n";
      s += fmt::format("/PART/{}\n{}\n", part, title) + I(pid) + I(0) + I(0) + F(0) + "\n";
      s += fmt::format("/SPRING/{}\n", part);
      for (auto n : members)
        s += I(static_cast<long long>(++next_elem)) +
             I(m.ties[tie].points[springs[n].point].node + 1) + I(springs[n].p) + "\n";
    }
  }

  // An /RBE3's weights: N_a, with a floor (its starter reads a zero weight as 1 and needs three
  // independent nodes), normalised.
  static std::array<double, 4> weights(const ExportTiePoint& q) {
    std::array<double, 4> w{};
    double sum = 0;
    for (std::size_t a = 0; a < 4; ++a) sum += w[a] = std::max(q.weight[a], kLeastWeight);
    for (auto& x : w) x /= sum;
    return w;
  }

  // The punch's rigid body (its force), the contacts, the parts' energies.
  void time_histories() {
    s += "/TH/RBODY/1\ntools\n" + fmt::format("{:<10}", "DEF") + "\n";
    for (std::size_t t = 0; t < tools.size(); ++t) s += I(static_cast<long long>(t + 1));
    s += "\n/TH/INTER/2\ninterfaces\n" + fmt::format("{:<10}", "DEF") + "\n";
    for (std::size_t t = 0; t < tools.size(); ++t) s += I(static_cast<long long>(t + 1));
    s += "\n/TH/PART/3\nparts\n" + fmt::format("{:<10}", "DEF") + "\n";
    for (std::size_t p = 0; p < parts.size(); ++p)
      s += I(static_cast<long long>(p + 1)) + (p % 10 == 9 || p + 1 == parts.size() ? "\n" : "");
    s += "/TH/NODE/4\npunch_main_node\n" + fmt::format("{:<10}", "DEF") + "\n" +
         I(static_cast<long long>(tool_main_node[static_cast<std::size_t>(cr.punch)])) + I(0) +
         "punch\n";
  }
};

// The smallest stable step of the undeformed bricks, estimated as an explicit code takes it:
// each brick's smallest height (volume over its largest face) over the fastest wave (along the
// fibres). The erosion limit is a share of it.
double estimated_first_step(const ExportModel& m) {
  double dt = 1e30;
  for (std::size_t e = 0; e < m.hex.size(); ++e) {
    const auto& h = m.hex[e];
    const auto p = [&](int k) {
      return m.nodes[static_cast<std::size_t>(h[static_cast<std::size_t>(k)])];
    };
    double largest = 0;
    for (const auto& face : fem::kHex8Faces) {
      const auto a = p(face.corner[0]), b = p(face.corner[1]), c = p(face.corner[2]),
                 d = p(face.corner[3]);
      const double u[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]};
      const double w[3] = {d[0] - b[0], d[1] - b[1], d[2] - b[2]};
      const double n[3] = {u[1] * w[2] - u[2] * w[1], u[2] * w[0] - u[0] * w[2],
                           u[0] * w[1] - u[1] * w[0]};
      largest = std::max(largest, 0.5 * std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]));
    }
    const auto& mat = m.materials[static_cast<std::size_t>(m.material[e])];
    const double c1 = std::sqrt(mat.elastic.E1 / mat.density);
    if (largest > 0) dt = std::min(dt, deck::hex_volume(m, e) / largest / c1);
  }
  return dt;
}

}  // namespace

std::vector<std::filesystem::path> write_radioss_deck(const std::filesystem::path& dir,
                                                      const ExportModel& m) {
  deck::check(m);
  if (!m.crush.enabled)
    throw std::invalid_argument("export: the Radioss deck is a crush (export a crush case)");
  RadiossDeck d(m);
  d.header();
  d.nodes();
  d.materials();
  d.properties();
  d.tows();
  d.rigid_tools();
  d.tool_contacts();
  d.resin_bonds();
  d.time_histories();
  d.s += "/END\n";
  const auto& cr = m.crush;
  std::string e = "#RADIOSS ENGINE\n/RUN/" + cr.name + "/1\n" + fmt::format("{:g}", cr.end_time) +
                  "\n/TFILE/0\n" + fmt::format("{:g}", cr.history_interval) + "\n/TH/TITLE\n";
  e += "/ANIM/DT\n0 " + fmt::format("{:g}", cr.frame_interval) + "\n";
  e += "/ANIM/ELEM/DAMG\n/ANIM/ELEM/VONM\n/ANIM/VECT/CONT\n/ANIM/VECT/VEL\n";
  if (cr.erosion_step_ratio > 0)
    e += "/DT/BRICK/DEL\n" +
         fmt::format("{:g} {:g}\n", cr.safety_factor,
                     cr.erosion_step_ratio * cr.safety_factor * estimated_first_step(m));
  e += "/PRINT/-1000\n/END\n";
  const std::filesystem::path starter = dir / (cr.name + "_0000.rad"),
                              engine = dir / (cr.name + "_0001.rad");
  fem::io::atomic_write_text(starter, d.s);
  fem::io::atomic_write_text(engine, e);
  return {starter, engine};
}

}  // namespace ncfsim::transfer

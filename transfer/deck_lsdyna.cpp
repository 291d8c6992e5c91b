// The LS-DYNA keyword deck (transfer/deck_export.hpp): the impregnated model alone, or, with an
// ExportCrush, the whole crush. What maps to what: docs/export.md.
#include <fmt/format.h>

#include <cmath>

#include "fem/elements/element_kind.hpp"
#include "fem/io/atomic_file.hpp"
#include "transfer/deck_common.hpp"

namespace ncfsim::transfer {

namespace {

using deck::field;
constexpr const char* kModeNames[6] = {"fibre tension",  "fibre compression",
                                       "matrix tension", "matrix compression",
                                       "in-plane shear", "transverse shear"};

std::string fields(std::initializer_list<double> v) {
  std::string s;
  for (double x : v) s += field(x);
  return s + "\n";
}
std::string ints(std::initializer_list<long long> v) {
  std::string s;
  for (long long x : v) s += fmt::format("{:>10}", x);
  return s + "\n";
}

// The elastic law of the model alone: *MAT_ORTHOTROPIC_ELASTIC, AOPT 2 (the element's vectors).
std::string elastic_material(std::size_t id, const ExportMaterial& mat) {
  const auto& c = mat.elastic;
  std::string s = "*MAT_ORTHOTROPIC_ELASTIC\n";
  s += fmt::format("{:>10}", id) + field(mat.density) + field(c.E1) + field(c.E2) + field(c.E3) +
       field(c.nu12 * c.E2 / c.E1) + field(c.nu13 * c.E3 / c.E1) + field(c.nu23 * c.E3 / c.E2) +
       "\n";
  s += fields({c.G12, c.G23, c.G13, 2.0});
  s += fields({0, 0, 0, 1, 0, 0});
  s += fields({0, 0, 0, 0, 1, 0});
  return s;
}

// The tows' per-mode failure: *MAT_LAMINATED_FRACTURE_DAIMLER_CAMANHO (*MAT_262). Its
// a, b, c axes are the tow's 1, 2, 3; AOPT 2 with the element's own vectors. Its energies are
// regularised by LS-DYNA with each element's length, as the tow law's crack band; the transverse
// shears are given as strains (card 8): initiation S / G, rupture 2 G_f / (S L) with L the
// material's mean element size.
std::string failure_material(std::size_t id, const ExportMaterial& mat, const ExportFailure& f,
                             double length) {
  const auto& c = mat.elastic;
  const auto& G = f.fracture_energy;  // ft, fc, mt, mc, in-plane shear, transverse shear
  const double e23 = f.S23 / c.G23, e31 = f.S12 / c.G13;
  const double r23 = std::max(1.001 * e23, 2 * G[5] / (f.S23 * length));
  const double r31 = std::max(1.001 * e31, 2 * G[4] / (f.S12 * length));
  std::string s = "*MAT_LAMINATED_FRACTURE_DAIMLER_CAMANHO\n";
  s += "$      MID        RO        EA        EB        EC      PRBA      PRCA      PRCB\n";
  s += fmt::format("{:>10}", id) + field(mat.density) + field(c.E1) + field(c.E2) + field(c.E3) +
       field(c.nu12 * c.E2 / c.E1) + field(c.nu13 * c.E3 / c.E1) + field(c.nu23 * c.E3 / c.E2) +
       "\n";
  s += "$      GAB       GBC       GCA      AOPT       DAF       DKF       DMF       EFS\n";
  // DAF, DKF, DMF, DSF: 1 where a mode's full damage keeps the element (the law's erode_on).
  const auto& er = f.erode_on;
  const auto keep = [](bool erode) { return erode ? 0.0 : 1.0; };
  s += fields({c.G12, c.G23, c.G13, 2.0, keep(er[0]), keep(er[1]), keep(er[2] || er[3]), 0});
  s += "$       XP        YP        ZP        A1        A2        A3       DSF\n";
  s += fields({0, 0, 0, 1, 0, 0, keep(er[4])});
  s += "$       V1        V2        V3        D1        D2        D3    MANGLE       MSG\n";
  s += fields({0, 0, 0, 0, 1, 0, 0, 0});
  s += "$      GXC       GXT       GYC       GYT       GSL      GXCO      GXTO\n";
  s += fields({G[1], G[0], G[3], G[2], G[4]});
  s += "$       XC        XT        YC        YT        SL       XCO       XTO\n";
  s += fields({f.Xc, f.Xt, f.Yc, f.Yt, f.S12});
  s += "$      FIO      SIGY      ETAN      BETA       PFL      PUCK      SOFT        DT\n";
  s += fields({53.0});
  s += "$   EPSF23    EPSR23    TSMD23    EPSF31    EPSR31    TSMD31\n";
  s += fields({e23, r23, 0.9, e31, r31, 0.9});
  return s;
}

std::string segment_set(int id, const ExportModel& m,
                        const std::vector<std::pair<std::int32_t, int>>& faces) {
  std::string s = fmt::format("*SET_SEGMENT\n{:>10}\n", id);
  for (auto [e, f] : faces) {
    const auto& h = m.hex[static_cast<std::size_t>(e)];
    s += ints({h[fem::kHex8Faces[f].corner[0]] + 1, h[fem::kHex8Faces[f].corner[1]] + 1,
               h[fem::kHex8Faces[f].corner[2]] + 1, h[fem::kHex8Faces[f].corner[3]] + 1});
  }
  return s;
}

// Cards 1 to 3 of a *CONTACT_..._ID.
std::string contact_cards(const std::string& keyword, int cid, const std::string& heading, int ssid,
                          int msid, int sstyp, int mstyp, double mu, double mst) {
  std::string s = keyword + "\n" + fmt::format("{:>10}{}\n", cid, heading);
  s += "$     SSID      MSID     SSTYP     MSTYP    SBOXID    MBOXID       SPR       MPR\n";
  s += ints({ssid, msid, sstyp, mstyp, 0, 0, 1, 1});
  s += "$       FS        FD        DC        VC       VDC    PENCHK        BT        DT\n";
  s += fields({mu, mu, 0, 0, 10});  // VDC 10 %: the engine's contact damping
  s += "$      SFS       SFM       SST       MST\n";
  s += fields({1, 1, 0, mst});
  return s;
}

// The deck in named steps, numbering as it goes: parts, materials and elements after the tows'.
struct LsDynaDeck {
  const ExportModel& m;
  const ExportCrush& cr;
  std::string s;
  std::vector<deck::ToolMesh> tools;
  std::vector<std::size_t> tool_first_node, tool_part;
  std::vector<deck::DeckPart> parts;
  std::vector<std::int32_t> part_of;
  std::vector<double> length;
  std::size_t next_part = 0, next_mat = 0, next_elem = 0;
  int set = 0, cid = 0;

  explicit LsDynaDeck(const ExportModel& model) : m(model), cr(model.crush) {}

  void header() {
    s = "*KEYWORD\n*TITLE\n";
    s += cr.enabled ? fmt::format("ncfsim crush '{}' (units: m, kg, s, N, Pa)\n", cr.name)
                    : "ncfsim impregnated model (units: m, kg, s, N, Pa)\n";
    const auto contents = deck_contents(m, "lsdyna");
    for (const auto& line : contents.carried) s += "$ carried: " + line + "\n";
    for (const auto& line : contents.left_out) s += "$ left out: " + line + "\n";
    for (std::size_t k = 0; k < cr.raised_elements.size(); ++k)
      if (cr.enabled && cr.raised_elements[k] > 0)
        s += fmt::format(
            "$ crack band: ncfsim raises the {} energy of {} elements too long for it\n",
            kModeNames[k], cr.raised_elements[k]);
  }

  void controls() {
    s += "*CONTROL_TERMINATION\n$   ENDTIM    ENDCYC     DTMIN\n";
    s += field(cr.end_time) + fmt::format("{:>10}", 0) + field(cr.erosion_step_ratio) + "\n";
    s += "*CONTROL_TIMESTEP\n$   DTINIT    TSSFAC      ISDO    TSLIMT     DT2MS      LCTM     "
         "ERODE\n";
    s += fields({0, cr.safety_factor, 0, 0, 0, 0, cr.erosion_step_ratio > 0 ? 1.0 : 0.0});
    // The engine's one-point hexahedron with physical (assumed-strain) stabilisation.
    s += "*CONTROL_HOURGLASS\n$      IHQ        QH\n" + ints({6}).substr(0, 10) + field(1.0) + "\n";
    s += "*CONTROL_ENERGY\n$     HGEN      RWEN    SLNTEN     RYLEN\n" + ints({2, 2, 2, 2});
    for (const char* db : {"GLSTAT", "MATSUM", "RCFORC", "RBDOUT", "SLEOUT"})
      s += fmt::format("*DATABASE_{}\n", db) + field(cr.history_interval) + "\n";
    s += "*DATABASE_BINARY_D3PLOT\n" + field(cr.frame_interval) + "\n";
  }

  // The model's nodes, then the tools' facets'.
  void nodes() {
    if (cr.enabled)
      for (const auto& t : cr.tools) tools.push_back(deck::tool_mesh(t));
    s += "*NODE\n";
    std::size_t n_node = 0;
    auto node = [&](const std::array<double, 3>& p) {
      s += fmt::format("{:>8}{:>16.9e}{:>16.9e}{:>16.9e}\n", ++n_node, p[0], p[1], p[2]);
    };
    for (const auto& p : m.nodes) node(p);
    for (const auto& t : tools) {
      tool_first_node.push_back(n_node);
      for (const auto& p : t.nodes) node(p);
    }
  }

  // A part per group and material, one solid section, a material per class.
  void tows() {
    parts = deck::tow_parts(m, part_of);
    for (std::size_t p = 0; p < parts.size(); ++p)
      s += fmt::format("*PART\n{}\n", parts[p].name) +
           ints({static_cast<long long>(p + 1), 1, parts[p].material + 1});
    s += "*SECTION_SOLID\n" + ints({1, 1});  // ELFORM 1: one point, as the engine's hexahedron
    length = deck::mean_element_length(m);
    for (std::size_t k = 0; k < m.materials.size(); ++k)
      s += cr.enabled ? failure_material(k + 1, m.materials[k], cr.failure[k], length[k])
                      : elastic_material(k + 1, m.materials[k]);
    s += "*ELEMENT_SOLID_ORTHO\n";
    for (std::size_t e = 0; e < m.hex.size(); ++e) {
      const auto& h = m.hex[e];
      const auto& R = m.frame[e];
      s += fmt::format("{:>8}{:>8}{:>8}{:>8}{:>8}{:>8}{:>8}{:>8}{:>8}{:>8}\n", e + 1,
                       part_of[e] + 1, h[0] + 1, h[1] + 1, h[2] + 1, h[3] + 1, h[4] + 1, h[5] + 1,
                       h[6] + 1, h[7] + 1);
      s += fmt::format("{:>16.9e}{:>16.9e}{:>16.9e}\n{:>16.9e}{:>16.9e}{:>16.9e}\n", R[0], R[3],
                       R[6], R[1], R[4], R[7]);
    }
    next_part = parts.size() + 1, next_mat = m.materials.size() + 1, next_elem = m.hex.size() + 1;
  }

  void stitches() {
    const auto& st = m.stitches;
    if (st.bars.empty()) return;
    const std::size_t id = next_part++, mid = next_mat++;
    s += fmt::format("*PART\nstitch\n") +
         ints({static_cast<long long>(id), 2, static_cast<long long>(mid)});
    // A discrete beam with a cable area CA is a cable: its mass from the density and CA.
    s += "*SECTION_BEAM\n" + ints({2, 6}) + field(0.0) + field(0.0) + ints({0}).substr(0, 10) +
         field(st.area) + "\n";
    s += "*MAT_CABLE_DISCRETE_BEAM\n" + fmt::format("{:>10}", mid) + field(st.density) +
         field(st.modulus) + "\n";
    s += "*ELEMENT_BEAM\n";
    for (std::size_t b = 0; b < st.bars.size(); ++b)
      s += fmt::format("{:>8}{:>8}{:>8}{:>8}\n", next_elem++, id, st.bars[b][0] + 1,
                       st.bars[b][1] + 1);
  }

  // The model alone: its interfaces tied.
  void tied_interfaces() {
    for (const auto& t : m.ties) {
      const int a = ++set, b = ++set;
      s += segment_set(a, m, t.slave) + segment_set(b, m, t.master);
      s += fmt::format(
          "*CONTACT_TIED_SURFACE_TO_SURFACE_ID\n{:>10}{:>10}\n{:>10}{:>10}{:>10}{:>10}\n\n\n",
          set / 2, t.name, a, b, 0, 0);
    }
  }

  // Rigid shells, a part and a rigid material each; the moving ones get a velocity curve (the
  // engine's cubic ramp) per direction, the fixed ones are held.
  void rigid_tools() {
    s += "*SECTION_SHELL\n" + ints({3, 2}) + fields({1e-4, 1e-4, 1e-4, 1e-4});
    s += "*DEFINE_CURVE\n" + ints({1}) + "$ the velocity's ramp (factor of the tool's velocity)\n";
    for (const auto& [t, f] :
         deck::ramp_curve(cr.tools[static_cast<std::size_t>(cr.punch)].ramp_time, cr.end_time))
      s += fmt::format("{:>20.9e}{:>20.9e}\n", t, f);
    for (std::size_t t = 0; t < tools.size(); ++t) {
      const auto& tool = cr.tools[t];
      const std::size_t pid = next_part++, mid = next_mat++;
      tool_part.push_back(pid);
      const bool moving = std::hypot(tool.velocity[0], tool.velocity[1], tool.velocity[2]) > 0;
      s += fmt::format("*PART\n{}\n", tool.name) +
           ints({static_cast<long long>(pid), 3, static_cast<long long>(mid)});
      s += "*MAT_RIGID\n$      MID        RO         E        PR\n" + fmt::format("{:>10}", mid) +
           field(7850) + field(2.1e11) + field(0.3) + "\n";
      // CON1: the translations at rest held (held_directions: 1 x, 2 y, 3 z, 4 x and y, 5 y and
      // z, 6 z and x, 7 all).
      const auto held = deck::held_directions(tool);
      const bool rx = held[0], ry = held[1], rz = held[2];
      const double con1 = rx && ry && rz ? 7
                          : rx && ry     ? 4
                          : ry && rz     ? 5
                          : rz && rx     ? 6
                          : rx           ? 1
                          : ry           ? 2
                          : rz           ? 3
                                         : 0;
      s += "$      CMO      CON1      CON2\n" + fields({1, con1, 7}) + "\n";
      s += "*ELEMENT_SHELL\n";
      const std::size_t first = tool_first_node[t] + 1;
      for (const auto& q : tools[t].quads)
        s += fmt::format(
            "{:>8}{:>8}{:>8}{:>8}{:>8}{:>8}\n", next_elem++, pid,
            first + static_cast<std::size_t>(q[0]), first + static_cast<std::size_t>(q[1]),
            first + static_cast<std::size_t>(q[2]), first + static_cast<std::size_t>(q[3]));
      if (!moving) continue;
      for (int d = 0; d < 3; ++d) {
        if (held[static_cast<std::size_t>(d)]) continue;
        s += "*BOUNDARY_PRESCRIBED_MOTION_RIGID\n$      PID       DOF       VAD      LCID        "
             "SF\n";
        s += ints({static_cast<long long>(pid), d + 1, 0, 1}).substr(0, 40) +
             field(tool.velocity[static_cast<std::size_t>(d)]) + "\n";
      }
    }
  }

  // Part sets: every tow part (1), each group's (2 ...).
  std::size_t part_sets() {
    s += "*SET_PART_LIST\n" + ints({1});
    for (std::size_t p = 0; p < parts.size(); ++p)
      s += fmt::format("{:>10}", p + 1) + ((p % 8 == 7 || p + 1 == parts.size()) ? "\n" : "");
    const std::size_t n_group = m.group_names.empty() ? 1 : m.group_names.size();
    for (std::size_t g = 0; g < n_group; ++g) {
      s += "*SET_PART_LIST\n" + ints({static_cast<long long>(g + 2)});
      std::size_t k = 0;
      for (std::size_t p = 0; p < parts.size(); ++p)
        if (static_cast<std::size_t>(parts[p].group) == g)
          s += fmt::format("{:>10}", p + 1) + (++k % 8 == 0 ? "\n" : "");
      if (k % 8 != 0) s += "\n";
    }
    return n_group;
  }

  void contacts() {
    const std::size_t n_group = part_sets();
    if (const auto& tied = m.stitches.tied_nodes; !tied.empty()) {
      s += "*SET_NODE_LIST\n" + ints({1});
      for (std::size_t k = 0; k < tied.size(); ++k)
        s +=
            fmt::format("{:>10}", tied[k] + 1) + ((k % 8 == 7 || k + 1 == tied.size()) ? "\n" : "");
      s += contact_cards("*CONTACT_TIED_NODES_TO_SURFACE_ID", ++cid, "stitch_on_tows", 1, 1, 4, 2,
                         0, 0);
    }
    for (std::size_t t = 0; t < tools.size(); ++t)
      s += contact_cards("*CONTACT_AUTOMATIC_SURFACE_TO_SURFACE_ID", ++cid, cr.tools[t].name, 1,
                         static_cast<int>(tool_part[t]), 2, 3, cr.tools[t].friction, 1e-6);
    if (cr.ply_contact && n_group >= 2)
      s += contact_cards("*CONTACT_AUTOMATIC_SURFACE_TO_SURFACE_ID", ++cid, "plies", 2, 3, 2, 2,
                         cr.ply_friction, 0);
  }

  // Resin bonds: tiebreak OPTION 9, a bilinear mixed-mode law with the B-K criterion
  // (PARAM < 0) and the two energies; its normal stiffness that of a resin layer 1/50 of the
  // element.
  void resin_bonds() {
    double e3 = 0, mean_length = 0;
    for (const auto& mat : m.materials)
      e3 += mat.elastic.E3 / static_cast<double>(m.materials.size());
    for (double l : length) mean_length += l / static_cast<double>(length.size());
    for (std::size_t i = 0; i < m.ties.size(); ++i) {
      const auto& t = m.ties[i];
      const auto& b = cr.bonds[i];
      const int a = ++set, c = ++set;
      s += segment_set(a, m, t.slave) + segment_set(c, m, t.master);
      s += contact_cards("*CONTACT_AUTOMATIC_ONE_WAY_SURFACE_TO_SURFACE_TIEBREAK_ID", ++cid, t.name,
                         a, c, 0, 0, cr.ply_friction, 0);
      s += "$   OPTION      NFLS      SFLS     PARAM    ERATEN    ERATES     CT2CN        CN\n";
      s += fields({9, b.normal_strength, b.shear_strength, -b.bk_exponent, b.mode_i_energy,
                   b.mode_ii_energy, 1, 50 * e3 / mean_length});
    }
  }
};

}  // namespace

void write_lsdyna_keyword(const std::filesystem::path& file, const ExportModel& m) {
  deck::check(m);
  LsDynaDeck d(m);
  d.header();
  if (m.crush.enabled) d.controls();
  d.nodes();
  d.tows();
  d.stitches();
  if (m.crush.enabled) {
    d.rigid_tools();
    d.contacts();
    d.resin_bonds();
  } else {
    d.tied_interfaces();
  }
  d.s += "*END\n";
  fem::io::atomic_write_text(file, d.s);
}

}  // namespace ncfsim::transfer

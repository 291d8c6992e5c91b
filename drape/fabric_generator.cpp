#include "drape/fabric_generator.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>

#include "fem/errors.hpp"

namespace ncfsim::drape {

namespace {

// Parameter interval [t0, t1] of the line p0 + t a inside the rectangle; false if it misses.
bool clip_line(const std::array<double, 2>& p0, const std::array<double, 2>& a, const std::array<double, 2>& lo,
               const std::array<double, 2>& hi, double& t0, double& t1) {
  t0 = -std::numeric_limits<double>::infinity();
  t1 = std::numeric_limits<double>::infinity();
  for (int k = 0; k < 2; ++k) {
    if (std::abs(a[k]) < 1e-14) {
      if (p0[k] < lo[k] || p0[k] > hi[k]) return false;
      continue;
    }
    double ta = (lo[k] - p0[k]) / a[k], tb = (hi[k] - p0[k]) / a[k];
    if (ta > tb) std::swap(ta, tb);
    t0 = std::max(t0, ta);
    t1 = std::min(t1, tb);
  }
  return t1 > t0;
}

// The nodes (every level) of the lattice points present in level[0] (an ni x nj lattice, -1 where
// none) with one of their eight neighbours missing: the lattice's outline.
std::vector<std::int32_t> lattice_outline_nodes(const std::vector<std::vector<std::int32_t>>& level,
                                                int ni, int nj) {
  const auto at = [&](int i, int j) { return level[0][static_cast<std::size_t>(j * ni + i)]; };
  std::vector<std::int32_t> out;
  for (int j = 0; j < nj; ++j)
    for (int i = 0; i < ni; ++i) {
      if (at(i, j) < 0) continue;
      bool outline = false;
      for (int dj = -1; dj <= 1; ++dj)
        for (int di = -1; di <= 1; ++di) {
          const int i2 = i + di, j2 = j + dj;
          outline = outline || i2 < 0 || j2 < 0 || i2 >= ni || j2 >= nj || at(i2, j2) < 0;
        }
      if (outline)
        for (const auto& lv : level) out.push_back(lv[static_cast<std::size_t>(j * ni + i)]);
    }
  return out;
}

// What the spec and the blanket make of each other: the sizes the steps below share.
struct BlanketLayout {
  double Lx, Ly;                     // blanket size
  double p, w, t;                    // tow pitch, width, thickness
  double s, g;                       // penetration spacing along the wales, gauge across them
  std::array<double, 2> lo, hi;      // the blanket rectangle
  std::array<double, 2> mdir, ndir;  // along and across the wales
  int nx, ny;                        // penetrations along and across, centred in the blanket
  double x_first, y_first;           // the first penetration point
  double h_el;                       // element length along a tow
  int nw, nt;                        // elements across a tow and through its thickness
  double z0;                         // the blanket's bottom face
  std::size_t n_levels;              // ply boundaries: bottom face, interfaces, top face
  /// Height of ply boundary k (0: the bottom face).
  double level_z(std::size_t k) const { return z0 + t * static_cast<double>(k); }
};

BlanketLayout layout_of(const FabricSpec& f, const BlanketSpec& bl) {
  BlanketLayout L{};
  L.Lx = bl.size[0], L.Ly = bl.size[1];
  L.p = f.tow_pitch(), L.w = f.tow_width, L.t = f.tow_thickness();
  L.s = f.penetration_spacing(), L.g = f.gauge();
  L.lo = {bl.origin[0], bl.origin[1]};
  L.hi = {bl.origin[0] + L.Lx, bl.origin[1] + L.Ly};
  // Penetration lattice: along the wales m (the stitch direction) every s, across them n every g,
  // centred in the blanket; points closer to the edge than half a spacing are left out. Its
  // reference point sets the gap lines of every ply. With the wales along x this is the centred
  // nx x ny grid.
  const double md = f.stitch_direction_deg * M_PI / 180.0;
  L.mdir = {std::cos(md), std::sin(md)};
  L.ndir = {-std::sin(md), std::cos(md)};
  L.nx = static_cast<int>(std::floor(L.Lx / L.s)), L.ny = static_cast<int>(std::floor(L.Ly / L.g));
  const double cx = L.lo[0] + 0.5 * L.Lx, cy = L.lo[1] + 0.5 * L.Ly;
  L.x_first = cx - 0.5 * (L.nx - 1) * L.s * L.mdir[0] - 0.5 * (L.ny - 1) * L.g * L.ndir[0];
  L.y_first = cy - 0.5 * (L.nx - 1) * L.s * L.mdir[1] - 0.5 * (L.ny - 1) * L.g * L.ndir[1];
  L.h_el = f.element_length > 0 ? f.element_length : L.p;
  L.nw = f.elements_across_tow, L.nt = f.elements_through_thickness;
  L.z0 = bl.z0;
  L.n_levels = f.ply_angles_deg.size() + 1;
  return L;
}

// The tows, ply by ply: each a structured grid of hexahedra along its strip of the blanket
// (strips the rectangle cuts too short are dropped and counted); axis_neighbour: per tow node,
// its next node along the tow on the same face.
void mesh_tows(fem::Mesh& mesh, const FabricSpec& f, const BlanketSpec& bl, const BlanketLayout& L,
               const std::string& prefix, FabricModel& fm,
               std::vector<std::int32_t>& axis_neighbour) {
  const double p = L.p, w = L.w, t = L.t, h_el = L.h_el, x_first = L.x_first, y_first = L.y_first;
  const std::array<double, 2> lo = L.lo, hi = L.hi;
  const int nw = L.nw, nt = L.nt;
  for (std::size_t q = 0; q < f.ply_angles_deg.size(); ++q) {
    const int part = mesh.add_part(prefix + "ply" + std::to_string(q + 1));
    fm.ply_parts.push_back(part);
    const double al = f.ply_angles_deg[q] * M_PI / 180.0;
    const std::array<double, 2> a{std::cos(al), std::sin(al)}, b{-std::sin(al), std::cos(al)};
    const double phase = b[0] * x_first + b[1] * y_first;  // a gap line passes through the first point
    // Range of b.x over the rectangle.
    double bmin = 1e300, bmax = -1e300;
    for (double x : {lo[0], hi[0]})
      for (double y : {lo[1], hi[1]}) {
        const double v = b[0] * x + b[1] * y;
        bmin = std::min(bmin, v), bmax = std::max(bmax, v);
      }
    const long k0 = static_cast<long>(std::floor((bmin - phase) / p)) - 1;
    const long k1 = static_cast<long>(std::ceil((bmax - phase) / p)) + 1;
    const double z0 = bl.z0 + static_cast<double>(q) * t;
    for (long k = k0; k <= k1; ++k) {
      const double centre = phase + (static_cast<double>(k) + 0.5) * p;
      // Each longitudinal node line m: b.x = centre - w/2 + m w/nw, clipped by the rectangle.
      std::vector<double> t0(static_cast<std::size_t>(nw + 1)), t1(static_cast<std::size_t>(nw + 1));
      bool ok = true;
      double mean = 0;
      for (int m = 0; m <= nw; ++m) {
        const double beta = centre - 0.5 * w + w * m / nw;
        const std::array<double, 2> p0{beta * b[0], beta * b[1]};
        if (!clip_line(p0, a, lo, hi, t0[static_cast<std::size_t>(m)], t1[static_cast<std::size_t>(m)])) {
          ok = false;
          break;
        }
        mean += t1[static_cast<std::size_t>(m)] - t0[static_cast<std::size_t>(m)];
      }
      if (!ok) {
        // The strip may still graze the rectangle at a corner: count it as dropped only if its centre line cuts.
        double c0, c1;
        const std::array<double, 2> pc{centre * b[0], centre * b[1]};
        if (clip_line(pc, a, lo, hi, c0, c1)) ++fm.n_dropped_tows;
        continue;
      }
      mean /= (nw + 1);
      double shortest = 1e300;
      for (int m = 0; m <= nw; ++m) shortest = std::min(shortest, t1[static_cast<std::size_t>(m)] - t0[static_cast<std::size_t>(m)]);
      if (shortest < 2 * h_el) {
        ++fm.n_dropped_tows;
        continue;
      }
      const int nl = std::max(2, static_cast<int>(std::lround(mean / h_el)));
      const std::int32_t base = static_cast<std::int32_t>(mesh.n_nodes());
      // Nodes: index = base + (kz * (nw+1) + m) * (nl+1) + i
      for (int kz = 0; kz <= nt; ++kz)
        for (int m = 0; m <= nw; ++m) {
          const double beta = centre - 0.5 * w + w * m / nw;
          for (int i = 0; i <= nl; ++i) {
            const double tt = t0[static_cast<std::size_t>(m)] +
                              (t1[static_cast<std::size_t>(m)] - t0[static_cast<std::size_t>(m)]) * i / nl;
            mesh.coords.push_back(beta * b[0] + tt * a[0]);
            mesh.coords.push_back(beta * b[1] + tt * a[1]);
            mesh.coords.push_back(z0 + t * kz / nt);
          }
        }
      auto node = [&](int i, int m, int kz) { return base + (kz * (nw + 1) + m) * (nl + 1) + i; };
      axis_neighbour.resize(mesh.n_nodes(), -1);
      for (int kz = 0; kz <= nt; ++kz)
        for (int m = 0; m <= nw; ++m)
          for (int i = 0; i <= nl; ++i)
            axis_neighbour[static_cast<std::size_t>(node(i, m, kz))] =
                node(i < nl ? i + 1 : i - 1, m, kz);
      for (int kz = 0; kz <= nt; ++kz) {
        fm.tow_end_pins.push_back(node(0, nw / 2, kz));
        fm.tow_end_pins.push_back(node(nl, nw / 2, kz));
      }
      const auto tow = static_cast<std::int32_t>(fm.n_tows++);
      fm.ply_of_tow.push_back(static_cast<int>(q));
      // The tow's node grid (i along, m across, kz through) is a structured grid: a x b = +z.
      append_grid_hexes(mesh, part, base, {nl, nw, nt});
      fm.tow_of_hex.resize(fm.tow_of_hex.size() + static_cast<std::size_t>(nl * nw * nt), tow);
      fem::ElementSet& hexes = mesh.elements(fem::ElementKind::Hex8);
      hexes.ply.resize(hexes.size() - static_cast<std::size_t>(nl * nw * nt), -1);
      hexes.tow.resize(hexes.ply.size(), -1);
      hexes.ply.resize(hexes.size(), static_cast<std::int32_t>(q));
      hexes.tow.resize(hexes.size(), tow);
    }
  }
}

// The stitch: nodes at the penetration points on every ply boundary, the pillars on the top face,
// the underlaps on the bottom face (tricot: zigzag between neighbouring wales) and a leg per ply.
void mesh_stitch(fem::Mesh& mesh, const FabricSpec& f, const BlanketLayout& L,
                 const std::string& file, const std::string& size_key, const std::string& prefix,
                 FabricModel& fm) {
  const double Lx = L.Lx, Ly = L.Ly, s = L.s, g = L.g, x_first = L.x_first, y_first = L.y_first;
  const std::array<double, 2> lo = L.lo, hi = L.hi, mdir = L.mdir, ndir = L.ndir;
  const int nx = L.nx, ny = L.ny;

  // Stitch nodes at the penetration points, one on every ply boundary (bottom face, interfaces,
  // top face). Lattice index (i, j), i along the wale; index ranges cover the blanket whatever the
  // stitch direction. The thread in a penetration hole bears on the tow edges of every ply it
  // passes: its nodes at the interfaces join the tows on both sides, so the plies are pinned to
  // each other at the stitch points (with a leg from the top to the bottom face only, held at its
  // ends, a relative slide d of the plies there met only the leg's second-order stretch d^2/2l).
  const std::size_t n_levels = L.n_levels;
  const int reach_i = static_cast<int>(std::ceil(std::hypot(Lx, Ly) / s)) + 1;
  const int reach_j = static_cast<int>(std::ceil(std::hypot(Lx, Ly) / g)) + 1;
  const int i0 = -reach_i, j0 = -reach_j, ni = 2 * reach_i + nx, nj = 2 * reach_j + ny;
  const bool own_margin = f.stitch_edge_margin >= 0;
  const double mx =
      own_margin ? f.stitch_edge_margin : 0.5 * (s * std::abs(mdir[0]) + g * std::abs(ndir[0]));
  const double my =
      own_margin ? f.stitch_edge_margin : 0.5 * (s * std::abs(mdir[1]) + g * std::abs(ndir[1]));
  // level[k][j * ni + i]: stitch node on ply boundary k (0: bottom face), -1 where none.
  std::vector<std::vector<std::int32_t>> level(
      n_levels, std::vector<std::int32_t>(static_cast<std::size_t>(ni * nj), -1));
  int i_min = 1 << 30;
  for (int jj = 0; jj < nj; ++jj)
    for (int ii = 0; ii < ni; ++ii) {
      const int i = ii + i0, j = jj + j0;
      const double x = x_first + i * s * mdir[0] + j * g * ndir[0], y = y_first + i * s * mdir[1] + j * g * ndir[1];
      if (x < lo[0] + mx - 1e-9 * Lx || x > hi[0] - mx + 1e-9 * Lx || y < lo[1] + my - 1e-9 * Ly || y > hi[1] - my + 1e-9 * Ly)
        continue;
      i_min = std::min(i_min, ii);
      for (std::size_t k = 0; k < n_levels; ++k) {
        level[k][static_cast<std::size_t>(jj * ni + ii)] =
            static_cast<std::int32_t>(mesh.n_nodes());
        fm.stitch_nodes.push_back(static_cast<std::int32_t>(mesh.n_nodes()));
        mesh.coords.insert(mesh.coords.end(), {x, y, L.level_z(k)});
      }
      ++fm.n_penetrations;
    }
  if (fm.n_penetrations == 0) throw InputError(file, size_key, "the blanket holds no stitch penetration");
  fm.stitch_end_pins = lattice_outline_nodes(level, ni, nj);
  fm.stitch_I_part = mesh.add_part(prefix + "stitch_I");
  fm.stitch_leg_part = mesh.add_part(prefix + "stitch_legs");
  const bool tricot = f.stitch == StitchPattern::Tricot;
  fm.stitch_Lambda_part = tricot ? mesh.add_part(prefix + "stitch_Lambda") : fm.stitch_I_part;
  const auto& top = level.back();
  const auto& bot = level.front();
  auto at = [&](const std::vector<std::int32_t>& arr, int i, int j) -> std::int32_t {
    if (i < 0 || j < 0 || i >= ni || j >= nj) return -1;
    return arr[static_cast<std::size_t>(j * ni + i)];
  };
  auto bar = [&](std::int32_t a, std::int32_t b, int part) {
    if (a < 0 || b < 0) return;
    mesh.elements(fem::ElementKind::Bar2).add({a, b}, part);
  };
  for (int j = 0; j < nj; ++j)
    for (int i = 0; i + 1 < ni; ++i) bar(at(top, i, j), at(top, i + 1, j), fm.stitch_I_part);  // pillars, top face
  for (int j = 0; j < nj; ++j)
    for (int i = 0; i + 1 < ni; ++i) {
      if (tricot) {  // underlaps: the yarn of wale j laps between wales j and j+1 every course
        const int p0 = (i - i_min) & 1, p1 = (i + 1 - i_min) & 1;
        bar(at(bot, i, j + p0), at(bot, i + 1, j + p1), fm.stitch_Lambda_part);
      } else {
        bar(at(bot, i, j), at(bot, i + 1, j), fm.stitch_I_part);
      }
    }
  for (std::size_t k = 0; k + 1 < n_levels; ++k)  // legs, one bar per ply
    for (int j = 0; j < nj; ++j)
      for (int i = 0; i < ni; ++i)
        bar(at(level[k + 1], i, j), at(level[k], i, j), fm.stitch_leg_part);
}

// Each stitch node joined to the nearest node of every tow within reach on its ply boundary.
void connect_stitch_to_tows(const fem::Mesh& mesh, const FabricSpec& f, const BlanketSpec& bl,
                            const BlanketLayout& L, const std::vector<std::int32_t>& axis_neighbour,
                            FabricModel& fm) {
  const double w = L.w, t = L.t, h_el = L.h_el;
  const int nw = L.nw;
  const std::size_t n_levels = L.n_levels;
  const double z_bot = L.level_z(0), z_top = L.level_z(n_levels - 1);
  // Each stitch node to the nearest node of every tow within reach on its ply boundary (on an
  // interface: the tows of both plies). The reach grows with the element length so that the nearest
  // node of a tow beside the gap is found; on meshes with elements longer than the tow pitch (the
  // case files' coarse resolution) it also takes the next tows over (docs/fabric-data.md).
  const double reach = 0.5 * f.tow_gap + std::max(w / nw, h_el) * 0.75;
  const double cell = reach;
  const double z_tol = 1e-9 * (1 + std::abs(z_top) + std::abs(z_bot));
  // Tow nodes on ply boundaries, bucketed.
  std::map<std::array<long, 2>, std::vector<std::int32_t>> grid;
  std::vector<std::int32_t> tow_of_node(mesh.n_nodes(), -1);
  const fem::ElementSet& tow_hexes = mesh.elements(fem::ElementKind::Hex8);
  for (std::size_t e = 0; e < fm.tow_of_hex.size(); ++e) {
    const std::size_t he = tow_hexes.size() - fm.tow_of_hex.size() + e;
    for (auto nd : tow_hexes.nodes(he)) tow_of_node[static_cast<std::size_t>(nd)] = fm.tow_of_hex[e];
  }
  auto on_a_level = [&](double z) {
    const double k = std::round((z - bl.z0) / t);
    return k >= 0 && k < static_cast<double>(n_levels) &&
           std::abs(z - L.level_z(static_cast<std::size_t>(k))) <= z_tol;
  };
  for (std::size_t nd = 0; nd < tow_of_node.size(); ++nd) {
    if (tow_of_node[nd] < 0 || !on_a_level(mesh.coords[3 * nd + 2])) continue;
    grid[{static_cast<long>(std::floor(mesh.coords[3 * nd] / cell)), static_cast<long>(std::floor(mesh.coords[3 * nd + 1] / cell))}]
        .push_back(static_cast<std::int32_t>(nd));
  }
  for (auto sn : fm.stitch_nodes) {
    const std::size_t i = static_cast<std::size_t>(sn);
    const double x = mesh.coords[3 * i], y = mesh.coords[3 * i + 1], z = mesh.coords[3 * i + 2];
    std::map<std::int32_t, std::pair<double, std::int32_t>> best;  // tow -> (distance, node)
    const long cx = static_cast<long>(std::floor(x / cell)), cy = static_cast<long>(std::floor(y / cell));
    for (long ix = cx - 1; ix <= cx + 1; ++ix)
      for (long iy = cy - 1; iy <= cy + 1; ++iy) {
        auto it = grid.find({ix, iy});
        if (it == grid.end()) continue;
        for (auto nd : it->second) {
          const std::size_t k = static_cast<std::size_t>(nd);
          if (std::abs(mesh.coords[3 * k + 2] - z) > z_tol) continue;
          const double d = std::hypot(mesh.coords[3 * k] - x, mesh.coords[3 * k + 1] - y);
          if (d > reach) continue;
          auto [it2, fresh] = best.try_emplace(tow_of_node[k], d, nd);
          if (!fresh && d < it2->second.first) it2->second = {d, nd};
        }
      }
    for (const auto& [tow, dn] : best)
      fm.connections.push_back(
          {sn, dn.second, axis_neighbour[static_cast<std::size_t>(dn.second)]});
  }
}

}  // namespace

FabricModel generate_blanket(fem::Mesh& mesh, const FabricSpec& f, const BlanketSpec& bl,
                             const std::string& file, const std::string& prefix,
                             const std::string& key_path) {
  // The spec as meshed (a case's resolution scales its divisions); the keys are checked here once.
  validate(f, file, !key_path.empty() ? key_path : prefix.empty() ? "fabric" : prefix);
  const std::string size_key = key_path.empty() ? prefix + "size" : key_path + ".size";
  const BlanketLayout L = layout_of(f, bl);
  if (!(L.Lx >= L.p * (1 - 1e-9) && L.Ly >= L.p * (1 - 1e-9)))
    throw InputError(
        file, size_key,
        "the blanket must be at least one tow pitch (" + std::to_string(L.p) + " m) long and wide");
  FabricModel fm;
  fm.tow_thickness = L.t;
  std::vector<std::int32_t> axis_neighbour;
  mesh_tows(mesh, f, bl, L, prefix, fm, axis_neighbour);
  if (f.stitch == StitchPattern::None) return fm;
  mesh_stitch(mesh, f, L, file, size_key, prefix, fm);
  connect_stitch_to_tows(mesh, f, bl, L, axis_neighbour, fm);
  return fm;
}

}  // namespace ncfsim::drape

#include "fem/mesh.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <stdexcept>

namespace ncfsim::fem {

int Mesh::add_part(const std::string& name) {
  if (int p = find_part(name); p >= 0) return p;
  part_names.push_back(name);
  return static_cast<int>(part_names.size()) - 1;
}

int Mesh::find_part(const std::string& name) const {
  for (std::size_t i = 0; i < part_names.size(); ++i)
    if (part_names[i] == name) return static_cast<int>(i);
  return -1;
}

void Mesh::fill_default_user_ids() {
  auto fill = [](std::vector<std::int64_t>& ids, std::size_t n) {
    if (ids.size() == n) return;
    ids.resize(n);
    std::iota(ids.begin(), ids.end(), std::int64_t{1});
  };
  fill(node_user_id, n_nodes());
  fill(hex_user_id, hexes.size());
  fill(bar_user_id, bars.size());
  hex_ply.resize(hexes.size(), -1);
  hex_tow.resize(hexes.size(), -1);
}

void Mesh::validate() const {
  const auto n = static_cast<std::int64_t>(n_nodes());
  if (coords.size() % 3 != 0) throw std::invalid_argument("coordinate array is not a multiple of 3");
  if (hex_part.size() != hexes.size() || bar_part.size() != bars.size())
    throw std::invalid_argument("part tag count differs from element count");
  if ((!hex_ply.empty() && hex_ply.size() != hexes.size()) ||
      (!hex_tow.empty() && hex_tow.size() != hexes.size()))
    throw std::invalid_argument("ply/tow tag count differs from the hexahedron count");
  const auto n_parts = static_cast<std::int32_t>(part_names.size());
  for (std::size_t e = 0; e < hexes.size(); ++e) {
    for (auto v : hexes[e])
      if (v < 0 || v >= n)
        throw std::invalid_argument("hexahedron " + std::to_string(e + 1) + " names node " +
                                    std::to_string(v) + " outside 0.." + std::to_string(n - 1));
    if (hex_part[e] < 0 || hex_part[e] >= n_parts)
      throw std::invalid_argument("hexahedron " + std::to_string(e + 1) + " has no valid part");
  }
  for (std::size_t e = 0; e < bars.size(); ++e) {
    for (auto v : bars[e])
      if (v < 0 || v >= n)
        throw std::invalid_argument("bar " + std::to_string(e + 1) + " names node " +
                                    std::to_string(v) + " outside 0.." + std::to_string(n - 1));
    if (bars[e][0] == bars[e][1])
      throw std::invalid_argument("bar " + std::to_string(e + 1) + " joins a node to itself");
    if (bar_part[e] < 0 || bar_part[e] >= n_parts)
      throw std::invalid_argument("bar " + std::to_string(e + 1) + " has no valid part");
  }
  for (double c : coords)
    if (!std::isfinite(c)) throw std::invalid_argument("a node coordinate is not finite");
}

namespace {

std::uint64_t spread_bits(std::uint64_t v) {  // 21 bits -> every third bit
  v &= 0x1fffff;
  v = (v | v << 32) & 0x1f00000000ffffULL;
  v = (v | v << 16) & 0x1f0000ff0000ffULL;
  v = (v | v << 8) & 0x100f00f00f00f00fULL;
  v = (v | v << 4) & 0x10c30c30c30c30c3ULL;
  v = (v | v << 2) & 0x1249249249249249ULL;
  return v;
}

template <std::size_t N>
std::vector<std::uint64_t> morton_keys(const Mesh& m, const std::vector<std::array<std::int32_t, N>>& elems,
                                       const std::array<double, 3>& lo, const std::array<double, 3>& span) {
  std::vector<std::uint64_t> keys(elems.size());
  for (std::size_t e = 0; e < elems.size(); ++e) {
    std::array<double, 3> c{0, 0, 0};
    for (auto v : elems[e])
      for (int k = 0; k < 3; ++k) c[k] += m.coords[3 * v + k] / N;
    std::uint64_t key = 0;
    for (int k = 0; k < 3; ++k) {
      const double t = span[k] > 0 ? (c[k] - lo[k]) / span[k] : 0.0;
      key |= spread_bits(static_cast<std::uint64_t>(std::clamp(t, 0.0, 1.0) * 2097151.0)) << k;
    }
    keys[e] = key;
  }
  return keys;
}

template <typename T>
void apply_order(std::vector<T>& v, const std::vector<std::size_t>& order) {
  std::vector<T> out(v.size());
  for (std::size_t i = 0; i < order.size(); ++i) out[i] = v[order[i]];
  v.swap(out);
}

}  // namespace

std::vector<std::int32_t> renumber_for_locality(Mesh& mesh) {
  mesh.fill_default_user_ids();
  const std::size_t n = mesh.n_nodes();
  std::array<double, 3> lo{}, hi{};
  lo.fill(std::numeric_limits<double>::max());
  hi.fill(std::numeric_limits<double>::lowest());
  for (std::size_t i = 0; i < n; ++i)
    for (int k = 0; k < 3; ++k) {
      lo[k] = std::min(lo[k], mesh.coords[3 * i + k]);
      hi[k] = std::max(hi[k], mesh.coords[3 * i + k]);
    }
  std::array<double, 3> span{hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]};

  auto sort_elements = [&](auto& elems, auto& parts, auto& ids, auto... tags) {
    auto keys = morton_keys(mesh, elems, lo, span);
    std::vector<std::size_t> order(elems.size());
    std::iota(order.begin(), order.end(), 0);
    // Elements stay grouped by part (blocks are built per part), Morton order inside a part.
    std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
      return parts[a] != parts[b] ? parts[a] < parts[b] : keys[a] < keys[b];
    });
    apply_order(elems, order);
    apply_order(parts, order);
    apply_order(ids, order);
    (apply_order(*tags, order), ...);
  };
  sort_elements(mesh.hexes, mesh.hex_part, mesh.hex_user_id, &mesh.hex_ply, &mesh.hex_tow);
  sort_elements(mesh.bars, mesh.bar_part, mesh.bar_user_id);

  std::vector<std::int32_t> new_of_old(n, -1);
  std::int32_t next = 0;
  for (auto& h : mesh.hexes)
    for (auto v : h)
      if (new_of_old[v] < 0) new_of_old[v] = next++;
  for (auto& b : mesh.bars)
    for (auto v : b)
      if (new_of_old[v] < 0) new_of_old[v] = next++;
  for (std::size_t i = 0; i < n; ++i)
    if (new_of_old[i] < 0) new_of_old[i] = next++;  // free nodes keep their relative order

  std::vector<double> coords(mesh.coords.size());
  std::vector<std::int64_t> uid(n);
  for (std::size_t i = 0; i < n; ++i) {
    for (int k = 0; k < 3; ++k) coords[3 * new_of_old[i] + k] = mesh.coords[3 * i + k];
    uid[new_of_old[i]] = mesh.node_user_id[i];
  }
  mesh.coords.swap(coords);
  mesh.node_user_id.swap(uid);
  for (auto& h : mesh.hexes)
    for (auto& v : h) v = new_of_old[v];
  for (auto& b : mesh.bars)
    for (auto& v : b) v = new_of_old[v];
  return new_of_old;
}

std::vector<std::int32_t> add_hex_block(Mesh& mesh, int part, const std::array<double, 3>& origin,
                                        const std::array<double, 3>& size,
                                        const std::array<int, 3>& div) {
  const int nx = div[0], ny = div[1], nz = div[2];
  if (nx < 1 || ny < 1 || nz < 1) throw std::invalid_argument("block divisions must be >= 1");
  const auto first = static_cast<std::int32_t>(mesh.n_nodes());
  std::vector<std::int32_t> ids;
  ids.reserve(static_cast<std::size_t>((nx + 1) * (ny + 1) * (nz + 1)));
  for (int k = 0; k <= nz; ++k)
    for (int j = 0; j <= ny; ++j)
      for (int i = 0; i <= nx; ++i) {
        ids.push_back(static_cast<std::int32_t>(mesh.n_nodes()));
        mesh.coords.push_back(origin[0] + size[0] * i / nx);
        mesh.coords.push_back(origin[1] + size[1] * j / ny);
        mesh.coords.push_back(origin[2] + size[2] * k / nz);
      }
  append_grid_hexes(mesh, part, first, {nx, ny, nz});
  return ids;
}

void append_grid_hexes(Mesh& mesh, int part, std::int32_t first, const std::array<int, 3>& cells) {
  const int nx = cells[0], ny = cells[1], nz = cells[2];
  auto id = [&](int i, int j, int k) { return first + i + (nx + 1) * (j + (ny + 1) * k); };
  for (int k = 0; k < nz; ++k)
    for (int j = 0; j < ny; ++j)
      for (int i = 0; i < nx; ++i) {
        mesh.hexes.push_back({id(i, j, k), id(i + 1, j, k), id(i + 1, j + 1, k), id(i, j + 1, k),
                              id(i, j, k + 1), id(i + 1, j, k + 1), id(i + 1, j + 1, k + 1),
                              id(i, j + 1, k + 1)});
        mesh.hex_part.push_back(part);
      }
}

}  // namespace ncfsim::fem

#include "fem/mesh.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <stdexcept>

namespace ncfsim::fem {

void ElementSet::add(std::span<const std::int32_t> element_nodes, int part_index) {
  if (element_nodes.size() != static_cast<std::size_t>(nodes_per_element))
    throw std::invalid_argument(std::string(element_noun(kind)) + " needs " +
                                std::to_string(nodes_per_element) + " nodes");
  conn.insert(conn.end(), element_nodes.begin(), element_nodes.end());
  part.push_back(part_index);
}

ElementSet& Mesh::elements(ElementKind kind) {
  auto it =
      std::find_if(sets.begin(), sets.end(), [&](const ElementSet& s) { return s.kind >= kind; });
  if (it != sets.end() && it->kind == kind) return *it;
  ElementSet s;
  s.kind = kind;
  s.nodes_per_element = nodes_per_element(kind);
  return *sets.insert(it, std::move(s));
}

const ElementSet& Mesh::elements(ElementKind kind) const {
  if (const ElementSet* s = find_set(kind)) return *s;
  static const auto empty = [] {
    std::array<ElementSet, kElementKinds.size()> e;
    for (std::size_t k = 0; k < e.size(); ++k)
      e[k].kind = kElementKinds[k], e[k].nodes_per_element = nodes_per_element(kElementKinds[k]);
    return e;
  }();
  return empty[static_cast<std::size_t>(kind)];
}

const ElementSet* Mesh::find_set(ElementKind kind) const {
  for (const auto& s : sets)
    if (s.kind == kind) return &s;
  return nullptr;
}

std::size_t Mesh::n_elements() const {
  std::size_t n = 0;
  for (const auto& s : sets) n += s.size();
  return n;
}

std::size_t Mesh::element_offset(ElementKind kind) const {
  std::size_t n = 0;
  for (const auto& s : sets)
    if (s.kind < kind) n += s.size();
  return n;
}

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
  for (auto& s : sets) {
    fill(s.user_id, s.size());
    s.ply.resize(s.size(), -1);
    s.tow.resize(s.size(), -1);
  }
}

void Mesh::validate() const {
  const auto n = static_cast<std::int64_t>(n_nodes());
  if (coords.size() % 3 != 0)
    throw std::invalid_argument("coordinate array is not a multiple of 3");
  const auto n_parts = static_cast<std::int32_t>(part_names.size());
  for (std::size_t k = 0; k < sets.size(); ++k) {
    const ElementSet& s = sets[k];
    const std::string noun = element_noun(s.kind);
    if (k > 0 && !(sets[k - 1].kind < s.kind))
      throw std::invalid_argument("element sets are not one per kind in kind order");
    if (s.nodes_per_element != nodes_per_element(s.kind) ||
        s.conn.size() != s.size() * static_cast<std::size_t>(s.nodes_per_element))
      throw std::invalid_argument("part tag count differs from element count");
    if ((!s.ply.empty() && s.ply.size() != s.size()) ||
        (!s.tow.empty() && s.tow.size() != s.size()))
      throw std::invalid_argument("ply/tow tag count differs from the " + noun + " count");
    for (std::size_t e = 0; e < s.size(); ++e) {
      const auto nodes = s.nodes(e);
      for (auto v : nodes)
        if (v < 0 || v >= n)
          throw std::invalid_argument(noun + " " + std::to_string(e + 1) + " names node " +
                                      std::to_string(v) + " outside 0.." + std::to_string(n - 1));
      if (element_needs_distinct_nodes(s.kind) && nodes[0] == nodes[1])
        throw std::invalid_argument(noun + " " + std::to_string(e + 1) + " joins a node to itself");
      if (s.part[e] < 0 || s.part[e] >= n_parts)
        throw std::invalid_argument(noun + " " + std::to_string(e + 1) + " has no valid part");
    }
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

}  // namespace

std::uint64_t morton_key(const std::array<double, 3>& c, const std::array<double, 3>& lo,
                         const std::array<double, 3>& span) {
  std::uint64_t key = 0;
  for (int k = 0; k < 3; ++k) {
    const double t = span[k] > 0 ? (c[k] - lo[k]) / span[k] : 0.0;
    key |= spread_bits(static_cast<std::uint64_t>(std::clamp(t, 0.0, 1.0) * 2097151.0)) << k;
  }
  return key;
}

namespace {

std::vector<std::uint64_t> morton_keys(const Mesh& m, const ElementSet& s,
                                       const std::array<double, 3>& lo,
                                       const std::array<double, 3>& span) {
  const auto nn = static_cast<std::size_t>(s.nodes_per_element);
  std::vector<std::uint64_t> keys(s.size());
  for (std::size_t e = 0; e < s.size(); ++e) {
    std::array<double, 3> c{0, 0, 0};
    for (auto v : s.nodes(e))
      for (int k = 0; k < 3; ++k) c[k] += m.coords[3 * static_cast<std::size_t>(v) + k] / nn;
    keys[e] = morton_key(c, lo, span);
  }
  return keys;
}

// v[i] = old v[order[i]], `width` values per element.
template <typename T>
void apply_order(std::vector<T>& v, const std::vector<std::size_t>& order, std::size_t width = 1) {
  std::vector<T> out(v.size());
  for (std::size_t i = 0; i < order.size(); ++i)
    for (std::size_t k = 0; k < width; ++k) out[width * i + k] = v[width * order[i] + k];
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
  // One scale for the three axes: the curve then runs through space evenly (a thin blanket is
  // ordered in its plane, not layer by layer), which is also what the MPI split cuts along.
  const double side = std::max({hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]});
  const std::array<double, 3> span{side, side, side};

  for (auto& s : mesh.sets) {
    auto keys = morton_keys(mesh, s, lo, span);
    std::vector<std::size_t> order(s.size());
    std::iota(order.begin(), order.end(), 0);
    const auto& parts = s.part;
    // Elements stay grouped by part (blocks are built per part), Morton order inside a part.
    std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
      return parts[a] != parts[b] ? parts[a] < parts[b] : keys[a] < keys[b];
    });
    apply_order(s.conn, order, static_cast<std::size_t>(s.nodes_per_element));
    apply_order(s.part, order);
    apply_order(s.user_id, order);
    apply_order(s.ply, order);
    apply_order(s.tow, order);
    if (!s.material_axes.empty()) apply_order(s.material_axes, order, 9);
    if (!s.material.empty()) apply_order(s.material, order);
  }

  // Nodes by first use, sets in kind order.
  std::vector<std::int32_t> new_of_old(n, -1);
  std::int32_t next = 0;
  for (const auto& s : mesh.sets)
    for (auto v : s.conn)
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
  for (auto& s : mesh.sets)
    for (auto& v : s.conn) v = new_of_old[v];
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
  ElementSet& hexes = mesh.elements(ElementKind::Hex8);
  for (int k = 0; k < nz; ++k)
    for (int j = 0; j < ny; ++j)
      for (int i = 0; i < nx; ++i) {
        hexes.add(
            {id(i, j, k), id(i + 1, j, k), id(i + 1, j + 1, k), id(i, j + 1, k), id(i, j, k + 1),
             id(i + 1, j, k + 1), id(i + 1, j + 1, k + 1), id(i, j + 1, k + 1)},
            part);
      }
}

}  // namespace ncfsim::fem

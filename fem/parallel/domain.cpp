#include "fem/parallel/domain.hpp"

#include <algorithm>
#include <array>
#include <limits>
#include <memory>

#include "fem/elements/element_group.hpp"
#include "fem/errors.hpp"
#include "fem/mesh.hpp"

namespace ncfsim::fem {

namespace {

// Relative cost of an element per cycle, by kind (bench_engine: a hexahedron ~200 ns, a bar
// ~10 ns, a shell ~60 ns); contacts follow the elements' surface.
double element_cost(ElementKind kind) {
  switch (kind) {
    case ElementKind::Hex8:
      return 1.0;
    case ElementKind::Bar2:
      return 0.05;
    case ElementKind::Quad4:
      return 0.3;
  }
  return 1.0;
}

// Morton keys of a group's element centroids at x0 (as Mesh::renumber_for_locality computes them).
std::vector<std::uint64_t> group_keys(const ElementGroup& g, const double* x0,
                                      const std::array<double, 3>& lo,
                                      const std::array<double, 3>& span) {
  const std::size_t n = g.size(), npe = static_cast<std::size_t>(g.nodes_per_element());
  std::vector<std::uint64_t> keys(n);
  for (std::size_t e = 0; e < n; ++e) {
    std::array<double, 3> c{0, 0, 0};
    for (std::size_t I = 0; I < npe; ++I)
      for (int k = 0; k < 3; ++k)
        c[k] +=
            x0[3 * static_cast<std::size_t>(g.conn()[I * n + e]) + k] / static_cast<double>(npe);
    keys[e] = morton_key(c, lo, span);
  }
  return keys;
}

// Where the curve is cut: keys t_1..t_{p-1} splitting the elements' cost in p equal shares.
std::vector<std::uint64_t> curve_cuts(const std::vector<std::unique_ptr<ElementGroup>>& groups,
                                      const std::vector<std::vector<std::uint64_t>>& keys, int p) {
  std::vector<std::pair<std::uint64_t, double>> all;
  double total = 0;
  for (std::size_t g = 0; g < groups.size(); ++g) {
    const double w = element_cost(groups[g]->kind());
    for (auto k : keys[g]) all.emplace_back(k, w), total += w;
  }
  std::sort(all.begin(), all.end());
  std::vector<std::uint64_t> cuts;
  double sum = 0;
  std::size_t i = 0;
  for (int r = 1; r < p; ++r) {
    const double target = total * r / p;
    while (i < all.size() && sum + all[i].second <= target) sum += all[i++].second;
    cuts.push_back(i < all.size() ? all[i].first : ~std::uint64_t{0});
  }
  return cuts;
}

// A star forest on nodes (3 doubles each): leaves at `leaves` (indices into a full-size array)
// whose roots are the same index on rank owner[leaf].
PetscSF node_sf(MPI_Comm comm, std::size_t n_nodes, const std::vector<std::int32_t>& leaves,
                const std::vector<int>& owner) {
  PetscSF sf = nullptr;
  NCF_PETSC(PetscSFCreate(comm, &sf));
  std::vector<PetscInt> ilocal(leaves.size());
  std::vector<PetscSFNode> iremote(leaves.size());
  for (std::size_t k = 0; k < leaves.size(); ++k) {
    const auto node = static_cast<std::size_t>(leaves[k]);
    ilocal[k] = static_cast<PetscInt>(node);
    iremote[k].rank = owner[node];
    iremote[k].index = static_cast<PetscInt>(node);
  }
  NCF_PETSC(PetscSFSetGraph(sf, static_cast<PetscInt>(n_nodes),
                            static_cast<PetscInt>(leaves.size()), ilocal.data(), PETSC_COPY_VALUES,
                            iremote.data(), PETSC_COPY_VALUES));
  NCF_PETSC(PetscSFSetUp(sf));
  return sf;
}

// Runs [begin, end) of consecutive set entries of a node mask.
std::vector<std::pair<std::size_t, std::size_t>> runs_of(const std::vector<std::uint8_t>& mask) {
  std::vector<std::pair<std::size_t, std::size_t>> runs;
  for (std::size_t i = 0; i < mask.size();) {
    if (!mask[i]) {
      ++i;
      continue;
    }
    std::size_t j = i;
    while (j < mask.size() && mask[j]) ++j;
    runs.emplace_back(i, j);
    i = j;
  }
  return runs;
}

}  // namespace

Domain::Domain(MPI_Comm comm, std::size_t n_nodes, const double* x0,
               const std::vector<std::unique_ptr<ElementGroup>>& groups)
    : comm_(comm), n_nodes_(n_nodes) {
  MPI_Comm_rank(comm_, &rank_);
  MPI_Comm_size(comm_, &size_);
  MPI_Type_contiguous(3, MPI_DOUBLE, &node3_);
  MPI_Type_commit(&node3_);
  MPI_Type_contiguous(6, MPI_DOUBLE, &node6_);
  MPI_Type_commit(&node6_);

  // Element runs, then node owners: of the ranks with an element on the node, the one whose
  // stretch of the curve holds the node itself (else the lowest). Every rank computes the same
  // split from the same model (no communication). A group's run on rank r
  // holds its elements whose curve position is between the cuts r and r + 1 (its elements are
  // in curve order: the run is contiguous), its ends moved to the nearest whole kernel chunk.
  std::array<double, 3> lo, hi, span;
  lo.fill(std::numeric_limits<double>::max());
  hi.fill(std::numeric_limits<double>::lowest());
  for (std::size_t i = 0; i < n_nodes; ++i)
    for (int k = 0; k < 3; ++k)
      lo[k] = std::min(lo[k], x0[3 * i + k]), hi[k] = std::max(hi[k], x0[3 * i + k]);
  const double side = std::max({hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]});
  span.fill(side);  // as Mesh::renumber_for_locality
  std::vector<std::vector<std::uint64_t>> keys;
  for (const auto& g : groups) keys.push_back(group_keys(*g, x0, lo, span));
  const std::vector<std::uint64_t> cuts = curve_cuts(groups, keys, size_);
  owner_.assign(n_nodes, size_);
  // Ranks with an element on each node (up to 64 ranks; beyond, the lowest owns it).
  const bool masks = size_ <= 64;
  std::vector<std::uint64_t> touched(masks ? n_nodes : 0, 0);
  all_ranges_.resize(groups.size());
  for (std::size_t g = 0; g < groups.size(); ++g) {
    const ElementGroup& grp = *groups[g];
    const std::size_t n = grp.size(), npe = static_cast<std::size_t>(grp.nodes_per_element());
    const std::size_t c = grp.chunk();
    std::vector<std::size_t> ends = {0};
    for (auto t : cuts) {
      // Elements before the cut (a count, so that a group out of curve order is still split in
      // proportion), rounded to a chunk, never before the previous end.
      const auto below = static_cast<std::size_t>(
          std::count_if(keys[g].begin(), keys[g].end(), [&](std::uint64_t k) { return k < t; }));
      ends.push_back(std::max(ends.back(), std::min(n, (below + c / 2) / c * c)));
    }
    ends.push_back(n);
    for (int r = 0; r < size_; ++r) {
      const std::pair<std::size_t, std::size_t> rr{ends[static_cast<std::size_t>(r)],
                                                   ends[static_cast<std::size_t>(r) + 1]};
      all_ranges_[g].push_back(rr);
      for (std::size_t e = rr.first; e < rr.second; ++e)
        for (std::size_t I = 0; I < npe; ++I) {
          const auto node = static_cast<std::size_t>(grp.conn()[I * n + e]);
          owner_[node] = std::min(owner_[node], r);
          if (masks) touched[node] |= std::uint64_t{1} << r;
        }
    }
    range_.push_back(all_ranges_[g][static_cast<std::size_t>(rank_)]);
  }
  // A node on the cut goes to the side of the cut it lies on: the lowest rank would own every
  // node of the cut, and the work per owned node (its contacts, its tools) with them (the CI
  // hemisphere's rank 0 owned 5 % more nodes, and did 5 % more contact).
  if (masks)
    for (std::size_t i = 0; i < n_nodes; ++i) {
      if ((touched[i] & (touched[i] - 1)) == 0) continue;  // one rank or none
      const std::array<double, 3> c{x0[3 * i], x0[3 * i + 1], x0[3 * i + 2]};
      const auto side_of_cut = static_cast<int>(
          std::upper_bound(cuts.begin(), cuts.end(), morton_key(c, lo, span)) - cuts.begin());
      if ((touched[i] >> side_of_cut) & 1) owner_[i] = side_of_cut;
    }
  owned_.assign(n_nodes, 0);
  readable_.assign(n_nodes, 0);
  for (std::size_t i = 0; i < n_nodes; ++i) {
    if (owner_[i] == size_) owner_[i] = 0;  // no element: the root keeps it
    if (owner_[i] == rank_) owned_[i] = readable_[i] = 1, ++n_owned_;
  }
  runs_ = runs_of(owned_);
  // Read: the nodes of my elements, and of every element on a node I own (a contact on an owned
  // surface node looks at the faces round it, whoever integrates them).
  for (std::size_t g = 0; g < groups.size(); ++g) {
    const ElementGroup& grp = *groups[g];
    const std::size_t n = grp.size(), npe = static_cast<std::size_t>(grp.nodes_per_element());
    const std::int32_t* conn = grp.conn();
    for (std::size_t e = 0; e < n; ++e) {
      bool mine = e >= range_[g].first && e < range_[g].second;
      for (std::size_t I = 0; I < npe && !mine; ++I)
        mine = owned_[static_cast<std::size_t>(conn[I * n + e])] != 0;
      if (mine)
        for (std::size_t I = 0; I < npe; ++I)
          readable_[static_cast<std::size_t>(conn[I * n + e])] = 1;
    }
  }
}

Domain::~Domain() {
  if (ghost_sf_) PetscSFDestroy(&ghost_sf_);
  if (gather_sf_) PetscSFDestroy(&gather_sf_);
  if (all_sf_) PetscSFDestroy(&all_sf_);
  if (exchange_sf_) PetscSFDestroy(&exchange_sf_);
  if (node3_ != MPI_DATATYPE_NULL) MPI_Type_free(&node3_);
  if (node6_ != MPI_DATATYPE_NULL) MPI_Type_free(&node6_);
}

std::pair<std::size_t, std::size_t> Domain::range(std::size_t g, int r) const {
  return all_ranges_[g][static_cast<std::size_t>(r)];
}

void Domain::add_readable(std::span<const std::int32_t> nodes) {
  if (ghost_sf_) throw std::logic_error("Domain::add_readable after finalise");
  if (base_readable_.empty()) base_readable_ = readable_;
  for (auto i : nodes) readable_[static_cast<std::size_t>(i)] = 1;
}

void Domain::finalise() {
  if (base_readable_.empty()) base_readable_ = readable_;
  gather_sf_ = node_sf(comm_, n_nodes_, root() ? not_owned() : std::vector<std::int32_t>{}, owner_);
  build_exchange();
}

void Domain::rebuild_ghosts(std::span<const std::int32_t> extra, double* x, double* v) {
  readable_ = base_readable_;
  for (auto i : extra) readable_[static_cast<std::size_t>(i)] = 1;
  if (ghost_sf_) PetscSFDestroy(&ghost_sf_);
  if (exchange_sf_) PetscSFDestroy(&exchange_sf_);
  shared_.clear();
  build_exchange();
  refresh_ghosts(x, v);
}

void Domain::gather_to_all(double* a) {
  if (!all_sf_) all_sf_ = node_sf(comm_, n_nodes_, not_owned(), owner_);
  NCF_PETSC(PetscSFBcastBegin(all_sf_, node3_, a, a, MPI_REPLACE));
  NCF_PETSC(PetscSFBcastEnd(all_sf_, node3_, a, a, MPI_REPLACE));
}

std::vector<std::int32_t> Domain::not_owned() const {
  std::vector<std::int32_t> nodes;
  for (std::size_t i = 0; i < n_nodes_; ++i)
    if (!owned_[i]) nodes.push_back(static_cast<std::int32_t>(i));
  return nodes;
}

void Domain::build_exchange() {
  readable_runs_ = runs_of(readable_);
  ghosts_.clear();
  for (std::size_t i = 0; i < n_nodes_; ++i)
    if (readable_[i] && !owned_[i]) ghosts_.push_back(static_cast<std::int32_t>(i));
  ghost_sf_ = node_sf(comm_, n_nodes_, ghosts_, owner_);
  // What the owners send back per cycle: x and v of the ghosts that others read of mine, plus
  // the forces I add into others' nodes (two arrays).
  PetscInt n_roots = 0, n_leaves = 0;
  const PetscInt* ilocal = nullptr;
  const PetscSFNode* iremote = nullptr;
  NCF_PETSC(PetscSFGetGraph(ghost_sf_, &n_roots, &n_leaves, &ilocal, &iremote));
  std::size_t n_root_leaves = 0;  // leaves of other ranks that hang on my roots
  {
    const PetscInt* degree = nullptr;
    NCF_PETSC(PetscSFComputeDegreeBegin(ghost_sf_, &degree));
    NCF_PETSC(PetscSFComputeDegreeEnd(ghost_sf_, &degree));
    for (PetscInt i = 0; i < n_roots; ++i) {
      n_root_leaves += static_cast<std::size_t>(degree[i]);
      if (degree[i] > 0) shared_.push_back(static_cast<std::int32_t>(i));
    }
  }
  bytes_per_cycle_ = 24 * (2 * static_cast<std::size_t>(n_leaves) + 2 * n_root_leaves);
  // The exchange on packed buffers: each ghost learns its node's place in its owner's shared_.
  {
    std::vector<PetscInt> place(n_nodes_, -1);
    for (std::size_t k = 0; k < shared_.size(); ++k)
      place[static_cast<std::size_t>(shared_[k])] = static_cast<PetscInt>(k);
    NCF_PETSC(PetscSFBcastBegin(ghost_sf_, MPIU_INT, place.data(), place.data(), MPI_REPLACE));
    NCF_PETSC(PetscSFBcastEnd(ghost_sf_, MPIU_INT, place.data(), place.data(), MPI_REPLACE));
    std::vector<PetscSFNode> iremote(ghosts_.size());
    for (std::size_t k = 0; k < ghosts_.size(); ++k) {
      const auto node = static_cast<std::size_t>(ghosts_[k]);
      iremote[k].rank = owner_[node];
      iremote[k].index = place[node];
    }
    NCF_PETSC(PetscSFCreate(comm_, &exchange_sf_));
    NCF_PETSC(PetscSFSetGraph(exchange_sf_, static_cast<PetscInt>(shared_.size()),
                              static_cast<PetscInt>(ghosts_.size()), nullptr, PETSC_COPY_VALUES,
                              iremote.data(), PETSC_COPY_VALUES));
    NCF_PETSC(PetscSFSetUp(exchange_sf_));
  }
  leaf_buf_.assign(6 * ghosts_.size(), 0.0);
  root_buf_.assign(6 * shared_.size(), 0.0);
}

namespace {
// Packs the 3 components of a and b (b may be null: a alone, 3 a node) of `nodes` into buf.
void pack(const std::vector<std::int32_t>& nodes, const double* a, const double* b, double* buf) {
  const std::size_t w = b ? 6 : 3;
  for (std::size_t k = 0; k < nodes.size(); ++k) {
    const std::size_t i = 3 * static_cast<std::size_t>(nodes[k]);
    double* p = buf + w * k;
    p[0] = a[i], p[1] = a[i + 1], p[2] = a[i + 2];
    if (b) p[3] = b[i], p[4] = b[i + 1], p[5] = b[i + 2];
  }
}
void unpack(const std::vector<std::int32_t>& nodes, const double* buf, double* a, double* b) {
  const std::size_t w = b ? 6 : 3;
  for (std::size_t k = 0; k < nodes.size(); ++k) {
    const std::size_t i = 3 * static_cast<std::size_t>(nodes[k]);
    const double* p = buf + w * k;
    a[i] = p[0], a[i + 1] = p[1], a[i + 2] = p[2];
    if (b) b[i] = p[3], b[i + 1] = p[4], b[i + 2] = p[5];
  }
}
}  // namespace

void Domain::add_ghosts_to_owners(double* f_int, double* f_contact) const {
  // The owners' own sums go in first: each root is then its value plus its ghosts' (MPI_SUM), as
  // a reduce in place on the whole arrays would give.
  const MPI_Datatype unit = f_contact ? node6_ : node3_;
  pack(ghosts_, f_int, f_contact, leaf_buf_.data());
  pack(shared_, f_int, f_contact, root_buf_.data());
  NCF_PETSC(PetscSFReduceBegin(exchange_sf_, unit, leaf_buf_.data(), root_buf_.data(), MPI_SUM));
  NCF_PETSC(PetscSFReduceEnd(exchange_sf_, unit, leaf_buf_.data(), root_buf_.data(), MPI_SUM));
  unpack(shared_, root_buf_.data(), f_int, f_contact);
}

void Domain::refresh_ghosts(double* x, double* v) const {
  pack(shared_, x, v, root_buf_.data());
  NCF_PETSC(
      PetscSFBcastBegin(exchange_sf_, node6_, root_buf_.data(), leaf_buf_.data(), MPI_REPLACE));
  NCF_PETSC(PetscSFBcastEnd(exchange_sf_, node6_, root_buf_.data(), leaf_buf_.data(), MPI_REPLACE));
  unpack(ghosts_, leaf_buf_.data(), x, v);
}

void Domain::refresh_ghosts(double* a) const {
  NCF_PETSC(PetscSFBcastBegin(ghost_sf_, node3_, a, a, MPI_REPLACE));
  NCF_PETSC(PetscSFBcastEnd(ghost_sf_, node3_, a, a, MPI_REPLACE));
}

void Domain::gather_to_root(double* a) const {
  NCF_PETSC(PetscSFBcastBegin(gather_sf_, node3_, a, a, MPI_REPLACE));
  NCF_PETSC(PetscSFBcastEnd(gather_sf_, node3_, a, a, MPI_REPLACE));
}

void Domain::gather_group_array(std::size_t g, double* data, std::size_t n, int components) const {
  std::vector<int> counts(static_cast<std::size_t>(size_)), displs(static_cast<std::size_t>(size_));
  for (int r = 0; r < size_; ++r) {
    const auto [b, e] = range(g, r);
    counts[static_cast<std::size_t>(r)] = static_cast<int>(e - b);
    displs[static_cast<std::size_t>(r)] = static_cast<int>(b);
  }
  const auto [b, e] = range_[g];
  for (int c = 0; c < components; ++c) {
    double* row = data + static_cast<std::size_t>(c) * n;
    if (root())
      MPI_Gatherv(MPI_IN_PLACE, 0, MPI_DOUBLE, row, counts.data(), displs.data(), MPI_DOUBLE, 0,
                  comm_);
    else
      MPI_Gatherv(row + b, static_cast<int>(e - b), MPI_DOUBLE, nullptr, nullptr, nullptr,
                  MPI_DOUBLE, 0, comm_);
  }
}

}  // namespace ncfsim::fem

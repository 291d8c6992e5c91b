#include "fem/parallel/domain.hpp"

#include <algorithm>
#include <memory>

#include "fem/elements/element_group.hpp"
#include "fem/errors.hpp"

namespace ncfsim::fem {

namespace {

// Chunk k0..k1 of nc chunks of c elements, as an element range of a group of n.
std::pair<std::size_t, std::size_t> chunk_range(std::size_t n, std::size_t c, int r, int p) {
  const std::size_t nc = (n + c - 1) / c;
  const std::size_t k0 = nc * static_cast<std::size_t>(r) / static_cast<std::size_t>(p);
  const std::size_t k1 = nc * static_cast<std::size_t>(r + 1) / static_cast<std::size_t>(p);
  return {std::min(n, k0 * c), std::min(n, k1 * c)};
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

}  // namespace

Domain::Domain(MPI_Comm comm, std::size_t n_nodes,
               const std::vector<std::unique_ptr<ElementGroup>>& groups)
    : comm_(comm), n_nodes_(n_nodes) {
  MPI_Comm_rank(comm_, &rank_);
  MPI_Comm_size(comm_, &size_);
  MPI_Type_contiguous(3, MPI_DOUBLE, &node3_);
  MPI_Type_commit(&node3_);

  // Element runs, then node owners: the lowest rank with an element on the node. Every rank
  // computes the same split from the same model (no communication).
  owner_.assign(n_nodes, size_);
  all_ranges_.resize(groups.size());
  for (std::size_t g = 0; g < groups.size(); ++g) {
    const ElementGroup& grp = *groups[g];
    const std::size_t n = grp.size(), npe = static_cast<std::size_t>(grp.nodes_per_element());
    for (int r = 0; r < size_; ++r) {
      const auto rr = chunk_range(n, grp.chunk(), r, size_);
      all_ranges_[g].push_back(rr);
      for (std::size_t e = rr.first; e < rr.second; ++e)
        for (std::size_t I = 0; I < npe; ++I) {
          int& o = owner_[static_cast<std::size_t>(grp.conn()[I * n + e])];
          o = std::min(o, r);
        }
    }
    range_.push_back(all_ranges_[g][static_cast<std::size_t>(rank_)]);
  }
  owned_.assign(n_nodes, 0);
  readable_.assign(n_nodes, 0);
  for (std::size_t i = 0; i < n_nodes; ++i) {
    if (owner_[i] == size_) owner_[i] = 0;  // no element: the root keeps it
    if (owner_[i] == rank_) owned_[i] = readable_[i] = 1, ++n_owned_;
  }
  for (std::size_t i = 0; i < n_nodes;) {
    if (!owned_[i]) {
      ++i;
      continue;
    }
    std::size_t j = i;
    while (j < n_nodes && owned_[j]) ++j;
    runs_.emplace_back(i, j);
    i = j;
  }
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
  if (node3_ != MPI_DATATYPE_NULL) MPI_Type_free(&node3_);
}

std::pair<std::size_t, std::size_t> Domain::range(std::size_t g, int r) const {
  return all_ranges_[g][static_cast<std::size_t>(r)];
}

void Domain::add_readable(std::span<const std::int32_t> nodes) {
  if (ghost_sf_) throw std::logic_error("Domain::add_readable after finalise");
  for (auto i : nodes) readable_[static_cast<std::size_t>(i)] = 1;
}

void Domain::finalise() {
  ghosts_.clear();
  for (std::size_t i = 0; i < n_nodes_; ++i)
    if (readable_[i] && !owned_[i]) ghosts_.push_back(static_cast<std::int32_t>(i));
  ghost_sf_ = node_sf(comm_, n_nodes_, ghosts_, owner_);
  std::vector<std::int32_t> remote;
  if (root())
    for (std::size_t i = 0; i < n_nodes_; ++i)
      if (!owned_[i]) remote.push_back(static_cast<std::int32_t>(i));
  gather_sf_ = node_sf(comm_, n_nodes_, remote, owner_);
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
    for (PetscInt i = 0; i < n_roots; ++i) n_root_leaves += static_cast<std::size_t>(degree[i]);
  }
  bytes_per_cycle_ = 24 * (2 * static_cast<std::size_t>(n_leaves) + 2 * n_root_leaves);
}

void Domain::add_ghosts_to_owners(double* a) const {
  NCF_PETSC(PetscSFReduceBegin(ghost_sf_, node3_, a, a, MPI_SUM));
  NCF_PETSC(PetscSFReduceEnd(ghost_sf_, node3_, a, a, MPI_SUM));
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

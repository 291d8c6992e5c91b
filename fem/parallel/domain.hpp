#pragma once
// Domain decomposition of the explicit engine over MPI ranks (issue #24, docs/parallel.md).
//
// Every rank builds the whole model (mesh, groups, contacts, tools) with its nodal arrays at full
// size and global node numbers, then integrates only its share:
//  - elements: the Morton curve of the element centroids (the order the mesh sorts each part's
//    elements in) is cut into one stretch per rank of equal element cost; each group's elements
//    on a stretch are one contiguous run (to whole kernel chunks) that the kernels run over, and
//    every group is cut at the same places in space, so the plies of a stack split together;
//  - nodes: a node is owned by the lowest rank holding an element on it (rank 0 for a node with
//    no element); a rank updates its owned nodes only;
//  - ghosts: the nodes a rank reads but does not own (the other corners of its elements, and what
//    its contacts read: remote segments within the contact halo, tie masters, joint hexahedra).
// Each cycle the forces at ghosts are added into their owners (one PetscSF reduce of the internal
// and contact forces, packed 6 doubles a node) and the owners' new positions and velocities are
// copied back to the ghosts (one PetscSF broadcast of x and v, 6 doubles a node): the only nodal
// traffic, proportional to the partition surface, in one message each way per neighbour.
#include <mpi.h>
#include <petscsf.h>

#include <cstdint>
#include <memory>
#include <span>
#include <utility>
#include <vector>

namespace ncfsim::fem {

class ElementGroup;
struct Mesh;

class Domain {
 public:
  /// The split of `groups` over the ranks of `comm`, at reference positions x0 [3*n_nodes].
  Domain(MPI_Comm comm, std::size_t n_nodes, const double* x0,
         const std::vector<std::unique_ptr<ElementGroup>>& groups);
  ~Domain();
  Domain(const Domain&) = delete;
  Domain& operator=(const Domain&) = delete;

  MPI_Comm comm() const { return comm_; }
  int rank() const { return rank_; }
  int size() const { return size_; }
  bool root() const { return rank_ == 0; }

  /// [begin, end) of the elements of group g this rank integrates.
  std::pair<std::size_t, std::size_t> range(std::size_t g) const { return range_[g]; }
  /// [begin, end) of the elements of group g that rank r integrates.
  std::pair<std::size_t, std::size_t> range(std::size_t g, int r) const;
  bool owns(std::size_t node) const { return owner_[node] == rank_; }
  int owner(std::size_t node) const { return owner_[node]; }
  const std::vector<std::uint8_t>& owned_mask() const { return owned_; }
  /// Runs [begin, end) of consecutive owned nodes.
  const std::vector<std::pair<std::size_t, std::size_t>>& owned_runs() const { return runs_; }
  std::size_t n_owned() const { return n_owned_; }

  /// Nodes this rank reads (owned, corners of its elements, and those added by add_readable).
  const std::vector<std::uint8_t>& readable_mask() const { return readable_; }
  /// Runs [begin, end) of consecutive readable nodes (after finalise): the only entries of a
  /// nodal force array this rank writes or reads, so the only ones it clears each cycle.
  const std::vector<std::pair<std::size_t, std::size_t>>& readable_runs() const {
    return readable_runs_;
  }
  /// Marks more nodes as read by this rank (before finalise()).
  void add_readable(std::span<const std::int32_t> nodes);
  /// Builds the ghost exchange (collective). No add_readable after it.
  void finalise();
  /// Rebuilds the ghost exchange after finalise() (collective): this rank reads its owned nodes,
  /// its elements' corners and `extra` (what its contacts read now: a contact halo built again
  /// at the nodes' current positions), then every ghost is refreshed from its owner (x and v).
  void rebuild_ghosts(std::span<const std::int32_t> extra, double* x, double* v);
  /// Copies every node's entries from its owner into every rank's array [3*n_nodes]
  /// (collective; the whole field on each rank, e.g. the current positions before a halo is
  /// built again; an SF made at the first call).
  void gather_to_all(double* a);
  std::size_t n_ghosts() const { return ghosts_.size(); }

  /// Adds the ghost entries of the nodal force arrays [3*n_nodes] f_int and f_contact (null: no
  /// contact forces, f_int alone) into their owners' (collective; one reduce, the two packed per
  /// node). The ghost entries are left as they were.
  void add_ghosts_to_owners(double* f_int, double* f_contact) const;
  /// Copies the owners' positions and velocities [3*n_nodes] to this rank's ghosts (collective;
  /// one broadcast, x and v packed per node).
  void refresh_ghosts(double* x, double* v) const;
  /// Copies the owners' entries of one nodal array to this rank's ghosts (collective).
  void refresh_ghosts(double* a) const;
  /// Copies every node's entries from its owner into the root's array (collective; the root's
  /// array then holds the whole field; other ranks' arrays are not changed).
  void gather_to_root(double* a) const;
  /// Gathers each rank's run of group g's state array [components][n] into the root's.
  void gather_group_array(std::size_t g, double* data, std::size_t n, int components) const;

  /// Bytes this rank sends per cycle in the ghost exchange (internal and contact forces, x and v:
  /// 48 bytes a ghost node each way).
  std::size_t ghost_bytes_per_cycle() const { return bytes_per_cycle_; }

 private:
  MPI_Comm comm_;
  int rank_ = 0, size_ = 1;
  std::size_t n_nodes_ = 0, n_owned_ = 0, bytes_per_cycle_ = 0;
  std::vector<std::pair<std::size_t, std::size_t>> range_;
  std::vector<std::vector<std::pair<std::size_t, std::size_t>>> all_ranges_;  // [group][rank]
  std::vector<int> owner_;
  std::vector<std::uint8_t> owned_, readable_;
  std::vector<std::uint8_t> base_readable_;  // readable_ before add_readable (owned, elements)
  std::vector<std::pair<std::size_t, std::size_t>> runs_, readable_runs_;
  std::vector<std::int32_t> ghosts_;
  std::vector<std::int32_t> shared_;  // owned nodes that other ranks read (ascending)
  PetscSF ghost_sf_ = nullptr;   // leaves: this rank's ghosts; roots: the owners' entries
  PetscSF gather_sf_ = nullptr;  // leaves (root only): nodes the root does not own
  PetscSF all_sf_ = nullptr;     // leaves: every node this rank does not own (gather_to_all)
  void build_exchange();         // ghosts_, ghost_sf_, shared_, exchange_sf_ from readable_
  std::vector<std::int32_t> not_owned() const;  // the nodes another rank owns, ascending
  // The per-cycle exchange on packed buffers: leaf k is ghosts_[k], root k is shared_[k].
  PetscSF exchange_sf_ = nullptr;
  mutable std::vector<double> leaf_buf_, root_buf_;  // [6 * ghosts], [6 * shared]
  MPI_Datatype node3_ = MPI_DATATYPE_NULL, node6_ = MPI_DATATYPE_NULL;
};

}  // namespace ncfsim::fem

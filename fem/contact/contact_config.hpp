#pragma once
// Plain configuration of the deformable contacts (fem/contact/): one struct per contact
// definition, filled by the case-file layer, range-checked in one place (validate_*), then handed
// to PenaltyContact / TiedContact. Units SI. Parts are named by their index in Mesh::part_names;
// the mesh-dependent checks (part exists, holds hexahedra, parts not in two groups) happen in
// initialise(), before the first cycle. Every check throws InputError(source_file, key, message)
// naming the case-file key (key_path + ".<field>", e.g. "contact[0].pair[1].friction") or, for a
// config built in code (key_path empty), "contact.<name>.<field>". These are the only range checks
// of the [[contact]] keys: the case reader (fem/case) reads the values and leaves them to
// validate().
#include <cstdint>
#include <string>
#include <vector>

namespace ncfsim::fem {

/// A contact surface: the outer quadrilateral faces of the hexahedra of some parts (faces used by
/// exactly one hexahedron of these parts). All tows of a ply in one group give self-contact
/// between the tows (and within each tow).
struct ContactGroup {
  std::string name;        // used in resultant names ("first__second") and messages
  std::vector<int> parts;  // indices into Mesh::part_names; solid (hexahedral) parts
};

/// A pair of groups that may touch. first == second: self-contact of that group.
struct ContactPair {
  int first = 0;        // index into PenaltyContactConfig::groups; resultant is the force on it
  int second = 0;       // index into PenaltyContactConfig::groups
  double friction = 0;  // Coulomb coefficient mu, [0, 10] (0: frictionless)
};

/// Node-to-segment penalty contact between deformable surfaces with Coulomb friction.
/// Symmetric: every node of a group in a pair is checked against the other group's segments and
/// vice versa (self-contact: against the group's own segments, except those of elements holding
/// the node). Penalty: k = penalty_scale * m_s m_m / (m_s + m_m) / dt0^2 with m_s the slave node
/// mass, m_m the master mass interpolated at the contact point and dt0 the initial (safety-scaled)
/// stable step: it adds at most ~2 penalty_scale to (omega dt)^2, so the step is never lowered.
struct PenaltyContactConfig {
  std::string name = "contact";
  std::vector<ContactGroup> groups;
  std::vector<ContactPair> pairs;
  double penalty_scale = 0.1;  // (0, 0.5]: share of the nodal stability bound m / dt0^2
  double thickness = 0;        // m, >= 0: contact offset, surfaces touch at gap = thickness
  /// Viscous damping of the normal penalty spring, share of critical damping 2 sqrt(k m), [0, 1].
  /// It damps contact chatter and friction-excited vibration of the contact nodes; it never pulls
  /// surfaces together. Its work is reported with the friction dissipation.
  double damping = 0.1;
  /// m, >= 0; 0: automatic = thickness + 0.5 * smallest contact element thickness. Segments
  /// within this distance of a node (box test) become its candidates at a bucket sort; the sort
  /// is redone when 2 * (largest nodal displacement since the last sort) > search_margin -
  /// thickness, so no contact is ever missed between sorts.
  double search_margin = 0;
  /// Share of a segment's size a projection may fall outside the segment and still count
  /// (closes the dead zones at convex edges between segments), [0, 0.5].
  double edge_tolerance = 0.02;
  /// A node deeper than this share of the master element's thickness is taken as having come
  /// from the other side (a back face, or passed through) and gets no force, (0, 1].
  double max_penetration = 0.5;
  std::string source_file;  // for messages only (the case file), may be empty
  std::string key_path;     // for messages only: the case-file table ("contact[0]"), may be empty
};

/// Nodes of the slave surface tied to the nearest master segment at t = 0 (within
/// search_distance), held by a penalty spring (same k as PenaltyContactConfig) in the normal and
/// tangential directions. A tie fails when (sigma_n / normal_strength)^2 + (tau /
/// shear_strength)^2 >= 1, with sigma_n = tensile normal force / tributary area and tau = shear
/// force / tributary area of the slave node (a zero strength leaves that term out; both zero:
/// unbreakable). A failed tie carries no force from then on; the elastic energy it held is
/// reported as dissipated (friction_dissipation()). Add a PenaltyContact between the same groups
/// if failed surfaces must still push on each other.
/// A slave face tied to a master face (faces of hexahedra: mesh hexahedron index, face 0..5 in
/// kHex8Faces order), e.g. the resin bonds a transfer found between tows and plies.
struct TiedFacePair {
  std::int32_t slave_hex = 0, master_hex = 0;
  int slave_face = 0, master_face = 0;
};

/// With mode_i_energy > 0 a tie softens instead of failing abruptly: the bilinear mixed-mode
/// cohesive law of fem/contact/cohesive_law.hpp per slave node, with traction = force / the
/// node's tributary area, penalty K = k / area, initiation on the quadratic traction criterion of
/// normal_strength and shear_strength (both > 0), linear softening to a separation set by the
/// Benzeggagh-Kenane mixed-mode toughness; the energy dissipated by damage is reported with the
/// friction dissipation and a tie whose damage reaches 1 fails (carries no force).
struct TiedContactConfig {
  std::string name = "tie";
  ContactGroup slave;          // its surface nodes are tied
  ContactGroup master;         // to its surface segments
  double penalty_scale = 0.1;  // (0, 0.5]
  /// m, >= 0; 0: automatic = 0.1 * smallest master element thickness. Slave nodes farther than
  /// this from every master segment are not tied.
  double search_distance = 0;
  double normal_strength = 0;  // Pa, >= 0; 0: no failure in tension
  double shear_strength = 0;   // Pa, >= 0; 0: no failure in shear
  double mode_i_energy = 0;    // J/m^2, >= 0; > 0: cohesive softening (needs mode_ii_energy > 0)
  double mode_ii_energy = 0;   // J/m^2, >= 0
  double bk_exponent = 1.45;   // Benzeggagh-Kenane eta, [1, 5]
  /// Explicit face pairs (non-empty: slave and master groups are not used): each node of a slave
  /// face is tied to the nearest of the master faces paired with its faces.
  std::vector<TiedFacePair> face_pairs;
  /// Explicit slave nodes (LS-DYNA's TIED_NODES_TO_SURFACE; non-empty: in place of the slave
  /// group's surface nodes), each tied to the nearest segment of the master group's surface
  /// within search_distance (0 here: the thinnest master hexahedron's thickness), with no
  /// tributary area (the strengths give such a tie no limit), e.g. the cured stitch yarn's nodes
  /// to the tows it runs on. A node beside no segment stays untied (untied_nodes()).
  std::vector<std::int32_t> slave_nodes;
  std::string source_file;  // for messages only, may be empty
  std::string key_path;     // for messages only: the case-file table ("contact[1]"), may be empty
};

/// Range checks independent of the mesh; throw InputError naming the key, value and range.
void validate(const PenaltyContactConfig& c);
void validate(const TiedContactConfig& c);

}  // namespace ncfsim::fem

#include "drape/case/kinematic_case.hpp"

#include <cmath>

#include "drape/case/drape_case.hpp"
#include "fem/case/fem_case.hpp"
#include "fem/case/stage_kinds.hpp"
#include "fem/case/toml_reader.hpp"
#include "fem/errors.hpp"

namespace ncfsim::drape {

namespace {

using fem::TableReader;
using fem::V3;

constexpr double kPi = 3.14159265358979323846;

void read_net(const TableReader& n, KinematicDrapeCase& kc) {
  kc.net.pole = V3::from(n.vec3("pole"));
  kc.net.spacing = n.number("spacing", 2e-3, Range::open_closed(0.0, 0.1));
  const double reach = n.number("reach", Range::positive());
  const double half = std::ceil(reach / kc.net.spacing);
  if (half > 5000)
    n.fail("reach", "reach / spacing = " + std::to_string(half) +
                        " joints per generator side, allowed <= 5000 (a net of 10^8 joints)");
  kc.net.half_nodes = static_cast<int>(half);
  const auto angles = n.numbers("fibre_angles_deg", Range::closed(-180, 180), 2);
  if (angles.size() != 2)
    n.fail("fibre_angles_deg", "give two fibre angles (deg), e.g. [45.0, -45.0]");
  if (std::abs(std::sin((angles[0] - angles[1]) * kPi / 180)) < 0.05)
    n.fail("fibre_angles_deg", "the two fibre directions must not be (nearly) parallel");
  kc.fibre_angles_deg = {angles[0], angles[1]};
  // In the plane normal to the ring axis, from the zero direction (the wale).
  const V3 e1 =
      normalized(kc.ring.zero_direction - dot(kc.ring.zero_direction, kc.ring.axis) * kc.ring.axis);
  const V3 e2 = cross(kc.ring.axis, e1);
  auto dir = [&](double deg) {
    return std::cos(deg * kPi / 180) * e1 + std::sin(deg * kPi / 180) * e2;
  };
  kc.net.fibre1 = dir(angles[0]);
  kc.net.fibre2 = dir(angles[1]);
}

}  // namespace

KinematicDrapeCase load_kinematic_drape_case(const std::filesystem::path& file,
                                             const std::vector<std::string>& overrides) {
  fem::CaseDocument doc = fem::CaseDocument::load(file, overrides);
  const TableReader root(doc, doc.root(), "");
  KinematicDrapeCase kc;
  kc.file = file;
  kc.overrides = overrides;
  const auto header = fem::read_stage_case_header(root, fem::stage_kind::kKinematicDrape);
  kc.name = header.name;
  kc.description = header.description;
  const auto surfaces = root.tables("surface");
  if (surfaces.empty())
    root.fail("surface", "missing: give at least one [[surface]] (the tool at its final position)");
  for (const auto& s : surfaces) {
    fem::RigidSurface rs;
    fem::read_rigid_surface(s, rs);
    kc.surface.bodies.push_back(rs);
  }
  if (auto r = root.table("ring")) read_ring(*r, kc.ring);
  read_net(root.required_table("net"), kc);
  double gap = 0;
  V3 nrm;
  if (!kc.surface.gap_at(kc.net.pole, gap, nrm))
    root.fail("net.pole", "no [[surface]] answers at the pole");
  if (gap < 0)
    root.fail("net.pole", "lies inside a [[surface]] body (gap " + std::to_string(gap) +
                              " m): start the net outside the tool");
  // The pole is the net's highest point along the ring axis (the net lies on the tool below it):
  // a ring at or above it meets nothing.
  const double pole_height = dot(kc.net.pole - kc.ring.centre, kc.ring.axis);
  if (kc.ring.height >= pole_height)
    root.fail("ring.height", std::to_string(kc.ring.height) + " m is at or above the net's pole (" +
                                 std::to_string(pole_height) +
                                 " m along the ring axis from ring.centre): the ring would meet "
                                 "nothing; give a height below the pole");
  doc.check_unknown_keys();
  return kc;
}

}  // namespace ncfsim::drape

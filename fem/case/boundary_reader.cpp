// [boundary], [load], [damping], [initial], [time].
#include <algorithm>
#include <cmath>

#include "fem/case/fem_case.hpp"

namespace ncfsim::fem {

namespace {

std::array<bool, 3> read_dofs(const TableReader& t, std::string_view key,
                              std::array<bool, 3> fallback) {
  if (!t.has(key)) return fallback;
  std::array<bool, 3> d{false, false, false};
  for (const auto& s : t.strings(key)) {
    if (s != "x" && s != "y" && s != "z")
      t.fail(key, "'" + s + "' is not an axis; one of 'x', 'y', 'z'");
    d[static_cast<std::size_t>(s[0] - 'x')] = true;
  }
  return d;
}

// The name, nodes and dofs of a constraint set (FixedDofs, PrescribedVelocity).
template <class Set>
Set read_constraint_set(const CaseReadContext& ctx, const TableReader& t) {
  Set set;
  set.name = t.string("name");
  set.nodes = select_nodes(ctx, t, "nodes");
  set.dofs = read_dofs(t, "dofs", {true, true, true});
  return set;
}

void read_velocity(CaseReadContext& ctx, const TableReader& t) {
  auto pv = read_constraint_set<PrescribedVelocity>(ctx, t);
  pv.velocity = V3::from(t.vec3("velocity"));
  pv.ramp_time = t.number("ramp_time", 0.0, Range::non_negative());
  pv.start_time = t.number("start_time", 0.0, Range::non_negative());
  ctx.model.velocities.push_back(std::move(pv));
}

void read_picture_frame(CaseReadContext& ctx, const TableReader& t) {
  PictureFrame pf;
  pf.name = t.string("name");
  pf.nodes = select_nodes(ctx, t, "nodes");
  if (t.has("anchored_nodes")) {  // held as `nodes` too (a union): e.g. the stitch lines' ends
    std::vector<std::int32_t> more = select_nodes(ctx, t, "anchored_nodes");
    pf.nodes.insert(pf.nodes.end(), more.begin(), more.end());
    std::sort(pf.nodes.begin(), pf.nodes.end());
    pf.nodes.erase(std::unique(pf.nodes.begin(), pf.nodes.end()), pf.nodes.end());
  }
  pf.corner = V3::from(t.vec3("corner"));
  V3 a1 = V3::from(t.vec3_or("arm1", {1, 0, 0})), a2 = V3::from(t.vec3_or("arm2", {0, 1, 0}));
  if (!(norm(a1) > 0) || !(norm(a2) > 0)) t.fail("arm1", "arms must not be zero");
  a1 = normalized(a1), a2 = normalized(a2);
  if (std::abs(dot(a1, a2)) > 1e-6) t.fail("arm2", "must be orthogonal to arm1");
  pf.arm1 = a1, pf.arm2 = a2;
  pf.arm_length = t.number("arm_length", Range::positive());
  pf.ramp_time = t.number("ramp_time", 0.0, Range::non_negative());
  if (t.has("wall_nodes_arm1")) pf.walls[0] = select_nodes(ctx, t, "wall_nodes_arm1");
  if (t.has("wall_nodes_arm2")) pf.walls[1] = select_nodes(ctx, t, "wall_nodes_arm2");
  pf.wall_penalty_scale = t.number("wall_penalty_scale", 0.1, Range::open_closed(0, 1));
  ctx.frame_final_angles.push_back(t.number("final_shear_angle_deg", Range::open_closed(0, 80)) *
                                   M_PI / 180.0);
  ctx.frame_fabric_length.push_back(t.number("fabric_length", pf.arm_length, Range::positive()));
  ctx.model.picture_frames.push_back(std::move(pf));
}

}  // namespace

void read_boundary(CaseReadContext& ctx) {
  const auto bc = ctx.root.table("boundary");
  if (!bc) return;
  for (const auto& t : bc->tables("fixed"))
  {
    auto set = read_constraint_set<FixedDofs>(ctx, t);
    // Shell nodes' rotations (held by the shell groups); none unless named.
    set.rotations = read_dofs(t, "rotations", {false, false, false});
    ctx.model.fixed.push_back(std::move(set));
  }
  for (const auto& t : bc->tables("velocity")) read_velocity(ctx, t);
  for (const auto& t : bc->tables("picture_frame")) read_picture_frame(ctx, t);
}

void read_loads(CaseReadContext& ctx) {
  Model& model = ctx.model;
  if (auto ld = ctx.root.table("load")) {
    model.gravity = V3::from(ld->vec3_or("gravity", {0, 0, 0}));
    model.gravity_ramp_time = ld->number("gravity_ramp_time", 0.0, Range::non_negative());
    for (const auto& t : ld->tables("nodal_force")) {
      NodalLoad l;
      l.name = t.string("name");
      l.nodes = select_nodes(ctx, t, "nodes");
      l.force_per_node =
          (1.0 / static_cast<double>(l.nodes.size())) * V3::from(t.vec3("total_force"));
      l.ramp_time = t.number("ramp_time", 0.0, Range::non_negative());
      model.loads.push_back(std::move(l));
    }
  }
  if (auto d = ctx.root.table("damping")) {
    model.mass_damping = d->number("mass_proportional", 0.0, Range::non_negative());
    model.mass_damping_end_time = d->number("end_time", 0.0, Range::non_negative());
  }
  if (auto par = ctx.root.table("parallel")) {
    model.parallel.contact_halo = par->number("contact_halo", 0.01, Range::positive());
    model.parallel.contact_halo_refresh =
        par->number("contact_halo_refresh", 0.25, Range::closed(0.0, 0.5));
  }
  if (auto init = ctx.root.table("initial"))
    for (const auto& t : init->tables("velocity"))
      model.initial_velocities.push_back(
          {select_nodes(ctx, t, "nodes"), V3::from(t.vec3("velocity"))});
}

void read_time(CaseReadContext& ctx) {
  const TableReader tc = ctx.root.required_table("time");
  auto& time = ctx.model.time;
  time.end_time = tc.number("end_time", Range::positive());
  time.safety_factor = tc.number("safety_factor", 0.9, Range::open_closed(0, 1));
  time.mass_scaling_dt = tc.number("mass_scaling_dt", 0.0, Range::non_negative());
  time.mass_scaling_dynamic = tc.boolean("mass_scaling_dynamic", false);
  if (time.mass_scaling_dynamic && !(time.mass_scaling_dt > 0))
    tc.fail("mass_scaling_dynamic",
            "dynamic mass scaling needs its target step: set time.mass_scaling_dt > 0");
  time.mass_scaling_max_ratio =
      tc.number("mass_scaling_max_ratio", 10.0, Range::open_closed(0, 1e6));
  time.mass_scaling_erode_at_cap = tc.boolean("mass_scaling_erode_at_cap", false);
  if (time.mass_scaling_erode_at_cap && !time.mass_scaling_dynamic)
    tc.fail("mass_scaling_erode_at_cap",
            "erodes elements at the cap of dynamic mass scaling: set time.mass_scaling_dynamic = "
            "true");
  time.history_interval = tc.number("history_interval", time.end_time / 200, Range::positive());
  time.frame_interval = tc.number("frame_interval", time.end_time / 20, Range::positive());
  time.max_cycles = tc.integer("max_cycles", 0, 0, std::int64_t{1} << 50);
  time.energy_balance_limit = tc.number("energy_balance_limit", 0.05, Range::open_closed(0, 1));
  time.quasi_static_from =
      tc.number("quasi_static_from", 0.1 * time.end_time, Range{0, time.end_time, false, true});
  time.kinetic_to_internal_limit = tc.number("kinetic_to_internal_limit", 0.0, Range::non_negative());
  time.erosion_step_ratio = tc.number("erosion_step_ratio", 0.0, Range{0, 1, false, true});
  if (time.erosion_step_ratio > 0 && time.erosion_step_ratio <= time.min_step_ratio)
    tc.fail("erosion_step_ratio", "must be 0 (off) or above " +
                                      std::to_string(time.min_step_ratio) +
                                      ", the share of the initial step at which a run stops");
  for (std::size_t k = 0; k < ctx.model.picture_frames.size();
       ++k) {  // constant rate to the final angle at end_time
    auto& pf = ctx.model.picture_frames[k];
    if (!(time.end_time > pf.ramp_time))
      tc.fail("end_time", "must exceed the picture frame's ramp_time");
    pf.shear_rate = ctx.frame_final_angles[k] / (time.end_time - 0.5 * pf.ramp_time);
  }
}

}  // namespace ncfsim::fem

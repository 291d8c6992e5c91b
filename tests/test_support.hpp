#pragma once
// Shared helpers for the engine tests: one tolerance comparator and small model builders.
#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <memory>

#include "fem/model.hpp"
#include "fem/solver.hpp"

namespace ncfsim::test {

/// |a - b| <= rel * max(|a|, |b|) + abs
inline ::testing::AssertionResult near_rel(double a, double b, double rel, double abs = 0.0) {
  const double tol = rel * std::max(std::abs(a), std::abs(b)) + abs;
  if (std::abs(a - b) <= tol) return ::testing::AssertionSuccess();
  return ::testing::AssertionFailure() << a << " vs " << b << ": difference " << std::abs(a - b)
                                       << " > tolerance " << tol << " (rel " << rel << ")";
}

/// Nodes whose coordinate `axis` equals `value` within `tol`.
inline std::vector<std::int32_t> nodes_at(const fem::Mesh& m, int axis, double value,
                                          double tol = 1e-9) {
  std::vector<std::int32_t> out;
  for (std::size_t i = 0; i < m.n_nodes(); ++i)
    if (std::abs(m.coords[3 * i + axis] - value) <= tol)
      out.push_back(static_cast<std::int32_t>(i));
  return out;
}

inline std::vector<std::int32_t> nodes_where(
    const fem::Mesh& m, const std::function<bool(double, double, double)>& pred) {
  std::vector<std::int32_t> out;
  for (std::size_t i = 0; i < m.n_nodes(); ++i)
    if (pred(m.coords[3 * i], m.coords[3 * i + 1], m.coords[3 * i + 2]))
      out.push_back(static_cast<std::int32_t>(i));
  return out;
}

/// A model with one solid part made of a structured block, isotropic elastic.
inline void add_elastic_block(fem::Model& model, const std::string& part,
                              std::array<double, 3> origin, std::array<double, 3> size,
                              std::array<int, 3> div, double rho, double E, double nu) {
  const int p = model.mesh.add_part(part);
  fem::add_hex_block(model.mesh, p, origin, size, div);
  model.materials.push_back(std::make_unique<fem::ElasticIsotropic>(part + "_mat", rho, E, nu));
  if (static_cast<int>(model.parts.size()) <= p)
    model.parts.resize(static_cast<std::size_t>(p) + 1);
  model.parts[static_cast<std::size_t>(p)].material = static_cast<int>(model.materials.size()) - 1;
}

/// Two cubes of side h stacked along z (no hourglass viscosity): the base held, the middle plane
/// driven down at speed v, so the lower cube is crushed in uniaxial strain while the upper one
/// rides on it (test_erosion.cpp, test_mass_scaling.cpp). Returns the base nodes.
inline std::vector<std::int32_t> add_crushed_column(fem::Model& model, double h, double rho,
                                                    double E, double nu, double v) {
  add_elastic_block(model, "column", {0, 0, 0}, {h, h, 2 * h}, {1, 1, 2}, rho, E, nu);
  model.parts[0].hourglass_viscosity = 0.0;
  const auto base = nodes_at(model.mesh, 2, 0.0);
  model.fixed.push_back({"base", base, {true, true, true}});
  fem::PrescribedVelocity pv;
  pv.name = "crush";
  pv.nodes = nodes_at(model.mesh, 2, h);
  pv.dofs = {true, true, true};
  pv.velocity = {0, 0, -v};
  model.velocities.push_back(pv);
  return base;
}

/// A fixed rigid plane through `point` (normal `axis`, the body on its side) touching `nodes`.
inline fem::RigidTool& add_rigid_plane(fem::Model& model, const std::string& name, fem::V3 point,
                                       fem::V3 axis, std::vector<std::int32_t> nodes,
                                       double friction = 0.0) {
  fem::RigidTool plane;
  plane.name = name;
  plane.surface.shape = fem::ToolShape::Plane;
  plane.surface.point = point;
  plane.surface.axis = axis;
  plane.contact_nodes = std::move(nodes);
  plane.friction = friction;
  model.tools.push_back(std::move(plane));
  return model.tools.back();
}

/// Every node of the mesh.
inline std::vector<std::int32_t> all_nodes(const fem::Mesh& m) {
  std::vector<std::int32_t> out(m.n_nodes());
  for (std::size_t i = 0; i < out.size(); ++i) out[i] = static_cast<std::int32_t>(i);
  return out;
}

inline double node_coord(const fem::ExplicitSolver& s, std::int32_t node, int c) {
  auto X = s.x.view();
  return X[3 * static_cast<std::size_t>(node) + c];
}

}  // namespace ncfsim::test

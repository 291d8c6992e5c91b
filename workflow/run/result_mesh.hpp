#pragma once
// The one place where the run turns the solver's element blocks into the writers' plain data
// (and a stage hand-off back into a mesh): per element kind, in the solver's block order, so that
// cell fields map one to one.
#include "fem/io/result_writers.hpp"
#include "fem/io/stage_handoff.hpp"
#include "fem/mesh.hpp"
#include "fem/solver.hpp"

namespace ncfsim::workflow {

/// Output mesh: reference points, connectivity, parts and the stage hand-off ids (user ids,
/// material per element, fabric ply and tow) in the solver's block order.
fem::io::ResultMesh result_mesh(const fem::ExplicitSolver& s);

/// The frame at the solver's current state: displacement, velocity and the cell fields
/// (docs/output.md).
fem::io::Frame make_frame(const fem::ExplicitSolver& s);

/// A mesh rebuilt from a handed-off frame, in the file's element order, with the reference
/// (`deformed` false) or the frame's current coordinates; user ids, parts, ply and tow tags come
/// along (defaults where the file holds none).
fem::Mesh mesh_from_stage_frame(const fem::io::StageFrame& frame, bool deformed);

}  // namespace ncfsim::workflow

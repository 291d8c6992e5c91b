#pragma once
// impact's case reading (docs/case-file.md, "Crush"):
//  * the `tow_damage` material type (impact/tow_damage_material.hpp) for [[material]] tables;
//  * `[model]`: the impregnated model a transfer wrote (its results.h5 and ties.csv) as the mesh
//    of a `kind = "crush"` case, with `[model.damage]` (fracture energies, erosion modes) and
//    `[model.ties.interply]` / `[model.ties.intraply]` (cohesive resin bonds);
//  * `[crush]`: which tool is the punch and the CFC class of its filtered force;
//  * the crack-band check of every tow_damage element (the snap-back limit), once the model is
//    read.
// Every value is range-checked here and reported as InputError naming the file and the key.
#include <filesystem>
#include <string>
#include <vector>

#include "fem/case/case_context.hpp"
#include "fem/contact/contact_config.hpp"
#include "fem/material.hpp"
#include "impact/crack_band.hpp"
#include "impact/tow_damage_material.hpp"

namespace ncfsim::impact {

/// impact's material types: tow_damage.
void register_impact_case_types(fem::CaseTypeRegistry& registry);

/// One Vf class of an imported impregnated model: the transfer's constants.
struct ImpregnatedClass {
  std::string name;  // the transfer's material name, e.g. tow_vf_0.605
  double density = 0;
  fem::OrthotropicConstants elastic{};
  TowStrength strength;
  std::size_t n_elements = 0;
};

/// What [model] read from a transfer's output: the mesh went into the context's model; the
/// per-element classes, the classes' constants and the tied face pairs per interface wait for
/// assign_impregnated_parts.
struct ImpregnatedImport {
  std::filesystem::path source;             // the transfer's results.h5
  std::vector<std::int32_t> element_class;  // per hexahedron (mesh order)
  std::vector<ImpregnatedClass> classes;
  std::vector<std::string> interfaces;               // tie interface names (interply, intraply)
  std::vector<std::vector<fem::TiedFacePair>> ties;  // per interface
  /// Kept stitches (the transfer's bars): one tension-only linear law for the cured yarn.
  std::size_t n_stitches = 0;
  double stitch_axial_stiffness = 0;       // N (E A)
  double stitch_linear_density = 0;        // kg/m
  double stitch_capture = 0;               // m, how far from a tow face a stitch node may lie
  std::vector<std::int32_t> stitch_nodes;  // mesh nodes of the stitches (tied to the tow faces)
};

/// Whether the case has a [model] section (a crush of an imported model).
bool has_impregnated_model(const fem::CaseReadContext& ctx);
/// [model]: reads the transfer's results.h5 (its last frame) into ctx.model.mesh: nodes at the
/// formed shape (stress free), the tow hexahedra with their parts (the drape's plies), user ids,
/// ply and tow tags and material frames. Call in place of the [mesh] readers.
ImpregnatedImport read_impregnated_model(fem::CaseReadContext& ctx);
/// After fem::read_parts: one tow_damage material per Vf class ([model.damage] + the class's
/// constants), every element its class's material and its own frame, the plies' parts defined,
/// and the tied interfaces ([model.ties.*]) as cohesive tied contacts.
void assign_impregnated_parts(fem::CaseReadContext& ctx, const ImpregnatedImport& import);

/// The crack band of every tow_damage element (2 G E / X^2, snap-back): an element longer across
/// a crack of some mode is bad input (InputError naming the material's fracture-energy key, the
/// element, its length, the limit and the smallest fracture energy that would do), unless its
/// law raises the energy (crack_band = "raise"): then it is counted in what is returned.
CrackBandRaise check_crack_band(const fem::CaseReadContext& ctx);

/// [crush]: the punch (a tool of the case) and the CFC class of the filtered force.
struct CrushSpec {
  bool enabled = false;
  int punch = -1;    // index into Model::tools
  double cfc = 600;  // SAE J211 channel frequency class of the filtered punch force
  CrackBandRaise crack_band;  // what check_crack_band found (a crush's log, summary and report)
};
CrushSpec read_crush(const fem::CaseReadContext& ctx);

}  // namespace ncfsim::impact

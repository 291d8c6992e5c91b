#pragma once
// The fabric description: a multi-ply non-crimp fabric with stitching, defaults from
// docs/fabric-data.md (the paper's SAERTEX +-45 T700 NCF with representative values where the
// paper gives none). All lengths in m, masses in kg.
#include <string>
#include <vector>

namespace ncfsim::drape {

enum class StitchPattern { Tricot, Chain, None };

struct FabricSpec {
  std::vector<double> ply_angles_deg{45.0, -45.0};  // bottom ply first; fibre angle to x (machine direction)
  double tow_width = 3.22e-3;                // m
  double tow_gap = 0.10e-3;                  // m, between neighbouring tows of a ply
  double areal_weight = 0.241;               // kg/m^2 per ply
  double fibre_density = 1800.0;             // kg/m^3 (T700)
  double tow_fibre_volume_fraction = 0.6;    // (0, 0.9069]
  StitchPattern stitch = StitchPattern::Tricot;
  double stitch_direction_deg = 0;           // wale (machine) direction to x; ply angles are to x too
  double stitch_gauge = 0;                   // m between wales (across x); 0: tow pitch * sqrt(2)
  double stitch_length = 0;                  // m between penetrations along a wale; 0: as the gauge
  // m: penetrations closer to the blanket's edge are left out; < 0: half a lattice cell (its
  // projection on x and y), which keeps every stitch inside a blanket; a small margin keeps the
  // stitch density of the fabric in a small cell (picture frame)
  double stitch_edge_margin = -1;
  // Mesh resolution of a tow.
  int elements_across_tow = 2;
  int elements_through_thickness = 1;
  double element_length = 0;                 // m along the tow; 0: tow pitch

  double tow_pitch() const { return tow_width + tow_gap; }
  /// Tow (and ply) thickness from the areal weight: t = AW / (rho_f Vf w/p).
  double tow_thickness() const;
  /// Dry tow density rho_f Vf.
  double gauge() const;
  double penetration_spacing() const;
};

/// Throws InputError(file, key, ...) for the first inconsistent value; `prefix` is the case-file
/// table the keys live in (e.g. "fabric").
void validate(const FabricSpec& f, const std::string& file, const std::string& prefix);

}  // namespace ncfsim::drape

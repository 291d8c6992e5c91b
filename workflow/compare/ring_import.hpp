#pragma once
// A macro drape result computed elsewhere, read onto the ring of the paper's Fig. 18 measure
// (drape/ring_measure.hpp: the circle at a height above the reference plane, sampled every
// step_deg from the wale direction): `ncfsim compare` puts it beside the meso, macro and kinematic
// rings. docs/output.md, "Comparison outputs"; docs/cli.md, `ncfsim compare`.
//
// Two ways onto the ring, chosen by what the file holds:
// * a surface (a .vtu with 2D cells, or 3D cells whose outer faces are taken): the ring's own
//   ray-triangle measure, drape::ring_shear, on its triangles (quadrilaterals split n0 n1 n2 /
//   n0 n2 n3 as the meso measure splits the faces of its hexahedra); a cell field is first
//   averaged to the points over the cells with a finite value (drape::element_to_node_mean's
//   rule; line cells take no part), and only those cells make the surface;
// * a point cloud (a CSV, a .vtu without 2D/3D cells): for each azimuth the points within
//   `tolerance` of the ray, of the sheet nearest the axis (distance along the ray within
//   `tolerance` of the nearest), give the value at the ray by a weighted linear least-squares fit
//   in the two directions across the ray (weights (1 - (d/tol)^2)^2, d the distance to the ray);
//   with fewer than three points spread across the ray, their weighted mean; the fit is kept
//   within the values of the points it used (no extrapolation).
#include <filesystem>
#include <string>
#include <vector>

#include "drape/ring_measure.hpp"
#include "fem/vec3.hpp"

namespace ncfsim::workflow {

struct RingImportOptions {
  drape::RingSpec ring;
  std::string field;        // shear field / column name; empty: the first of kShearNames found
  double tolerance = 0;     // m, point-cloud search radius about each ray; 0: 1.5 x the median
                            // nearest-neighbour spacing of the cloud, at most 10 mm
  double length_scale = 1;  // the files' coordinates times this are metres (1e-3: in mm)
};

/// Shear field / column names tried in order (case-insensitive) when none is given.
inline const std::vector<std::string> kShearNames{"shear_angle_deg", "shear_deg", "shear_angle",
                                                  "shear"};
/// Fibre-direction pairs (3 components each) a .vtu may give instead of a shear field:
/// shear = 90 deg - the angle between the fibre lines (drape::shear_angle_deg).
inline const std::vector<std::pair<std::string, std::string>> kFibrePairs{
    {"fibre_direction_1", "fibre_direction_2"},
    {"fiber_direction_1", "fiber_direction_2"},
    {"fibre1", "fibre2"}};
/// CSV coordinate columns accepted (case-insensitive), SI: metres.
inline const std::vector<std::string> kCsvX{"x", "x_m"}, kCsvY{"y", "y_m"}, kCsvZ{"z", "z_m"};

struct ImportedRing {
  std::vector<drape::RingSample> ring;
  std::string method;         // "surface" | "points"
  std::string field;          // the field / column read (or "fibre_direction_1/2")
  std::string location;       // "point" | "cell" | "column"
  std::size_t points = 0;     // points read
  std::size_t triangles = 0;  // surface method: triangles of the surface
  double tolerance = 0;       // points method: the search radius used, m
};

/// Reads a .vtu or .csv (by extension) onto the ring. Bad input (unreadable file, missing columns
/// or field, no finite value, no azimuth that meets the data): ncfsim::InputError naming the file
/// and why (exit code 2).
ImportedRing import_ring(const std::filesystem::path& file, const RingImportOptions& opt);

/// The point-cloud mapping above, on plain data (values NaN are skipped); tolerance > 0.
std::vector<drape::RingSample> ring_from_points(const std::vector<fem::V3>& points,
                                                const std::vector<double>& values,
                                                const drape::RingSpec& ring, double tolerance);

/// Median distance from a point to its nearest other point (a sample of up to 4000 points of a
/// deterministic stride); 0 for fewer than two distinct points.
double median_spacing(const std::vector<fem::V3>& points);

}  // namespace ncfsim::workflow

#include "transfer/case/transfer_case.hpp"

#include <fstream>
#include <nlohmann/json.hpp>

#include "fem/case/fem_case.hpp"
#include "fem/case/source_result.hpp"
#include "fem/case/stage_kinds.hpp"
#include "fem/case/toml_reader.hpp"
#include "fem/errors.hpp"

namespace ncfsim::transfer {

namespace {

using fem::TableReader;

void read_fibre(const TableReader& t, FibreData& f) {
  f.E1 = t.number("E1", f.E1, Range::positive());
  f.E2 = t.number("E2", f.E2, Range::positive());
  f.G12 = t.number("G12", f.G12, Range::positive());
  f.G23 = t.number("G23", f.G23, Range::positive());
  f.nu12 = t.number("nu12", f.nu12, Range::open(-1.0, 0.5));
  f.tensile_strength = t.number("tensile_strength", f.tensile_strength, Range::positive());
  f.density = t.number("density", f.density, Range::positive());
}

void read_resin(const TableReader& t, ResinData& r) {
  r.E = t.number("E", r.E, Range::positive());
  r.nu = t.number("nu", r.nu, Range::open(-1.0, 0.5));
  r.tensile_strength = t.number("tensile_strength", r.tensile_strength, Range::positive());
  r.shear_strength = t.number("shear_strength", r.shear_strength, Range::positive());
  r.density = t.number("density", r.density, Range::positive());
}

// A drape result is usable once its run completed, and only a drape's: summary.json beside it
// (the run's own record) says which stage wrote it and how it ended.
void check_source(const TableReader& s, const std::filesystem::path& h5) {
  if (!std::filesystem::is_regular_file(h5))
    s.fail("results", "no such drape result: " + h5.string() + " (run the drape case first)");
  fem::require_result_of(s, "results", h5, {fem::stage_kind::kEngine},
                         "a transfer needs the results.h5 of a meso drape run");
}

}  // namespace

TransferCase load_transfer_case(const std::filesystem::path& file,
                                const std::vector<std::string>& overrides) {
  fem::CaseDocument doc = fem::CaseDocument::load(file, overrides);
  const TableReader root(doc, doc.root(), "");
  TransferCase tc;
  tc.file = file;
  tc.overrides = overrides;
  const auto header = fem::read_stage_case_header(root, fem::stage_kind::kTransfer);
  tc.name = header.name;
  tc.description = header.description;

  const TableReader s = root.required_table("source");
  tc.results = s.string("results");
  if (tc.results.is_relative()) tc.results = file.parent_path() / tc.results;
  tc.frame = static_cast<long>(s.integer("frame", -1, -1, 1 << 30));
  if (s.has("parts")) tc.parts = s.strings("parts");

  auto& spec = tc.spec;
  if (auto f = root.table("fibre")) read_fibre(*f, spec.fibre);
  if (auto r = root.table("resin")) read_resin(*r, spec.resin);
  if (auto im = root.table("impregnation")) {
    spec.mapping.vf_undeformed = im->number("vf_undeformed", spec.mapping.vf_undeformed,
                                            Range::open_closed(0, kMaxFibreVolumeFraction));
    spec.mapping.vf_locking =
        im->number("vf_locking", spec.mapping.vf_locking,
                   Range::closed(spec.mapping.vf_undeformed, kMaxFibreVolumeFraction));
    spec.mapping.vf_bin = im->number("vf_bin", spec.mapping.vf_bin, Range::open_closed(0, 0.1));
    spec.compressive_ratio =
        im->number("compressive_ratio", spec.compressive_ratio, Range::open_closed(0, 1.5));
    spec.min_corner_jacobian =
        im->number("min_corner_jacobian", spec.min_corner_jacobian, Range::closed(0, 0.5));
  }
  if (auto t = root.table("trim")) {
    spec.trim.radius = t->number("radius", 0.0, Range::non_negative());
    spec.trim.centre = fem::V3::from(t->vec3_or("centre", {0, 0, 0}));
    spec.trim.axis = fem::read_unit_vector(*t, "axis", {0, 0, 1});
  }
  spec.ties.normal_strength = spec.resin.tensile_strength;
  spec.ties.shear_strength = spec.resin.shear_strength;
  if (auto t = root.table("ties")) {
    spec.ties.interply = t->boolean("interply", true);
    spec.ties.intraply = t->boolean("intraply", true);
    spec.ties.distance = t->number("distance", 0.0, Range::non_negative());
    spec.ties.normal_strength =
        t->number("normal_strength", spec.ties.normal_strength, Range::positive());
    spec.ties.shear_strength =
        t->number("shear_strength", spec.ties.shear_strength, Range::positive());
  }
  if (auto t = root.table("stitches")) {
    auto& st = spec.stitches;
    st.keep = t->boolean("keep", false);
    st.capture_distance = t->number("capture_distance", 0.0, Range::non_negative());
    st.modulus = t->number("modulus", st.modulus, Range::positive());
    st.linear_density = t->number("linear_density", st.linear_density, Range::positive());
    st.density = t->number("density", st.density, Range::positive());
  }
  if (auto o = root.table("output")) {
    tc.frames_xdmf = o->choice("frames", {"xdmf", "none"}, "xdmf") == "xdmf";
    tc.figures = o->boolean("figures", true);
  }
  doc.check_unknown_keys();
  check_source(s, tc.results);
  return tc;
}

}  // namespace ncfsim::transfer

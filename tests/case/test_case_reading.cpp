// Case reading per module: the registry dispatches a [[material]] type to the reader its module
// registered; an unknown type's error names the file, the key and the allowed types; a key's range
// is checked once, under the key's own name (the contact pair friction, [0, 10]).
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>

#include "fem/case/case_context.hpp"
#include "fem/case/fem_case.hpp"
#include "fem/errors.hpp"
#include "workflow/case/engine_case.hpp"

namespace fs = std::filesystem;
using namespace ncfsim;

namespace {

fs::path write_case(const std::string& name, const std::string& text) {
  const fs::path dir = fs::temp_directory_path() / "ncfsim_test_case_reading";
  fs::create_directories(dir);
  const fs::path file = dir / (name + ".toml");
  std::ofstream(file) << text;
  return file;
}

std::size_t count(const std::string& text, const std::string& what) {
  std::size_t n = 0;
  for (auto p = text.find(what); p != std::string::npos; p = text.find(what, p + 1)) ++n;
  return n;
}

const char* kMaterial = R"(
[[material]]
name = "m"
type = "%TYPE%"
density = 1000.0
youngs_modulus = 1e9
poisson_ratio = 0.3
)";

std::string material_case(const std::string& type) {
  std::string s = kMaterial;
  s.replace(s.find("%TYPE%"), 6, type);
  return s;
}

// Two blocks in a penalty contact; `pair` is the body of its [[contact.pair]].
std::string contact_case(const std::string& pair) {
  return R"(
[case]
name = "two_blocks"
[mesh]
[[mesh.block]]
part = "lower"
size = [0.01, 0.01, 0.01]
divisions = [1, 1, 1]
[[mesh.block]]
part = "upper"
origin = [0.0, 0.0, 0.01]
size = [0.01, 0.01, 0.01]
divisions = [1, 1, 1]
[[material]]
name = "steel"
type = "elastic_isotropic"
density = 7800.0
youngs_modulus = 2e11
poisson_ratio = 0.3
[[part]]
name = "lower"
material = "steel"
[[part]]
name = "upper"
material = "steel"
[[contact]]
name = "blocks"
[[contact.group]]
name = "a"
parts = ["lower"]
[[contact.group]]
name = "b"
parts = ["upper"]
[[contact.pair]]
groups = ["a", "b"]
)" + pair +
         R"(
[time]
end_time = 1e-4
)";
}

}  // namespace

TEST(CaseTypeRegistry, DispatchesAMaterialTypeToItsReader) {
  fem::CaseTypeRegistry registry;
  fem::register_fem_case_types(registry);
  int calls = 0;
  double density_seen = 0;
  registry.add_material_type("test_law",
                             [&](const fem::TableReader& t, const std::string& name, double rho) {
                               ++calls;
                               density_seen = rho;
                               return std::make_unique<fem::ElasticIsotropic>(
                                   name, rho, t.number("youngs_modulus", Range::positive()),
                                   t.number("poisson_ratio", Range{}));
                             });
  EXPECT_EQ(registry.material_types(),
            (std::vector<std::string>{"elastic_isotropic", "elastic_orthotropic", "test_law"}));
  EXPECT_THROW(registry.add_material_type("test_law", {}), std::logic_error);

  fem::CaseDocument doc =
      fem::CaseDocument::load(write_case("dispatch", material_case("test_law")), {});
  const fem::TableReader root(doc, doc.root(), "");
  const auto material = registry.read_material(root.tables("material").at(0), "m");
  EXPECT_EQ(calls, 1);
  EXPECT_EQ(density_seen, 1000.0);
  ASSERT_NE(material, nullptr);
  EXPECT_EQ(material->density(), 1000.0);
}

TEST(CaseTypeRegistry, EngineCasesKnowDrapesAndImpactsTowLaws) {
  const auto types = workflow::engine_case_types().material_types();
  EXPECT_EQ(types, (std::vector<std::string>{"elastic_isotropic", "elastic_orthotropic",
                                             "tow_biphase", "tow_damage"}));
}

TEST(CaseTypeRegistry, UnknownTypeNamesFileKeyAndTheAllowedTypes) {
  const fs::path file = write_case("unknown_type", material_case("rubber"));
  fem::CaseDocument doc = fem::CaseDocument::load(file, {});
  const fem::TableReader root(doc, doc.root(), "");
  try {
    workflow::engine_case_types().read_material(root.tables("material").at(0), "m");
    FAIL() << "no error for an unknown material type";
  } catch (const InputError& e) {
    EXPECT_EQ(e.file(), file.string());
    EXPECT_EQ(e.key(), "material[0].type");
    EXPECT_EQ(e.value(), "rubber");
    EXPECT_EQ(e.allowed(),
              "'elastic_isotropic', 'elastic_orthotropic', 'tow_biphase', 'tow_damage'");
    const std::string what = e.what();
    EXPECT_NE(what.find(file.string()), std::string::npos) << what;
    EXPECT_NE(what.find("'material[0].type'"), std::string::npos) << what;
    EXPECT_NE(what.find("'tow_biphase'"), std::string::npos) << what;
  }
}

TEST(CaseReading, ContactFrictionOutOfRangeNamesItsKeyOnce) {
  EXPECT_NO_THROW(
      workflow::load_engine_case(write_case("mu_ok", contact_case("friction = 10.0")), {}));
  for (const char* bad : {"friction = 10.5", "friction = -0.1"}) {
    const fs::path file = write_case("mu_bad", contact_case(bad));
    try {
      workflow::load_engine_case(file, {});
      ADD_FAILURE() << "no error for " << bad;
    } catch (const InputError& e) {
      const std::string what = e.what();
      EXPECT_EQ(e.file(), file.string());
      EXPECT_EQ(e.key(), "contact[0].pair[0].friction") << what;
      EXPECT_EQ(e.allowed(), "[0, 10]") << what;
      EXPECT_EQ(count(what, "friction"), 1u) << what;
      EXPECT_EQ(count(what, "out of range"), 1u) << what;
    }
  }
}

TEST(CaseReading, ReadsAreIndependent) {
  // Nothing is kept from one case to the next (the tow-end pins live in the reading context).
  const auto a =
      workflow::load_engine_case(write_case("independent", contact_case("friction = 0.2")), {});
  const auto b =
      workflow::load_engine_case(write_case("independent", contact_case("friction = 0.2")), {});
  EXPECT_EQ(a.model.mesh.coords, b.model.mesh.coords);
  EXPECT_EQ(a.model.contacts.size(), 1u);
  EXPECT_EQ(b.model.contacts.size(), 1u);
}

// A blankholder given by its pressure presses with the pressure over the blank area it covers:
// the 240 mm square blank of the hemisphere case less the 99 mm hole, 3.35 kPa.
TEST(CaseReading, BlankholderPressureGivesTheForceOverTheCoveredArea) {
  const std::filesystem::path file =
      std::filesystem::path(NCFSIM_SOURCE_DIR) / "cases/hemisphere/drape.toml";
  const std::vector<std::string> ci{
      "mesh.fabric[0].elements_across_tow=1", "mesh.fabric[0].element_length=6.64e-3",
      "mesh.fabric[0].size=[0.24,0.24]", "mesh.fabric[0].origin=[-0.12,-0.12,0.0]"};
  const auto ec = workflow::load_engine_case(file, ci);
  const auto& bh = ec.model.tools.at(1);
  ASSERT_EQ(bh.name, "blankholder");
  const double area = 0.24 * 0.24 - M_PI * 0.100 * 0.100;  // the 100 mm blankholder hole
  EXPECT_NEAR(bh.motion.pressed_area, area, 1e-9 * area);
  EXPECT_NEAR(bh.motion.force, 3350.0 * area, 1e-9 * 3350.0 * area);
  auto expect_key = [&](std::vector<std::string> extra, const std::string& key) {
    auto o = ci;
    o.insert(o.end(), extra.begin(), extra.end());
    try {
      workflow::load_engine_case(file, o);
      ADD_FAILURE() << "accepted: " << extra[0];
    } catch (const InputError& e) {
      EXPECT_EQ(e.key(), key) << e.what();
    }
  };
  expect_key({"tool[1].pressure=0.0"}, "tool[1].pressure");
  expect_key({"tool[1].force=10.0"}, "tool[1].pressure");  // both given
  expect_key({"mesh.fabric[0].size=[0.15,0.15]", "mesh.fabric[0].origin=[-0.075,-0.075,0.0]"},
             "tool[1].radius");
}

// A variant case ([case] base, set): the base with the listed changes and the variant's name; a
// variant with tables of its own, a set entry without '=', a missing base: bad input naming the key.
TEST(CaseReading, VariantCaseIsItsBaseWithItsChanges) {
  write_case("variant_base", "[case]\nname = \"base\"\ndescription = \"the base\"\n[mesh]\nresolution = \"default\"\n"
                             "[time]\nend_time = 0.01\nsafety_factor = 0.9\n");
  const fs::path variant = write_case(
      "variant", "[case]\nbase = \"variant_base.toml\"\nname = \"variant\"\n"
                 "set = [\"time.end_time = 0.02\", \"mesh.resolution='coarse'\"]\n");
  const auto doc = fem::CaseDocument::load(variant, {"time.safety_factor=0.5"});
  const auto& root = doc.root();
  EXPECT_EQ(root["case"]["name"].value<std::string>(), "variant");
  EXPECT_EQ(root["case"]["description"].value<std::string>(), "the base");
  EXPECT_FALSE(root["case"]["base"]);
  EXPECT_DOUBLE_EQ(root["time"]["end_time"].value<double>().value(), 0.02);
  EXPECT_DOUBLE_EQ(root["time"]["safety_factor"].value<double>().value(), 0.5);  // the command line last
  EXPECT_EQ(root["mesh"]["resolution"].value<std::string>(), "coarse");

  auto key_of_error = [](const fs::path& f) -> std::string {
    try {
      (void)fem::CaseDocument::load(f, {});
    } catch (const InputError& e) {
      return e.key();
    }
    return "(no error)";
  };
  EXPECT_EQ(key_of_error(write_case("variant_table", "[case]\nbase = \"variant_base.toml\"\n[time]\nend_time = 1.0\n")),
            "time");
  EXPECT_EQ(key_of_error(write_case("variant_noeq", "[case]\nbase = \"variant_base.toml\"\nset = [\"time.end_time\"]\n")),
            "time.end_time");
  EXPECT_EQ(key_of_error(write_case("variant_missing", "[case]\nbase = \"nowhere.toml\"\n")), "case.base");
  EXPECT_EQ(key_of_error(write_case("variant_loop", "[case]\nbase = \"variant_loop.toml\"\n")), "case.base");

  // A variant's own include adds sections to its base (another fabric), before its set, which may
  // change what it included; a key the base gives too is bad input naming it.
  write_case("variant_extra", "[fabric.other]\ntow_gap = 1e-4\n[[material]]\nname = \"other_tow\"\n");
  const auto with_inc = fem::CaseDocument::load(
      write_case("variant_inc", "include = [\"variant_extra.toml\"]\n[case]\nbase = \"variant_base.toml\"\n"
                                "set = [\"fabric.other.tow_gap = 2e-4\"]\n"),
      {});
  EXPECT_DOUBLE_EQ(with_inc.root()["fabric"]["other"]["tow_gap"].value<double>().value(), 2e-4);
  EXPECT_EQ(with_inc.root()["material"][0]["name"].value<std::string>(), "other_tow");
  EXPECT_DOUBLE_EQ(with_inc.root()["time"]["end_time"].value<double>().value(), 0.01);  // the base's
  write_case("variant_clash", "[time]\nend_time = 0.5\n");
  EXPECT_EQ(key_of_error(write_case("variant_inc_clash",
                                    "include = \"variant_clash.toml\"\n[case]\nbase = \"variant_base.toml\"\n")),
            "time.end_time");
}

// time.quasi_static_from lies in [0, end_time): 0 (the whole run) is allowed, end_time is not.
TEST(CaseReading, QuasiStaticWindowStartsInsideTheRun) {
  const std::filesystem::path file =
      std::filesystem::path(NCFSIM_SOURCE_DIR) / "cases/verification/cantilever.toml";
  EXPECT_EQ(workflow::load_engine_case(file, {"time.quasi_static_from=0.0"}).model.time.quasi_static_from, 0.0);
  try {
    workflow::load_engine_case(file, {"time.end_time=0.04", "time.quasi_static_from=0.04"});
    ADD_FAILURE() << "a window starting at the end was accepted";
  } catch (const InputError& e) {
    EXPECT_EQ(e.key(), "time.quasi_static_from") << e.what();
  }
}

// Dynamic mass scaling's keys (issue #41): each bad value names its own key and what is allowed.
TEST(CaseReading, MassScalingKeysNameTheirRangeAndWhatTheyNeed) {
  const std::filesystem::path file =
      std::filesystem::path(NCFSIM_SOURCE_DIR) / "cases/verification/cantilever.toml";
  const auto refused = [&](const std::vector<std::string>& sets, const std::string& key,
                           const std::string& says) {
    try {
      workflow::load_engine_case(file, sets);
      ADD_FAILURE() << key << ": accepted";
    } catch (const InputError& e) {
      EXPECT_EQ(e.key(), key) << e.what();
      EXPECT_NE(std::string(e.what()).find(says), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find("cantilever.toml"), std::string::npos) << e.what();
    }
  };
  refused({"time.mass_scaling_dynamic=true"}, "time.mass_scaling_dynamic", "mass_scaling_dt > 0");
  refused({"time.mass_scaling_dt=1e-6", "time.mass_scaling_dynamic=true",
           "time.mass_scaling_max_ratio=0"},
          "time.mass_scaling_max_ratio", "1e+06");
  refused({"time.mass_scaling_dt=1e-6", "time.mass_scaling_dynamic=true",
           "time.mass_scaling_max_ratio=2e6"},
          "time.mass_scaling_max_ratio", "1e+06");
  refused({"time.mass_scaling_erode_at_cap=true"}, "time.mass_scaling_erode_at_cap",
          "mass_scaling_dynamic = true");
  const auto ok = workflow::load_engine_case(
      file, {"time.mass_scaling_dt=1e-6", "time.mass_scaling_dynamic=true",
             "time.mass_scaling_max_ratio=3", "time.mass_scaling_erode_at_cap=true"});
  EXPECT_EQ(ok.model.time.mass_scaling_max_ratio, 3.0);
  EXPECT_TRUE(ok.model.time.mass_scaling_erode_at_cap);
}

// `case.laws` (a calibration's laws.toml handed on by a workflow): each of its named [[material]],
// [[bar_law]] and [[membrane_law]] tables replaces the case's table of that name whole, the other
// tables stay; a law the case lacks, a table without a name or another section is bad input naming
// the laws file and the key.
TEST(CaseReading, LawsFileReplacesTheCasesLawsOfTheSameName) {
  write_case("laws_ok", "[[material]]\nname = \"dry_tow\"\ntype = \"elastic\"\nE = 2.0e9\n");
  const fs::path c =
      write_case("laws_case",
                 "[case]\nname = \"laws\"\nlaws = \"laws_ok.toml\"\n"
                 "[[material]]\nname = \"other\"\ntype = \"elastic\"\nE = 1.0\n"
                 "[[material]]\nname = \"dry_tow\"\ntype = \"elastic\"\nE = 1.0e9\nnu = 0.3\n");
  auto doc = fem::CaseDocument::load(c, {});
  doc.apply_laws_files();
  const auto& m = *doc.root()["material"].as_array();
  ASSERT_EQ(m.size(), 2u);
  EXPECT_DOUBLE_EQ((*m.get(0)->as_table())["E"].value<double>().value(), 1.0);  // untouched
  EXPECT_DOUBLE_EQ((*m.get(1)->as_table())["E"].value<double>().value(), 2.0e9);
  EXPECT_FALSE((*m.get(1)->as_table())["nu"]) << "the table is replaced whole, not merged";

  // None given: an empty list (what a workflow's input key replaces) changes nothing.
  auto none = fem::CaseDocument::load(c, {"case.laws=[]"});
  none.apply_laws_files();
  EXPECT_DOUBLE_EQ(
      (*(*none.root()["material"].as_array()).get(1)->as_table())["E"].value<double>().value(),
      1.0e9);

  const auto error_of = [&](const std::string& laws_text) -> std::pair<std::string, std::string> {
    const fs::path f = write_case("laws_bad", laws_text);
    auto d = fem::CaseDocument::load(c, {"case.laws='laws_bad.toml'"});
    try {
      d.apply_laws_files();
    } catch (const InputError& e) {
      return {e.file(), e.key()};
    }
    return {"", "(no error)"};
  };
  const std::string bad =
      (fs::temp_directory_path() / "ncfsim_test_case_reading/laws_bad.toml").string();
  EXPECT_EQ(error_of("[[material]]\nname = \"missing\"\nE = 1.0\n"),
            std::make_pair(bad, std::string("material[0].name")));
  EXPECT_EQ(error_of("[[bar_law]]\ntype = \"tabulated\"\n"),
            std::make_pair(bad, std::string("bar_law[0].name")));
  EXPECT_EQ(error_of("[time]\nend_time = 1.0\n"), std::make_pair(bad, std::string("time")));
  auto nofile = fem::CaseDocument::load(c, {"case.laws='nowhere.toml'"});
  try {
    nofile.apply_laws_files();
    ADD_FAILURE() << "a missing laws file must be bad input";
  } catch (const InputError& e) {
    EXPECT_EQ(e.key(), "case.laws");
  }
}

// `seat_clearance`: a plane tool is moved along its normal until the nearest of its contact nodes
// is that far (plus its thickness) on the side its axis points to, wherever its point put it
// (inside the part or far from it); a curved tool is refused.
TEST(CaseReading, SeatedPlaneSitsItsClearanceFromTheNearestNode) {
  const auto with_tool = [](const std::string& tool) {
    std::string c = contact_case("friction = 0.1\n");
    return c + tool;
  };
  for (const double z0 : {0.005, -0.3}) {  // inside the lower block; far below it
    const fs::path f = write_case(
        "seated",
        with_tool("[[tool]]\nname = \"support\"\nshape = \"plane\"\npoint = [0.002, 0.0, " +
                  std::to_string(z0) +
                  "]\naxis = [0.0, 0.0, 1.0]\nseat_clearance = 2.0e-4\nthickness = 1.0e-4\n"));
    const auto ec = workflow::load_engine_case(f, {});
    ASSERT_EQ(ec.model.tools.size(), 1u);
    const auto& s = ec.model.tools[0].surface;
    EXPECT_NEAR(s.point.z, 0.0 - 1.0e-4 - 2.0e-4, 1e-12) << z0;  // the lowest nodes lie at z = 0
    EXPECT_DOUBLE_EQ(s.point.x, 0.002);
  }
  const fs::path bad = write_case(
      "seated_sphere",
      with_tool("[[tool]]\nname = \"ball\"\nshape = \"sphere\"\npoint = [0.0, 0.0, 0.1]\n"
                "radius = 0.01\nseat_clearance = 1.0e-4\n"));
  try {
    (void)workflow::load_engine_case(bad, {});
    ADD_FAILURE() << "a seated sphere must be refused";
  } catch (const InputError& e) {
    EXPECT_EQ(e.key(), "tool[0].seat_clearance");
  }
}

// A tool's speed curve: both arrays or neither, as many of each, times strictly increasing;
// each fault names its key.
TEST(CaseReading, ToolVelocityCurveNamesItsKeyWhenIllFormed) {
  const auto key_of = [](const std::string& curve) -> std::string {
    const fs::path f = write_case(
        "curve", contact_case("friction = 0.1\n") +
                     "[[tool]]\nname = \"punch\"\nshape = \"plane\"\npoint = [0.0, 0.0, -0.01]\n"
                     "motion = \"velocity\"\nvelocity = [0.0, 0.0, 1.0]\n" +
                     curve);
    try {
      const auto ec = workflow::load_engine_case(f, {});
      return ec.model.tools.at(0).motion.curve_time.size() == 3 ? "(read)" : "(not read)";
    } catch (const InputError& e) {
      return e.key();
    }
  };
  EXPECT_EQ(key_of("velocity_curve_time = [0.0, 0.01, 0.02]\n"
                   "velocity_curve_scale = [0.3, 0.3, 1.0]\n"),
            "(read)");
  EXPECT_EQ(key_of("velocity_curve_time = [0.0, 0.01]\n"), "tool[0].velocity_curve_time");
  EXPECT_EQ(key_of("velocity_curve_scale = [0.3, 1.0]\n"), "tool[0].velocity_curve_scale");
  EXPECT_EQ(key_of("velocity_curve_time = [0.0, 0.01, 0.02]\nvelocity_curve_scale = [0.3, 1.0]\n"),
            "tool[0].velocity_curve_scale");
  EXPECT_EQ(key_of("velocity_curve_time = [0.0, 0.02, 0.01]\n"
                   "velocity_curve_scale = [0.3, 0.3, 1.0]\n"),
            "tool[0].velocity_curve_time");
  EXPECT_EQ(key_of("velocity_curve_time = [0.0, 0.01, 0.02]\n"
                   "velocity_curve_scale = [0.3, -0.3, 1.0]\n"),
            "tool[0].velocity_curve_scale");
}

// [[output.target]]: exactly one of target and target_quantity, at most one tolerance; a bad one
// names its key.
TEST(CaseReading, OutputTargetNamesItsKeyWhenIllFormed) {
  const auto key_of = [](const std::string& target) -> std::string {
    const fs::path f =
        write_case("target", contact_case("friction = 0.1\n") + "[[output.target]]\n" + target);
    try {
      (void)workflow::load_engine_case(f, {});
    } catch (const InputError& e) {
      return e.key();
    }
    return "(no error)";
  };
  EXPECT_EQ(key_of("quantity = \"x\"\ntarget = 1.0\nrelative_tolerance = 0.02\n"), "(no error)");
  EXPECT_EQ(key_of("quantity = \"x\"\n"), "output.target[0].target");
  EXPECT_EQ(key_of("quantity = \"x\"\ntarget = 1.0\ntarget_quantity = \"y\"\n"),
            "output.target[0].target");
  EXPECT_EQ(key_of("quantity = \"x\"\ntarget = 1.0\ntolerance = 0.1\nrelative_tolerance = 0.1\n"),
            "output.target[0].tolerance");
  EXPECT_EQ(key_of("quantity = \"x\"\ntarget = 1.0\ntolerance = -0.1\n"),
            "output.target[0].tolerance");
  EXPECT_EQ(key_of("target = 1.0\n"), "output.target[0].quantity");
}

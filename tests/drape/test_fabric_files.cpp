// One fabric file per fabric (issue #43): every virtual test and forming case of the +-45 NCF reads
// its fabric from cases/fabrics/saertex_pm45.toml, and none keeps a copy of a fabric datum. A
// [[mesh.fabric]] entry names the fabric (`fabric = "saertex_pm45"`) and gives beside it only
// where the blanket lies, how it is meshed and how the specimen is cut; a fabric key given in both
// is bad input naming it, a change to the fabric is made where the fabric is
// (`--set fabric.saertex_pm45.<key>`), and a fabric nobody defined is named with those there are.
// Contact pairs and tools take the fabric's Coulomb coefficients by reference
// ("&fabric.saertex_pm45.friction_tow_tow").
#include <gtest/gtest.h>
#include <toml++/toml.h>

#include <filesystem>
#include <set>
#include <string>
#include <vector>

#include "fem/case/toml_reader.hpp"
#include "fem/errors.hpp"
#include "workflow/case/engine_case.hpp"

namespace fs = std::filesystem;
using namespace ncfsim;

namespace {

const fs::path kSource = NCFSIM_SOURCE_DIR;
const fs::path kFabricFile = kSource / "cases/fabrics/saertex_pm45.toml";

// The case files of the +-45 fabric: every case under cases/drape and cases/hemisphere that
// meshes a fabric or uses its laws, as the user runs them (includes and bases resolved).
std::vector<fs::path> case_files() {
  std::vector<fs::path> out;
  for (const char* dir : {"cases/drape", "cases/hemisphere"})
    for (const auto& e : fs::recursive_directory_iterator(kSource / dir))
      if (e.path().extension() == ".toml") out.push_back(e.path());
  std::sort(out.begin(), out.end());
  return out;
}

// The names of the entries of an array of tables ([[material]], [[bar_law]]).
std::set<std::string> names_in(const toml::table& t, const char* array) {
  std::set<std::string> out;
  if (const auto* a = t[array].as_array())
    for (const auto& e : *a)
      if (const auto* et = e.as_table())
        if (const auto n = (*et)["name"].value<std::string>()) out.insert(*n);
  return out;
}

const toml::table* entry_named(const toml::table& t, const char* array, const std::string& name) {
  if (const auto* a = t[array].as_array())
    for (const auto& e : *a)
      if (const auto* et = e.as_table())
        if ((*et)["name"].value<std::string>() == name) return et;
  return nullptr;
}

TEST(FabricFiles, EveryCaseOfTheFabricReadsTheOneFabricFile) {
  const toml::table fabric = toml::parse_file(kFabricFile.string());
  const auto* spec = fabric["fabric"]["saertex_pm45"].as_table();
  ASSERT_NE(spec, nullptr);
  const std::set<std::string> laws = names_in(fabric, "bar_law"),
                              materials = names_in(fabric, "material");
  ASSERT_EQ(laws, (std::set<std::string>{"stitch_I", "stitch_Lambda"}));
  ASSERT_EQ(materials, std::set<std::string>{"dry_tow"});

  std::size_t fabric_cases = 0, blankets = 0;
  for (const auto& file : case_files()) {
    SCOPED_TRACE(file.string());
    // The file as written: no copy of a fabric datum.
    const toml::table raw = toml::parse_file(file.string());
    EXPECT_FALSE(raw.contains("fabric")) << "a [fabric] table outside cases/fabrics";
    for (const auto& n : names_in(raw, "material")) EXPECT_FALSE(materials.count(n)) << n;
    for (const auto& n : names_in(raw, "bar_law")) EXPECT_FALSE(laws.count(n)) << n;
    if (const auto* a = raw["material"].as_array()) {
      for (const auto& e : *a) {
        EXPECT_NE((*e.as_table())["type"].value<std::string>(), "tow_biphase")
            << "a tow law outside the fabric file";
      }
    }

    // The fabric's Coulomb coefficients by reference (contact pairs and tools), except in a crush
    // (the impregnated part's, not the dry fabric's).
    if (raw["case"]["kind"].value<std::string>() != "crush") {
      auto by_reference = [&](const toml::node_view<const toml::node>& f, const std::string& what) {
        if (!f) return;
        const auto ref = f.value<std::string>();
        EXPECT_TRUE(ref && ref->rfind("&fabric.saertex_pm45.friction_", 0) == 0)
            << what << ": a friction coefficient of its own";
      };
      if (const auto* tools = raw["tool"].as_array())
        for (std::size_t k = 0; k < tools->size(); ++k)
          by_reference(toml::node_view<const toml::node>(*tools->get(k))["friction"],
                       "tool " + std::to_string(k));
      if (const auto* cs = raw["contact"].as_array())
        for (const auto& c : *cs)
          if (const auto* pairs = (*c.as_table())["pair"].as_array())
            for (const auto& pr : *pairs)
              by_reference(toml::node_view<const toml::node>(pr)["friction"], "a contact pair");
    }

    // As read: its blankets name the fabric, and the laws it uses are the fabric file's.
    const fem::CaseDocument doc = fem::CaseDocument::load(file, {});
    const toml::table& t = doc.root();
    bool uses_fabric = false;
    if (const auto* fabs = t["mesh"]["fabric"].as_array())
      for (const auto& e : *fabs) {
        ++blankets;
        uses_fabric = true;
        EXPECT_EQ((*e.as_table())["fabric"].value<std::string>(), "saertex_pm45");
      }
    for (const auto& n : materials)
      if (const auto* m = entry_named(t, "material", n)) {
        uses_fabric = true;
        EXPECT_EQ(*m, *entry_named(fabric, "material", n)) << n;
      }
    for (const auto& n : laws)
      if (const auto* l = entry_named(t, "bar_law", n)) {
        uses_fabric = true;
        EXPECT_EQ(*l, *entry_named(fabric, "bar_law", n)) << n;
      }
    if (uses_fabric) {
      ++fabric_cases;
      const auto* read_spec = t["fabric"]["saertex_pm45"].as_table();
      ASSERT_NE(read_spec, nullptr);
      // A variant may change the fabric on purpose (its `set`): none of the shipped ones does.
      EXPECT_EQ(*read_spec, *spec);
    }
  }
  // The virtual tests (bias extension +-, picture frames +-, unstitched, pull-out, sleds,
  // cantilever), the macro stitched model's, and the hemisphere's meso and macro cases.
  EXPECT_GE(fabric_cases, 20u);
  EXPECT_GE(blankets, 14u);
}

// The second fabric (a 0/90 chain-stitched NCF, issue #43 item 4) through the same readers: its
// cases (cases/fabrics/biax_0_90_chain/) name it, read its laws from its file and take its Coulomb
// coefficients by reference; its hemisphere is the +-45 fabric's CI case with the fabric swapped
// (a variant that includes the second fabric's file), and the generator makes a chain stitch:
// pillars along the wales on both faces, one part for them, no underlap part.
TEST(FabricFiles, TheSecondFabricsCasesReadItsFile) {
  const fs::path file = kSource / "cases/fabrics/biax_0_90_chain.toml";
  const toml::table fabric = toml::parse_file(file.string());
  const auto* spec = fabric["fabric"]["biax_0_90_chain"].as_table();
  ASSERT_NE(spec, nullptr);
  const fs::path hemisphere = kSource / "cases/fabrics/biax_0_90_chain/hemisphere_ci.toml";
  const fem::CaseDocument doc = fem::CaseDocument::load(hemisphere, {});
  const toml::table& t = doc.root();
  EXPECT_EQ(*t["fabric"]["biax_0_90_chain"].as_table(), *spec);
  EXPECT_EQ(t["mesh"]["fabric"][0]["fabric"].value<std::string>(), "biax_0_90_chain");
  EXPECT_EQ(*entry_named(t, "material", "dry_tow_24k"),
            *entry_named(fabric, "material", "dry_tow_24k"));
  EXPECT_EQ(*entry_named(t, "bar_law", "stitch_pillar_76dtex"),
            *entry_named(fabric, "bar_law", "stitch_pillar_76dtex"));
  for (std::size_t k = 0; k < 5; ++k)
    EXPECT_EQ(t["tool"][k]["friction"].value<std::string>(),
              "&fabric.biax_0_90_chain.friction_tool")
        << k;
  for (std::size_t k = 0; k < 3; ++k)
    EXPECT_EQ(t["contact"][0]["pair"][k]["friction"].value<std::string>().value_or("").rfind(
                  "&fabric.biax_0_90_chain.friction_tow_tow", 0),
              0u)
        << k;

  const auto ec = workflow::load_engine_case(hemisphere, {});
  const auto& mesh = ec.model.mesh;
  std::set<std::string> parts(mesh.part_names.begin(), mesh.part_names.end());
  EXPECT_TRUE(parts.count("ncf_stitch_I"));
  EXPECT_TRUE(parts.count("ncf_stitch_legs"));
  EXPECT_FALSE(parts.count("ncf_stitch_Lambda")) << "a chain stitch has no underlap";
  // The blanket has the tows of a 5.08 mm pitch: fewer than the +-45 fabric's 3.32 mm on the
  // same 270 mm blank.
  const auto pm45 = workflow::load_engine_case(kSource / "cases/hemisphere/ci/drape.toml", {});
  EXPECT_LT(mesh.n_nodes(), pm45.model.mesh.n_nodes());
}

std::string key_of_refusal(const fs::path& file, const std::vector<std::string>& sets) {
  try {
    (void)workflow::load_engine_case(file, sets);
  } catch (const InputError& e) {
    return e.key() + " | " + e.what();
  }
  return "";
}

TEST(FabricFiles, AFabricKeyIsGivenInOnePlace) {
  const fs::path pullout = kSource / "cases/drape/tow_pullout.toml";
  // The fabric's datum given in the blanket too: refused, naming it.
  std::string r = key_of_refusal(pullout, {"mesh.fabric[0].tow_gap=0.2e-3"});
  EXPECT_EQ(r.substr(0, r.find(" | ")), "mesh.fabric[0].tow_gap") << r;
  EXPECT_NE(r.find("given both here and in [fabric.saertex_pm45]"), std::string::npos) << r;
  // ... changed where the fabric is: read from there, and checked there.
  EXPECT_EQ(key_of_refusal(pullout, {"fabric.saertex_pm45.tow_gap=0.2e-3"}), "");
  r = key_of_refusal(pullout, {"fabric.saertex_pm45.tow_gap=-1.0"});
  EXPECT_EQ(r.substr(0, r.find(" | ")), "fabric.saertex_pm45.tow_gap") << r;
  r = key_of_refusal(pullout, {"fabric.saertex_pm45.tow_material='resin'"});
  EXPECT_EQ(r.substr(0, r.find(" | ")), "fabric.saertex_pm45.tow_material") << r;
  // Fabric data that contradict each other: refused naming the fabric's key and the rule.
  r = key_of_refusal(pullout, {"fabric.saertex_pm45.stitch_gauge=5e-3"});
  EXPECT_EQ(r.rfind("fabric.saertex_pm45.", 0), 0u) << r;
  EXPECT_NE(r.find("do not fall into the gaps between tows"), std::string::npos) << r;
  r = key_of_refusal(pullout, {"fabric.saertex_pm45.tow_gap=4e-3"});
  EXPECT_EQ(r.substr(0, r.find(" | ")), "fabric.saertex_pm45.tow_gap") << r;
  EXPECT_NE(r.find("smaller than the tow width"), std::string::npos) << r;
  r = key_of_refusal(pullout, {"fabric.saertex_pm45.friction_tool=-1"});
  EXPECT_EQ(r.substr(0, r.find(" | ")), "fabric.saertex_pm45.friction_tool") << r;
  // How a specimen is cut is the case's: its ply angles, and its stitch left out.
  EXPECT_EQ(key_of_refusal(kSource / "cases/drape/friction_sled_tow_tow_0_90.toml",
                           {"mesh.fabric[1].ply_angles_deg=[0.0]"}),
            "");
  EXPECT_EQ(key_of_refusal(pullout, {"mesh.fabric[0].stitch='none'"}), "");
  r = key_of_refusal(pullout, {"mesh.fabric[0].stitch='chain'"});
  EXPECT_EQ(r.substr(0, r.find(" | ")), "mesh.fabric[0].stitch") << r;
  // A reference to a datum the fabric does not give.
  r = key_of_refusal(kSource / "cases/drape/friction_sled_aluminium.toml",
                     {"tool[0].friction='&fabric.saertex_pm45.friction_glass'"});
  EXPECT_EQ(r.substr(0, r.find(" | ")), "tool[0].friction") << r;
  EXPECT_NE(r.find("refers to 'fabric.saertex_pm45.friction_glass'"), std::string::npos) << r;
  // A fabric nobody defined: the ones there are.
  r = key_of_refusal(pullout, {"mesh.fabric[0].fabric='t300_0_90'"});
  EXPECT_EQ(r.substr(0, r.find(" | ")), "mesh.fabric[0].fabric") << r;
  EXPECT_NE(r.find("there are: saertex_pm45"), std::string::npos) << r;
}

TEST(FabricFiles, ASpecimenReadsTheFabricsArchitecture) {
  // The generated blanket follows the fabric file: a wider gap, a longer pitch, fewer tows.
  const fs::path pullout = kSource / "cases/drape/tow_pullout.toml";
  const auto base = workflow::load_engine_case(pullout, {});
  const auto wide = workflow::load_engine_case(pullout, {"fabric.saertex_pm45.tow_gap=1.0e-3"});
  EXPECT_LT(wide.model.mesh.n_nodes(), base.model.mesh.n_nodes());
}

}  // namespace

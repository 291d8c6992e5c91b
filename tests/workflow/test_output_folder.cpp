// Output folders and the user's files (workflow/output/output_files.hpp, OutputFolder), through
// the command line on the crushed-cube case (a second's run):
//  * a non-empty folder that ncfsim did not write is refused (exit 2, naming it), its files intact;
//  * with --overwrite the run writes beside them and never removes them, nor does any rerun;
//  * a rerun removes what the earlier run wrote and it alone (a frame file of an earlier run with
//    more frames goes, a user's file inside figures/ stays);
//  * a run that died (its manifest incomplete) is cleared on the next run except what was there
//    before it.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include "tests/workflow/cli_test_support.hpp"

namespace ncfsim::test {
namespace {

const fs::path kCube = kSource / "tests/cases/erosion/crushed_cube.toml";

void touch(const fs::path& p, const std::string& text) {
  fs::create_directories(p.parent_path());
  std::ofstream(p) << text;
}

std::vector<std::string> run_args(const fs::path& out, std::vector<std::string> extra = {}) {
  std::vector<std::string> a = {"-q",         "run",   kCube.string(),          "-o",
                                out.string(), "--set", "output.frames=\"both\""};
  a.insert(a.end(), extra.begin(), extra.end());
  return a;
}

TEST(CliOutputFolder, UserFilesAreNeverRemoved) {
  const fs::path out = fresh_dir("output_folder_user");
  touch(out / "figures" / "fig1_paper.png", "the user's figure");
  touch(out / "notes.txt", "the user's notes");
  auto r = run_cli(run_args(out));
  EXPECT_EQ(r.code, 2) << r.output;
  EXPECT_NE(r.output.find("--overwrite"), std::string::npos) << r.output;
  EXPECT_FALSE(fs::exists(out / "summary.json"));

  r = run_cli(run_args(out, {"--overwrite"}));
  ASSERT_EQ(r.code, 0) << r.output;
  EXPECT_TRUE(fs::exists(out / "summary.json"));
  EXPECT_TRUE(fs::exists(out / ".ncfsim_manifest.json"));
  // A rerun (no --overwrite needed now) with fewer frames: the stale frame files go.
  std::size_t vtu_before = 0;
  for (const auto& e : fs::directory_iterator(out / "frames"))
    vtu_before += e.path().extension() == ".vtu";
  r = run_cli(run_args(out, {"--set", "time.frame_interval=0.0075"}));
  ASSERT_EQ(r.code, 0) << r.output;
  std::size_t vtu_after = 0;
  for (const auto& e : fs::directory_iterator(out / "frames"))
    vtu_after += e.path().extension() == ".vtu";
  EXPECT_LT(vtu_after, vtu_before);
  EXPECT_EQ(slurp(out / "figures" / "fig1_paper.png"), "the user's figure");
  EXPECT_EQ(slurp(out / "notes.txt"), "the user's notes");

  // A run that died: its manifest is incomplete and a file it wrote is left behind.
  {
    auto m = nlohmann::json::parse(slurp(out / ".ncfsim_manifest.json"));
    m["complete"] = false;
    std::ofstream(out / ".ncfsim_manifest.json") << m.dump();
  }
  touch(out / "frames" / "frame_99999.vtu", "left by a run that was killed");
  r = run_cli(run_args(out));
  ASSERT_EQ(r.code, 0) << r.output;
  EXPECT_FALSE(fs::exists(out / "frames" / "frame_99999.vtu"));
  EXPECT_EQ(slurp(out / "figures" / "fig1_paper.png"), "the user's figure");
  EXPECT_EQ(slurp(out / "notes.txt"), "the user's notes");
  EXPECT_TRUE(fs::exists(out / "summary.json"));
}

TEST(CliOutputFolder, AFileGivenAsTheFolderIsBadInput) {
  const fs::path dir = fresh_dir("output_folder_file");
  touch(dir / "plain_file", "x");
  const auto r = run_cli(run_args(dir / "plain_file"));
  EXPECT_EQ(r.code, 2) << r.output;
  EXPECT_EQ(slurp(dir / "plain_file"), "x");
}

}  // namespace
}  // namespace ncfsim::test

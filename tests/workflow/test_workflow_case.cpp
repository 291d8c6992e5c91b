// The workflow stage (workflow/stages/workflow_stage.hpp) through the command line, on the tiny
// stages of tests/cases/workflow (a crushed cube each: b runs after a, c on its own):
//  * every stage runs into its sub-folder, with the workflow's summary.json and report.html;
//  * a rerun with nothing changed skips every stage (and takes seconds);
//  * a key of a changed (--set a.KEY) reruns a and b (downstream of it), not c; a key for every
//    stage (--set KEY) reruns those whose case it changes; --force c reruns c alone;
//  * a stage that fails stops the workflow: the stages after it are not run and a rerun does not
//    take the failed stage for done;
//  * bad input (exit 2, naming it): a stage case that does not exist, a cycle between stages, an
//    override for no stage, --force of no stage, an input key the stage's case does not have;
//  * a workflow folder copied elsewhere reruns nothing (issue #45: a stage's inputs hash takes
//    its upstream's hash, not the upstream folder's path).
#include <gtest/gtest.h>

#include <chrono>
#include <map>
#include <nlohmann/json.hpp>

#include "tests/workflow/cli_test_support.hpp"

namespace ncfsim::test {
namespace {

const fs::path kCases = kSource / "tests/cases/workflow";

std::map<std::string, std::string> stage_status(const fs::path& out) {
  const auto s = nlohmann::json::parse(slurp(out / "summary.json"));
  std::map<std::string, std::string> m;
  for (const auto& e : s["stages"]) m[e["name"]] = e["status"];
  return m;
}

std::vector<std::string> run_args(const fs::path& out, std::vector<std::string> extra = {}) {
  std::vector<std::string> a = {"-q", "run", (kCases / "chain.toml").string(), "-o", out.string()};
  a.insert(a.end(), extra.begin(), extra.end());
  return a;
}

TEST(CliWorkflow, StagesRunIntoSubFoldersAndUnchangedOnesAreSkipped) {
  const fs::path out = fresh_dir("workflow_chain");
  auto r = run_cli(run_args(out));
  ASSERT_EQ(r.code, 0) << r.output;
  for (const char* st : {"a", "b", "c"}) {
    EXPECT_TRUE(fs::exists(out / st / "summary.json")) << st;
    EXPECT_TRUE(fs::exists(out / st / "history.csv")) << st;
    EXPECT_TRUE(fs::exists(out / st / "stage_inputs.json")) << st;
  }
  EXPECT_TRUE(fs::exists(out / "report.html"));
  auto s = nlohmann::json::parse(slurp(out / "summary.json"));
  EXPECT_EQ(s["stage"], "workflow");
  EXPECT_EQ(s["status"], "completed");
  EXPECT_EQ(stage_status(out), (std::map<std::string, std::string>{
                                   {"a", "completed"}, {"b", "completed"}, {"c", "completed"}}));

  const auto t0 = std::chrono::steady_clock::now();
  r = run_cli(run_args(out));
  const double rerun_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  ASSERT_EQ(r.code, 0) << r.output;
  EXPECT_EQ(stage_status(out), (std::map<std::string, std::string>{
                                   {"a", "skipped"}, {"b", "skipped"}, {"c", "skipped"}}));
  EXPECT_LT(rerun_s, 10.0);

  // A key of a: a and b (after a) rerun, c does not.
  r = run_cli(run_args(out, {"--set", "a.time.end_time=0.014"}));
  ASSERT_EQ(r.code, 0) << r.output;
  EXPECT_EQ(stage_status(out), (std::map<std::string, std::string>{
                                   {"a", "completed"}, {"b", "completed"}, {"c", "skipped"}}));
  const auto a = nlohmann::json::parse(slurp(out / "a" / "summary.json"));
  EXPECT_DOUBLE_EQ(a["end_time_s"].get<double>(), 0.014);
  // The same again: nothing changed.
  r = run_cli(run_args(out, {"--set", "a.time.end_time=0.014"}));
  EXPECT_EQ(stage_status(out), (std::map<std::string, std::string>{
                                   {"a", "skipped"}, {"b", "skipped"}, {"c", "skipped"}}));
  // A key for every stage: a has it already, b and c change.
  r = run_cli(run_args(out, {"--set", "time.end_time=0.014"}));
  ASSERT_EQ(r.code, 0) << r.output;
  EXPECT_EQ(stage_status(out), (std::map<std::string, std::string>{
                                   {"a", "skipped"}, {"b", "completed"}, {"c", "completed"}}));
  // --force reruns one stage.
  r = run_cli(run_args(out, {"--set", "time.end_time=0.014", "--force", "c"}));
  ASSERT_EQ(r.code, 0) << r.output;
  EXPECT_EQ(stage_status(out), (std::map<std::string, std::string>{
                                   {"a", "skipped"}, {"b", "skipped"}, {"c", "completed"}}));
  EXPECT_NE(slurp(out / "log.txt").find("[3/3 c] forced"), std::string::npos)
      << "progress names the stage";

  // A stage that fails stops the workflow; a rerun does not take it for done.
  r = run_cli(run_args(out, {"--set", "b.time.nosuch=1"}));
  EXPECT_EQ(r.code, 2) << r.output;
  EXPECT_NE(r.output.find("nosuch"), std::string::npos) << r.output;
  EXPECT_EQ(stage_status(out), (std::map<std::string, std::string>{
                                   {"a", "completed"}, {"b", "bad_input"}, {"c", "not_run"}}));
  EXPECT_FALSE(fs::exists(out / "b" / "stage_inputs.json"));
  r = run_cli(run_args(out));
  ASSERT_EQ(r.code, 0) << r.output;
  EXPECT_EQ(stage_status(out)["b"], "completed");
}

TEST(CliWorkflow, BadInputNamesTheStageOrKey) {
  const fs::path out = fresh_dir("workflow_bad");
  struct Bad {
    std::vector<std::string> args;
    std::string says;
  };
  const std::vector<Bad> bad = {
      {{"run", (kCases / "missing_stage_case.toml").string(), "-o", out.string()},
       "no_such_case.toml does not exist"},
      {{"run", (kCases / "cycle.toml").string(), "-o", out.string()}, "wait for each other"},
      {run_args(out, {"--set", "nosuch.x=1"}), "neither names a stage"},
      {run_args(out, {"--force", "nosuch"}), "'nosuch' is not a stage"},
      {{"check", (kCases / "cycle.toml").string()}, "wait for each other"},
      {{"check", (kCases / "input_key_missing.toml").string()}, "source.nothing"},
      {{"run", (kCases / "input_key_missing.toml").string(), "-o", out.string()},
       "is not a key of stage 'b'"},
  };
  for (const auto& b : bad) {
    const auto r = run_cli(b.args);
    EXPECT_EQ(r.code, 2) << b.args[1] << ": " << r.output;
    EXPECT_NE(r.output.find(b.says), std::string::npos) << r.output;
  }
  EXPECT_FALSE(fs::exists(out / "summary.json")) << "bad input must not start the workflow";
}

// A stage's inputs hash takes its upstream stage's hash, not the path of the upstream's folder:
// the workflow folder copied elsewhere (cp -a) reruns nothing.
TEST(CliWorkflow, FolderCopiedElsewhereRerunsNothing) {
  const fs::path out = fresh_dir("workflow_handoff"), moved = fresh_dir("workflow_handoff_moved");
  const auto args = [&](const fs::path& o) {
    return std::vector<std::string>{"-q", "run", (kCases / "handoff.toml").string(), "-o",
                                    o.string()};
  };
  auto r = run_cli(args(out));
  ASSERT_EQ(r.code, 0) << r.output;
  EXPECT_EQ(stage_status(out),
            (std::map<std::string, std::string>{{"a", "completed"}, {"b", "completed"}}));
  fs::copy(out, moved, fs::copy_options::recursive);
  r = run_cli(args(moved));
  ASSERT_EQ(r.code, 0) << r.output;
  EXPECT_EQ(stage_status(moved),
            (std::map<std::string, std::string>{{"a", "skipped"}, {"b", "skipped"}}));
  // b's hand-off still changes with a: a key of a reruns both.
  r = run_cli({"-q", "run", (kCases / "handoff.toml").string(), "-o", moved.string(), "--set",
               "a.time.end_time=0.014"});
  ASSERT_EQ(r.code, 0) << r.output;
  EXPECT_EQ(stage_status(moved),
            (std::map<std::string, std::string>{{"a", "completed"}, {"b", "completed"}}));
}

}  // namespace
}  // namespace ncfsim::test

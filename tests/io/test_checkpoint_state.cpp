// Checkpointed state (issue #22, docs/checkpoint-plan.md, test 6.2): solver A runs N cycles, its
// state is saved to checkpoint.h5 and A runs M more; solver B, built from the same case as a
// fresh run builds it, loads the file and runs M cycles. B must be A bit for bit: positions,
// velocities, energies and every saved array (element state, tools, contacts), compared as the
// checkpoint trees both write at the end. Cases: rigid tool with friction (the aluminium sled),
// penalty contact with friction and ties (the tow-tow sled), stitch-to-tow joints, bars and the
// picture-frame rig, erosion with freed nodes (the crushed cube), shells with rotations.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cstring>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "fem/checkpoint.hpp"
#include "fem/contact/penalty_contact.hpp"
#include "fem/io/hdf5_checkpoint.hpp"
#include "fem/solver.hpp"
#include "workflow/case/engine_case.hpp"

namespace fs = std::filesystem;
using namespace ncfsim;
using fem::CheckpointTree;

namespace {

fs::path fresh_dir(const std::string& name) {
  const fs::path d =
      fs::temp_directory_path() / ("ncfsim_ckstate_" + name + "_" + std::to_string(::getpid()));
  fs::remove_all(d);
  fs::create_directories(d);
  return d;
}

struct Built {
  workflow::EngineCase ec;
  std::unique_ptr<fem::ExplicitSolver> solver;
  Built(const std::string& file, const std::vector<std::string>& overrides)
      : ec(workflow::load_engine_case(fs::path(NCFSIM_SOURCE_DIR) / file, overrides)),
        solver(std::make_unique<fem::ExplicitSolver>(ec.model)) {}
};

CheckpointTree state_of(const fem::ExplicitSolver& s) {
  CheckpointTree t;
  s.save_state(t);
  return t;
}

bool same_bits(double a, double b) { return std::memcmp(&a, &b, sizeof a) == 0; }

// Every value of b equals a's bit for bit, but the wall-clock timers.
void expect_same(const CheckpointTree::Node& a, const CheckpointTree::Node& b,
                 const std::string& path, int& n_values) {
  ASSERT_EQ(a.values.size(), b.values.size()) << path;
  ASSERT_EQ(a.groups.size(), b.groups.size()) << path;
  for (const auto& [name, va] : a.values) {
    if (name == "timers") continue;
    const auto it = b.values.find(name);
    ASSERT_NE(it, b.values.end()) << path << "/" << name;
    const auto& vb = it->second;
    ASSERT_EQ(va.index(), vb.index()) << path << "/" << name;
    ++n_values;
    if (const auto* da = std::get_if<std::vector<double>>(&va)) {
      const auto& db = std::get<std::vector<double>>(vb);
      ASSERT_EQ(da->size(), db.size()) << path << "/" << name;
      // stats_values: maximum penetrations, then seconds spent (wall clock).
      const std::size_t n = name == "stats_values" ? 2 : da->size();
      std::size_t n_diff = 0, first = 0;
      for (std::size_t k = 0; k < n; ++k)
        if (!same_bits((*da)[k], db[k]) && n_diff++ == 0) first = k;
      EXPECT_EQ(n_diff, 0u) << path << "/" << name << ": first at [" << first
                            << "]: " << (n_diff ? (*da)[first] : 0.0) << " vs "
                            << (n_diff ? db[first] : 0.0);
    } else if (const auto* xa = std::get_if<double>(&va)) {
      EXPECT_TRUE(same_bits(*xa, std::get<double>(vb)))
          << path << "/" << name << ": " << *xa << " vs " << std::get<double>(vb);
    } else {
      EXPECT_TRUE(va == vb) << path << "/" << name;
    }
  }
  for (const auto& [name, ga] : a.groups)
    expect_same(ga, b.groups.at(name), path + "/" + name, n_values);
}

// A runs until `n_cycles` (or until `until` says so), is checkpointed through the file and runs
// m more; B loads and runs m. Returns A for case-specific checks.
std::unique_ptr<Built> check_continuation(
    const std::string& name, const std::string& file, const std::vector<std::string>& overrides,
    int n_cycles, int m_cycles, const std::function<bool(fem::ExplicitSolver&)>& until = {}) {
  const fs::path dir = fresh_dir(name);
  auto a = std::make_unique<Built>(file, overrides);
  for (int k = 0; k < n_cycles || (until && !until(*a->solver)); ++k) a->solver->step();
  const std::int64_t saved_cycle = a->solver->cycle();
  fem::io::write_checkpoint_file(dir / "checkpoint.h5", state_of(*a->solver));
  for (int k = 0; k < m_cycles; ++k) a->solver->step();

  Built b(file, overrides);
  {
    CheckpointTree t = fem::io::read_checkpoint_file(dir / "checkpoint.h5");
    t.set_reading(true);
    b.solver->load_state(t);
  }
  EXPECT_EQ(b.solver->cycle(), saved_cycle);
  for (int k = 0; k < m_cycles; ++k) b.solver->step();
  EXPECT_EQ(b.solver->cycle(), a->solver->cycle());
  int n_values = 0;
  expect_same(state_of(*a->solver).root(), state_of(*b.solver).root(), "", n_values);
  EXPECT_GT(n_values, 20);
  const auto& ea = a->solver->energy();
  const auto& eb = b.solver->energy();
  EXPECT_TRUE(same_bits(ea.total(), eb.total()));
  EXPECT_TRUE(same_bits(ea.error(), eb.error()));
  fs::remove_all(dir);
  return a;
}

}  // namespace

TEST(CheckpointState, RigidToolWithFrictionContinuesBitForBit) {
  auto a = check_continuation("sled_aluminium", "cases/drape/friction_sled_aluminium.toml", {}, 400,
                              400);
  ASSERT_FALSE(a->ec.model.tools.empty());
  EXPECT_GT(a->ec.model.tools.front().proximity.n_rebuilds, 0);
  EXPECT_GT(a->solver->energy().friction, 0.0);
}

TEST(CheckpointState, PenaltyContactWithFrictionAndTiesContinuesBitForBit) {
  auto a = check_continuation(
      "sled_tows", "cases/drape/friction_sled_tow_tow_0_90.toml",
      // pulled early and fast so that the bucket sort is redone on both sides of the checkpoint
      {"boundary.velocity[0].start_time=0.0005", "boundary.velocity[0].ramp_time=0.0005",
       "boundary.velocity[0].velocity=[1.0, 0.0, 0.0]"},
      2000, 2000);
  bool sorted_again = false;
  for (const auto& c : a->ec.model.contacts)
    if (const auto* p = dynamic_cast<const fem::PenaltyContact*>(c.get()))
      sorted_again = sorted_again || p->stats().n_sorts > 10;
  EXPECT_TRUE(sorted_again);
  EXPECT_GT(a->solver->energy().friction, 0.0);
}

TEST(CheckpointState, StitchJointsBarsAndPictureFrameContinueBitForBit) {
  check_continuation("picture_frame", "cases/drape/picture_frame_positive.toml",
                     {"output.figures=false"}, 300, 300);
}

TEST(CheckpointState, ErosionContinuesBitForBit) {
  // Saved a few cycles after the first erosion (t = 10 ms): erosion events, freed nodes, eroded
  // flags; then more erosions after the restart.
  auto a = check_continuation("crushed_cube", "tests/cases/erosion/crushed_cube.toml", {}, 0, 300,
                              [](fem::ExplicitSolver& s) { return !s.erosions().empty(); });
  EXPECT_FALSE(a->solver->erosions().empty());
}

TEST(CheckpointState, ShellsContinueBitForBit) {
  auto a = check_continuation("shell_cantilever", "cases/verification/shell_cantilever.toml", {},
                              300, 300);
  EXPECT_GT(a->solver->energy().rotational_kinetic, 0.0);
}

TEST(CheckpointState, AnotherModelIsRefusedNamingTheObject) {
  const fs::path dir = fresh_dir("mismatch");
  Built a("tests/cases/erosion/crushed_cube.toml", {});
  for (int k = 0; k < 5; ++k) a.solver->step();
  CheckpointTree t = state_of(*a.solver);
  Built b("cases/verification/shell_cantilever.toml", {});
  t.set_reading(true);
  try {
    b.solver->load_state(t);
    ADD_FAILURE() << "another model was loaded";
  } catch (const fem::CheckpointMismatch& e) {
    EXPECT_NE(std::string(e.what()).find("/solver/n_nodes"), std::string::npos) << e.what();
  }
  // A solver that has stepped does not load.
  t.set_reading(true);
  EXPECT_THROW(a.solver->load_state(t), std::logic_error);
  fs::remove_all(dir);
}

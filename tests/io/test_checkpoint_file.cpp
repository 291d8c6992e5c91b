// checkpoint.h5 (fem/io/hdf5_checkpoint.hpp): a CheckpointTree written and read back holds the
// same groups, scalars and arrays bit for bit; a missing object, an array of another size or type
// is refused naming the object; the write is atomic (an existing file stays until the rename).
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>

#include "fem/checkpoint.hpp"
#include "fem/io/hdf5_checkpoint.hpp"
#include "fem/io/result_reader.hpp"
#include "fem/io/result_writers.hpp"

namespace fs = std::filesystem;
using ncfsim::fem::CheckpointMismatch;
using ncfsim::fem::CheckpointScope;
using ncfsim::fem::CheckpointTree;
using ncfsim::fem::CheckpointWriter;
using ncfsim::fem::io::read_checkpoint_file;
using ncfsim::fem::io::write_checkpoint_file;

namespace {

fs::path temp_dir(const std::string& name) {
  const fs::path d = fs::temp_directory_path() / ("ncfsim_test_checkpoint_" + name);
  fs::remove_all(d);
  fs::create_directories(d);
  return d;
}

void fill(CheckpointWriter& w) {
  w.write_string("format", "ncfsim-checkpoint");
  w.write_string("empty", "");
  w.write_int("cycle", 1234567890123LL);
  w.write_double("time", 0.1 + 0.2);
  const std::vector<double> x = {1.0 / 3.0, -0.0, std::numeric_limits<double>::quiet_NaN(), 1e-300};
  w.write_array("x", x);
  {
    CheckpointScope s(w, "solver");
    const std::vector<std::int64_t> a = {-1, 1LL << 40};
    const std::vector<std::int32_t> b = {7, -8, 9};
    const std::vector<std::uint8_t> c = {0, 1, 2, 255};
    w.write_array("a", a);
    w.write_array("b", b);
    w.write_array("c", c);
    w.write_array("none", std::span<const double>{});
    CheckpointScope g(w, "groups");
    CheckpointScope g0(w, "000");
    w.write_double("e", 2.5);
  }
}

}  // namespace

TEST(CheckpointFile, RoundTripOfGroupsScalarsAndArrays) {
  const fs::path dir = temp_dir("round_trip");
  CheckpointTree t;
  fill(t);
  write_checkpoint_file(dir / "checkpoint.h5", t);
  EXPECT_FALSE(fs::exists(dir / "checkpoint.h5.tmp"));
  CheckpointTree r = read_checkpoint_file(dir / "checkpoint.h5");
  r.set_reading(true);
  EXPECT_EQ(r.read_string("format"), "ncfsim-checkpoint");
  EXPECT_EQ(r.read_string("empty"), "");
  EXPECT_EQ(r.read_int("cycle"), 1234567890123LL);
  EXPECT_EQ(r.read_double("time"), 0.1 + 0.2);
  std::vector<double> x;
  r.read_array("x", x, 4);
  EXPECT_EQ(x[0], 1.0 / 3.0);
  EXPECT_TRUE(std::signbit(x[1]));
  EXPECT_TRUE(std::isnan(x[2]));
  EXPECT_EQ(x[3], 1e-300);
  r.begin("solver");
  std::vector<std::int64_t> a;
  std::vector<std::int32_t> b;
  std::vector<std::uint8_t> c;
  std::vector<double> none;
  r.read_array("a", a);
  r.read_array("b", b, 3);
  r.read_array("c", c);
  r.read_array("none", none, 0);
  EXPECT_EQ(a, (std::vector<std::int64_t>{-1, 1LL << 40}));
  EXPECT_EQ(b, (std::vector<std::int32_t>{7, -8, 9}));
  EXPECT_EQ(c, (std::vector<std::uint8_t>{0, 1, 2, 255}));
  EXPECT_TRUE(r.has("groups"));
  r.begin("groups");
  r.begin("000");
  EXPECT_EQ(r.read_double("e"), 2.5);
  EXPECT_EQ(r.where(), "/solver/groups/000");
  r.end();
  r.end();
  r.end();
  fs::remove_all(dir);
}

TEST(CheckpointFile, MissingObjectOrOtherSizeIsRefusedNamingIt) {
  const fs::path dir = temp_dir("mismatch");
  CheckpointTree t;
  fill(t);
  write_checkpoint_file(dir / "checkpoint.h5", t);
  CheckpointTree r = read_checkpoint_file(dir / "checkpoint.h5");
  r.set_reading(true);
  auto message = [](auto&& f) {
    try {
      f();
    } catch (const CheckpointMismatch& e) {
      return std::string(e.what());
    }
    return std::string("(no exception)");
  };
  std::vector<double> x;
  EXPECT_NE(
      message([&] { r.read_array("x", x, 5); }).find("'/x': has 4 values, this model needs 5"),
      std::string::npos);
  EXPECT_NE(message([&] { r.read_double("dt"); }).find("'/dt': missing"), std::string::npos);
  EXPECT_NE(message([&] { r.begin("tools"); }).find("'/tools'"), std::string::npos);
  r.begin("solver");
  std::vector<std::int32_t> a;
  EXPECT_NE(message([&] { r.read_array("a", a); }).find("'/solver/a': of another type"),
            std::string::npos);
  EXPECT_NE(message([&] { r.check_int("nothing", 1); }).find("/solver/nothing"), std::string::npos);
  r.end();
  fs::remove_all(dir);
}

TEST(CheckpointFile, WriteIsAtomicAndBadFilesAreRefused) {
  const fs::path dir = temp_dir("atomic");
  CheckpointTree a;
  a.write_int("n", 1);
  write_checkpoint_file(dir / "checkpoint.h5", a);
  // A write that fails (here: the temporary file cannot be created, a folder holds its name)
  // leaves the previous file as it was.
  fs::create_directories(dir / "checkpoint.h5.tmp" / "x");
  CheckpointTree b;
  b.write_int("n", 2);
  EXPECT_THROW(write_checkpoint_file(dir / "checkpoint.h5", b), std::runtime_error);
  fs::remove_all(dir / "checkpoint.h5.tmp");
  CheckpointTree r = read_checkpoint_file(dir / "checkpoint.h5");
  r.set_reading(true);
  EXPECT_EQ(r.read_int("n"), 1);
  // Not a checkpoint: a missing file, a text file.
  EXPECT_THROW(read_checkpoint_file(dir / "none.h5"), CheckpointMismatch);
  std::ofstream(dir / "text.h5") << "not hdf5\n";
  EXPECT_THROW(read_checkpoint_file(dir / "text.h5"), CheckpointMismatch);
  fs::remove_all(dir);
}

// A resumed run takes over results.h5 (XdmfResultWriter::reopen): the frames before the
// checkpoint stay, later ones go, and the next frames follow them; results.xdmf and the frames
// read back are those of a writer that never stopped.
TEST(CheckpointFile, ResultsReopenedKeepTheFramesBeforeTheCheckpoint) {
  namespace io = ncfsim::fem::io;
  io::ResultMesh mesh;
  for (int k = 0; k < 8; ++k)
    mesh.points.insert(mesh.points.end(), {double(k & 1), double((k >> 1) & 1), double(k >> 2)});
  mesh.hex().conn = {0, 1, 3, 2, 4, 5, 7, 6};
  mesh.hex().part = {0};
  mesh.part_names = {"cube"};
  auto frame = [](double t) {
    io::Frame f;
    f.time = t;
    f.cycle = static_cast<int>(10 * t);
    f.displacement.assign(24, t);
    f.fields.push_back({"s", true, 1, {2 * t}});
    f.fields.push_back({"a", false, 1, std::vector<double>(8, t)});
    return f;
  };
  const fs::path one = temp_dir("reopen_one"), two = temp_dir("reopen_two");
  {
    io::XdmfResultWriter w(one, mesh);
    for (double t : {0.0, 1.0, 2.0, 3.0}) w.write_frame(frame(t));
  }
  std::vector<io::WrittenFrame> kept;
  {
    io::XdmfResultWriter w(two, mesh);
    for (double t : {0.0, 1.0}) w.write_frame(frame(t));
    kept = w.written_frames();
    w.write_frame(frame(1.5));  // written after the checkpoint: goes
  }
  {
    io::XdmfResultWriter w = io::XdmfResultWriter::reopen(two, mesh, kept);
    EXPECT_EQ(w.frames_written(), 2u);
    for (double t : {2.0, 3.0}) w.write_frame(frame(t));
  }
  auto slurp = [](const fs::path& p) {
    std::ifstream in(p);
    return std::string(std::istreambuf_iterator<char>(in), {});
  };
  EXPECT_EQ(slurp(one / "results.xdmf"), slurp(two / "results.xdmf"));
  const io::ResultReader a(one / "results.h5"), b(two / "results.h5");
  ASSERT_EQ(b.n_frames(), 4u);
  for (std::size_t k = 0; k < 4; ++k) {
    EXPECT_EQ(a.frame(k).time, b.frame(k).time);
    EXPECT_EQ(a.frame(k).coordinates, b.frame(k).coordinates);
  }
  // Another mesh, or fewer frames than the checkpoint's, is refused.
  io::ResultMesh other = mesh;
  other.points.resize(21);
  other.hex().conn = {0, 1, 3, 2, 4, 5, 6, 6};
  EXPECT_THROW(io::XdmfResultWriter::reopen(two, other, kept), std::runtime_error);
  kept.resize(6, kept.back());
  EXPECT_THROW(io::XdmfResultWriter::reopen(two, mesh, kept), std::runtime_error);
  fs::remove_all(one);
  fs::remove_all(two);
}

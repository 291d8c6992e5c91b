// ncfsim::render — off-screen rendering checked by pixel statistics of the written PNGs.
//
// Every picture is read back with vtkPNGReader and measured; no reference images are stored.
// The program unsets DISPLAY before any test runs, so a pass proves that no X server is involved.
// CTest runs it once per back end (NCFSIM_RENDER_BACKEND = osmesa, egl; and auto falling back to
// EGL when libOSMesa cannot be loaded), NCFSIM_RENDER_TEST_EXPECT naming the back end the context
// must report.
// Images are kept for a human to look at in $NCFSIM_RENDER_TEST_OUTPUT (set by CTest to
// <build>/tests/render/render_test_output), else in the system temporary folder.
#include "render.hpp"

#include <gtest/gtest.h>

#include <vtkImageData.h>
#include <vtkNew.h>
#include <vtkPNGReader.h>
#include <vtkSmartPointer.h>

#include <array>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <limits>
#include <optional>
#include <set>
#include <stdexcept>
#include <string>

namespace fs = std::filesystem;
using namespace ncfsim::render;
namespace fem = ncfsim::fem;

namespace {

const bool kDisplayUnset = [] {
  ::unsetenv("DISPLAY");
  ::unsetenv("WAYLAND_DISPLAY");
  return true;
}();

fs::path output_dir()
{
  static const fs::path dir = [] {
    const char* env = std::getenv("NCFSIM_RENDER_TEST_OUTPUT");
    fs::path d = env != nullptr && *env != '\0' ? fs::path(env)
                                                : fs::temp_directory_path() / "ncfsim_render_test";
    fs::create_directories(d);
    return d;
  }();
  return dir;
}

struct Rgb {
  int r, g, b;
};

// Decoded PNG, rows stored bottom-up as VTK gives them (y = 0 is the bottom row).
struct Image {
  int width = 0, height = 0, n_components = 0;
  vtkSmartPointer<vtkImageData> data;

  Rgb at(int x, int y) const
  {
    const auto* p = static_cast<const unsigned char*>(data->GetScalarPointer(x, y, 0));
    return {p[0], p[1], p[2]};
  }
};

Image read_png(const fs::path& path)
{
  vtkNew<vtkPNGReader> reader;
  EXPECT_GT(reader->CanReadFile(path.c_str()), 0) << path; // 0 = not a PNG
  reader->SetFileName(path.c_str());
  reader->Update();
  Image img;
  img.data = reader->GetOutput();
  int dims[3] = {0, 0, 0};
  img.data->GetDimensions(dims);
  img.width = dims[0];
  img.height = dims[1];
  img.n_components = img.data->GetNumberOfScalarComponents();
  return img;
}

bool is_background(const Rgb& c) { return c.r >= 250 && c.g >= 250 && c.b >= 250; }
// A fully saturated colour-map colour: the slab's faces, lit head-on, and the colour strip.
bool is_saturated(const Rgb& c)
{
  return std::max({c.r, c.g, c.b}) - std::min({c.r, c.g, c.b}) > 150;
}
bool is_blueish(const Rgb& c) { return c.b > 200 && c.r < 60 && c.g < 90; }
bool is_redish(const Rgb& c) { return c.r > 200 && c.g < 60 && c.b < 60; }
bool is_dark(const Rgb& c) { return c.r < 90 && c.g < 90 && c.b < 90; }
bool near(const Rgb& c, const std::array<int, 3>& ref, int tol)
{
  return std::abs(c.r - ref[0]) <= tol && std::abs(c.g - ref[1]) <= tol &&
         std::abs(c.b - ref[2]) <= tol;
}

// n_x x n_y x 1 hexahedra of unit size, x in [0, n_x], y in [0, n_y], z in [0, 1].
// Cell field "temperature" [K] = x of the cell centre (linear in x, 0.5 ... n_x - 0.5);
// point field "velocity" [m/s] = (x, y, 0).
RenderMesh slab(int n_x, int n_y)
{
  RenderMesh mesh;
  auto node = [&](int i, int j, int k) {
    return static_cast<std::int64_t>((k * (n_y + 1) + j) * (n_x + 1) + i);
  };
  MeshField velocity{"velocity", "m/s", false, 3, {}};
  for (int k = 0; k <= 1; ++k) {
    for (int j = 0; j <= n_y; ++j) {
      for (int i = 0; i <= n_x; ++i) {
        mesh.points.insert(mesh.points.end(), {double(i), double(j), double(k)});
        velocity.values.insert(velocity.values.end(), {double(i), double(j), 0.0});
      }
    }
  }
  MeshField temperature{"temperature", "K", true, 1, {}};
  for (int j = 0; j < n_y; ++j) {
    for (int i = 0; i < n_x; ++i) {
      mesh.of(fem::ElementKind::Hex8)
          .insert(mesh.of(fem::ElementKind::Hex8).end(),
                  {node(i, j, 0), node(i + 1, j, 0), node(i + 1, j + 1, 0), node(i, j + 1, 0),
                   node(i, j, 1), node(i + 1, j, 1), node(i + 1, j + 1, 1), node(i, j + 1, 1)});
      temperature.values.push_back(i + 0.5);
    }
  }
  mesh.fields = {temperature, velocity};
  return mesh;
}

} // namespace

TEST(Render, OffscreenContextIsAvailable)
{
  std::string why;
  const bool ok = offscreen_rendering_available(&why);
  ASSERT_TRUE(ok) << why;
  EXPECT_NE(why.find("OpenGL"), std::string::npos) << why;
  std::cout << "off-screen context: " << why << "\n";
  if (const char* expect = std::getenv("NCFSIM_RENDER_TEST_EXPECT");
      expect != nullptr && *expect != '\0') {
    EXPECT_EQ(why.rfind(expect, 0), 0u) << "expected the back end '" << expect << "', got " << why;
  }
}

// 10 x 10 x 1 slab, linear cell field in x, camera Top, 1200 x 900.
//
// Expected slab size, from the renderer's rules: the model viewport is [0, 0.82] x [0, 0.92] of
// the image = 984 x 828 px; ResetCamera with a parallel projection sets the half-height of the
// view to the radius of the bounds' sphere, r = |(10, 10, 1)| / 2 = 7.089; so the 10 x 10 top
// face spans 828 * 10 / (2 r) = 584 px each way: 584^2 = 341,000 px = 31.6 % of the image.
// Everything else that is not background: the colour strip (~50 x 700 px = 3.2 %), the labels
// and the titles (~1 %). Measured on llvmpipe (Mesa 22.3.6): 35.7 % non-background, 341,056
// saturated pixels left of the scalar bar (exactly 584^2), 34,456 blue and 34,456 red ones.
TEST(Render, SlabTopViewPixelStatistics)
{
  const fs::path png = output_dir() / "slab_top.png";
  fs::remove(png);
  MeshFigure figure;
  figure.field = "temperature";
  figure.title = "10 x 10 x 1 slab, temperature linear in x";
  figure.camera = CameraPreset::Top;
  ASSERT_NO_THROW(render_mesh_png(slab(10, 10), figure, png));

  const Image img = read_png(png);
  ASSERT_EQ(img.width, 1200);
  ASSERT_EQ(img.height, 900);
  ASSERT_GE(img.n_components, 3);

  const int model_right = static_cast<int>(0.82 * img.width); // scalar bar starts at 0.85
  long n_background = 0, n_slab = 0, n_blue = 0, n_red = 0, n_dark_top = 0;
  double blue_x = 0.0, red_x = 0.0;
  for (int y = 0; y < img.height; ++y) {
    for (int x = 0; x < img.width; ++x) {
      const Rgb c = img.at(x, y);
      n_background += is_background(c) ? 1 : 0;
      if (y > 0.93 * img.height && is_dark(c)) {
        ++n_dark_top; // the figure title
      }
      if (x >= model_right) {
        continue;
      }
      n_slab += is_saturated(c) ? 1 : 0;
      if (is_blueish(c)) {
        ++n_blue;
        blue_x += x;
      }
      if (is_redish(c)) {
        ++n_red;
        red_x += x;
      }
    }
  }
  const double n_pixels = double(img.width) * img.height;
  const double share_foreground = 1.0 - n_background / n_pixels;
  std::cout << "non-background share " << share_foreground << ", slab pixels " << n_slab
            << ", blue " << n_blue << ", red " << n_red << ", title dark pixels " << n_dark_top
            << "\n";

  // Whole image: slab 31.6 % + scalar bar and text ~4 %; +-3 points covers anti-aliasing and
  // font differences, and still fails if the camera, the viewport or the scalar bar change.
  EXPECT_GT(share_foreground, 0.33);
  EXPECT_LT(share_foreground, 0.39);

  // The slab alone: 584^2 = 341,056 px expected; 2 % allows for edge rasterisation.
  const double expected_slab = std::pow(0.92 * img.height * 10.0 / std::sqrt(201.0), 2);
  EXPECT_NEAR(n_slab, expected_slab, 0.02 * expected_slab);

  // Both ends of the colour map on the model itself: the x = 0..1 cell column (value 0.5, the
  // minimum) is blue, the x = 9..10 column (9.5, the maximum) is red; one column is
  // 58 x 584 = 34,000 px. Blue must lie left of red (the field grows with x, +x is to the right).
  const double column = expected_slab / 10.0;
  EXPECT_GT(n_blue, 0.7 * column);
  EXPECT_GT(n_red, 0.7 * column);
  ASSERT_GT(n_blue, 0);
  ASSERT_GT(n_red, 0);
  EXPECT_LT(blue_x / n_blue + 0.6 * std::sqrt(expected_slab), red_x / n_red);

  // The title is drawn (dark text pixels in the top 7 % of the image).
  EXPECT_GT(n_dark_top, 500);

  // Written atomically: no temporary file left beside it.
  for (const auto& entry : fs::directory_iterator(output_dir())) {
    EXPECT_EQ(entry.path().filename().string().find(".tmp-"), std::string::npos)
        << entry.path();
  }
}

// The other cameras, a point field (vector magnitude) and bars drawn as lines.
TEST(Render, IsoAndFrontViewsWithBarsAndPointField)
{
  RenderMesh mesh = slab(6, 4);
  // A bar lattice beside the slab, on its own nodes (x in [7, 10]).
  const auto first = static_cast<std::int64_t>(mesh.points.size() / 3);
  for (int i = 0; i <= 3; ++i) {
    mesh.points.insert(mesh.points.end(), {7.0 + i, 0.0, 0.0, 7.0 + i, 4.0, 1.0});
  }
  for (int i = 0; i <= 3; ++i) {
    mesh.of(fem::ElementKind::Bar2)
        .insert(mesh.of(fem::ElementKind::Bar2).end(), {first + 2 * i, first + 2 * i + 1});
  }
  const std::size_t n_points = mesh.points.size() / 3;
  for (auto& f : mesh.fields) {
    if (f.on_cells) {
      f.values.resize(f.values.size() + 4, 10.0); // the bars' cell values follow the hexes'
    } else {
      f.values.resize(n_points * 3, 5.0);
    }
  }
  for (auto camera : {CameraPreset::Iso, CameraPreset::Front}) {
    const fs::path png =
        output_dir() / (camera == CameraPreset::Iso ? "slab_iso.png" : "slab_front.png");
    MeshFigure figure;
    figure.field = camera == CameraPreset::Iso ? "velocity" : "temperature";
    figure.camera = camera;
    figure.width = 800;
    figure.height = 600;
    figure.range = std::array<double, 2>{0.0, 10.0};
    figure.title = "iso/front";
    ASSERT_NO_THROW(render_mesh_png(mesh, figure, png));
    const Image img = read_png(png);
    ASSERT_EQ(img.width, 800);
    ASSERT_EQ(img.height, 600);
    long n_model = 0;
    std::set<int> colours;
    for (int y = 0; y < img.height; ++y) {
      for (int x = 0; x < static_cast<int>(0.82 * img.width); ++x) {
        const Rgb c = img.at(x, y);
        if (!is_background(c)) {
          ++n_model;
          colours.insert((c.r << 16) | (c.g << 8) | c.b);
        }
      }
    }
    std::cout << figure.field << ": model share " << n_model / double(img.width * img.height)
              << ", distinct colours " << colours.size() << "\n";
    // Iso: the 6 x 4 slab and the bars fill a good part of the model viewport; Front: the 1-high
    // slab seen edge-on is a thin band (measured 4.4 % and 2.6 % of the image).
    EXPECT_GT(n_model, 0.01 * img.width * img.height);
    EXPECT_GT(colours.size(), 20u) << "a field-coloured model has many colours";
  }
}

TEST(Render, CurvePlotShowsSeriesColours)
{
  const fs::path png = output_dir() / "plot.png";
  CurvePlot plot;
  plot.title = "Bias-extension test";
  plot.x_label = "displacement [mm]";
  plot.y_label = "force [N]";
  CurveSeries sim{"simulation", {}, {}, false, false};
  CurveSeries ref{"reference", {}, {}, true, false};
  CurveSeries exp{"experiment", {}, {}, false, true};
  for (int i = 0; i <= 60; ++i) {
    const double x = 0.5 * i;
    sim.x.push_back(x);
    sim.y.push_back(12.0 * x + 0.3 * x * x);
    ref.x.push_back(x);
    ref.y.push_back(10.0 * x + 0.35 * x * x);
  }
  for (int i = 0; i <= 10; ++i) {
    exp.x.push_back(3.0 * i);
    exp.y.push_back(11.0 * 3 * i + 0.32 * 9.0 * i * i);
  }
  plot.series = {sim, ref, exp};
  ASSERT_NO_THROW(plot_curves_png(plot, png));

  const Image img = read_png(png);
  ASSERT_EQ(img.width, 1000);
  ASSERT_EQ(img.height, 700);
  // Series colours are matplotlib's tab10 in order: blue, orange, green.
  const std::array<int, 3> blue{31, 119, 180}, orange{255, 127, 14}, green{44, 160, 44};
  long n_blue = 0, n_orange = 0, n_green = 0, n_background = 0;
  std::set<int> colours;
  for (int y = 0; y < img.height; ++y) {
    for (int x = 0; x < img.width; ++x) {
      const Rgb c = img.at(x, y);
      n_blue += near(c, blue, 12) ? 1 : 0;
      n_orange += near(c, orange, 12) ? 1 : 0;
      n_green += near(c, green, 12) ? 1 : 0;
      n_background += is_background(c) ? 1 : 0;
      colours.insert((c.r << 16) | (c.g << 8) | c.b);
    }
  }
  const double share_foreground = 1.0 - n_background / (double(img.width) * img.height);
  std::cout << "plot: blue " << n_blue << ", orange " << n_orange << ", green " << n_green
            << ", distinct colours " << colours.size() << ", non-background share "
            << share_foreground << "\n";
  // The solid blue line crosses the ~900 px wide plot area at 2.5 px width: thousands of pixels
  // (measured 2,079); the dashed green one less (427: dashes, and anti-aliased where it
  // crosses the blue one); the 11 orange markers plus the legend's (1,040).
  EXPECT_GT(n_blue, 1000);
  EXPECT_GT(n_green, 200);
  EXPECT_GT(n_orange, 300);
  // Not a uniform image: lines, grid, text, legend (measured 7.1 % non-background, 290 colours).
  EXPECT_GT(colours.size(), 50u);
  EXPECT_GT(share_foreground, 0.03);
  EXPECT_LT(share_foreground, 0.30);
}

namespace {

// Per-channel (R, G, B) mean and standard deviation of an image, in 0..255.
struct ChannelStats {
  std::array<double, 3> mean{}, stddev{};
};

ChannelStats channel_stats(const Image& img) {
  std::array<double, 3> sum{}, sum_sq{};
  for (int y = 0; y < img.height; ++y) {
    for (int x = 0; x < img.width; ++x) {
      const Rgb c = img.at(x, y);
      const double v[3] = {double(c.r), double(c.g), double(c.b)};
      for (int k = 0; k < 3; ++k) {
        sum[k] += v[k];
        sum_sq[k] += v[k] * v[k];
      }
    }
  }
  ChannelStats s;
  const double n = double(img.width) * img.height;
  for (int k = 0; k < 3; ++k) {
    s.mean[k] = sum[k] / n;
    s.stddev[k] = std::sqrt(std::max(0.0, sum_sq[k] / n - s.mean[k] * s.mean[k]));
  }
  return s;
}

// Back to NCFSIM_RENDER_BACKEND when a test that chose a back end ends, however it ends.
struct BackendOverride {
  explicit BackendOverride(RenderBackend b) { set_render_backend(b); }
  ~BackendOverride() { set_render_backend(std::nullopt); }
  BackendOverride(const BackendOverride&) = delete;
  BackendOverride& operator=(const BackendOverride&) = delete;
};

}  // namespace

// The same mesh figure and curve plot drawn by OSMesa and by EGL in one process are the same
// picture: per-channel mean and standard deviation within 0.5 (of 255), and under 0.5 % of the
// pixels differ. Both back ends are Mesa's llvmpipe behind the same VTK path; measured on Mesa
// 22.3.6: byte-identical PNGs. Auto picks OSMesa when it is installed (scripts/setup installs it).
TEST(Render, OSMesaAndEglDrawTheSamePicture) {
  {
    BackendOverride choose(RenderBackend::Auto);
    std::string why;
    ASSERT_TRUE(offscreen_rendering_available(&why)) << why;
    EXPECT_EQ(why.rfind("OSMesa: ", 0), 0u) << why;
  }
  MeshFigure figure;
  figure.field = "velocity";
  figure.title = "6 x 4 x 1 slab, velocity magnitude";
  figure.camera = CameraPreset::Iso;
  figure.width = 800;
  figure.height = 600;
  CurvePlot plot;
  plot.title = "two curves";
  plot.x_label = "x [mm]";
  plot.y_label = "y [N]";
  plot.series = {{"rising", {0.0, 1.0, 2.0, 3.0}, {0.0, 1.0, 4.0, 9.0}, false, false},
                 {"falling", {0.0, 1.0, 2.0, 3.0}, {9.0, 5.0, 2.0, 0.0}, true, false}};
  plot.width = 800;
  plot.height = 600;

  const std::pair<RenderBackend, const char*> backends[2] = {{RenderBackend::OSMesa, "osmesa"},
                                                             {RenderBackend::Egl, "egl"}};
  for (const char* scene : {"mesh", "plot"}) {
    Image img[2];
    for (int b = 0; b < 2; ++b) {
      BackendOverride choose(backends[b].first);
      std::string why;
      ASSERT_TRUE(offscreen_rendering_available(&why)) << backends[b].second << ": " << why;
      EXPECT_EQ(why.rfind(b == 0 ? "OSMesa: " : "EGL: ", 0), 0u) << why;
      const fs::path png =
          output_dir() / (std::string("backend_") + backends[b].second + "_" + scene + ".png");
      if (std::string(scene) == "mesh") {
        ASSERT_NO_THROW(render_mesh_png(slab(6, 4), figure, png)) << backends[b].second;
      } else {
        ASSERT_NO_THROW(plot_curves_png(plot, png)) << backends[b].second;
      }
      img[b] = read_png(png);
      ASSERT_EQ(img[b].width, 800);
      ASSERT_EQ(img[b].height, 600);
    }
    const ChannelStats os = channel_stats(img[0]), egl = channel_stats(img[1]);
    long n_differ = 0;
    for (int y = 0; y < 600; ++y) {
      for (int x = 0; x < 800; ++x) {
        const Rgb a = img[0].at(x, y), c = img[1].at(x, y);
        n_differ += (a.r != c.r || a.g != c.g || a.b != c.b) ? 1 : 0;
      }
    }
    std::cout << scene << ": mean RGB OSMesa " << os.mean[0] << " " << os.mean[1] << " "
              << os.mean[2] << ", EGL " << egl.mean[0] << " " << egl.mean[1] << " " << egl.mean[2]
              << "; std OSMesa " << os.stddev[0] << " " << os.stddev[1] << " " << os.stddev[2]
              << ", EGL " << egl.stddev[0] << " " << egl.stddev[1] << " " << egl.stddev[2]
              << "; pixels that differ " << n_differ << "\n";
    for (int k = 0; k < 3; ++k) {
      EXPECT_NEAR(os.mean[k], egl.mean[k], 0.5) << scene << " channel " << k;
      EXPECT_NEAR(os.stddev[k], egl.stddev[k], 0.5) << scene << " channel " << k;
    }
    // Not a blank picture on either side.
    EXPECT_GT(os.stddev[0], 10.0) << scene;
    EXPECT_LT(n_differ, 0.005 * 800 * 600) << scene;
  }
}

// A back end name the program does not know is an error naming the variable, not a silent
// default.
TEST(Render, UnknownBackendNamesTheVariable) {
  const char* old = std::getenv("NCFSIM_RENDER_BACKEND");
  const std::optional<std::string> saved =
      old != nullptr ? std::optional<std::string>(old) : std::nullopt;
  set_render_backend(std::nullopt);
  ::setenv("NCFSIM_RENDER_BACKEND", "vulkan", 1);
  std::string why;
  const bool ok = offscreen_rendering_available(&why);
  MeshFigure figure;
  figure.field = "temperature";
  bool threw = false;
  try {
    render_mesh_png(slab(2, 2), figure, output_dir() / "never_written.png");
  } catch (const std::runtime_error& e) {
    threw = std::string(e.what()).find("NCFSIM_RENDER_BACKEND='vulkan'") != std::string::npos;
  }
  if (saved) {
    ::setenv("NCFSIM_RENDER_BACKEND", saved->c_str(), 1);
  } else {
    ::unsetenv("NCFSIM_RENDER_BACKEND");
  }
  EXPECT_FALSE(ok);
  EXPECT_NE(why.find("NCFSIM_RENDER_BACKEND='vulkan'"), std::string::npos) << why;
  EXPECT_TRUE(threw);
  EXPECT_FALSE(fs::exists(output_dir() / "never_written.png"));
}

TEST(Render, UnknownFieldThrowsWithTheNames)
{
  MeshFigure figure;
  figure.field = "shear_angle_deg";
  try {
    render_mesh_png(slab(2, 2), figure, output_dir() / "never.png");
    FAIL() << "expected std::runtime_error";
  } catch (const std::runtime_error& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("unknown field 'shear_angle_deg'"), std::string::npos) << what;
    EXPECT_NE(what.find("temperature"), std::string::npos) << what;
  }
  EXPECT_FALSE(fs::exists(output_dir() / "never.png"));
}

TEST(Render, BadInputThrows)
{
  RenderMesh bad = slab(2, 2);
  bad.of(fem::ElementKind::Hex8)[3] = 1000;  // node id out of range
  MeshFigure figure;
  figure.field = "temperature";
  EXPECT_THROW(render_mesh_png(bad, figure, output_dir() / "never.png"), std::runtime_error);

  RenderMesh short_field = slab(2, 2);
  short_field.fields[0].values.pop_back();
  EXPECT_THROW(render_mesh_png(short_field, figure, output_dir() / "never.png"),
               std::runtime_error);

  figure.component = 3; // temperature has one component
  EXPECT_THROW(render_mesh_png(slab(2, 2), figure, output_dir() / "never.png"),
               std::runtime_error);

  CurvePlot plot;
  plot.series = {CurveSeries{"a", {0.0, 1.0}, {0.0}, false, false}};
  EXPECT_THROW(plot_curves_png(plot, output_dir() / "never.png"), std::runtime_error);
  EXPECT_FALSE(fs::exists(output_dir() / "never.png"));
}

// Eroded hexahedra are left out of a figure: a 3 x 2 slab (temperature i + 0.5 per cell) with a
// bar, less its two middle cells, keeps 4 hexahedra and their values (0.5, 2.5, 0.5, 2.5) in
// order, the bar and its value after them, every point and the point field; the slab less those
// cells renders (a gap down the middle).
TEST(Render, WithoutHexesDropsTheCellsAndTheirValues) {
  RenderMesh mesh = slab(3, 2);
  mesh.of(fem::ElementKind::Bar2) = {0, 3};
  MeshField stress{"stress", "Pa", true, 2, {}};
  for (int c = 0; c < 6; ++c) {
    stress.values.insert(stress.values.end(), {double(c), 10.0 * c});
  }
  stress.values.insert(stress.values.end(), {-1.0, -2.0});  // the bar
  mesh.fields[0].values.push_back(7.0);                     // temperature of the bar
  mesh.fields.push_back(stress);
  const std::vector<char> drop{0, 1, 0, 0, 1, 0};
  const RenderMesh kept = without_hexes(mesh, drop);
  ASSERT_EQ(kept.of(fem::ElementKind::Hex8).size(), 4u * 8u);
  EXPECT_EQ(std::vector<std::int64_t>(kept.of(fem::ElementKind::Hex8).begin() + 8,
                                      kept.of(fem::ElementKind::Hex8).begin() + 16),
            std::vector<std::int64_t>(mesh.of(fem::ElementKind::Hex8).begin() + 16,
                                      mesh.of(fem::ElementKind::Hex8).begin() + 24));
  EXPECT_EQ(kept.points, mesh.points);
  EXPECT_EQ(kept.of(fem::ElementKind::Bar2), mesh.of(fem::ElementKind::Bar2));
  ASSERT_EQ(kept.fields.size(), 3u);
  EXPECT_EQ(kept.fields[0].values, (std::vector<double>{0.5, 2.5, 0.5, 2.5, 7.0}));
  EXPECT_EQ(kept.fields[1].values, mesh.fields[1].values);  // on the points
  EXPECT_EQ(kept.fields[2].values, (std::vector<double>{0, 0, 2, 20, 3, 30, 5, 50, -1, -2}));
  EXPECT_THROW(without_hexes(mesh, {0, 1}), std::invalid_argument);

  MeshFigure figure;
  figure.field = "temperature";
  const fs::path png = output_dir() / "slab_without_middle.png";
  EXPECT_NO_THROW(render_mesh_png(kept, figure, png));
  EXPECT_TRUE(fs::exists(png));
}

namespace {

// n_x x n_y shells of unit size in the plane z = z0, x in [x0, x0 + n_x], y in [0, n_y], corners
// counter-clockwise seen from +z (normal +z), or clockwise (normal -z) with `flipped`. Appended
// to `mesh` on nodes of their own; returns the index of the first shell.
std::size_t add_plate(RenderMesh& mesh, int n_x, int n_y, double x0, double z0,
                      bool flipped = false)
{
  const auto first = static_cast<std::int64_t>(mesh.points.size() / 3);
  auto node = [&](int i, int j) { return first + static_cast<std::int64_t>(j * (n_x + 1) + i); };
  for (int j = 0; j <= n_y; ++j) {
    for (int i = 0; i <= n_x; ++i) {
      mesh.points.insert(mesh.points.end(), {x0 + i, double(j), z0});
    }
  }
  const std::size_t first_shell = mesh.of(fem::ElementKind::Quad4).size() / 4;
  for (int j = 0; j < n_y; ++j) {
    for (int i = 0; i < n_x; ++i) {
      if (flipped) {
        mesh.of(fem::ElementKind::Quad4)
            .insert(mesh.of(fem::ElementKind::Quad4).end(),
                    {node(i, j), node(i, j + 1), node(i + 1, j + 1), node(i + 1, j)});
      } else {
        mesh.of(fem::ElementKind::Quad4)
            .insert(mesh.of(fem::ElementKind::Quad4).end(),
                    {node(i, j), node(i + 1, j), node(i + 1, j + 1), node(i, j + 1)});
      }
    }
  }
  return first_shell;
}

struct PixelCount {
  long model = 0, saturated = 0, blue = 0, red = 0, grey = 0;
  double blue_x = 0.0, red_x = 0.0;
};

// Pixels of the model viewport (left of the scalar bar, below the title).
PixelCount count_model_pixels(const Image& img)
{
  PixelCount n;
  for (int y = 0; y < static_cast<int>(0.92 * img.height); ++y) {
    for (int x = 0; x < static_cast<int>(0.82 * img.width); ++x) {
      const Rgb c = img.at(x, y);
      n.model += is_background(c) ? 0 : 1;
      n.saturated += is_saturated(c) ? 1 : 0;
      n.grey += near(c, {128, 128, 128}, 12) ? 1 : 0; // the NaN colour (0.5, 0.5, 0.5)
      if (is_blueish(c)) {
        ++n.blue;
        n.blue_x += x;
      }
      if (is_redish(c)) {
        ++n.red;
        n.red_x += x;
      }
    }
  }
  return n;
}

} // namespace

// A shells-only 10 x 10 plate (no hexahedra, no bars) seen from the top, coloured by a cell field
// linear in x (the shear angle of a macro drape, 0.5 .. 9.5 deg): the plate fills the expected
// square, the colour range spans the field (the x = 0..1 column blue, the x = 9..10 column red,
// blue left of red), the plate looks the same seen from below (clockwise corners: two-sided
// lighting), and a 3-component cell field (magnitude) and a point field colour it too.
//
// Expected size as in SlabTopViewPixelStatistics: bounds 10 x 10 x 0, r = |(10, 10, 0)| / 2 =
// 7.071, the plate spans 828 * 10 / (2 r) = 585.5 px each way: 342,800 px.
TEST(Render, ShellsOnlyPlateColouredByCellField)
{
  for (const bool flipped : {false, true}) {
    RenderMesh mesh;
    add_plate(mesh, 10, 10, 0.0, 0.0, flipped);
    ASSERT_TRUE(mesh.of(fem::ElementKind::Hex8).empty() && mesh.of(fem::ElementKind::Bar2).empty());
    MeshField shear{"shear_angle_deg", "deg", true, 1, {}};
    MeshField membrane{"membrane_force", "N/m", true, 3, {}};
    for (int j = 0; j < 10; ++j) {
      for (int i = 0; i < 10; ++i) {
        shear.values.push_back(i + 0.5);
        membrane.values.insert(membrane.values.end(), {0.0, -(i + 0.5), 0.0}); // |.| = i + 0.5
      }
    }
    MeshField velocity{"velocity", "m/s", false, 3, {}};
    for (std::size_t p = 0; p < mesh.points.size(); p += 3) {
      velocity.values.insert(velocity.values.end(), {mesh.points[p], 0.0, 0.0});
    }
    mesh.fields = {shear, membrane, velocity};

    for (const char* field : {"shear_angle_deg", "membrane_force", "velocity"}) {
      const fs::path png = output_dir() / (std::string("plate_") + field +
                                           (flipped ? "_from_below" : "") + ".png");
      fs::remove(png);
      MeshFigure figure;
      figure.field = field;
      figure.title = "10 x 10 shells, " + std::string(field);
      figure.camera = CameraPreset::Top;
      ASSERT_NO_THROW(render_mesh_png(mesh, figure, png)) << field;
      const Image img = read_png(png);
      ASSERT_EQ(img.width, 1200);
      ASSERT_EQ(img.height, 900);
      const PixelCount n = count_model_pixels(img);
      std::cout << field << (flipped ? " (clockwise)" : "") << ": plate pixels " << n.saturated
                << ", blue " << n.blue << ", red " << n.red << "\n";

      const double expected_plate = std::pow(0.92 * img.height * 10.0 / std::sqrt(200.0), 2);
      EXPECT_NEAR(n.saturated, expected_plate, 0.02 * expected_plate) << field;
      // A cell field: one column of cells (10 % of the plate) at each end of the map; a point
      // field interpolated from 0 to 10 along x: the outer 5 % or so.
      const double end_share = std::string(field) == "velocity" ? 0.03 : 0.07;
      EXPECT_GT(n.blue, end_share * expected_plate) << field;
      EXPECT_GT(n.red, end_share * expected_plate) << field;
      ASSERT_GT(n.blue, 0);
      ASSERT_GT(n.red, 0);
      EXPECT_LT(n.blue_x / n.blue + 0.6 * std::sqrt(expected_plate), n.red_x / n.red) << field;
    }
  }
}

// Hexahedra, bars and shells in one mesh; a cell field's values are the hexes', then the bars',
// then the shells'. A 4 x 4 x 1 slab (x in [0, 4]) at value 0, a 4 x 4 plate beside it (x in
// [5, 9], z = 0.5) at value 10, a bar from the slab to the plate at value 5: from the top the
// slab is blue, the plate red (same size: 16 cells each), blue left of red. A field the shells
// do not have (NaN there) draws them grey; a point field colours all three kinds.
TEST(Render, MixedHexBarShellMesh)
{
  RenderMesh mesh = slab(4, 4);
  mesh.fields.clear();
  add_plate(mesh, 4, 4, 5.0, 0.5);
  mesh.of(fem::ElementKind::Bar2) = {
      static_cast<std::int64_t>(4 * 5 + 4 + 25),  // slab top corner (4, 4, 1) ..
      static_cast<std::int64_t>(50)};             // .. first plate node (5, 0, 0.5)
  ASSERT_EQ(mesh.of(fem::ElementKind::Hex8).size() / 8, 16u);
  ASSERT_EQ(mesh.of(fem::ElementKind::Quad4).size() / 4, 16u);
  const double nan = std::numeric_limits<double>::quiet_NaN();
  MeshField value{"value", "-", true, 1, {}};
  MeshField hex_only{"von_mises_stress", "Pa", true, 1, {}};
  value.values.assign(16, 0.0);
  value.values.push_back(5.0);
  value.values.insert(value.values.end(), 16, 10.0);
  for (int e = 0; e < 16; ++e) {
    hex_only.values.push_back(e);
  }
  hex_only.values.push_back(nan);
  hex_only.values.insert(hex_only.values.end(), 16, nan);
  MeshField height{"height", "m", false, 1, {}};
  for (std::size_t p = 0; p < mesh.points.size(); p += 3) {
    height.values.push_back(mesh.points[p]); // x
  }
  mesh.fields = {value, hex_only, height};

  const fs::path png = output_dir() / "mixed_hex_bar_shell.png";
  MeshFigure figure;
  figure.field = "value";
  figure.camera = CameraPreset::Top;
  figure.title = "hexahedra 0, bar 5, shells 10";
  ASSERT_NO_THROW(render_mesh_png(mesh, figure, png));
  PixelCount n = count_model_pixels(read_png(png));
  std::cout << "mixed: blue " << n.blue << ", red " << n.red << ", saturated " << n.saturated
            << "\n";
  // The bounds are 9 x 4 x 1: r = |(9, 4, 1)| / 2 = 4.95; a 4 x 4 square is 828 * 4 / (2 r) =
  // 334.5 px wide: 111,900 px each.
  const double square = std::pow(0.92 * 900 * 4.0 / std::sqrt(98.0), 2);
  EXPECT_NEAR(n.blue, square, 0.05 * square);
  EXPECT_NEAR(n.red, square, 0.05 * square);
  ASSERT_GT(n.blue, 0);
  ASSERT_GT(n.red, 0);
  EXPECT_LT(n.blue_x / n.blue + 300.0, n.red_x / n.red);

  figure.field = "von_mises_stress"; // seen from the top: faces lit head-on show exact colours
  const fs::path png_nan = output_dir() / "mixed_hex_field_on_shells.png";
  ASSERT_NO_THROW(render_mesh_png(mesh, figure, png_nan));
  n = count_model_pixels(read_png(png_nan));
  std::cout << "hex field: grey " << n.grey << ", saturated " << n.saturated << "\n";
  EXPECT_GT(n.grey, 0.5 * square) << "the shells (NaN) are grey";
  EXPECT_GT(n.saturated, 0.5 * square) << "the hexahedra are coloured";

  figure.field = "height";
  const fs::path png_point = output_dir() / "mixed_point_field.png";
  ASSERT_NO_THROW(render_mesh_png(mesh, figure, png_point));
  n = count_model_pixels(read_png(png_point));
  EXPECT_GT(n.blue, 0.1 * square);
  EXPECT_GT(n.red, 0.1 * square);
  EXPECT_LT(n.grey, 0.01 * square) << "every kind has the point field";

  // A cell field sized for the hexes and bars alone is refused, naming the count it expects.
  mesh.fields[0].values.resize(17);
  figure.field = "value";
  try {
    render_mesh_png(mesh, figure, output_dir() / "never.png");
    FAIL() << "expected std::runtime_error";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("expected 33 cells"), std::string::npos) << e.what();
  }
  RenderMesh bad = mesh;
  bad.of(fem::ElementKind::Quad4).pop_back();
  EXPECT_THROW(render_mesh_png(bad, figure, output_dir() / "never.png"), std::runtime_error);
  bad = mesh;
  bad.of(fem::ElementKind::Quad4)[5] = -1;
  EXPECT_THROW(render_mesh_png(bad, figure, output_dir() / "never.png"), std::runtime_error);
  EXPECT_FALSE(fs::exists(output_dir() / "never.png"));
}

// without_cells takes one flag per cell (hexes, bars, shells): dropping a hexahedron, the bar and
// a shell keeps the others and their values in order; without_hexes keeps every bar and shell.
TEST(Render, WithoutCellsDropsShellsToo)
{
  RenderMesh mesh = slab(2, 1);
  mesh.fields.clear();
  add_plate(mesh, 3, 1, 3.0, 0.0);
  mesh.of(fem::ElementKind::Bar2) = {0, 1};
  MeshField f{"f", "-", true, 2, {}};
  for (int c = 0; c < 6; ++c) { // 2 hexes, 1 bar, 3 shells
    f.values.insert(f.values.end(), {double(c), -double(c)});
  }
  mesh.fields = {f};
  const RenderMesh kept = without_cells(mesh, {1, 0, 1, 0, 1, 0});
  EXPECT_EQ(kept.of(fem::ElementKind::Hex8),
            std::vector<std::int64_t>(mesh.of(fem::ElementKind::Hex8).begin() + 8,
                                      mesh.of(fem::ElementKind::Hex8).end()));
  EXPECT_TRUE(kept.of(fem::ElementKind::Bar2).empty());
  ASSERT_EQ(kept.of(fem::ElementKind::Quad4).size(), 8u);
  EXPECT_EQ(std::vector<std::int64_t>(kept.of(fem::ElementKind::Quad4).begin(),
                                      kept.of(fem::ElementKind::Quad4).begin() + 4),
            std::vector<std::int64_t>(mesh.of(fem::ElementKind::Quad4).begin(),
                                      mesh.of(fem::ElementKind::Quad4).begin() + 4));
  EXPECT_EQ(std::vector<std::int64_t>(kept.of(fem::ElementKind::Quad4).begin() + 4,
                                      kept.of(fem::ElementKind::Quad4).end()),
            std::vector<std::int64_t>(mesh.of(fem::ElementKind::Quad4).begin() + 8,
                                      mesh.of(fem::ElementKind::Quad4).end()));
  EXPECT_EQ(kept.fields[0].values, (std::vector<double>{1, -1, 3, -3, 5, -5}));
  EXPECT_THROW(without_cells(mesh, {0, 0, 0}), std::invalid_argument);

  const RenderMesh no_hex = without_hexes(mesh, {1, 1});
  EXPECT_TRUE(no_hex.of(fem::ElementKind::Hex8).empty());
  EXPECT_EQ(no_hex.of(fem::ElementKind::Bar2), mesh.of(fem::ElementKind::Bar2));
  EXPECT_EQ(no_hex.of(fem::ElementKind::Quad4), mesh.of(fem::ElementKind::Quad4));
  EXPECT_EQ(no_hex.fields[0].values, (std::vector<double>{2, -2, 3, -3, 4, -4, 5, -5}));
}

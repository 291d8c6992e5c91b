// Figures of a shell run through the CLI (issue #19): the shell cantilever
// (cases/verification/shell_cantilever.toml, shortened to 0.01 s) writes its default figures, the
// mesh picture included, as non-blank PNGs; a [[figures.picture]] of the shells' cell field
// shear_angle_deg (how the macro drape shows its shear) is drawn too. Pixel statistics, not only
// that the files exist: the pictures of the strip are coloured along it (both ends of the map).
#include <gtest/gtest.h>
#include <vtkImageData.h>
#include <vtkNew.h>
#include <vtkPNGReader.h>
#include <vtkSmartPointer.h>

#include <algorithm>
#include <fstream>
#include <string>

#include "tests/workflow/cli_test_support.hpp"

namespace ncfsim::test {
namespace {

struct PngStats {
  int width = 0, height = 0;
  long not_white = 0;  // pixels that are not the white background, in the whole image
  // In a mesh picture's model viewport (left of the scalar bar, below the title; rows are
  // bottom-up): colour-map colours (max - min channel > 100), its blue and its red end.
  long saturated = 0, blue = 0, red = 0;
};

// Reads a PNG back with VTK and counts its pixels; width 0 when it cannot be read.
PngStats png_stats(const fs::path& png) {
  PngStats s;
  vtkNew<vtkPNGReader> reader;
  if (reader->CanReadFile(png.c_str()) == 0) return s;
  reader->SetFileName(png.c_str());
  reader->Update();
  vtkImageData* img = reader->GetOutput();
  int dims[3] = {0, 0, 0};
  img->GetDimensions(dims);
  if (img->GetNumberOfScalarComponents() < 3) return s;
  s.width = dims[0];
  s.height = dims[1];
  for (int y = 0; y < dims[1]; ++y)
    for (int x = 0; x < dims[0]; ++x) {
      const auto* p = static_cast<const unsigned char*>(img->GetScalarPointer(x, y, 0));
      const int r = p[0], g = p[1], b = p[2];
      s.not_white += (r < 250 || g < 250 || b < 250) ? 1 : 0;
      if (x >= 0.82 * dims[0] || y >= 0.92 * dims[1]) continue;
      s.saturated += std::max({r, g, b}) - std::min({r, g, b}) > 100 ? 1 : 0;
      // The ends of the map whatever the shading (the iso camera sees the strip obliquely).
      s.blue += (b > 100 && 4 * r < b && 3 * g < b) ? 1 : 0;
      s.red += (r > 100 && 4 * g < r && 4 * b < r) ? 1 : 0;
    }
  return s;
}

const fs::path kCase = kSource / "cases/verification/shell_cantilever.toml";

// The default figures: energy balance, the case's tip plot and the deformed strip coloured by
// the displacement magnitude (0 at the clamp, largest at the tip: blue and red both on it).
TEST(CliShellFigures, ShellCantileverWritesItsDefaultFiguresNonBlank) {
  const fs::path out = fresh_dir("shell_figures");
  const Result r = run_cli({"run", kCase.string(), "-o", out.string(), "--set",
                            "time.end_time=0.01", "--set", "output.report=false"});
  ASSERT_EQ(r.code, 0) << r.output;
  EXPECT_EQ(r.output.find("skipped"), std::string::npos) << r.output;
  EXPECT_EQ(slurp(out / "warnings.txt").find("figure"), std::string::npos)
      << slurp(out / "warnings.txt");
  for (const char* name : {"energy_balance", "tip_displacement", "final_displacement"}) {
    const PngStats s = png_stats(out / "figures" / (std::string(name) + ".png"));
    ASSERT_GT(s.width, 0) << name << ": not a readable PNG";
    // A plot or a picture covers several % of its image (axes, curves, text, the model).
    EXPECT_GT(s.not_white, 0.02 * s.width * s.height) << name;
  }
  // The strip: 40 shells, 200 x 20 mm, seen from the iso camera: measured 4.3 % of the image in
  // colour-map colours, 15,000 px of them at the blue end (the clamped half) and 2,200 at the red
  // end (the tip).
  const PngStats d = png_stats(out / "figures/final_displacement.png");
  std::cout << "final_displacement: saturated " << d.saturated << ", blue " << d.blue << ", red "
            << d.red << " of " << d.width * d.height << "\n";
  EXPECT_GT(d.saturated, 0.03 * d.width * d.height);
  EXPECT_GT(d.blue, 5000);
  EXPECT_GT(d.red, 1000);
  // Shells have no stress tensor: no default von Mises picture (it would only be skipped).
  EXPECT_FALSE(fs::exists(out / "figures/final_von_mises.png"));
  fs::remove_all(out);
}

// Case pictures of the shells' cell fields: shear_angle_deg from the top, and a component of
// fibre_direction from the iso camera following the strip's part, displacements scaled.
TEST(CliShellFigures, ShearAnglePictureOfShells) {
  const fs::path out = fresh_dir("shell_shear_picture");
  const fs::path toml = fs::temp_directory_path() /
                        ("ncfsim_test_shell_pictures_" + std::to_string(getpid()) + ".toml");
  {
    std::ofstream f(toml);
    f << slurp(kCase) << R"(
[[figures.picture]]
name = "shear"
field = "shear_angle_deg"
camera = "top"
title = "Shell strip: shear angle"

[[figures.picture]]
name = "fibres"
field = "fibre_direction"
component = 0
camera = "iso"
follow_part = "strip"
deformation_scale = 20.0
title = "Shell strip: fibre direction x"
)";
  }
  const Result r = run_cli({"run", toml.string(), "-o", out.string(), "--set", "time.end_time=0.01",
                            "--set", "output.report=false"});
  fs::remove(toml);
  ASSERT_EQ(r.code, 0) << r.output;
  EXPECT_EQ(r.output.find("skipped"), std::string::npos) << r.output;
  for (const char* name : {"shear", "fibres"}) {
    const PngStats s = png_stats(out / "figures" / (std::string(name) + ".png"));
    ASSERT_GT(s.width, 0) << name << ": not a readable PNG";
    std::cout << name << ": saturated " << s.saturated << " of " << s.width * s.height << "\n";
    // Measured: the strip from the top 6.2 % of the image, from the iso camera 4.5 %.
    EXPECT_GT(s.saturated, 0.03 * s.width * s.height) << name;
  }
  fs::remove_all(out);
}

}  // namespace
}  // namespace ncfsim::test

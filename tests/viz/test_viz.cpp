// The viz module: colourings, screenshots of a synthetic two-class cloud (headless: the CLI runs
// itself under xvfb-run when there is no display), and the training report.
#include <gtest/gtest.h>

#include <vtkImageData.h>
#include <vtkNew.h>
#include <vtkPNGReader.h>

#include <cmath>
#include <fstream>
#include <map>

#include "sadsplat/common/error.h"
#include "sadsplat/io/filesystem.h"
#include "sadsplat/io/gaussian_ply.h"
#include "sadsplat/io/scene.h"
#include "sadsplat/viz/color_mode.h"
#include "test_support/test_support.h"

namespace sadsplat {
namespace {

using test::kCli;
const std::array<std::uint8_t, 3> kRed = {220, 30, 30};
const std::array<std::uint8_t, 3> kBlue = {30, 60, 220};
const std::array<std::uint8_t, 3> kBackground = {28, 30, 36};

struct Png {
  int width = 0, height = 0;
  std::vector<std::array<int, 3>> pixels;
  const std::array<int, 3>& at(int x, int y) const { return pixels[y * width + x]; }
};

Png readPng(const std::string& path) {
  vtkNew<vtkPNGReader> reader;
  reader->SetFileName(path.c_str());
  reader->Update();
  vtkImageData* image = reader->GetOutput();
  int dims[3];
  image->GetDimensions(dims);
  Png png;
  png.width = dims[0];
  png.height = dims[1];
  const int channels = image->GetNumberOfScalarComponents();
  for (int y = png.height - 1; y >= 0; --y) {  // VTK's rows run bottom-up
    for (int x = 0; x < png.width; ++x) {
      std::array<int, 3> p{};
      for (int c = 0; c < 3 && c < channels; ++c) {
        p[c] = static_cast<int>(image->GetScalarComponentAsDouble(x, y, 0, c));
      }
      png.pixels.push_back(p);
    }
  }
  return png;
}

bool near(const std::array<int, 3>& p, const std::array<std::uint8_t, 3>& c, int tolerance) {
  for (int k = 0; k < 3; ++k) {
    if (std::abs(p[k] - c[k]) > tolerance) return false;
  }
  return true;
}

// Share of the pixels of columns [x0, x1) whose colour is near `c`.
double share(const Png& png, int x0, int x1, const std::array<std::uint8_t, 3>& c) {
  std::size_t n = 0, hit = 0;
  for (int y = 0; y < png.height; ++y) {
    for (int x = x0; x < x1; ++x, ++n) hit += near(png.at(x, y), c, 60);
  }
  return static_cast<double>(hit) / std::max<std::size_t>(n, 1);
}

// A flat 2 x 1 m field: class "a" (red) for x < 0, class "b" (blue) for x > 0, dense opaque
// splats whose own colour (SH DC) is green; written with classes.json beside it.
void writeTwoClassModel(const std::string& dir, bool semantic = true) {
  pcl::PointCloud<GaussianPoint> cloud;
  for (int i = 0; i < 40; ++i) {
    for (int j = 0; j < 20; ++j) {
      GaussianPoint p;
      p.x = -1.0f + (i + 0.5f) / 20.0f;
      p.y = -0.5f + (j + 0.5f) / 20.0f;
      p.z = 0.0f;
      for (float& s : p.scale) s = std::log(0.03f);
      p.opacity = 5.0f;
      p.f_dc[0] = -1.5f;
      p.f_dc[1] = 1.5f;
      p.f_dc[2] = -1.5f;
      p.label = p.x < 0 ? 0 : 1;
      p.confidence = p.x < 0 ? 0.0f : 1.0f;
      p.log_alpha = 3.0f;
      cloud.push_back(p);
    }
  }
  io::PlyWriteOptions options;
  options.semantic = semantic;
  io::writeGaussianPly(dir + "/model.ply", cloud, options);
  io::writeClassesJson(dir + "/classes.json", {{"a", kRed, "a"}, {"b", kBlue, "b"}});
}

std::string screenshot(const std::string& model, const std::string& png, const std::string& extra,
                       std::string* out) {
  const int rc = test::runCommand(
      kCli + " view " + model + " --screenshot " + png + " --size 320x240 " + extra, out);
  return rc == 0 ? png : std::string();
}

TEST(ColorMode, NamesRoundTripAndUnknownNamesAreErrors) {
  for (const char* name : {"class", "rgb", "confidence", "gate", "opacity"}) {
    EXPECT_EQ(viz::colorModeName(viz::parseColorMode(name)), name);
  }
  try {
    viz::parseColorMode("heat");
    FAIL();
  } catch (const Error& e) {
    EXPECT_EQ(e.field(), "--color");
  }
}

TEST(ColorMode, ValuesAreTheDocumentedFunctions) {
  GaussianPoint p;
  p.opacity = 0.0f;
  p.log_alpha = 0.0f;
  p.confidence = 0.25f;
  EXPECT_FLOAT_EQ(viz::scalarValue(p, viz::ColorMode::kOpacity), 0.5f);
  EXPECT_FLOAT_EQ(viz::scalarValue(p, viz::ColorMode::kConfidence), 0.25f);
  // P(z > 0) = sigmoid(log_alpha - (2/3) logit(1/12)) = sigmoid(1.5986) at log_alpha = 0.
  EXPECT_NEAR(viz::gateOpenProbability(0.0f), 1.0 / (1.0 + std::exp(-1.598612)), 1e-5);
  EXPECT_LT(viz::gateOpenProbability(-5.0f), viz::gateOpenProbability(5.0f));
  const auto grey = viz::dcColor(p);  // f_dc = 0: 0.5 grey
  EXPECT_EQ(grey[0], 128);
  p.f_dc[0] = 10.0f;
  EXPECT_EQ(viz::dcColor(p)[0], 255);
}

// The classes are drawn where they are, in their colours, and the background elsewhere.
TEST(ViewScreenshot, ShowsBothClassColoursWhereTheClassesAre) {
  test::TempDir dir;
  writeTwoClassModel(dir.path());
  std::string out;
  ASSERT_FALSE(screenshot(dir.path(), dir.file("class.png"), "", &out).empty()) << out;
  const Png png = readPng(dir.file("class.png"));
  ASSERT_EQ(png.width, 320);
  ASSERT_EQ(png.height, 240);
  const int third = png.width / 3;
  const double red_left = share(png, 0, third, kRed), red_right = share(png, 2 * third, 320, kRed);
  const double blue_left = share(png, 0, third, kBlue);
  const double blue_right = share(png, 2 * third, 320, kBlue);
  // One side red, the other blue (which side depends on the viewing direction).
  EXPECT_GT(std::max(red_left, red_right), 0.10) << out;
  EXPECT_GT(std::max(blue_left, blue_right), 0.10) << out;
  EXPECT_TRUE((red_left > 5 * blue_left && blue_right > 5 * red_right) ||
              (red_right > 5 * blue_right && blue_left > 5 * red_left))
      << red_left << " " << red_right << " " << blue_left << " " << blue_right;
  // The background at the top corners (the field is seen from 45 degrees, below them).
  EXPECT_TRUE(near(png.at(300, 30), kBackground, 8));
  EXPECT_TRUE(near(png.at(5, 60), kBackground, 8));
}

TEST(ViewScreenshot, ColourModesAndClassSelectionChangeThePicture) {
  test::TempDir dir;
  writeTwoClassModel(dir.path());
  std::string out;
  ASSERT_FALSE(screenshot(dir.path(), dir.file("rgb.png"), "--color rgb", &out).empty()) << out;
  const Png rgb = readPng(dir.file("rgb.png"));
  const std::array<std::uint8_t, 3> green = {0, 230, 0};  // 0.5 + C0 * 1.5 = 0.92 green
  EXPECT_GT(share(rgb, 0, 320, green), 0.15) << out;
  EXPECT_LT(share(rgb, 0, 320, kRed), 0.01);

  ASSERT_FALSE(screenshot(dir.path(), dir.file("a.png"), "--class a", &out).empty()) << out;
  const Png only_a = readPng(dir.file("a.png"));
  EXPECT_GT(share(only_a, 0, 320, kRed), 0.05);
  EXPECT_LT(share(only_a, 0, 320, kBlue), 0.001);

  // Confidence 0 (class a) and 1 (class b) map to the ends of the blue-to-red scale.
  ASSERT_FALSE(screenshot(dir.path(), dir.file("conf.png"), "--color confidence", &out).empty())
      << out;
  const Png conf = readPng(dir.file("conf.png"));
  const std::array<std::uint8_t, 3> pure_red = {255, 0, 0}, pure_blue = {0, 0, 255};
  EXPECT_GT(share(conf, 0, 320, pure_red), 0.05);
  EXPECT_GT(share(conf, 0, 320, pure_blue), 0.05);

  // Two models side by side: the left half and the right half both hold the field.
  ASSERT_FALSE(
      screenshot(dir.path(), dir.file("cmp.png"), "--compare " + dir.file("model.ply"), &out)
          .empty())
      << out;
  const Png cmp = readPng(dir.file("cmp.png"));
  EXPECT_GT(share(cmp, 0, 160, kRed) + share(cmp, 0, 160, kBlue), 0.1);
  EXPECT_GT(share(cmp, 160, 320, kRed) + share(cmp, 160, 320, kBlue), 0.1);
}

TEST(ViewScreenshot, BadInputIsAOneLineError) {
  test::TempDir dir;
  writeTwoClassModel(dir.path());
  std::string out;
  const std::string base = kCli + " view " + dir.path() + " --screenshot " + dir.file("x.png");
  EXPECT_EQ(test::runCommand(base + " --class water", &out), 1);
  EXPECT_NE(out.find("--class water: expected one of: a, b"), std::string::npos) << out;
  EXPECT_EQ(test::runCommand(base + " --color heat", &out), 1);
  EXPECT_NE(out.find("--color"), std::string::npos) << out;
  EXPECT_EQ(test::runCommand(base + " --view view_042", &out), 1);
  EXPECT_NE(out.find("--view view_042"), std::string::npos) << out;
  EXPECT_EQ(test::runCommand(base + " --size 12", &out), 1);
  EXPECT_EQ(test::runCommand(
                kCli + " view " + dir.file("none") + " --screenshot " + dir.file("x.png"), &out),
            1);
  EXPECT_NE(out.find("no such file"), std::string::npos) << out;
  test::TempDir plain;
  writeTwoClassModel(plain.path(), /*semantic=*/false);
  EXPECT_EQ(test::runCommand(kCli + " view " + plain.path() + "/model.ply --screenshot " +
                                 dir.file("x.png") + " --color gate",
                             &out),
            1);
  EXPECT_NE(out.find("semantic fields"), std::string::npos) << out;
  EXPECT_FALSE(std::ifstream(dir.file("x.png")).good());
}

bool nonBlank(const std::string& path) {
  const Png png = readPng(path);
  std::size_t coloured = 0;
  for (const auto& p : png.pixels) {
    coloured += std::abs(p[0] - p[1]) > 40 || std::abs(p[1] - p[2]) > 40;  // plot lines, bars
  }
  return png.width > 100 && coloured > 200;
}

// A short run with the full drop, evaluated; the report holds every plot, non-blank, linked.
TEST(Report, HoldsEveryPlotAndLinksThem) {
  test::TempDir dir;
  // Both runs called "run" (as `sadsplat demo` names them): their names and plot columns must
  // not collide (a vtkTable column of the same name replaced the first one).
  const std::string run = dir.file("full/run"), base = dir.file("base/run");
  test::writeFile(dir.file("cfg.json"), "{\"drop\": \"full\", \"drop_interval\": 10}");
  const std::string cache = std::string(SADSPLAT_TEST_DATA_DIR) + "/tiny_scene.cache";
  std::string out;
  ASSERT_EQ(test::runCommand(kCli + " train " + cache + " --iterations 40 --config " +
                                 dir.file("cfg.json") + " --out " + run,
                             &out),
            0)
      << out;
  ASSERT_EQ(test::runCommand(kCli + " train " + cache + " --iterations 40 --out " + base, &out), 0)
      << out;
  ASSERT_EQ(test::runCommand(kCli + " eval " + run + " && " + kCli + " eval " + base, &out), 0)
      << out;
  ASSERT_EQ(test::runCommand(kCli + " report " + run + " --baseline " + base, &out), 0) << out;
  const std::string md = test::readFile(run + "/report/report.md");
  for (const char* png : {"loss.png", "gaussians.png", "per_class_iou.png"}) {
    EXPECT_NE(md.find(std::string("](") + png + ")"), std::string::npos) << png << md;
    EXPECT_TRUE(nonBlank(run + "/report/" + png)) << png;
  }
  EXPECT_NE(md.find("| mIoU (%) |"), std::string::npos) << md;
  EXPECT_NE(md.find("| PSNR on covered pixels (dB) | "), std::string::npos) << md;
  EXPECT_EQ(md.find("| PSNR on covered pixels (dB) | - |"), std::string::npos) << md;  // a value
  EXPECT_NE(md.find("| | full/run | base/run |"), std::string::npos) << md;
  EXPECT_NE(md.find("](../panels/view_002.png)"), std::string::npos) << md;
  EXPECT_NE(md.find("| 10 | "), std::string::npos) << md;  // the drop event at iteration 10
  // The run's own cameras: a view from test camera view_002 shows the scene.
  ASSERT_EQ(test::runCommand(kCli + " view " + run +
                                 " --view view_002 --color rgb --size 160x120 "
                                 "--screenshot " +
                                 dir.file("cam.png"),
                             &out),
            0)
      << out;
  ASSERT_EQ(test::runCommand(kCli + " view " + run + " --color rgb --size 160x120 --screenshot " +
                                 dir.file("aerial.png"),
                             &out),
            0)
      << out;
  const Png cam = readPng(dir.file("cam.png")), aerial = readPng(dir.file("aerial.png"));
  EXPECT_LT(share(cam, 0, cam.width, kBackground), 0.99) << "the camera sees some Gaussians";
  std::size_t differ = 0;
  for (std::size_t i = 0; i < cam.pixels.size(); ++i) differ += cam.pixels[i] != aerial.pixels[i];
  EXPECT_GT(differ, cam.pixels.size() / 50) << "the view from view_002 is not the aerial view";
  EXPECT_EQ(test::runCommand(kCli + " report " + dir.file("nothing"), &out), 1);
  EXPECT_NE(out.find("run directory"), std::string::npos) << out;
}

// A run whose log records the max_gaussians cap: the report says so, with the iteration; a run
// without the record does not.
TEST(Report, SaysWhenTheModelReachedTheGaussianCap) {
  test::TempDir dir;
  const std::string steps =
      "{\"type\":\"step\",\"iteration\":10,\"loss\":0.5,\"rgb_loss\":0.5,"
      "\"semantic_loss\":0,\"gaussians\":400,\"seconds\":1}\n"
      "{\"type\":\"step\",\"iteration\":20,\"loss\":0.4,\"rgb_loss\":0.4,"
      "\"semantic_loss\":0,\"gaussians\":800,\"seconds\":2}\n";
  io::makeDirectory(dir.file("capped"));
  io::makeDirectory(dir.file("plain"));
  test::writeFile(dir.file("capped/train_log.jsonl"),
                  steps +
                      "{\"type\":\"max_gaussians_reached\",\"iteration\":15,"
                      "\"gaussians\":800}\n");
  test::writeFile(dir.file("plain/train_log.jsonl"), steps);
  std::string out;
  ASSERT_EQ(test::runCommand(kCli + " report " + dir.file("capped"), &out), 0) << out;
  ASSERT_EQ(test::runCommand(kCli + " report " + dir.file("plain"), &out), 0) << out;
  const std::string capped = test::readFile(dir.file("capped/report/report.md"));
  EXPECT_NE(capped.find("reached max_gaussians at iteration 15 (800 Gaussians)"), std::string::npos)
      << capped;
  EXPECT_EQ(test::readFile(dir.file("plain/report/report.md")).find("max_gaussians"),
            std::string::npos);
  // The Gaussians chart marks it (a purple point and its legend entry); the plain run's has no
  // purple.
  const std::array<std::uint8_t, 3> kCapColour = {148, 103, 189};
  const auto purple = [&](const std::string& png_path) {
    const Png png = readPng(png_path);
    std::size_t n = 0;
    for (const auto& p : png.pixels) n += near(p, kCapColour, 20);
    return n;
  };
  EXPECT_GT(purple(dir.file("capped/report/gaussians.png")), 20u);
  EXPECT_EQ(purple(dir.file("plain/report/gaussians.png")), 0u);
}

// Splat mode (the default): a short run seen through a scene camera is what `sadsplat render`
// draws for that camera; classes are decoded per pixel; colourings and --mode points change the
// picture.
class SplatMode : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = new test::TempDir;
    const std::string cache = std::string(SADSPLAT_TEST_DATA_DIR) + "/tiny_scene.cache";
    std::string out;
    // 30 iterations: an early model whose young Gaussians are still faint (opacity ~0.1).
    ASSERT_EQ(test::runCommand(kCli + " train " + cache + " --iterations 30 --out " + run(), &out),
              0)
        << out;
  }
  static void TearDownTestSuite() { delete dir_; }
  static std::string run() { return dir_->file("run"); }
  static test::TempDir* dir_;
};
test::TempDir* SplatMode::dir_ = nullptr;

TEST_F(SplatMode, AViewFromASceneCameraIsTheRunsRenderOfIt) {
  std::string out;
  ASSERT_EQ(test::runCommand(kCli + " view " + run() +
                                 " --view view_002 --color rgb --size 256x192 --background 0,0,0 "
                                 "--screenshot " + dir_->file("view.png"),
                             &out),
            0)
      << out;
  ASSERT_EQ(test::runCommand(kCli + " render " + run() + " --views view_002.png --size 256x192 " +
                                 "--outputs rgb --out " + dir_->file("render"),
                             &out),
            0)
      << out;
  const Png view = readPng(dir_->file("view.png"));
  const Png render = readPng(dir_->file("render/rgb/view_002.png"));
  ASSERT_EQ(view.width, render.width);
  ASSERT_EQ(view.height, render.height);
  // Below the title line (the top 30 rows), pixel for pixel.
  std::size_t n = 0, off = 0;
  double sum = 0;
  for (int y = 30; y < view.height; ++y) {
    for (int x = 0; x < view.width; ++x, ++n) {
      int d = 0;
      for (int k = 0; k < 3; ++k) d = std::max(d, std::abs(view.at(x, y)[k] - render.at(x, y)[k]));
      sum += d;
      off += d > 2;
    }
  }
  EXPECT_LT(sum / n, 0.5) << "mean difference";
  EXPECT_LT(static_cast<double>(off) / n, 0.01) << off << " of " << n << " pixels differ by > 2";
  // The render is not black: the comparison compared something.
  std::size_t black = 0;
  for (const auto& p : render.pixels) black += p[0] == 0 && p[1] == 0 && p[2] == 0;
  EXPECT_LT(black, render.pixels.size() / 2);
}

TEST_F(SplatMode, ClassColoursCoverTheModelEvenEarlyInTraining) {
  std::string out;
  ASSERT_EQ(test::runCommand(kCli + " view " + run() + " --size 320x240 --screenshot " +
                                 dir_->file("class.png"),
                             &out),
            0)
      << out;
  const Png png = readPng(dir_->file("class.png"));
  // tiny_scene's classes (data/tiny_scene/classes.json).
  const std::array<std::uint8_t, 3> road = {128, 64, 128}, grass = {0, 160, 0},
                                    building = {220, 20, 60};
  std::size_t model = 0, coloured = 0;
  for (int y = 30; y < png.height; ++y) {  // below the title
    for (int x = 80; x < png.width; ++x) {  // right of the legend
      const auto& p = png.at(x, y);
      if (near(p, kBackground, 3)) continue;
      ++model;
      coloured += near(p, road, 2) || near(p, grass, 2) || near(p, building, 2);
    }
  }
  const std::size_t area = static_cast<std::size_t>(png.height - 30) * (png.width - 80);
  EXPECT_GT(model, area / 10) << "the model covers a tenth of the picture";
  EXPECT_GT(coloured, model * 95 / 100) << coloured << " of " << model;
}

TEST_F(SplatMode, ColouringsAndModesChangeThePicture) {
  std::string out;
  std::map<std::string, Png> shots;
  for (const std::string& args : {std::string("--color class"), std::string("--color rgb"),
                                  std::string("--color opacity"),
                                  std::string("--mode points --color class")}) {
    const std::string png = dir_->file("shot" + std::to_string(shots.size()) + ".png");
    ASSERT_EQ(test::runCommand(kCli + " view " + run() + " " + args + " --size 160x120 --screenshot " +
                                   png,
                               &out),
              0)
        << out;
    shots[args] = readPng(png);
  }
  const auto differing = [](const Png& a, const Png& b) {
    std::size_t d = 0;
    for (std::size_t i = 0; i < a.pixels.size(); ++i) d += a.pixels[i] != b.pixels[i];
    return d;
  };
  const std::size_t tenth = shots.begin()->second.pixels.size() / 10;
  EXPECT_GT(differing(shots["--color class"], shots["--color rgb"]), tenth);
  EXPECT_GT(differing(shots["--color rgb"], shots["--color opacity"]), tenth);
  EXPECT_GT(differing(shots["--color class"], shots["--mode points --color class"]), tenth);
  EXPECT_EQ(test::runCommand(kCli + " view " + run() + " --mode dots --screenshot " +
                                 dir_->file("x.png"),
                             &out),
            1);
  EXPECT_NE(out.find("--mode: expected splat or points"), std::string::npos) << out;
  EXPECT_EQ(test::runCommand(kCli + " view " + run() + " --background 1,2 --screenshot " +
                                 dir_->file("x.png"),
                             &out),
            1);
  EXPECT_NE(out.find("--background"), std::string::npos) << out;
  EXPECT_FALSE(std::ifstream(dir_->file("x.png")).good());
}

// `sadsplat table --plots`: two frontier charts with a point per configuration and scene, the
// target drawn; without baseline runs a clear error.
TEST(FrontierCharts, TableWritesBothChartsWithTheirPoints) {
  test::TempDir dir;
  const std::string results = dir.file("results");
  const auto metrics = [&](const std::string& run, double miou, double psnr, int gaussians) {
    io::makeDirectory(results + "/" + run);
    test::writeFile(results + "/" + run + "/metrics.json",
                    "{\"miou\": " + std::to_string(miou) + ", \"psnr\": " +
                        std::to_string(psnr) + ", \"ssim\": 0.9, \"num_gaussians\": " +
                        std::to_string(gaussians) + "}");
  };
  metrics("city_0/none_t0", 0.70, 32.0, 1000);
  metrics("city_0/full_t0", 0.80, 29.0, 100);
  metrics("port_0/none_t0", 0.80, 31.0, 900);
  metrics("port_0/full_t0", 0.85, 30.0, 60);
  std::string out;
  ASSERT_EQ(test::runCommand(kCli + " table " + results + " --plots " + dir.file("plots"), &out),
            0)
      << out;
  EXPECT_NE(out.find("wrote " + dir.file("plots/frontier_psnr.png")), std::string::npos) << out;
  EXPECT_EQ(out.find("| city_0 | none |"), out.rfind("| city_0 | none |")) << "printed once";
  for (const char* name : {"frontier_psnr.png", "frontier_miou.png"}) {
    const Png png = readPng(dir.file(std::string("plots/") + name));
    EXPECT_EQ(png.width, 900) << name;
    EXPECT_EQ(png.height, 550) << name;
    // The baseline's points (blue) and the full method's (orange) are drawn.
    EXPECT_GT(share(png, 0, png.width, {31, 119, 180}), 0.0) << name;
    EXPECT_GT(share(png, 0, png.width, {255, 127, 14}), 0.0) << name;
  }
  EXPECT_EQ(test::runCommand(kCli + " table " + results + " --baseline nothing --plots " +
                                 dir.file("plots2"),
                             &out),
            1);
  EXPECT_NE(out.find("runs of the baseline configuration 'nothing'"), std::string::npos) << out;
}

}  // namespace
}  // namespace sadsplat

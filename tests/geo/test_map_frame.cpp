// The map frame (ENU -> UTM through PROJ, the similarity the ortho camera renders with) and the
// orthographic camera of a map grid: a Gaussian at a known map position lands in its pixel.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <set>

#include "sadsplat/common/error.h"
#include "sadsplat/gaussians/rasterizer.h"
#include "sadsplat/geo/geodesy.h"
#include "sadsplat/geo/map_frame.h"
#include "sadsplat/geo/raster_files.h"
#include "sadsplat/io/filesystem.h"
#include "sadsplat/pipeline/ortho_render.h"
#include "test_support/test_support.h"

namespace sadsplat {
namespace {

io::Georeference brighton() {
  io::Georeference g;
  g.origin = {46.843, -91.994, 198.6};
  g.epsg_utm = geo::utmEpsg(g.origin);
  return g;
}

TEST(MapFrame, UtmSimilarityMatchesProjToAMillimetreOverAKilometre) {
  if (!geo::haveGdal()) GTEST_SKIP() << "built without GDAL";
  const io::Georeference g = brighton();
  const geo::MapFrame f = geo::utmMapFrame(g, -500, -500, 500, 500);
  EXPECT_EQ(f.epsg, 32615);
  EXPECT_NE(f.crs_name.find("UTM zone 15N"), std::string::npos);
  EXPECT_NEAR(f.k, 0.99964, 2e-5);  // UTM's scale 0.9996 near the central meridian (93 W)
  // Grid convergence: (lon - lon0) sin(lat) = 1.006 deg x sin(46.843 deg) = 0.734 deg.
  EXPECT_NEAR(std::atan2(f.s, f.c) * 180 / M_PI, 0.734, 0.01);
  EXPECT_LT(f.fit_residual, 1e-3);
  for (const std::array<double, 3> p :
       {std::array<double, 3>{400, -300, 12}, std::array<double, 3>{-480, 450, -3}}) {
    const auto exact = geo::enuToUtm(g, {p})[0];
    const auto approx = f.toMap(p);
    EXPECT_NEAR(approx[0], exact[0], 2e-3);
    EXPECT_NEAR(approx[1], exact[1], 2e-3);
    EXPECT_NEAR(approx[2], p[2] + 198.6, 0.05);  // ellipsoid curvature over 0.6 km: 3 cm
  }
}

TEST(MapFrame, LocalFrameTakesTheGivenUpAsZ) {
  const geo::MapFrame f = geo::localMapFrame({0, -1, 0});  // a frame whose up is -y
  const auto l = f.toLocal({2, -5, 3});
  EXPECT_NEAR(l[2], 5.0, 1e-12);
  EXPECT_NEAR(std::hypot(l[0], l[1]), std::hypot(2.0, 3.0), 1e-12);
  EXPECT_FALSE(f.georeferenced);
}

TEST(OrthoCamera, AGaussianLandsInThePixelOfItsMapPosition) {
  if (!geo::haveGdal()) GTEST_SKIP() << "built without GDAL";
  pipeline::OrthoGrid grid;
  grid.frame = geo::utmMapFrame(brighton(), -100, -100, 100, 100);
  grid.gsd = 0.5;
  const std::array<double, 3> p{37.3, -21.8, 4.0};  // ENU
  const auto m = geo::enuToUtm(brighton(), {p})[0];
  grid.x0 = std::floor(m[0]) - 20;  // pixel column of p: (E - x0) / gsd = 40 + ...
  grid.y0 = std::floor(m[1]) + 15;
  grid.width = 100;
  grid.height = 80;
  grid.top = 50;
  gaussians::GaussianParams g;
  const auto opts = at::TensorOptions().dtype(at::kDouble);
  g.means = at::tensor({p[0], p[1], p[2]}, opts).reshape({1, 3});
  g.quats = at::tensor({1.0, 0.0, 0.0, 0.0}, opts).reshape({1, 4});
  g.log_scales = at::full({1, 3}, std::log(0.3), opts);
  g.opacity_logits = at::full({1}, 3.0, opts);
  g.sh = at::zeros({1, 1, 3}, opts);
  gaussians::RenderSettings settings;
  settings.sh_degree = 0;
  const auto r = gaussians::render(g, pipeline::orthoCamera(grid, 0, 0, 100, 80), settings);
  const double u = (m[0] - grid.x0) / grid.gsd, v = (grid.y0 - m[1]) / grid.gsd;
  EXPECT_NEAR(r.means2d[0][0].item<double>(), u, 0.01);  // the similarity: mm over 100 m
  EXPECT_NEAR(r.means2d[0][1].item<double>(), v, 0.01);
  const int64_t argmax = r.alpha.reshape({-1}).argmax().item<int64_t>();
  EXPECT_EQ(argmax % 100, static_cast<int64_t>(std::floor(u)));
  EXPECT_EQ(argmax / 100, static_cast<int64_t>(std::floor(v)));
  // Depth: the camera plane at local up 50, the Gaussian at up 4.
  EXPECT_NEAR(r.depth[static_cast<int>(v)][static_cast<int>(u)].item<double>(), 46.0, 1e-6);
  // A tile of the grid is the same camera shifted: the Gaussian moves by the tile's offset.
  const auto t = gaussians::render(g, pipeline::orthoCamera(grid, 30, 10, 40, 40), settings);
  EXPECT_NEAR(t.means2d[0][0].item<double>(), r.means2d[0][0].item<double>() - 30, 1e-9);
  EXPECT_NEAR(t.means2d[0][1].item<double>(), r.means2d[0][1].item<double>() - 10, 1e-9);
}

TEST(RasterFiles, ByteRasterRoundTripsThroughGeoTiffAndPng) {
  if (!geo::haveGdal()) GTEST_SKIP() << "built without GDAL";
  test::TempDir dir;
  geo::Raster r = geo::Raster::bytesOf(7, 5, 1);
  for (std::size_t i = 0; i < r.bytes.size(); ++i) r.bytes[i] = static_cast<std::uint8_t>(i * 7);
  r.palette = {{255, 0, 0}, {0, 255, 0}};
  r.nodata = 255;
  geo::MapGrid grid{500000.0, 5188000.0, 0.25, ""};
  geo::writeGeoTiff(dir.file("a.tif"), r, &grid);
  geo::writePng(dir.file("a.png"), r);
  EXPECT_EQ(geo::readByteRaster(dir.file("a.tif")).bytes, r.bytes);
  EXPECT_EQ(geo::readByteRaster(dir.file("a.png")).bytes, r.bytes);
  EXPECT_FALSE(io::pathExists(dir.file("a.tif.aux.xml")));  // no side files
  r.bytes.pop_back();
  EXPECT_THROW(geo::writeGeoTiff(dir.file("b.tif"), r, &grid), Error);
  // Only the two files: no temporary left behind, no b.tif.
  std::set<std::string> files;
  for (const auto& e : std::filesystem::directory_iterator(dir.path())) {
    files.insert(e.path().filename().string());
  }
  EXPECT_EQ(files, (std::set<std::string>{"a.png", "a.tif"}));
}

}  // namespace
}  // namespace sadsplat

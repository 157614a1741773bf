// Real elevation formats: GeoTIFF through GDAL (georeferencing, no-data,
// units), SRTM .hgt tiles, terrain-RGB / Terrarium PNG tiles, longitude /
// latitude regions, and the sidecar JSON that turns a DEM north-up. Every
// fixture is written here (GDAL, OpenCV or by hand); none is downloaded.
#include <gtest/gtest.h>

#include "expect_error.h"
#include "matrix_checks.h"

#include <gdal_priv.h>
#include <ogr_spatialref.h>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>

#include <cmath>
#include <cstdint>
#include <fstream>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include "scratch_dir.h"
#include "shapes/geo_region.h"
#include "shapes/goal_importer.h"
#include "shapes/region.h"
#include "shapes/sidecar.h"

namespace hj {
namespace {

using testing_support::expect_same;

namespace fs = std::filesystem;
using testing_support::expect_error;
using testing_support::ScratchDir;

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
const fs::path kDem = fs::path(HJ_SHARED_DIR) / "data" / "dem";

void write_text(const fs::path& file, const std::string& text) { std::ofstream(file, std::ios::binary) << text; }

void expect_import_error(const fs::path& file, const std::vector<std::string>& words, const ImportOptions& options = {}) {
  std::vector<std::string> all = words;
  all.push_back(file.filename().string());
  expect_error<ImportError>([&] { (void)import_goal(file, options); }, all);
}

void write_noise(const fs::path& file, std::size_t bytes) {
  std::mt19937 rng(5);
  std::string noise(bytes, '\0');
  for (char& ch : noise) ch = char(rng() & 0xFF);
  write_text(file, noise);
}

// A GeoTIFF of `z` (row 0 = north) written by GDAL; NaN pixels get `nodata`.
void write_geotiff(const fs::path& file, const Eigen::MatrixXd& z, GDALDataType type, const double gt[6],
                   int epsg = 4326, std::optional<double> nodata = std::nullopt, const char* unit = nullptr,
                   double scale = 1.0, double offset = 0.0) {
  GDALAllRegister();
  GDALDriver* driver = GetGDALDriverManager()->GetDriverByName("GTiff");
  ASSERT_NE(driver, nullptr);
  GDALDataset* ds = driver->Create(file.string().c_str(), int(z.cols()), int(z.rows()), 1, type, nullptr);
  ASSERT_NE(ds, nullptr);
  if (gt) ds->SetGeoTransform(const_cast<double*>(gt));
  if (epsg > 0) {
    OGRSpatialReference srs;
    srs.importFromEPSG(epsg);
    ds->SetSpatialRef(&srs);
  }
  GDALRasterBand* band = ds->GetRasterBand(1);
  if (nodata) band->SetNoDataValue(*nodata);
  if (unit) band->SetUnitType(unit);
  if (scale != 1.0) band->SetScale(scale);
  if (offset != 0.0) band->SetOffset(offset);
  std::vector<double> buf;
  for (int r = 0; r < z.rows(); ++r)
    for (int c = 0; c < z.cols(); ++c) buf.push_back(std::isnan(z(r, c)) ? nodata.value_or(kNaN) : z(r, c));
  ASSERT_EQ(band->RasterIO(GF_Write, 0, 0, int(z.cols()), int(z.rows()), buf.data(), int(z.cols()), int(z.rows()),
                           GDT_Float64, 0, 0),
            CE_None);
  GDALClose(ds);
}

const double kLonLatGt[6] = {5.0, 0.5, 0.0, 50.0, 0.0, -0.25};  // 0.5 deg columns, 0.25 deg rows, NW corner 5E 50N

// --- GeoTIFF ---------------------------------------------------------------

TEST(ElevationGeoTiff, Int16WithNoDataAndGeoreferenceReadsBackExactly) {
  const ScratchDir dir("geotiff");
  Eigen::MatrixXd z(3, 4);
  z << 100, 101, kNaN, -5,  //
      200, 32767, 7, 8,     //
      kNaN, -32000, 0, 1;
  write_geotiff(dir.path / "dem.tif", z, GDT_Int16, kLonLatGt, 4326, -32768.0);
  const HeightMap map = import_goal(dir.path / "dem.tif");
  expect_same(z, map.z);
  ASSERT_TRUE(map.georef);
  for (int k = 0; k < 6; ++k) EXPECT_EQ(map.georef->geotransform[k], kLonLatGt[k]);
  EXPECT_NE(map.georef->crs_wkt.find("WGS 84"), std::string::npos);
}

TEST(ElevationGeoTiff, FeetAndScaleOffsetBecomeMetres) {
  const ScratchDir dir("units");
  Eigen::MatrixXd z(2, 2);
  z << 0, 10, 100, 1000;
  write_geotiff(dir.path / "ft.tif", z, GDT_Float32, kLonLatGt, 4326, std::nullopt, "ft");
  const HeightMap feet = import_goal(dir.path / "ft.tif");
  EXPECT_EQ(feet.units, "m");
  EXPECT_DOUBLE_EQ(feet.z(1, 1), 1000 * 0.3048);
  write_geotiff(dir.path / "scaled.tif", z, GDT_Int16, kLonLatGt, 4326, std::nullopt, "m", 0.5, -3.0);
  const HeightMap scaled = import_goal(dir.path / "scaled.tif");
  EXPECT_DOUBLE_EQ(scaled.z(0, 1), 10 * 0.5 - 3.0);
  EXPECT_DOUBLE_EQ(scaled.z(1, 1), 1000 * 0.5 - 3.0);
}

TEST(ElevationGeoTiff, PlainTiffStillGoesThroughTheImagePath) {
  // No georeferencing, no no-data: the OpenCV path, validity mask included.
  const ScratchDir dir("plain");
  cv::Mat grey(2, 3, CV_16UC1);
  for (int k = 0; k < 6; ++k) grey.at<std::uint16_t>(k / 3, k % 3) = std::uint16_t(1000 * k);
  ASSERT_TRUE(cv::imwrite((dir.path / "g.tif").string(), grey));
  cv::Mat mask(2, 3, CV_8UC1, cv::Scalar(255));
  mask.at<unsigned char>(1, 2) = 0;
  ASSERT_TRUE(cv::imwrite((dir.path / "g_validmask.png").string(), mask));
  const HeightMap map = import_goal(dir.path / "g.tif");
  EXPECT_FALSE(map.georef);
  EXPECT_EQ(map.z(1, 1), 4000.0);
  EXPECT_TRUE(std::isnan(map.z(1, 2)));
}

TEST(ElevationGeoTiff, LuxembourgKeepsItsGeoreference) {
  // luxembourg_elev.json: geotransform [5.7417, 1/120, 0, 50.1917, 0, -1/120], WGS 84, nodata -32768.
  const HeightMap tif = import_goal(kDem / "luxembourg_elev.tif");
  ASSERT_TRUE(tif.georef);
  EXPECT_NEAR(tif.georef->geotransform[0], 5.741666666666666, 1e-12);
  EXPECT_NEAR(tif.georef->geotransform[1], 1.0 / 120.0, 1e-12);
  EXPECT_NEAR(tif.georef->geotransform[3], 50.19166666666666, 1e-12);
  EXPECT_NEAR(tif.georef->geotransform[5], -1.0 / 120.0, 1e-12);
  EXPECT_EQ(tif.z.array().isNaN().count(), 3942);
}

TEST(ElevationGeoTiff, RejectsCorruptEmptyNoDataOnlyAndOversized) {
  const ScratchDir dir("bad");
  write_noise(dir.path / "noise.tif", 4096);
  expect_import_error(dir.path / "noise.tif", {"not a readable TIFF"});
  write_text(dir.path / "empty.tif", "");
  expect_import_error(dir.path / "empty.tif", {"empty"});
  const Eigen::MatrixXd voids = Eigen::MatrixXd::Constant(3, 3, kNaN);
  write_geotiff(dir.path / "void.tif", voids, GDT_Int16, kLonLatGt, 4326, -32768.0);
  expect_import_error(dir.path / "void.tif", {"no data", "-32768"});
  write_geotiff(dir.path / "big.tif", Eigen::MatrixXd::Ones(40, 50), GDT_Float32, kLonLatGt, 4326, -9999.0);
  ImportOptions small;
  small.max_pixels = 1999;
  expect_import_error(dir.path / "big.tif", {"50 x 40", "1999", "max_pixels"}, small);
}

// --- SRTM .hgt ---------------------------------------------------------------

void write_hgt(const fs::path& file, int n, const std::function<int(int, int)>& value) {
  std::string raw(std::size_t(n) * n * 2, '\0');
  for (int r = 0; r < n; ++r)
    for (int c = 0; c < n; ++c) {
      const auto v = static_cast<std::uint16_t>(static_cast<std::int16_t>(value(r, c)));
      raw[2 * (std::size_t(r) * n + c)] = char(v >> 8);
      raw[2 * (std::size_t(r) * n + c) + 1] = char(v & 0xFF);
    }
  write_text(file, raw);
}

TEST(ElevationHgt, BigEndianValuesVoidsAndCornerFromTheName) {
  const ScratchDir dir("hgt");
  const auto value = [](int r, int c) { return r == 5 && c == 7 ? -32768 : (r * 7 + c * 3) % 5000 - 400; };
  write_hgt(dir.path / "N37W122.hgt", 1201, value);
  const HeightMap map = import_goal(dir.path / "N37W122.hgt");
  ASSERT_EQ(map.z.rows(), 1201);
  ASSERT_EQ(map.z.cols(), 1201);
  EXPECT_EQ(map.z(0, 0), -400.0);
  EXPECT_EQ(map.z(1200, 3), double(value(1200, 3)));
  EXPECT_EQ(map.z(17, 1000), double(value(17, 1000)));
  EXPECT_TRUE(std::isnan(map.z(5, 7)));
  EXPECT_EQ(map.z.array().isNaN().count(), 1);
  EXPECT_EQ(map.units, "m");
  ASSERT_TRUE(map.georef);
  // Pixel (0, 0)'s centre is the tile's north-west sample, (-122, 38); the last one's (-121, 37).
  const auto& gt = map.georef->geotransform;
  EXPECT_NEAR(gt[0] + 0.5 * gt[1], -122.0, 1e-12);
  EXPECT_NEAR(gt[3] + 0.5 * gt[5], 38.0, 1e-12);
  EXPECT_NEAR(gt[0] + 1200.5 * gt[1], -121.0, 1e-12);
  EXPECT_NEAR(gt[3] + 1200.5 * gt[5], 37.0, 1e-12);

  write_hgt(dir.path / "s05e010.hgt", 1201, [](int, int) { return 3; });
  const HeightMap south = import_goal(dir.path / "s05e010.hgt");
  ASSERT_TRUE(south.georef);
  EXPECT_NEAR(south.georef->geotransform[3] + 1200.5 * south.georef->geotransform[5], -5.0, 1e-12);
  EXPECT_NEAR(south.georef->geotransform[0] + 0.5 * south.georef->geotransform[1], 10.0, 1e-12);

  write_hgt(dir.path / "tile.hgt", 1201, [](int, int) { return 3; });
  EXPECT_FALSE(import_goal(dir.path / "tile.hgt").georef);  // no corner in the name
}

TEST(ElevationHgt, RejectsOtherSizesEmptyVoidOnlyAndOversized) {
  const ScratchDir dir("badhgt");
  write_noise(dir.path / "N00E000.hgt", 1000);
  expect_import_error(dir.path / "N00E000.hgt", {"1000 bytes", "1201 x 1201", "3601 x 3601"});
  write_text(dir.path / "N01E000.hgt", "");
  expect_import_error(dir.path / "N01E000.hgt", {"empty"});
  write_hgt(dir.path / "N02E000.hgt", 1201, [](int, int) { return -32768; });
  expect_import_error(dir.path / "N02E000.hgt", {"void"});
  write_hgt(dir.path / "N03E000.hgt", 1201, [](int, int) { return 1; });
  ImportOptions small;
  small.max_pixels = 1'000'000;
  expect_import_error(dir.path / "N03E000.hgt", {"1201 x 1201", "1000000", "max_pixels"}, small);
}

// --- terrain-RGB and Terrarium PNG ------------------------------------------

TEST(ElevationTerrainRgb, BothEncodingsDecodeExactly) {
  const ScratchDir dir("rgb");
  cv::Mat bgra(2, 3, CV_8UC4);
  const unsigned char rgb[6][3] = {{1, 134, 160}, {0, 0, 0}, {255, 255, 255}, {128, 0, 0}, {1, 2, 3}, {127, 255, 128}};
  for (int k = 0; k < 6; ++k) bgra.at<cv::Vec4b>(k / 3, k % 3) = {rgb[k][2], rgb[k][1], rgb[k][0], 255};
  bgra.at<cv::Vec4b>(1, 2)[3] = 0;  // transparent: no data
  ASSERT_TRUE(cv::imwrite((dir.path / "tile.png").string(), bgra));
  ImportOptions mapbox;
  mapbox.encoding = PixelEncoding::kTerrainRgb;
  const HeightMap m = import_goal(dir.path / "tile.png", mapbox);
  ImportOptions terrarium;
  terrarium.encoding = PixelEncoding::kTerrarium;
  const HeightMap t = import_goal(dir.path / "tile.png", terrarium);
  for (int k = 0; k < 5; ++k) {
    const double r = rgb[k][0], g = rgb[k][1], b = rgb[k][2];
    EXPECT_EQ(m.z(k / 3, k % 3), -10000.0 + (r * 65536.0 + g * 256.0 + b) * 0.1) << k;
    EXPECT_EQ(t.z(k / 3, k % 3), r * 256.0 + g + b / 256.0 - 32768.0) << k;
  }
  EXPECT_NEAR(m.z(0, 0), 0.0, 1e-9);  // (1, 134, 160) is sea level in Terrain-RGB
  EXPECT_EQ(t.z(1, 0), 0.0);          // (128, 0, 0) is sea level in Terrarium
  EXPECT_TRUE(std::isnan(m.z(1, 2)));
  EXPECT_TRUE(std::isnan(t.z(1, 2)));
  EXPECT_EQ(m.units, "m");
}

TEST(ElevationTerrainRgb, RejectsCorruptEmptyTransparentGreyAndOversized) {
  const ScratchDir dir("badrgb");
  ImportOptions o;
  o.encoding = PixelEncoding::kTerrainRgb;
  write_noise(dir.path / "noise.png", 4096);
  expect_import_error(dir.path / "noise.png", {"not a readable"}, o);
  write_text(dir.path / "empty.png", "");
  expect_import_error(dir.path / "empty.png", {"empty"}, o);
  ASSERT_TRUE(cv::imwrite((dir.path / "clear.png").string(), cv::Mat(4, 4, CV_8UC4, cv::Scalar(1, 2, 3, 0))));
  expect_import_error(dir.path / "clear.png", {"no data"}, o);
  ASSERT_TRUE(cv::imwrite((dir.path / "grey.png").string(), cv::Mat(4, 4, CV_8UC1, cv::Scalar(9))));
  expect_import_error(dir.path / "grey.png", {"terrain-rgb", "RGB"}, o);
  ASSERT_TRUE(cv::imwrite((dir.path / "big.png").string(), cv::Mat(40, 50, CV_8UC3, cv::Scalar(1, 2, 3))));
  o.max_pixels = 1999;
  expect_import_error(dir.path / "big.png", {"50 x 40", "1999", "max_pixels"}, o);
  ImportOptions both;
  both.hue = true;
  both.encoding = PixelEncoding::kTerrarium;
  EXPECT_THROW((void)import_goal(dir.path / "big.png", both), std::invalid_argument);
  EXPECT_THROW(parse_pixel_encoding("mapbox"), std::invalid_argument);
  EXPECT_EQ(parse_pixel_encoding("terrarium"), PixelEncoding::kTerrarium);
}

// --- longitude / latitude regions ------------------------------------------------

TEST(ElevationLonLat, CropsAGeographicMapToTheBoxPixels) {
  const ScratchDir dir("lonlat");
  Eigen::MatrixXd z(8, 10);  // 5E..10E, 50N..48N
  for (int r = 0; r < 8; ++r)
    for (int c = 0; c < 10; ++c) z(r, c) = 100 * r + c;
  write_geotiff(dir.path / "dem.tif", z, GDT_Float32, kLonLatGt);
  const HeightMap map = import_goal(dir.path / "dem.tif");
  // lon 6.0..7.0 = columns 2, 3; lat 49.0..49.5 = rows 2, 3.
  const HeightMap c = crop_lonlat(map, parse_lonlat_box("6.0,49.0,7.0,49.5"));
  ASSERT_EQ(c.z.rows(), 2);
  ASSERT_EQ(c.z.cols(), 2);
  EXPECT_EQ(c.z(0, 0), 202.0);
  EXPECT_EQ(c.z(1, 1), 303.0);
  ASSERT_TRUE(c.georef);
  EXPECT_DOUBLE_EQ(c.georef->geotransform[0], 6.0);
  EXPECT_DOUBLE_EQ(c.georef->geotransform[3], 49.5);
  // A box inside one pixel keeps that pixel.
  EXPECT_EQ(crop_lonlat(map, parse_lonlat_box("6.1,49.1,6.2,49.2")).z(0, 0), 302.0);
}

TEST(ElevationLonLat, ProjectedMapGoesThroughOgr) {
  // UTM zone 10N, 100 m pixels, 200 x 200 around (-123 E, 37 N) = (500000, 4095248) roughly.
  const ScratchDir dir("utm");
  OGRSpatialReference ll, utm;
  ll.importFromEPSG(4326);
  ll.SetAxisMappingStrategy(OAMS_TRADITIONAL_GIS_ORDER);
  utm.importFromEPSG(32610);
  utm.SetAxisMappingStrategy(OAMS_TRADITIONAL_GIS_ORDER);
  std::unique_ptr<OGRCoordinateTransformation> to_utm(OGRCreateCoordinateTransformation(&ll, &utm));
  double x = -123.0, y = 37.0;
  ASSERT_TRUE(to_utm->Transform(1, &x, &y));
  const double gt[6] = {std::floor(x / 100) * 100 - 10000, 100, 0, std::floor(y / 100) * 100 + 10000, 0, -100};
  Eigen::MatrixXd z(200, 200);
  for (int r = 0; r < 200; ++r)
    for (int c = 0; c < 200; ++c) z(r, c) = r * 1000 + c;
  write_geotiff(dir.path / "utm.tif", z, GDT_Float64, gt, 32610);
  const HeightMap map = import_goal(dir.path / "utm.tif");
  // 0.02 deg of longitude ~ 1.78 km, of latitude ~ 2.22 km around the centre.
  const HeightMap c = crop_lonlat(map, parse_lonlat_box("-123.01,36.99,-122.99,37.01"));
  EXPECT_GE(c.z.cols(), 18);
  EXPECT_LE(c.z.cols(), 20);
  EXPECT_GE(c.z.rows(), 22);
  EXPECT_LE(c.z.rows(), 24);
  // The centre pixel of the crop is the one holding (-123, 37).
  const int col = int((x - gt[0]) / 100), row = int((gt[3] - y) / 100);
  const double centre = c.z(c.z.rows() / 2, c.z.cols() / 2);
  EXPECT_NEAR(std::floor(centre / 1000), row, 1);
  EXPECT_NEAR(std::fmod(centre, 1000), col, 1);
}

TEST(ElevationLonLat, ClearErrorsOutsideAndWithoutGeoreference) {
  const ScratchDir dir("lonlaterr");
  write_geotiff(dir.path / "dem.tif", Eigen::MatrixXd::Ones(8, 10), GDT_Float32, kLonLatGt);
  const HeightMap map = import_goal(dir.path / "dem.tif");
  expect_error<std::invalid_argument>([&] { (void)crop_lonlat(map, parse_lonlat_box("20,10,21,11")); },
                                      {"outside", "dem.tif", "lon 5..10", "lat 48..50"});
  expect_error<std::invalid_argument>([&] { (void)crop_lonlat(map, parse_lonlat_box("9,49,11,49.5")); },
                                      {"reaches outside", "lon 5..10"});
  write_text(dir.path / "plain.csv", "1,2\n3,4\n");
  const HeightMap plain = import_goal(dir.path / "plain.csv");
  expect_error<std::invalid_argument>([&] { (void)crop_lonlat(plain, parse_lonlat_box("6,49,7,49.5")); },
                                      {"not georeferenced", "plain.csv"});
  expect_error<std::invalid_argument>([] { (void)parse_lonlat_box("7,49,6,49.5"); }, {"lon1", "east"});
  expect_error<std::invalid_argument>([] { (void)parse_lonlat_box("6,95,7,96"); }, {"latitudes"});
  expect_error<std::invalid_argument>([] { (void)parse_lonlat_box("6,49,7"); }, {"four numbers"});
}

// --- sidecar orientation -----------------------------------------------------

TEST(ElevationSidecar, OrientationTurnsTheGoalNorthUp) {
  const ScratchDir dir("sidecar");
  write_text(dir.path / "rot.csv", "1,2,3\n4,5,6\n");
  write_text(dir.path / "rot.json", R"J({"orientation": {"north_up_numpy": "a[::-1, ::-1]  (i.e. rotate 180 deg)"}})J");
  Eigen::MatrixXd rotated(2, 3);
  rotated << 6, 5, 4, 3, 2, 1;
  expect_same(rotated, import_goal(dir.path / "rot.csv").z);
  ImportOptions raw;
  raw.sidecar = false;
  EXPECT_EQ(import_goal(dir.path / "rot.csv", raw).z(0, 0), 1.0);

  // sf_bay_area's form: rows are longitude (W->E), columns latitude (S->N).
  write_text(dir.path / "t.csv", "1,2,3\n4,5,6\n");
  write_text(dir.path / "t.json", R"J({"orientation": {"north_up_numpy": "a.T[::-1, :]"}})J");
  Eigen::MatrixXd north_up(3, 2);
  north_up << 3, 6, 2, 5, 1, 4;
  expect_same(north_up, import_goal(dir.path / "t.csv").z);

  write_text(dir.path / "bad.csv", "1,2\n");
  write_text(dir.path / "bad.json", R"J({"orientation": {"north_up_numpy": "np.flipud(a)"}})J");
  expect_import_error(dir.path / "bad.csv", {"bad.json", "orientation", "np.flipud(a)"});
  write_text(dir.path / "broken.csv", "1,2\n");
  write_text(dir.path / "broken.json", "{not json");
  expect_import_error(dir.path / "broken.csv", {"broken.json", "not valid JSON"});
}

TEST(ElevationSidecar, GeorefFollowsTheReorientation) {
  // A south-up CSV (row 0 = south) with its georef in file order: after the
  // flip, pixel (0, 0) is the north-west one and a lon/lat box finds it.
  const ScratchDir dir("georef");
  write_text(dir.path / "s.csv", "1,2\n3,4\n");  // row 0 = south
  write_text(dir.path / "s.json",
             R"J({"georef": {"crs": "WGS 84", "geotransform": [10, 1, 0, 20, 0, 1]},
                 "orientation": {"north_up_numpy": "a[::-1]"}, "units": "metres"})J");
  const HeightMap map = import_goal(dir.path / "s.csv");
  EXPECT_EQ(map.z(0, 0), 3.0);
  EXPECT_EQ(map.units, "m");
  ASSERT_TRUE(map.georef);
  EXPECT_EQ(map.georef->geotransform[3], 22.0);
  EXPECT_EQ(map.georef->geotransform[5], -1.0);
  EXPECT_EQ(crop_lonlat(map, parse_lonlat_box("11.2,20.2,11.8,20.8")).z(0, 0), 2.0);  // south-east pixel
  EXPECT_EQ(crop_lonlat(map, parse_lonlat_box("10.2,21.2,10.8,21.8")).z(0, 0), 3.0);  // north-west pixel

  // A georef block in another form (jacksboro_fault_tn.json's xmin/dx) is not guessed at.
  write_text(dir.path / "j.csv", "1,2\n3,4\n");
  write_text(dir.path / "j.json", R"J({"georef": {"xmin": -84.4, "dx": 0.0008}})J");
  EXPECT_FALSE(import_goal(dir.path / "j.csv").georef);
}

TEST(ElevationSidecar, VolcanoIsTurnedNorthUp) {
  // volcano_maunga_whau.json: rows S->N, columns E->W; north-up is a[::-1, ::-1].
  ImportOptions raw;
  raw.sidecar = false;
  const HeightMap source = import_goal(kDem / "volcano_maunga_whau.csv", raw);
  const HeightMap north_up = import_goal(kDem / "volcano_maunga_whau.csv");
  expect_same(source.z.reverse(), north_up.z);
  EXPECT_NE(north_up.source.find("north-up"), std::string::npos);
}

}  // namespace
}  // namespace hj

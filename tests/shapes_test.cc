// Goal shapes: importers (CSV, PNG, TIFF, hue mode, validity masks, errors)
// on synthetic files and the real DEMs in shared/data/dem, regions of
// interest, and resampling onto the paper's mesh (orientation, scaling).
#include <gtest/gtest.h>

#include "expect_error.h"
#include "matrix_checks.h"

#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>

#include <cmath>
#include <fstream>
#include <functional>
#include <iomanip>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include "model/mesh.h"
#include "scratch_dir.h"
#include "shapes/goal_importer.h"
#include "shapes/region.h"
#include "shapes/resample.h"

namespace hj {
namespace {

using testing_support::expect_same;

using testing_support::ScratchDir;

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
const ArrayGeometry kPaper{3, 4, 0.038, 4};  // 13 x 17 points
const std::filesystem::path kDem = std::filesystem::path(HJ_SHARED_DIR) / "data" / "dem";

void write_text(const std::filesystem::path& file, const std::string& text) {
  std::ofstream(file, std::ios::binary) << text;
}

long nan_count(const Eigen::MatrixXd& z) { return z.array().isNaN().count(); }

using testing_support::expect_error;

void expect_import_error(const std::filesystem::path& file, const std::vector<std::string>& words,
                         const ImportOptions& options = {}) {
  std::vector<std::string> all = words;
  all.push_back(file.filename().string());
  expect_error<ImportError>([&] { (void)import_goal(file, options); }, all);
}

TEST(ShapesCsv, RoundTripWithNaN) {
  const ScratchDir dir("csv");
  Eigen::MatrixXd z(3, 4);
  z << 1.5, kNaN, -3.25, 1e-7,  //
      0.1, 2e3, kNaN, 12345.678901234567,  //
      -0.0, 7, 8, 9;
  std::ostringstream text;
  text << std::setprecision(17);
  for (int r = 0; r < z.rows(); ++r)
    for (int c = 0; c < z.cols(); ++c) text << z(r, c) << (c + 1 < z.cols() ? "," : "\n");
  write_text(dir.path / "goal.csv", text.str());
  const HeightMap map = import_goal(dir.path / "goal.csv");
  expect_same(z, map.z);
  EXPECT_EQ(map.source, (dir.path / "goal.csv").string());
}

TEST(ShapesCsv, NanSpellingsEmptyFieldsAndCrLf) {
  const ScratchDir dir("spell");
  write_text(dir.path / "g.CSV", "1, nan ,NaN\r\n,2,NAN\r\n\r\n");
  const HeightMap map = import_goal(dir.path / "g.CSV");
  ASSERT_EQ(map.z.rows(), 2);
  ASSERT_EQ(map.z.cols(), 3);
  EXPECT_EQ(map.z(0, 0), 1.0);
  EXPECT_EQ(map.z(1, 1), 2.0);
  EXPECT_EQ(nan_count(map.z), 4);
}

TEST(ShapesCsv, MalformedFilesNameLineAndColumn) {
  const ScratchDir dir("bad");
  write_text(dir.path / "word.csv", "1,2,3\n4,five,6\n");
  expect_import_error(dir.path / "word.csv", {"line 2", "column 2", "five"});
  write_text(dir.path / "ragged.csv", "1,2,3\n4,5\n");
  expect_import_error(dir.path / "ragged.csv", {"line 2", "2 values", "3"});
  write_text(dir.path / "inf.csv", "1,inf\n");
  expect_import_error(dir.path / "inf.csv", {"line 1", "column 2", "finite"});
  write_text(dir.path / "blank.csv", "1,2\n\n3,4\n");
  expect_import_error(dir.path / "blank.csv", {"line 2", "blank"});
  write_text(dir.path / "empty.csv", "");
  expect_import_error(dir.path / "empty.csv", {"empty"});
  write_text(dir.path / "blank_only.csv", "\n \n");
  expect_import_error(dir.path / "blank_only.csv", {"empty"});
  write_text(dir.path / "all_nan.csv", "nan,NaN\n,nan\n");
  expect_import_error(dir.path / "all_nan.csv", {"NaN"});
  write_text(dir.path / "big.csv", "1,2,3\n4,5,6\n7,8,9\n");
  ImportOptions small;
  small.max_pixels = 8;
  expect_import_error(dir.path / "big.csv", {"8", "max_pixels"}, small);
}

TEST(ShapesImport, MissingFileAndUnknownExtension) {
  const ScratchDir dir("missing");
  expect_import_error(dir.path / "nothing.png", {"no such file"});
  write_text(dir.path / "goal.xyz", "1,2\n");
  expect_import_error(dir.path / "goal.xyz", {".xyz", ".csv", ".png", ".tif", ".tiff"});
  expect_import_error(dir.path / "README", {"no file extension", ".csv"});
  ImportOptions bad;
  bad.max_pixels = 0;
  expect_error<std::invalid_argument>([&] { (void)import_goal(dir.path / "goal.xyz", bad); }, {"max_pixels"});
}

TEST(ShapesImage, GreyPngAndFloatTiffReadBackExactly) {
  const ScratchDir dir("img");
  std::mt19937 rng(7);
  cv::Mat u8(23, 31, CV_8UC1), u16(17, 29, CV_16UC1), f32(11, 13, CV_32FC1);
  cv::randu(u8, 0, 256);
  cv::randu(u16, 0, 65536);
  std::uniform_real_distribution<float> height(-50.0f, 900.0f);
  for (int r = 0; r < f32.rows; ++r)
    for (int c = 0; c < f32.cols; ++c) f32.at<float>(r, c) = (r + c) % 5 == 0 ? NAN : height(rng);
  ASSERT_TRUE(cv::imwrite((dir.path / "u8.png").string(), u8));
  ASSERT_TRUE(cv::imwrite((dir.path / "u16.PNG").string(), u16));
  ASSERT_TRUE(cv::imwrite((dir.path / "f32.tiff").string(), f32));
  ASSERT_TRUE(cv::imwrite((dir.path / "u16.tif").string(), u16));
  for (const auto& [name, mat] : std::vector<std::pair<std::string, cv::Mat>>{
           {"u8.png", u8}, {"u16.PNG", u16}, {"f32.tiff", f32}, {"u16.tif", u16}}) {
    SCOPED_TRACE(name);
    const HeightMap map = import_goal(dir.path / name);
    cv::Mat expected64;
    mat.convertTo(expected64, CV_64F);
    Eigen::MatrixXd expected(mat.rows, mat.cols);
    for (int r = 0; r < mat.rows; ++r)
      for (int c = 0; c < mat.cols; ++c) expected(r, c) = expected64.at<double>(r, c);
    expect_same(expected, map.z);
  }
}

TEST(ShapesImage, ColourByLuminanceAndTransparencyAsNoData) {
  const ScratchDir dir("colour");
  cv::Mat bgra(2, 3, CV_8UC4, cv::Scalar(0, 0, 255, 255));  // opaque red
  bgra.at<cv::Vec4b>(1, 2) = cv::Vec4b(255, 255, 255, 0);   // transparent white
  ASSERT_TRUE(cv::imwrite((dir.path / "rgba.png").string(), bgra));
  const HeightMap map = import_goal(dir.path / "rgba.png");
  EXPECT_NEAR(map.z(0, 0), 0.299 * 255, 0.01);
  EXPECT_TRUE(std::isnan(map.z(1, 2)));
  EXPECT_EQ(nan_count(map.z), 1);
}

TEST(ShapesImage, HueModeRedIsHighBlueIsLow) {
  const ScratchDir dir("hue");
  cv::Mat image(20, 40, CV_8UC3, cv::Scalar(255, 0, 0));                     // blue (BGR)
  image(cv::Rect(0, 0, 20, 20)).setTo(cv::Scalar(0, 0, 255));                 // left half red
  ASSERT_TRUE(cv::imwrite((dir.path / "map.png").string(), image));
  ImportOptions hue;
  hue.hue = true;
  const HeightMap map = import_goal(dir.path / "map.png", hue);
  EXPECT_DOUBLE_EQ(map.z(5, 5), 1.0);
  EXPECT_NEAR(map.z(5, 30), (280.0 - 240.0) / 280.0, 1e-6);
  EXPECT_GT(map.z.leftCols(20).minCoeff(), map.z.rightCols(20).maxCoeff());

  // A topographic tint ramp red > yellow > green > blue; grey has no hue.
  cv::Mat tints(1, 5, CV_8UC3);
  tints.at<cv::Vec3b>(0, 0) = {0, 0, 255};
  tints.at<cv::Vec3b>(0, 1) = {0, 255, 255};
  tints.at<cv::Vec3b>(0, 2) = {0, 255, 0};
  tints.at<cv::Vec3b>(0, 3) = {255, 0, 0};
  tints.at<cv::Vec3b>(0, 4) = {128, 128, 128};
  ASSERT_TRUE(cv::imwrite((dir.path / "tints.png").string(), tints));
  const Eigen::MatrixXd t = import_goal(dir.path / "tints.png", hue).z;
  EXPECT_GT(t(0, 0), t(0, 1));
  EXPECT_GT(t(0, 1), t(0, 2));
  EXPECT_GT(t(0, 2), t(0, 3));
  EXPECT_TRUE(std::isnan(t(0, 4)));

  cv::Mat grey(4, 4, CV_8UC3, cv::Scalar(90, 90, 90));
  ASSERT_TRUE(cv::imwrite((dir.path / "grey.png").string(), grey));
  expect_import_error(dir.path / "grey.png", {"hue"}, hue);
}

TEST(ShapesImage, BrokenAndOversizedImagesThrow) {
  const ScratchDir dir("broken");
  std::mt19937 rng(11);
  std::string noise(4096, '\0');
  for (char& ch : noise) ch = char(rng() & 0xFF);
  write_text(dir.path / "noise.png", noise);
  expect_import_error(dir.path / "noise.png", {"not a readable"});
  write_text(dir.path / "empty.png", "");
  expect_import_error(dir.path / "empty.tif", {"no such file"});
  expect_import_error(dir.path / "empty.png", {"empty"});

  cv::Mat image(40, 50, CV_16UC1, cv::Scalar(1000));
  ASSERT_TRUE(cv::imwrite((dir.path / "big.png").string(), image));
  ASSERT_TRUE(cv::imwrite((dir.path / "big.tif").string(), image));
  std::string png;
  {
    std::ifstream in(dir.path / "big.png", std::ios::binary);
    png.assign(std::istreambuf_iterator<char>(in), {});
  }
  write_text(dir.path / "cut.png", png.substr(0, png.size() / 2));
  expect_import_error(dir.path / "cut.png", {"not a readable"});
  ImportOptions small;
  small.max_pixels = 1999;
  expect_import_error(dir.path / "big.png", {"50 x 40", "1999", "max_pixels"}, small);
  expect_import_error(dir.path / "big.tif", {"50 x 40", "1999", "max_pixels"}, small);
  small.max_pixels = 2000;
  EXPECT_EQ(import_goal(dir.path / "big.tif", small).z.size(), 2000);
}

TEST(ShapesDem, VolcanoCsvAndPngAgree) {
  // volcano_maunga_whau.json: 87 x 61, min 94, max 195, no NaN.
  const HeightMap csv = import_goal(kDem / "volcano_maunga_whau.csv");
  EXPECT_EQ(csv.z.rows(), 87);
  EXPECT_EQ(csv.z.cols(), 61);
  EXPECT_EQ(csv.z.minCoeff(), 94.0);
  EXPECT_EQ(csv.z.maxCoeff(), 195.0);
  EXPECT_EQ(nan_count(csv.z), 0);

  // The PNG holds round((h - min) / (max - min) * 65535).
  const HeightMap png = import_goal(kDem / "volcano_maunga_whau.png");
  ASSERT_EQ(png.z.rows(), 87);
  ASSERT_EQ(png.z.cols(), 61);
  const Eigen::MatrixXd metres = png.z.array() / 65535.0 * (195.0 - 94.0) + 94.0;
  EXPECT_LE((metres - csv.z).cwiseAbs().maxCoeff(), 0.5 * (195.0 - 94.0) / 65535.0 + 1e-9);
}

TEST(ShapesDem, LuxembourgValidMaskMatchesCsvNaNs) {
  // luxembourg_elev.json: 90 x 95, 3942 NaN outside the border, min 141, max 547.
  const HeightMap csv = import_goal(kDem / "luxembourg_elev.csv");
  const HeightMap png = import_goal(kDem / "luxembourg_elev.png");
  ASSERT_EQ(csv.z.rows(), 90);
  ASSERT_EQ(csv.z.cols(), 95);
  ASSERT_EQ(png.z.rows(), 90);
  ASSERT_EQ(png.z.cols(), 95);
  EXPECT_EQ(nan_count(csv.z), 3942);
  EXPECT_EQ(nan_count(png.z), 3942);
  EXPECT_TRUE((csv.z.array().isNaN() == png.z.array().isNaN()).all());
  EXPECT_EQ(csv.z.array().isNaN().select(0.0, csv.z).maxCoeff(), 547.0);

  // The original Int16 GeoTIFF shares the mask; its valid heights are the CSV's.
  const HeightMap tif = import_goal(kDem / "luxembourg_elev.tif");
  ASSERT_EQ(tif.z.rows(), 90);
  EXPECT_TRUE((csv.z.array().isNaN() == tif.z.array().isNaN()).all());
  expect_same(csv.z, tif.z);
}

TEST(ShapesRegion, ParseFractionsAndPixels) {
  const Region f = parse_region("0.25, 0, 0.75,0.5");
  EXPECT_TRUE(f.fractions);
  EXPECT_EQ(f.x0, 0.25);
  EXPECT_EQ(f.y1, 0.5);
  const Region p = parse_region("10,20,30,40");
  EXPECT_FALSE(p.fractions);
  EXPECT_EQ(p.x1, 30.0);
  EXPECT_TRUE(parse_region("0,0,1,1").fractions);
}

TEST(ShapesRegion, CropByFractionsAndByPixels) {
  HeightMap map;
  map.z.resize(8, 10);
  for (int r = 0; r < 8; ++r)
    for (int c = 0; c < 10; ++c) map.z(r, c) = 100 * r + c;
  map.source = "grid";
  const HeightMap right_half_top = crop(map, parse_region("0.5,0,1,0.5"));
  EXPECT_EQ(right_half_top.z, map.z.block(0, 5, 4, 5));
  EXPECT_NE(right_half_top.source.find("crop"), std::string::npos);
  // 0.25 of 10 columns falls inside pixel 2: the crop keeps every touched pixel.
  EXPECT_EQ(crop(map, parse_region("0.25,0.25,0.75,0.75")).z, map.z.block(2, 2, 4, 6));
  EXPECT_EQ(crop(map, parse_region("2,3,7,8")).z, map.z.block(3, 2, 5, 5));
  EXPECT_EQ(crop(map, parse_region("0,0,10,8")).z, map.z);
}

TEST(ShapesRegion, BadRegionsAreRefused) {
  using E = std::invalid_argument;
  expect_error<E>([] { (void)parse_region("0,0,1"); }, {"four numbers", "got 3"});
  expect_error<E>([] { (void)parse_region("0,0,a,1"); }, {"\"a\"", "not a number"});
  expect_error<E>([] { (void)parse_region("0.5,0,0.2,1"); }, {"inverted", "x1"});
  expect_error<E>([] { (void)parse_region("0,0.5,1,0.5"); }, {"empty", "y1"});
  expect_error<E>([] { (void)parse_region("-1,0,5,5"); }, {"negative"});
  expect_error<E>([] { (void)parse_region("0.5,0,10,10"); }, {"whole numbers"});
  HeightMap map;
  map.z = Eigen::MatrixXd::Ones(8, 10);
  map.source = "grid";
  expect_error<E>([&] { (void)crop(map, parse_region("0,0,11,8")); }, {"outside", "10 x 8"});
  expect_error<E>([&] { (void)crop(map, Region{0.0, 0.0, 1.5, 1.0, true}); }, {"[0, 1]"});
  map.z.topRows(4).setConstant(kNaN);
  expect_error<E>([&] { (void)crop(map, parse_region("0,0,1,0.5")); }, {"no-data"});
}

TEST(ShapesResample, ConstantGoalGivesZeros) {
  const Mesh mesh(kPaper);
  HeightMap goal;
  goal.z = Eigen::MatrixXd::Constant(40, 50, 123.0);
  goal.z(3, 4) = kNaN;
  const Eigen::MatrixXd h = resample_to_mesh(goal, mesh, 30.0);
  ASSERT_EQ(h.rows(), 13);
  ASSERT_EQ(h.cols(), 17);
  EXPECT_EQ(h.cwiseAbs().maxCoeff(), 0.0);
}

TEST(ShapesResample, RampInXIsRampInJ) {
  const Mesh mesh(kPaper);
  HeightMap goal;  // 2 pixels per mesh spacing: footprints fall on pixel edges
  goal.z.resize(24, 2 * 16);
  for (int c = 0; c < goal.z.cols(); ++c) goal.z.col(c).setConstant(c);
  const Eigen::MatrixXd h = resample_to_mesh(goal, mesh, 30.0);
  EXPECT_EQ(h.minCoeff(), 0.0);
  EXPECT_NEAR(h.maxCoeff(), 30.0, 1e-12);
  for (int i = 0; i < 13; ++i) {
    EXPECT_NEAR(h(i, 0), 0.0, 1e-12);
    EXPECT_NEAR(h(i, 16), 30.0, 1e-12);
    for (int j = 1; j < 17; ++j) EXPECT_GT(h(i, j), h(i, j - 1));
    for (int j = 2; j < 16; ++j) EXPECT_NEAR(h(i, j) - h(i, j - 1), h(0, 2) - h(0, 1), 1e-9);  // even steps inside
    EXPECT_NEAR((h.row(i) - h.row(0)).cwiseAbs().maxCoeff(), 0.0, 1e-12);
  }
}

TEST(ShapesResample, CentrePixelPeaksAtCentrePoint) {
  const Mesh mesh(kPaper);
  HeightMap goal;
  goal.z = Eigen::MatrixXd::Zero(39, 51);
  goal.z(19, 25) = 1.0;
  const Eigen::MatrixXd h = resample_to_mesh(goal, mesh, 25.0);
  EXPECT_EQ(h(6, 8), 25.0);
  Eigen::MatrixXd others = h;
  others(6, 8) = 0.0;
  EXPECT_EQ(others.maxCoeff(), 0.0);
}

TEST(ShapesResample, ImageTopIsHighMeshRows) {
  const Mesh mesh(kPaper);
  HeightMap goal;
  goal.z = Eigen::MatrixXd::Zero(30, 40);
  goal.z.topRows(5).setConstant(1.0);  // the top (north) edge is high
  const Eigen::MatrixXd h = resample_to_mesh(goal, mesh);
  EXPECT_EQ(h.row(12).minCoeff(), default_relief_mm(mesh.geometry()));
  EXPECT_EQ(h.row(0).maxCoeff(), 0.0);
  EXPECT_GT(h.row(11).mean(), h.row(1).mean());
}

TEST(ShapesResample, DefaultReliefScalesWithTheArraysShorterSide) {
  // The paper's convention: a 9 x 12 array gets a goal three times as tall as 3 x 4.
  EXPECT_DOUBLE_EQ(default_relief_mm({3, 4, 0.038, 4}), 30.0);
  EXPECT_DOUBLE_EQ(default_relief_mm({9, 12, 0.038, 4}), 90.0);
  EXPECT_DOUBLE_EQ(default_relief_mm({12, 9, 0.038, 4}), 90.0);
  EXPECT_DOUBLE_EQ(default_relief_mm({3, 4, 0.076, 4}), 60.0);
  EXPECT_DOUBLE_EQ(relief_or_default_mm(25.0, {9, 12, 0.038, 4}), 25.0);
  EXPECT_DOUBLE_EQ(relief_or_default_mm(0.0, {1, 2, 0.038, 4}), 10.0);
}

TEST(ShapesResample, NoDataTakesNearestValidValue) {
  const Mesh mesh(kPaper);
  HeightMap goal;
  goal.z = Eigen::MatrixXd::Constant(26, 34, kNaN);
  goal.z.leftCols(4).setConstant(10.0);
  goal.z.rightCols(4).setConstant(20.0);
  const Eigen::MatrixXd h = resample_to_mesh(goal, mesh, 30.0);
  EXPECT_FALSE(h.hasNaN());
  EXPECT_NEAR(h.col(0).maxCoeff(), 0.0, 1e-9);
  EXPECT_NEAR(h.col(16).minCoeff(), 30.0, 1e-9);
  EXPECT_NEAR(h.col(5).maxCoeff(), 0.0, 1e-9);    // nearer the left band
  EXPECT_NEAR(h.col(11).minCoeff(), 30.0, 1e-9);  // nearer the right band
}

TEST(ShapesResample, VolcanoFillsTheRange) {
  const HeightMap volcano = import_goal(kDem / "volcano_maunga_whau.csv");
  const Eigen::MatrixXd h = resample_to_mesh(volcano, Mesh(kPaper), 30.0);
  EXPECT_EQ(h.minCoeff(), 0.0);
  EXPECT_NEAR(h.maxCoeff(), 30.0, 1e-12);
  const HeightMap lux = import_goal(kDem / "luxembourg_elev.png");
  EXPECT_FALSE(resample_to_mesh(lux, Mesh(kPaper)).hasNaN());
}

TEST(ShapesResample, BadInputIsRefused) {
  const Mesh mesh(kPaper);
  HeightMap goal;
  goal.source = "g";
  using E = std::invalid_argument;
  expect_error<E>([&] { (void)resample_to_mesh(goal, mesh, 30.0); }, {"\"g\"", "empty"});
  goal.z = Eigen::MatrixXd::Constant(4, 4, kNaN);
  expect_error<E>([&] { (void)resample_to_mesh(goal, mesh, 30.0); }, {"no valid"});
  goal.z(0, 0) = 1.0;
  expect_error<E>([&] { (void)resample_to_mesh(goal, mesh, 0.0); }, {"max_height_mm"});
  expect_error<E>([&] { (void)resample_to_mesh(goal, mesh, kNaN); }, {"max_height_mm"});
  goal.z(1, 1) = std::numeric_limits<double>::infinity();
  expect_error<E>([&] { (void)resample_to_mesh(goal, mesh, 30.0); }, {"infinite"});
}

}  // namespace
}  // namespace hj

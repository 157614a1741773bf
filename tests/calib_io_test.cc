// Reading sessions and frames (src/calib/session.h, frame_csv.h) and the
// top-view rasterisation (src/calib/rasterize.h): the demo datasets read
// with the right shapes, malformed input names its key, rasterised planes
// come out exact.
#include <gtest/gtest.h>

#include "scratch_dir.h"
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <nlohmann/json.hpp>
#include <random>
#include <string>

#include "calib/frame_csv.h"
#include "calib/rasterize.h"
#include "calib/session.h"

namespace hj {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

const fs::path kBaseline = fs::path(HJ_SHARED_DIR) / "data/sessions/demo-baseline";
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

using testing_support::ScratchDir;

void write_text(const fs::path& path, const std::string& text) {
  std::ofstream out(path, std::ios::binary);
  out << text;
}

int count_captures(const Session& s) {
  int n = 0;
  for (const SessionStep& step : s.steps) n += step.kind == SessionStep::Kind::kCapture;
  return n;
}

TEST(SessionRead, DemoBaselineSessionsHaveTheirStepsAndGrid) {
  struct Expected {
    const char* name;
    int steps;
    int captures;
  };
  const Expected expected[] = {{"jammed-sweep", 33, 10}, {"mixed-1", 11, 4},        {"mixed-2", 12, 4},
                               {"mixed-3", 13, 5},       {"paper-sequence", 18, 4}, {"unjammed-sweep", 21, 11}};
  for (const Expected& e : expected) {
    SCOPED_TRACE(e.name);
    const Session s = read_session(kBaseline / e.name);
    EXPECT_EQ(s.name, e.name);
    EXPECT_EQ(s.dir, kBaseline / e.name);
    EXPECT_EQ(static_cast<int>(s.steps.size()), e.steps);
    EXPECT_EQ(count_captures(s), e.captures);
    EXPECT_EQ(s.device.rows, 3);
    EXPECT_EQ(s.device.cols, 4);
    EXPECT_DOUBLE_EQ(s.device.cell_size_mm, 38.0);
    EXPECT_DOUBLE_EQ(s.device.max_pressure_kpa, 3.45);
    EXPECT_EQ(s.grid.nx, 77);
    EXPECT_EQ(s.grid.ny, 58);
    EXPECT_DOUBLE_EQ(s.grid.x_mm(76), 152.0);  // the grid spans the array exactly
    EXPECT_DOUBLE_EQ(s.grid.y_mm(57), 114.0);
    for (int i = 0; i < static_cast<int>(s.steps.size()); ++i) EXPECT_EQ(s.steps[i].index, i);
    // Every session captures the rest state first.
    ASSERT_FALSE(s.steps.empty());
    EXPECT_EQ(s.steps[0].kind, SessionStep::Kind::kCapture);
    EXPECT_EQ(s.steps[0].frame, "frames/000.csv");
    EXPECT_EQ(s.steps[0].label, "rest");
  }
}

TEST(SessionRead, ActionsAreDecodedInPascalAndIndices) {
  const Session s = read_session(kBaseline / "paper-sequence" / "session.json");
  EXPECT_EQ(s.dir, kBaseline / "paper-sequence");
  ASSERT_EQ(s.steps.size(), 18u);
  EXPECT_EQ(s.steps[1].action.op, Action::Op::kSetPressure);
  EXPECT_NEAR(s.steps[1].action.pressure_pa, 590.0, 1e-9);
  EXPECT_EQ(s.steps[3].action.op, Action::Op::kJam);
  EXPECT_EQ(s.steps[3].action.a, 0);
  EXPECT_EQ(s.steps[3].action.b, 2);
  EXPECT_EQ(s.steps[7].action.op, Action::Op::kPin);
  EXPECT_EQ(s.steps[7].action.a, 1);
  EXPECT_EQ(s.steps[7].action.b, 2);
  EXPECT_EQ(s.steps[11].kind, SessionStep::Kind::kCapture);
  EXPECT_EQ(s.steps[11].label, "sequence 1");
  EXPECT_EQ(s.frame_path(s.steps[11]), kBaseline / "paper-sequence" / "frames/001.csv");
  EXPECT_DOUBLE_EQ(s.sensor_accuracy_mm, 1.0);
  EXPECT_DOUBLE_EQ(s.sensor_resolution_mm, 1.0);
}

TEST(FrameCsv, EveryDemoFrameReadsAsNyByNxWithSomeMissing) {
  for (const char* name : {"jammed-sweep", "mixed-1", "mixed-2", "mixed-3", "paper-sequence", "unjammed-sweep"}) {
    const Session s = read_session(kBaseline / name);
    for (const SessionStep& step : s.steps) {
      if (step.kind != SessionStep::Kind::kCapture) continue;
      SCOPED_TRACE(s.frame_path(step).string());
      const Eigen::MatrixXd f = read_frame_csv(s.frame_path(step), s.grid.ny, s.grid.nx);
      EXPECT_EQ(f.rows(), 58);
      EXPECT_EQ(f.cols(), 77);
      EXPECT_GT(f.array().isNaN().count(), 0);
    }
  }
}

TEST(FrameCsv, RestFrameSagsBelowTheClampedEdge) {
  const Eigen::MatrixXd f = read_frame_csv(kBaseline / "unjammed-sweep/frames/000.csv", 58, 77);
  ASSERT_EQ(f.rows(), 58);
  ASSERT_EQ(f.cols(), 77);
  const Eigen::Index missing = f.array().isNaN().count();
  EXPECT_GT(missing, 0);
  EXPECT_LT(missing, f.size() / 20);  // about 1 % dropped
  // At rest the membrane sags under gravity: the middle is well below 0.
  double middle = 0.0;
  int n = 0;
  for (int iy = 25; iy <= 32; ++iy)
    for (int ix = 34; ix <= 42; ++ix)
      if (!std::isnan(f(iy, ix))) {
        middle += f(iy, ix);
        ++n;
      }
  ASSERT_GT(n, 0);
  EXPECT_LT(middle / n, -10.0);
}

TEST(FrameCsv, WriteThenReadRoundTripsIncludingNaN) {
  const ScratchDir scratch("roundtrip");
  const fs::path& dir = scratch.path;
  const fs::path path = dir / "nested/frames/007.csv";  // parents do not exist yet
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> height(-60.0, 80.0);
  Eigen::MatrixXd heights(5, 9);
  for (Eigen::Index i = 0; i < heights.size(); ++i) heights(i) = height(rng);
  heights(0, 0) = kNaN;
  heights(4, 8) = kNaN;
  heights(2, 3) = -0.00001;  // rounds to 0, written as "0"
  heights(3, 1) = 1e6 + 0.12345;

  write_frame_csv(path, heights);
  const Eigen::MatrixXd back = read_frame_csv(path, 5, 9);
  ASSERT_EQ(back.rows(), 5);
  ASSERT_EQ(back.cols(), 9);
  for (Eigen::Index i = 0; i < heights.size(); ++i) {
    if (std::isnan(heights(i))) {
      EXPECT_TRUE(std::isnan(back(i))) << "at " << i;
    } else {
      EXPECT_NEAR(back(i), heights(i), 1e-3) << "at " << i;
    }
  }
  // No temporary file is left beside it.
  int files = 0;
  for ([[maybe_unused]] const auto& entry : fs::directory_iterator(path.parent_path())) ++files;
  EXPECT_EQ(files, 1);
}

TEST(FrameCsv, ReadsCrLfEmptyFieldsAndNanSpellings) {
  const ScratchDir scratch("spellings");
  const fs::path& dir = scratch.path;
  write_text(dir / "f.csv", "1,NaN,2.5\r\n,nan,-3\r\n");
  const Eigen::MatrixXd f = read_frame_csv(dir / "f.csv", 2, 3);
  EXPECT_DOUBLE_EQ(f(0, 0), 1.0);
  EXPECT_TRUE(std::isnan(f(0, 1)));
  EXPECT_DOUBLE_EQ(f(0, 2), 2.5);
  EXPECT_TRUE(std::isnan(f(1, 0)));
  EXPECT_TRUE(std::isnan(f(1, 1)));
  EXPECT_DOUBLE_EQ(f(1, 2), -3.0);
}

// Expects read_frame_csv to throw SessionError whose message holds each of `parts`.
void expect_frame_error(const fs::path& path, int ny, int nx, std::initializer_list<std::string> parts) {
  try {
    read_frame_csv(path, ny, nx);
    ADD_FAILURE() << "no error reading " << path;
  } catch (const SessionError& e) {
    for (const std::string& part : parts) EXPECT_NE(std::string(e.what()).find(part), std::string::npos) << e.what();
  }
}

TEST(FrameCsv, WrongShapeOrBadNumberNamesTheFile) {
  const ScratchDir scratch("badframe");
  const fs::path& dir = scratch.path;
  write_text(dir / "short.csv", "1,2,3\n4,5,6\n");
  expect_frame_error(dir / "short.csv", 3, 3, {"short.csv", "2 lines", "expected 3"});
  write_text(dir / "narrow.csv", "1,2,3\n4,5\n7,8,9\n");
  expect_frame_error(dir / "narrow.csv", 3, 3, {"narrow.csv", "line 2", "2 values", "expected 3"});
  write_text(dir / "wide.csv", "1,2,3,4\n");
  expect_frame_error(dir / "wide.csv", 1, 3, {"wide.csv", "line 1", "4 values"});
  write_text(dir / "word.csv", "1,2,3\n4,x5,6\n");
  expect_frame_error(dir / "word.csv", 2, 3, {"word.csv", "line 2, column 2", "x5"});
  write_text(dir / "inf.csv", "1,inf,3\n");
  expect_frame_error(dir / "inf.csv", 1, 3, {"inf.csv", "line 1, column 2"});
  expect_frame_error(dir / "absent.csv", 1, 3, {"absent.csv", "no such file"});
  // A real frame against the wrong grid.
  expect_frame_error(kBaseline / "mixed-1/frames/000.csv", 58, 76, {"000.csv", "line 1", "77 values"});
}

// A valid session to break one key at a time.
json valid_session() {
  return json::parse(R"({
    "format": "hapticjam.session/1",
    "name": "t",
    "device": {"rows": 3, "cols": 4, "cell_size_mm": 38.0, "max_pressure_kpa": 3.45},
    "grid": {"nx": 77, "ny": 58, "x0_mm": 0.0, "y0_mm": 0.0, "dx_mm": 2.0, "dy_mm": 2.0},
    "steps": [
      {"op": "capture", "frame": "frames/000.csv"},
      {"op": "set_pressure", "kpa": 0.301},
      {"op": "jam", "cell": [0, 3]},
      {"op": "pin", "node": [1, 2]},
      {"op": "capture", "frame": "frames/001.csv", "label": "after"}
    ]
  })");
}

// Writes `doc` as session.json and expects a SessionError holding each of `parts`.
void expect_session_error(const json& doc, std::initializer_list<std::string> parts) {
  const ScratchDir scratch("badsession");
  const fs::path& dir = scratch.path;
  write_text(dir / "session.json", doc.dump(1));
  try {
    read_session(dir);
    ADD_FAILURE() << "no error for " << doc.dump();
  } catch (const SessionError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("session.json"), std::string::npos) << what;
    for (const std::string& part : parts) EXPECT_NE(what.find(part), std::string::npos) << what;
  }
}

TEST(SessionRead, ValidSessionReadsWithSensorDefaults) {
  const ScratchDir scratch("valid");
  const fs::path& dir = scratch.path;
  json doc = valid_session();
  doc["extra"] = {{"ignored", true}};
  doc["steps"][2]["note"] = "unknown keys are ignored";
  write_text(dir / "session.json", doc.dump());
  const Session s = read_session(dir / "session.json");
  EXPECT_EQ(s.name, "t");
  EXPECT_DOUBLE_EQ(s.sensor_accuracy_mm, 3.0);
  EXPECT_DOUBLE_EQ(s.sensor_resolution_mm, 1.0);
  ASSERT_EQ(s.steps.size(), 5u);
  EXPECT_NEAR(s.steps[1].action.pressure_pa, 301.0, 1e-9);
  EXPECT_EQ(s.steps[4].label, "after");
  EXPECT_TRUE(s.steps[0].label.empty());
}

TEST(SessionRead, MalformedTopLevelNamesTheKey) {
  json d = valid_session();
  d.erase("format");
  expect_session_error(d, {"\"format\"", "missing"});
  d = valid_session();
  d["format"] = "hapticjam.session/2";
  expect_session_error(d, {"\"format\"", "hapticjam.session/2"});
  d = valid_session();
  d["device"].erase("rows");
  expect_session_error(d, {"\"device.rows\"", "missing"});
  d = valid_session();
  d["device"]["cols"] = "4";
  expect_session_error(d, {"\"device.cols\"", "integer"});
  d = valid_session();
  d["device"]["cell_size_mm"] = 0;
  expect_session_error(d, {"\"device.cell_size_mm\"", "positive"});
  d = valid_session();
  d["device"]["max_pressure_kpa"] = -1.0;
  expect_session_error(d, {"\"device.max_pressure_kpa\""});
  d = valid_session();
  d["device"]["rows"] = 100000;
  expect_session_error(d, {"\"device\"", "mesh points"});
  d = valid_session();
  d["grid"].erase("dy_mm");
  expect_session_error(d, {"\"grid.dy_mm\"", "missing"});
  d = valid_session();
  d["grid"]["dx_mm"] = 0.0;
  expect_session_error(d, {"\"grid.dx_mm\"", "positive"});
  d = valid_session();
  d["grid"]["ny"] = -3;
  expect_session_error(d, {"\"grid.ny\"", "-3"});
  d = valid_session();
  d["grid"]["nx"] = 5000;
  d["grid"]["ny"] = 6000;
  expect_session_error(d, {"\"grid.nx\"", "25000000"});
  d = valid_session();
  d["grid"]["x0_mm"] = "0";
  expect_session_error(d, {"\"grid.x0_mm\"", "number"});
  d = valid_session();
  d["sensor"] = {{"accuracy_mm", -2.0}};
  expect_session_error(d, {"\"sensor.accuracy_mm\""});
  d = valid_session();
  d.erase("steps");
  expect_session_error(d, {"\"steps\"", "missing"});
  d = valid_session();
  d["steps"] = json::object();
  expect_session_error(d, {"\"steps\"", "array"});
}

TEST(SessionRead, MalformedStepNamesIndexAndKey) {
  json d = valid_session();
  d["steps"][2]["cell"] = {5, 0};
  expect_session_error(d, {"steps[2] (\"jam\")", "\"cell\"", "[5, 0] is out of range: rows 0..2, cols 0..3"});
  d = valid_session();
  d["steps"][2]["cell"] = {1};
  expect_session_error(d, {"steps[2]", "\"cell\"", "2-element integer array"});
  d = valid_session();
  d["steps"][2]["cell"] = {1.5, 2};
  expect_session_error(d, {"steps[2]", "\"cell\"", "2-element integer array"});
  d = valid_session();
  d["steps"][2].erase("cell");
  expect_session_error(d, {"steps[2]", "\"cell\"", "missing"});
  d = valid_session();
  d["steps"][3]["node"] = {0, 2};
  expect_session_error(d, {"steps[3] (\"pin\")", "\"node\"", "out of range"});
  d = valid_session();
  d["steps"][3]["node"] = "1,2";
  expect_session_error(d, {"steps[3]", "\"node\""});
  d = valid_session();
  d["steps"][1]["kpa"] = -0.1;
  expect_session_error(d, {"steps[1] (\"set_pressure\")", "\"kpa\"", "pressure"});
  d = valid_session();
  d["steps"][1]["kpa"] = 3.46;
  expect_session_error(d, {"steps[1]", "\"kpa\"", "3.45"});
  d = valid_session();
  d["steps"][1]["kpa"] = "0.3";
  expect_session_error(d, {"steps[1]", "\"kpa\"", "number"});
  d = valid_session();
  d["steps"][2]["op"] = "jamm";
  expect_session_error(d, {"steps[2] (\"jamm\")", "\"op\"", "unknown op"});
  d = valid_session();
  d["steps"][2].erase("op");
  expect_session_error(d, {"steps[2]", "\"op\"", "missing"});
  d = valid_session();
  d["steps"][2] = 7;
  expect_session_error(d, {"steps[2]", "object"});
  d = valid_session();
  d["steps"][4].erase("frame");
  expect_session_error(d, {"steps[4] (\"capture\")", "\"frame\"", "missing"});
  d = valid_session();
  d["steps"][4]["frame"] = "/tmp/001.csv";
  expect_session_error(d, {"steps[4]", "\"frame\"", "relative"});
  d = valid_session();
  d["steps"][4]["frame"] = "frames/../../001.csv";
  expect_session_error(d, {"steps[4]", "\"frame\"", ".."});
  d = valid_session();
  d["steps"][4]["frame"] = "./frames/000.csv";
  expect_session_error(d, {"steps[4]", "\"frame\"", "steps[0]"});
  d = valid_session();
  d["steps"][4]["label"] = 3;
  expect_session_error(d, {"steps[4]", "\"label\"", "string"});
}

TEST(SessionRead, UnreadableOrInvalidJsonNamesTheFile) {
  const ScratchDir scratch("syntax");
  const fs::path& dir = scratch.path;
  write_text(dir / "session.json", "{\"format\": \"hapticjam.session/1\",\n \"device\": {\"rows\": 3,,}}");
  try {
    read_session(dir);
    ADD_FAILURE() << "no error";
  } catch (const SessionError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("session.json"), std::string::npos) << what;
    EXPECT_NE(what.find("invalid JSON at byte"), std::string::npos) << what;
  }
  try {
    read_session(dir / "absent");
    ADD_FAILURE() << "no error";
  } catch (const SessionError& e) {
    EXPECT_NE(std::string(e.what()).find("absent"), std::string::npos) << e.what();
  }
  write_text(dir / "session.json", "[1, 2]");
  EXPECT_THROW(read_session(dir), SessionError);
}

// The paper's 3 x 4 array at p = 4: 13 x 17 points, 152 x 114 mm.
Mesh paper_mesh() { return Mesh(ArrayGeometry{}); }

SessionGrid grid_around_device() {
  // 4 mm past every edge, 2 mm pitch: samples at x = -4, -2, ..., 156.
  return SessionGrid{81, 62, -4.0, -4.0, 2.0, 2.0};
}

TEST(Rasterize, FlatMeshIsZeroOverTheArrayAndMissingOutside) {
  const Mesh mesh = paper_mesh();
  const SessionGrid grid = grid_around_device();
  const Eigen::MatrixXd z = rasterize_top_view(mesh, mesh.rest_positions(), grid);
  ASSERT_EQ(z.rows(), grid.ny);
  ASSERT_EQ(z.cols(), grid.nx);
  int inside = 0;
  for (int iy = 0; iy < grid.ny; ++iy) {
    for (int ix = 0; ix < grid.nx; ++ix) {
      const double x = grid.x_mm(ix), y = grid.y_mm(iy);
      if (x >= 0.0 && x <= 152.0 && y >= 0.0 && y <= 114.0) {
        EXPECT_EQ(z(iy, ix), 0.0) << "at x = " << x << ", y = " << y;
        ++inside;
      } else {
        EXPECT_TRUE(std::isnan(z(iy, ix))) << "at x = " << x << ", y = " << y;
      }
    }
  }
  EXPECT_EQ(inside, 77 * 58);
}

TEST(Rasterize, TiltedPlaneIsReproducedAtEveryCoveredSample) {
  const Mesh mesh = paper_mesh();
  Eigen::Matrix3Xd x = mesh.rest_positions();
  // z = a x + b y + c (all in metres), then moved off the grid's pitch in xy.
  const double a = 0.13, b = -0.27, c = 0.004;
  x.row(2) = a * x.row(0) + b * x.row(1) + Eigen::RowVectorXd::Constant(x.cols(), c);
  x.row(0).array() += 0.0013;
  x.row(1).array() -= 0.0007;
  const double x_shift_mm = 1.3, y_shift_mm = -0.7;
  const SessionGrid grid{57, 43, -3.1, -2.9, 2.8, 2.8};
  const Eigen::MatrixXd z = rasterize_top_view(mesh, x, grid);
  int covered = 0;
  for (int iy = 0; iy < grid.ny; ++iy) {
    for (int ix = 0; ix < grid.nx; ++ix) {
      const double xm = grid.x_mm(ix), ym = grid.y_mm(iy);
      const bool inside = xm >= x_shift_mm && xm <= 152.0 + x_shift_mm && ym >= y_shift_mm && ym <= 114.0 + y_shift_mm;
      if (!inside) {
        EXPECT_TRUE(std::isnan(z(iy, ix)));
        continue;
      }
      ASSERT_FALSE(std::isnan(z(iy, ix))) << "uncovered at x = " << xm << ", y = " << ym;
      const double plane_mm = a * (xm - x_shift_mm) + b * (ym - y_shift_mm) + 1000.0 * c;
      EXPECT_NEAR(z(iy, ix), plane_mm, 1e-9);
      ++covered;
    }
  }
  EXPECT_GT(covered, 2000);
}

TEST(Rasterize, RaisedPointIsThePeakAndNothingIsHigher) {
  const Mesh mesh = paper_mesh();
  Eigen::Matrix3Xd x = mesh.rest_positions();
  const int i = 4, j = 8;  // node [1, 2] at x = 76 mm, y = 38 mm
  x(2, mesh.index(i, j)) = 0.012;
  const SessionGrid grid{77, 58, 0.0, 0.0, 2.0, 2.0};
  const Eigen::MatrixXd z = rasterize_top_view(mesh, x, grid);
  const int px = 38, py = 19;
  EXPECT_NEAR(z(py, px), 12.0, 1e-9);
  for (int iy = 0; iy < grid.ny; ++iy) {
    for (int ix = 0; ix < grid.nx; ++ix) {
      ASSERT_FALSE(std::isnan(z(iy, ix)));
      if (iy == py && ix == px) continue;
      EXPECT_LT(z(iy, ix), z(py, px)) << "at ix = " << ix << ", iy = " << iy;
      EXPECT_GE(z(iy, ix), 0.0);
      // Only the squares around the raised point rise.
      if (std::abs(grid.x_mm(ix) - 76.0) >= 9.5 || std::abs(grid.y_mm(iy) - 38.0) >= 9.5) {
        EXPECT_EQ(z(iy, ix), 0.0);
      }
    }
  }
}

TEST(Rasterize, SquaresSplitAlongTheIJToI1J1Diagonal) {
  const Mesh mesh = paper_mesh();
  // Samples at every mesh point and every square centre (pitch h / 2 = 4.75 mm).
  const SessionGrid grid{33, 25, 0.0, 0.0, 4.75, 4.75};
  const int i = 4, j = 8;
  // Square (i, j)-(i+1, j+1) has its centre at sample (2j + 1, 2i + 1).
  {
    // Raising (i, j): the centre lies on the raised diagonal, so half height.
    Eigen::Matrix3Xd x = mesh.rest_positions();
    x(2, mesh.index(i, j)) = 0.010;
    EXPECT_NEAR(rasterize_top_view(mesh, x, grid)(2 * i + 1, 2 * j + 1), 5.0, 1e-9);
  }
  {
    // Raising (i, j+1): off the diagonal, so the centre stays at 0.
    Eigen::Matrix3Xd x = mesh.rest_positions();
    x(2, mesh.index(i, j + 1)) = 0.010;
    EXPECT_NEAR(rasterize_top_view(mesh, x, grid)(2 * i + 1, 2 * j + 1), 0.0, 1e-9);
  }
}

TEST(Rasterize, HighestOfOverlappingTrianglesWins) {
  // Fold: push column 8 of points 20 mm along +x and up, so the mesh overlaps
  // itself in xy; the covered samples take the higher sheet.
  const Mesh mesh = paper_mesh();
  Eigen::Matrix3Xd x = mesh.rest_positions();
  for (int i = 1; i + 1 < mesh.point_rows(); ++i) {
    x(0, mesh.index(i, 8)) += 0.020;
    x(2, mesh.index(i, 8)) = 0.005;
  }
  const SessionGrid grid{77, 58, 0.0, 0.0, 2.0, 2.0};
  const Eigen::MatrixXd z = rasterize_top_view(mesh, x, grid);
  // Along mesh row 4 (y = 38 mm) at x = 90 mm three sheets overlap: the
  // flat one beyond column 9 (85.5 mm), the slope from column 7 (66.5 mm,
  // z = 0) up to the moved column 8 (96 mm, 5 mm), giving 5 * 23.5 / 29.5,
  // and the fold back down to column 9, giving 5 * 4.5 / 10.5. The highest wins.
  const int iy = 19, ix = 45;  // x = 90 mm, y = 38 mm
  EXPECT_NEAR(z(iy, ix), 5.0 * 23.5 / 29.5, 1e-9);
  // Beyond the fold the flat sheet is alone again.
  EXPECT_EQ(z(iy, 50), 0.0);  // x = 100 mm
}

TEST(Rasterize, RejectsPositionsOfTheWrongSize) {
  const Mesh mesh = paper_mesh();
  const Eigen::Matrix3Xd x = Eigen::Matrix3Xd::Zero(3, 10);
  EXPECT_THROW(rasterize_top_view(mesh, x, SessionGrid{77, 58, 0, 0, 2, 2}), std::invalid_argument);
}

}  // namespace
}  // namespace hj

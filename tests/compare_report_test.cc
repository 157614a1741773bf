// The compare report (src/calib/report/compare_report.h): one heat map per
// capture, named in summary.json and embedded in a report.html that needs
// no other file; base64 against RFC 4648's test vectors.
#include <gtest/gtest.h>

#include <opencv2/imgcodecs.hpp>

#include "calib/diagnosis.h"
#include "calib/report/compare_report.h"
#include "calib/report/report_file.h"
#include "calib/residuals.h"

namespace hj {
namespace {

const std::filesystem::path kBaseline = std::filesystem::path(HJ_SHARED_DIR) / "data/sessions/demo-baseline";

TEST(Base64, MatchesTheRfc4648TestVectors) {
  EXPECT_EQ(base64(""), "");
  EXPECT_EQ(base64("f"), "Zg==");
  EXPECT_EQ(base64("fo"), "Zm8=");
  EXPECT_EQ(base64("foo"), "Zm9v");
  EXPECT_EQ(base64("foob"), "Zm9vYg==");
  EXPECT_EQ(base64("fooba"), "Zm9vYmE=");
  EXPECT_EQ(base64("foobar"), "Zm9vYmFy");
  EXPECT_EQ(base64(std::string("\xff\x00\x80", 3)), "/wCA");
}

TEST(CompareReport, OneEmbeddedHeatMapPerCaptureNamedInTheSummary) {
  const Dataset dataset = select_sessions(read_dataset(kBaseline), {"unjammed-sweep"}, true);
  ModelParams params;
  params.surface = SurfaceParameters::paper_defaults(dataset.device().geometry(2));
  params.surface.max_pressure_pa = dataset.device().max_pressure_kpa * 1000.0;
  ReplayOptions replay;
  replay.segments = 2;
  const Evaluation evaluation = evaluate_dataset(dataset, params, replay);
  int progress_calls = 0;
  const CompareReport report =
      compare_report(dataset, params, evaluation, 5.0, [&](int done, int total, const std::string&) {
        EXPECT_EQ(done, ++progress_calls);
        EXPECT_EQ(total, dataset.capture_count());
      });
  ASSERT_EQ(static_cast<int>(report.maps.size()), dataset.capture_count());
  EXPECT_EQ(progress_calls, dataset.capture_count());
  const auto& session = dataset.sessions.front().session;
  for (size_t c = 0; c < report.maps.size(); ++c) {
    const ReportFile& map = report.maps[c];
    EXPECT_EQ(report.summary["sessions"][0]["captures"][c]["image"], map.path);
    // A PNG of the sample grid at 6 pixels a sample, plus the title and legend.
    const cv::Mat image = cv::imdecode(cv::Mat(1, static_cast<int>(map.bytes.size()), CV_8U,
                                               const_cast<char*>(map.bytes.data())),
                                       cv::IMREAD_COLOR);
    ASSERT_FALSE(image.empty()) << map.path;
    EXPECT_GE(image.rows, 6 * session.grid.ny);
    EXPECT_GE(image.cols, 6 * session.grid.nx);
    // Embedded as it is, so report.html needs no other file.
    EXPECT_NE(report.html.find("data:image/png;base64," + base64(map.bytes) + "'"), std::string::npos) << map.path;
  }
  EXPECT_EQ(report.html.find("src='maps/"), std::string::npos) << "no reference to a file beside the page";
  EXPECT_NE(report.html.find("Residual per cell"), std::string::npos);
}

}  // namespace
}  // namespace hj

// A bad dataset handed to compare, fit or diagnose stops at reading with an
// error naming the file and key at fault, before any replay: a frame the
// session lists but the folder lacks, a frame of the wrong shape, a
// pressure above the device's safe maximum, an empty folder.
#include <gtest/gtest.h>

#include <fstream>

#include "calib/dataset.h"
#include "calib/frame_csv.h"
#include "calib_synthetic.h"
#include "scratch_dir.h"

namespace hj {
namespace {

namespace fs = std::filesystem;

// The tiny sessions with flat frames (no simulation needed to read them).
fs::path flat_dataset(const fs::path& root) {
  testing_support::write_tiny_sessions(root);
  for (const char* session : {"sweep", "jammed"})
    for (int k = 0; k < (std::string(session) == "sweep" ? 5 : 3); ++k)
      write_frame_csv(root / session / ("frames/00" + std::to_string(k) + ".csv"), Eigen::MatrixXd::Zero(58, 77));
  return root;
}

void expect_dataset_error(const fs::path& dir, std::initializer_list<std::string> parts) {
  try {
    read_dataset(dir);
    ADD_FAILURE() << "no error reading " << dir;
  } catch (const SessionError& e) {
    const std::string what = e.what();
    for (const std::string& part : parts) EXPECT_NE(what.find(part), std::string::npos) << what;
  }
}

TEST(CalibBadDataset, AFlatDatasetReads) {
  testing_support::ScratchDir scratch("flat");
  EXPECT_EQ(read_dataset(flat_dataset(scratch.path)).sessions.size(), 2u);
}

TEST(CalibBadDataset, AMissingFrameNamesTheFile) {
  testing_support::ScratchDir scratch("missing");
  fs::remove(flat_dataset(scratch.path) / "sweep/frames/003.csv");
  expect_dataset_error(scratch.path, {"sweep", "003.csv", "no such file"});
}

TEST(CalibBadDataset, AFrameOfTheWrongShapeNamesTheFileAndLine) {
  testing_support::ScratchDir scratch("shape");
  write_frame_csv(flat_dataset(scratch.path) / "jammed/frames/001.csv", Eigen::MatrixXd::Zero(58, 76));
  expect_dataset_error(scratch.path, {"jammed", "001.csv", "line 1", "76 values", "expected 77"});
}

TEST(CalibBadDataset, AnUnsafePressureNamesTheStepAndKey) {
  testing_support::ScratchDir scratch("pressure");
  const fs::path session = flat_dataset(scratch.path) / "sweep/session.json";
  nlohmann::json doc = nlohmann::json::parse(std::ifstream(session));
  doc["steps"][7]["kpa"] = 3.6;  // above max_pressure_kpa 3.45
  std::ofstream(session) << doc.dump(1);
  expect_dataset_error(scratch.path, {"sweep", "session.json", "steps[7]", "\"kpa\"", "3.45"});
}

TEST(CalibBadDataset, AnEmptyFolderSaysSo) {
  testing_support::ScratchDir scratch("empty");
  expect_dataset_error(scratch.path, {scratch.path.string(), "no session folders"});
}

}  // namespace
}  // namespace hj

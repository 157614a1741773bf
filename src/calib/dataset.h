// A dataset (docs/session-format.md, "Datasets"): a folder of measurement
// sessions on one device, read with all their frames, and for every capture
// the device state the steps had set when it was taken (pressure, jammed
// cells, pinned nodes), which the residual analysis groups by.
#pragma once

#include <Eigen/Core>
#include <filesystem>
#include <functional>
#include <string>
#include <utility>
#include <vector>

#include "calib/session.h"

namespace hj {

struct MeasuredCapture {
  int step_index = 0;  // position in the session's "steps"
  std::string frame;   // relative frame path
  std::string label;
  Eigen::MatrixXd heights_mm;                 // (ny x nx), NaN = missing
  double pressure_pa = 0.0;                   // chamber pressure when taken
  std::vector<bool> jammed;                   // (R*C), cell r*C + c jammed
  std::vector<std::pair<int, int>> pinned;    // pinned nodes (a, b)
  int jammed_count() const;
};

struct MeasuredSession {
  Session session;
  std::vector<MeasuredCapture> captures;  // in step order
};

struct Dataset {
  std::filesystem::path dir;
  std::vector<MeasuredSession> sessions;  // sorted by folder name

  const SessionDevice& device() const { return sessions.front().session.device; }
  int capture_count() const;
};

// A session with its captures' frames (from `frame`, one per capture step,
// (ny x nx)) and the device state each capture was taken in: how a dataset
// is read from files, and how captures that never touched a disk (a render
// job's, on_the_fly.h) become one.
MeasuredSession measured_session(Session session,
                                 const std::function<Eigen::MatrixXd(const Session&, const SessionStep&)>& frame);

// Reads every sub-folder of `dir` that holds a session.json, and its frames.
// @throws SessionError naming the folder if it holds no session, a session
//         whose device differs from the first one's, or (from read_session
//         and read_frame_csv) the file, step and key that is wrong.
Dataset read_dataset(const std::filesystem::path& dir);

// The sessions of `dataset` named in `names` (keep = true) or all others
// (keep = false). @throws SessionError naming an unknown session.
Dataset select_sessions(const Dataset& dataset, const std::vector<std::string>& names, bool keep);

// Each session that has a capture matching `chosen`, cut after the last
// such capture (steps and captures): what a fit of those captures needs to
// replay. Captures before it that do not match stay.
Dataset sessions_up_to(const Dataset& dataset, const std::function<bool(const MeasuredCapture&)>& chosen);

}  // namespace hj

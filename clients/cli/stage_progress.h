// Progress of a job with stages (levelling, Algorithm 1, least squares ...):
// one ProgressLine per stage, replaced when the stage changes, and the wall
// and CPU time (all threads) spent in each stage, for the speed report; with
// a ReplayTally, also the session replays each stage made.
#pragma once

#include <chrono>
#include <ctime>
#include <map>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "calib/replay_tally.h"
#include "progress.h"

namespace hj::cli {

class StageProgress {
 public:
  StageProgress() = default;
  // Counts the replays of `tally` (which must outlive this) per stage.
  explicit StageProgress(const ReplayTally* tally) : tally_(tally), replays_since_(tally ? tally->replays() : 0) {}

  void operator()(const std::string& stage, int done, int total, const std::string& detail) {
    if (!line_ || stage != stage_) {
      if (line_) line_->finish();
      account();
      stage_ = stage;
      line_ = std::make_unique<ProgressLine>(stage);
    }
    line_->update(done, total, detail);
  }
  void finish() {
    if (line_) line_->finish();
    account();
    line_.reset();
  }

  // [{"stage", "wall_s", "cpu_s"(, "replays")}] in order of first appearance.
  nlohmann::json timing() const {
    nlohmann::json out = nlohmann::json::array();
    for (const auto& name : order_) {
      nlohmann::json entry = {{"stage", name}, {"wall_s", time_.at(name).first}, {"cpu_s", time_.at(name).second}};
      if (tally_) entry["replays"] = replays_.count(name) ? replays_.at(name) : 0L;
      out.push_back(entry);
    }
    return out;
  }

 private:
  // Charges the time since the last stage change to the current stage.
  void account() {
    const auto now = std::chrono::steady_clock::now();
    const std::clock_t cpu = std::clock();
    if (line_) {
      if (!time_.count(stage_)) order_.push_back(stage_);
      auto& [wall, cpu_s] = time_[stage_];
      wall += std::chrono::duration<double>(now - since_).count();
      cpu_s += static_cast<double>(cpu - cpu_since_) / CLOCKS_PER_SEC;
    }
    since_ = now;
    cpu_since_ = cpu;
    if (tally_) {
      const long replays = tally_->replays();
      if (line_) replays_[stage_] += replays - replays_since_;
      replays_since_ = replays;
    }
  }

  std::string stage_;
  std::unique_ptr<ProgressLine> line_;
  std::chrono::steady_clock::time_point since_ = std::chrono::steady_clock::now();
  std::clock_t cpu_since_ = std::clock();
  std::vector<std::string> order_;
  std::map<std::string, std::pair<double, double>> time_;
  const ReplayTally* tally_ = nullptr;
  long replays_since_ = 0;
  std::map<std::string, long> replays_;
};

}  // namespace hj::cli

// Progress of a job with stages (levelling, Algorithm 1, least squares ...):
// one ProgressLine per stage, replaced when the stage changes, and the wall
// and CPU time (all threads) spent in each stage, for the speed report.
#pragma once

#include <chrono>
#include <ctime>
#include <map>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "progress.h"

namespace hj::cli {

class StageProgress {
 public:
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

  // {"stage": {"wall_s", "cpu_s"}} in order of first appearance.
  nlohmann::json timing() const {
    nlohmann::json out = nlohmann::json::array();
    for (const auto& name : order_)
      out.push_back({{"stage", name}, {"wall_s", time_.at(name).first}, {"cpu_s", time_.at(name).second}});
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
  }

  std::string stage_;
  std::unique_ptr<ProgressLine> line_;
  std::chrono::steady_clock::time_point since_ = std::chrono::steady_clock::now();
  std::clock_t cpu_since_ = std::clock();
  std::vector<std::string> order_;
  std::map<std::string, std::pair<double, double>> time_;
};

}  // namespace hj::cli

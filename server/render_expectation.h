// What the device is expected to make of a render's next plan
// (render_loop.h, the screen and the corrections in the model): the plan's
// predicted surface as the camera would see it at the mesh points, moved by
// the last run's misfit (capture minus prediction) when that run was
// planned with the model the next plans use.
#pragma once

#include <Eigen/Core>

#include "hapticjam/v1/render_service.pb.h"
#include "model/mesh.h"
#include "plan/planner.h"

namespace hj::server {

class RenderExpectation {
 public:
  RenderExpectation(const Mesh& mesh, const Eigen::MatrixXd& goal_mm) : mesh_(mesh), goal_mm_(goal_mm) {}

  // A run's capture and prediction at the mesh points, and its camera grid.
  void after_run(const Eigen::MatrixXd& measured, const Eigen::MatrixXd& predicted,
                 const hapticjam::v1::CaptureGrid& grid);
  // The model was refitted after the last run: its misfit was the old model's.
  void model_refitted() { misfit_applies_ = false; }

  struct Expected {
    Eigen::MatrixXd surface;  // at the mesh points
    double mae_mm = 0.0;      // against the goal
  };
  // @throws std::invalid_argument when the shapes differ or nothing is finite in both.
  Expected of(const PlanResult& planned) const;

 private:
  const Mesh& mesh_;
  const Eigen::MatrixXd& goal_mm_;
  Eigen::MatrixXd last_measured_, last_predicted_;
  hapticjam::v1::CaptureGrid last_grid_;
  bool misfit_applies_ = false;
};

}  // namespace hj::server

// The depth camera's plane is tilted and offset against the device's: a
// measurement effect, not a physical one. It adds no force; it changes the
// heights a camera reports for a predicted surface (Effect::adjust_measurement),
//   z_seen = z + offset_mm + 1e-3 (tilt_x (x - x_c) + tilt_y (y - y_c)),
// with tilts in mrad (mm per m) about the array's centre (x_c, y_c), so that
// the offset and the tilts do not trade off. All zero is the baseline.
#include "sim/effect_registry.h"

namespace hj {
namespace {

class SensorTilt final : public Effect {
 public:
  SensorTilt(double tilt_x_mrad, double tilt_y_mrad, double offset_mm)
      : tilt_x_mrad_(tilt_x_mrad), tilt_y_mrad_(tilt_y_mrad), offset_mm_(offset_mm) {}
  std::string_view name() const override { return "sensor_tilt"; }

  void add_forces(const ForceContext&, const Eigen::Matrix3Xd&, Eigen::Matrix3Xd&) const override {}
  void add_stiffness(const ForceContext&, const Eigen::Matrix3Xd&, StiffnessSink&) const override {}
  std::optional<double> energy(const ForceContext&, const Eigen::Matrix3Xd&) const override { return 0.0; }

  void adjust_measurement(const Mesh& mesh, const Eigen::VectorXd& x_mm, const Eigen::VectorXd& y_mm,
                          Eigen::MatrixXd& heights_mm) const override {
    const double xc_mm = 500.0 * mesh.cols() * mesh.cell_size(), yc_mm = 500.0 * mesh.rows() * mesh.cell_size();
    for (int iy = 0; iy < heights_mm.rows(); ++iy)
      for (int ix = 0; ix < heights_mm.cols(); ++ix)
        heights_mm(iy, ix) +=
            offset_mm_ + 1e-3 * (tilt_x_mrad_ * (x_mm(ix) - xc_mm) + tilt_y_mrad_ * (y_mm(iy) - yc_mm));
  }

 private:
  double tilt_x_mrad_, tilt_y_mrad_, offset_mm_;
};

HJ_REGISTER_EFFECT(EffectInfo{"sensor_tilt",
                              "camera plane tilted (tilt_x, tilt_y about the array centre) and offset: "
                              "changes the measured frames, not the forces",
                              false,
                              {{"tilt_x_mrad", "mrad", 0.0, -50.0, 50.0},
                               {"tilt_y_mrad", "mrad", 0.0, -50.0, 50.0},
                               {"offset_mm", "mm", 0.0, -20.0, 20.0}},
                              [](const EffectParameterValues& v) {
                                return std::make_unique<SensorTilt>(v.at("tilt_x_mrad"), v.at("tilt_y_mrad"),
                                                                    v.at("offset_mm"));
                              },
                              /*measurement_only=*/true});

}  // namespace
}  // namespace hj

// After the greedy selection, an effect that a later one made redundant is
// dropped (calib/redundant_effects.h): it no longer pays for its parameters
// in BIC. An effect the data need is kept.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "calib/redundant_effects.h"
#include "calib_synthetic.h"
#include "scratch_dir.h"

namespace hj {
namespace {

struct Tilted {
  testing_support::ScratchDir scratch{"redundant"};
  ModelParams truth = testing_support::true_tiny_baseline();
  Dataset dataset;
  Tilted() {
    truth.effects = {"sensor_tilt"};
    truth.effect_parameters["sensor_tilt"] = {{"tilt_x_mrad", 15.0}, {"tilt_y_mrad", -10.0}};
    dataset = testing_support::synthesize_tiny(scratch.path, truth);
  }
};

// The fit of `effects` at `params`, replayed there (no iteration).
LeastSquaresResult fitted_at(const Dataset& d, const ModelParams& params, const std::vector<std::string>& effects) {
  LeastSquaresOptions replay_only;
  replay_only.max_iterations = 0;
  return fit_least_squares(d, params, fit_parameters(effects), replay_only);
}

TEST(RedundantEffects, AnEffectAtItsNeutralValueIsDroppedAndTheOtherKept) {
  Tilted data;
  // A cell defect chosen first, then the tilt: the defect has gone back to 1.
  ModelParams model = data.truth;
  model.effects = {"cell_defect", "sensor_tilt"};
  model.effect_parameters["cell_defect"] = {{"factor", 1.0}, {"row", 1}, {"col", 1}};
  DiagnoseOptions options;
  Diagnosis out;
  const DiagnoseProgress progress;
  Selection s{data.dataset, options, progress, out, {"cell_defect", "sensor_tilt"},
              fitted_at(data.dataset, model, {"cell_defect", "sensor_tilt"}), 1.0};
  drop_redundant_effects(s);
  EXPECT_EQ(s.chosen, std::vector<std::string>{"sensor_tilt"});
  EXPECT_EQ(s.current.params.effects, std::vector<std::string>{"sensor_tilt"});
  EXPECT_EQ(s.current.params.effect_parameters.count("cell_defect"), 0u);
  ASSERT_EQ(out.notes.size(), 1u);
  EXPECT_NE(out.notes[0].find("cell_defect dropped"), std::string::npos) << out.notes[0];
}

TEST(RedundantEffects, AnEffectTheDataNeedIsKeptWhereItIsTriedFirst) {
  Tilted data;
  // The tilt chosen first, then a defect the data do not have (1.3 k).
  ModelParams model = data.truth;
  model.effects = {"sensor_tilt", "cell_defect"};
  model.effect_parameters["cell_defect"] = {{"factor", 1.3}, {"row", 0}, {"col", 2}};
  DiagnoseOptions options;
  Diagnosis out;
  const DiagnoseProgress progress;
  Selection s{data.dataset, options, progress, out, {"sensor_tilt", "cell_defect"},
              fitted_at(data.dataset, model, {"sensor_tilt", "cell_defect"}), 1.0};
  const double with_both = s.current.rmse_mm;
  drop_redundant_effects(s);
  EXPECT_EQ(s.chosen, std::vector<std::string>{"sensor_tilt"});
  EXPECT_LT(s.current.rmse_mm, with_both);
}

}  // namespace
}  // namespace hj

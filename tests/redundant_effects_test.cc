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

// Tilted tiny data, and the selection step's inputs around them.
class RedundantEffects : public ::testing::Test {
 protected:
  RedundantEffects() {
    truth.effects = {"sensor_tilt"};
    truth.effect_parameters["sensor_tilt"] = {{"tilt_x_mrad", 15.0}, {"tilt_y_mrad", -10.0}};
    dataset = testing_support::synthesize_tiny(scratch.path, truth);
  }

  // The selection of `chosen`, its fit replayed at the truth with the
  // cell defect `defect` added (no iteration).
  Selection chose(const std::vector<std::string>& chosen, const EffectParameterValues& defect) {
    ModelParams model = truth;
    model.effects = chosen;
    model.effect_parameters["cell_defect"] = defect;
    LeastSquaresOptions replay_only;
    replay_only.max_iterations = 0;
    return Selection{dataset, options, progress, out, chosen,
                     fit_least_squares(dataset, model, fit_parameters(chosen), replay_only), 1.0};
  }

  testing_support::ScratchDir scratch{"redundant"};
  ModelParams truth = testing_support::true_tiny_baseline();
  Dataset dataset;
  DiagnoseOptions options;
  Diagnosis out;
  const DiagnoseProgress progress;
};

TEST_F(RedundantEffects, AnEffectAtItsNeutralValueIsDroppedAndTheOtherKept) {
  // A cell defect chosen first, then the tilt: the defect has gone back to 1.
  Selection s = chose({"cell_defect", "sensor_tilt"}, {{"factor", 1.0}, {"row", 1}, {"col", 1}});
  drop_redundant_effects(s);
  EXPECT_EQ(s.chosen, std::vector<std::string>{"sensor_tilt"});
  EXPECT_EQ(s.current.params.effects, std::vector<std::string>{"sensor_tilt"});
  EXPECT_EQ(s.current.params.effect_parameters.count("cell_defect"), 0u);
  ASSERT_EQ(out.notes.size(), 1u);
  EXPECT_NE(out.notes[0].find("cell_defect dropped"), std::string::npos) << out.notes[0];
}

TEST_F(RedundantEffects, AnEffectTheDataNeedIsKeptWhereItIsTriedFirst) {
  // The tilt chosen first, then a defect the data do not have (1.3 k).
  Selection s = chose({"sensor_tilt", "cell_defect"}, {{"factor", 1.3}, {"row", 0}, {"col", 2}});
  const double with_both = s.current.rmse_mm;
  drop_redundant_effects(s);
  EXPECT_EQ(s.chosen, std::vector<std::string>{"sensor_tilt"});
  EXPECT_LT(s.current.rmse_mm, with_both);
}

}  // namespace
}  // namespace hj

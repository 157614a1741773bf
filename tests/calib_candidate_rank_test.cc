// The order of a round's candidates (calib/selection.h, ranks_before): the
// significant ones first, by delta BIC, then the rest by held-out RMSE.
#include <gtest/gtest.h>

#include <algorithm>
#include <string>
#include <vector>

#include "calib/selection.h"

namespace hj {
namespace {

CandidateFit candidate(const std::string& name, bool significant, double delta_bic, double heldout_mm) {
  CandidateFit c;
  c.added = name;
  c.effects = {name};
  c.significant = significant;
  c.delta_bic = delta_bic;
  c.heldout_rmse_mm = heldout_mm;
  return c;
}

std::vector<std::string> ranked(std::vector<CandidateFit> fits) {
  std::stable_sort(fits.begin(), fits.end(), ranks_before);
  std::vector<std::string> names;
  for (const auto& c : fits) names.push_back(c.added);
  return names;
}

TEST(CandidateRank, SignificantCandidatesAreRankedByTheirEvidenceNotTheirHeldOutFigures) {
  // An off-form soft cell: cell_defect fits far better in sample, but one of
  // its folds was truly held out while two of cell_stiffness's kept the
  // full-data optimum, so its held-out figure is the larger.
  const auto names = ranked({candidate("cell_stiffness", true, -28919.0, 1.446),
                             candidate("cell_defect", true, -41339.0, 1.587)});
  EXPECT_EQ(names.front(), "cell_defect");
}

TEST(CandidateRank, ASignificantCandidateComesBeforeAnyOtherAndTheRestGoByHeldOutError) {
  const auto names = ranked({candidate("stiffening", false, -500000.0, 1.30),  // refused, e.g. immaterial
                             candidate("jam_creep", false, 11.0, 1.70),
                             candidate("bending", true, -120.0, 1.60),
                             candidate("sensor_tilt", false, -90.0, 1.50)});
  EXPECT_EQ(names, (std::vector<std::string>{"bending", "stiffening", "sensor_tilt", "jam_creep"}));
}

}  // namespace
}  // namespace hj

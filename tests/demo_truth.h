// The true baseline parameters of the shared demo datasets (the READMEs of
// shared/data/sessions/demo-baseline and demo-bending).
#pragma once

#include "model/parameters.h"

namespace hj::testing_support {

inline SurfaceParameters demo_true_parameters() {
  SurfaceParameters p;
  p.mass_kg = 0.52;
  p.spring_k = 58.0;
  p.kappa_jam = 4.2;
  return p;
}

}  // namespace hj::testing_support

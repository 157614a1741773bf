#include "fitted_parameter_proto.h"

namespace hj::server {

void estimate_to_proto(const ParameterEstimate& e, hapticjam::v1::FittedParameter* p) {
  p->set_name(e.parameter.qualified_name());
  p->set_value(e.value);
  p->set_unit(e.parameter.spec.unit);
  p->set_active(e.active);
  if (!e.active) return;
  p->set_std_error(e.std_error);
  p->set_ci95_low(e.ci95_low);
  p->set_ci95_high(e.ci95_high);
  p->set_interval_method(e.interval_method);
  p->set_loose(e.loose);
}

}  // namespace hj::server

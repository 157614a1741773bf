#include "model/parameters.h"

#include <cmath>
#include <stdexcept>
#include <string>

namespace hj {

namespace {

void require_positive(double value, const char* field, const char* unit) {
  if (!std::isfinite(value) || value <= 0.0)
    throw std::invalid_argument(std::string("parameter ") + field + " (" + unit +
                                ") must be a finite positive number, got " + std::to_string(value));
}

void require_non_negative(double value, const char* field, const char* unit) {
  if (!std::isfinite(value) || value < 0.0)
    throw std::invalid_argument(std::string("parameter ") + field + " (" + unit +
                                ") must be a finite non-negative number, got " + std::to_string(value));
}

}  // namespace

void SurfaceParameters::validate() const {
  require_positive(mass_kg, "mass_kg", "kg");
  require_positive(spring_k, "spring_k", "N/m");
  require_non_negative(damping_b, "damping_b", "N s/m");
  require_non_negative(kappa_jam, "kappa_jam", "N m/rad");
  require_non_negative(gravity, "gravity", "m/s^2");
  require_positive(max_pressure_pa, "max_pressure_pa", "Pa");
}

SurfaceParameters SurfaceParameters::paper_defaults(const ArrayGeometry& geometry) {
  SurfaceParameters p;
  p.mass_kg = 0.55 * (geometry.rows * geometry.cols) / 12.0;
  return p;
}

}  // namespace hj

#include "shapes/region.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <sstream>
#include <stdexcept>
#include <vector>

namespace hj {
namespace {

std::string describe(const Region& r) {
  std::ostringstream s;
  s << r.x0 << "," << r.y0 << "," << r.x1 << "," << r.y1 << (r.fractions ? " (fractions)" : " (pixels)");
  return s.str();
}

void check_region(const Region& r) {
  const auto fail = [&](const std::string& what) {
    throw std::invalid_argument("region " + describe(r) + ": " + what);
  };
  for (double v : {r.x0, r.y0, r.x1, r.y1}) {
    if (!std::isfinite(v)) fail("values must be finite numbers");
    if (v < 0.0) fail("values must not be negative");
    if (r.fractions && v > 1.0) fail("fractions must lie in [0, 1]");
    if (!r.fractions && v != std::floor(v)) fail("pixel indices must be whole numbers");
  }
  if (r.x1 <= r.x0) fail(r.x1 == r.x0 ? "empty: x1 equals x0" : "inverted: x1 is less than x0");
  if (r.y1 <= r.y0) fail(r.y1 == r.y0 ? "empty: y1 equals y0" : "inverted: y1 is less than y0");
}

// Pixel range [begin, end) along an axis of n pixels.
struct Span {
  long begin, end;
};

Span fraction_span(double lo, double hi, long n) {
  constexpr double kSlack = 1e-9;  // so 0.3 * 10 is pixel 3, not 4
  const long begin = std::min(n - 1, long(std::floor(lo * double(n) + kSlack)));
  const long end = std::clamp(long(std::ceil(hi * double(n) - kSlack)), begin + 1, n);
  return {begin, end};
}

}  // namespace

Region parse_region(const std::string& text) {
  std::vector<double> v;
  for (std::size_t start = 0;;) {
    const std::size_t comma = text.find(',', start);
    std::string field = text.substr(start, comma == std::string::npos ? std::string::npos : comma - start);
    field.erase(0, field.find_first_not_of(" \t"));
    field.erase(field.find_last_not_of(" \t") + 1);
    double value = 0.0;
    const auto [end, ec] = std::from_chars(field.data(), field.data() + field.size(), value);
    if (field.empty() || ec != std::errc() || end != field.data() + field.size())
      throw std::invalid_argument("region \"" + text + "\": \"" + field + "\" is not a number; expected x0,y0,x1,y1");
    v.push_back(value);
    if (comma == std::string::npos) break;
    start = comma + 1;
  }
  if (v.size() != 4)
    throw std::invalid_argument("region \"" + text + "\": expected four numbers x0,y0,x1,y1, got " +
                                std::to_string(v.size()));
  Region r{v[0], v[1], v[2], v[3], std::all_of(v.begin(), v.end(), [](double x) { return x <= 1.0; })};
  check_region(r);
  return r;
}

Region pixel_region(const Region& region, long rows, long cols) {
  check_region(region);
  if (!region.fractions && (region.x1 > double(cols) || region.y1 > double(rows)))
    throw std::invalid_argument("region " + describe(region) + " reaches outside the goal of " +
                                std::to_string(cols) + " x " + std::to_string(rows) + " pixels");
  const Span x = region.fractions ? fraction_span(region.x0, region.x1, cols) : Span{long(region.x0), long(region.x1)};
  const Span y = region.fractions ? fraction_span(region.y0, region.y1, rows) : Span{long(region.y0), long(region.y1)};
  return Region{double(x.begin), double(y.begin), double(x.end), double(y.end), false};
}

HeightMap crop(const HeightMap& map, const Region& region) {
  check_region(region);
  const long rows = map.z.rows(), cols = map.z.cols();
  if (rows == 0 || cols == 0) throw std::invalid_argument("cannot crop goal \"" + map.source + "\": it is empty");
  if (!region.fractions && (region.x1 > double(cols) || region.y1 > double(rows)))
    throw std::invalid_argument("region " + describe(region) + " reaches outside goal \"" + map.source + "\" of " +
                                std::to_string(cols) + " x " + std::to_string(rows) + " pixels");
  const Region px = pixel_region(region, rows, cols);
  const Span x{long(px.x0), long(px.x1)}, y{long(px.y0), long(px.y1)};
  HeightMap out = map;  // keeps units, uncovered_height and georef
  out.z = map.z.block(y.begin, x.begin, y.end - y.begin, x.end - x.begin);
  if (out.georef) {
    auto& gt = out.georef->geotransform;
    const double dx = double(x.begin), dy = double(y.begin);
    const double x0 = gt[0] + dx * gt[1] + dy * gt[2], y0 = gt[3] + dx * gt[4] + dy * gt[5];
    gt[0] = x0;
    gt[3] = y0;
  }
  if (out.z.array().isNaN().all())
    throw std::invalid_argument("region " + describe(region) + " of goal \"" + map.source +
                                "\" holds only no-data (NaN) pixels");
  out.source = map.source + " [crop " + describe(region) + "]";
  return out;
}

}  // namespace hj

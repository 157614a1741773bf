// A region of interest of a goal, to zoom into part of a map before it is
// fitted to the array: "x0,y0,x1,y1" in fractions of the image or in pixels,
// x along the columns (left to right), y along the rows (top to bottom).
#pragma once

#include <string>

#include "shapes/height_map.h"

namespace hj {

// The half-open box [x0, x1) x [y0, y1).
// fractions: of the image's width and height, 0..1; crop keeps every pixel the
//   box touches. Otherwise pixel indices (whole numbers): columns x0..x1-1,
//   rows y0..y1-1.
struct Region {
  double x0 = 0.0, y0 = 0.0, x1 = 1.0, y1 = 1.0;
  bool fractions = true;
};

// Parses "x0,y0,x1,y1". If every value is <= 1 they are fractions, otherwise
// pixels: "0,0,0.5,0.5" is the top-left quarter, "0,0,50,40" the top-left
// 50 x 40 pixels. (A one-pixel region at the origin must be given as fractions.)
// @throws std::invalid_argument naming the text and what is wrong: not four
//         numbers, negative, x1 <= x0 or y1 <= y0, fractional pixel indices.
Region parse_region(const std::string& text);

// The pixels crop() takes for `region` from an image of rows x cols: a
// pixel region (fractions = false) of whole-number bounds.
// @throws std::invalid_argument as crop() does for a bad or outside region.
Region pixel_region(const Region& region, long rows, long cols);

// The part of `map` inside `region`; source gains " [crop x0,y0,x1,y1]".
// Units, uncovered_height and the georeference (its origin moved to the
// crop's corner) are kept.
// @throws std::invalid_argument on an invalid region, one reaching outside
//         the image, or one that holds no valid (non-NaN) pixel.
HeightMap crop(const HeightMap& map, const Region& region);

}  // namespace hj

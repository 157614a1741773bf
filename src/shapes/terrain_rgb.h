// Elevation packed into the red, green and blue bytes of a PNG map tile:
//   Mapbox Terrain-RGB:  h = -10000 + (R 65536 + G 256 + B) 0.1  metres
//   Terrarium (Mapzen):  h = R 256 + G + B / 256 - 32768         metres
// A PNG does not say which, so the caller chooses (ImportOptions::encoding).
#pragma once

#include <filesystem>

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include "shapes/goal_importer.h"

namespace hj {

// Heights in metres from an 8-bit BGR or BGRA image as OpenCV decodes it;
// alpha 0 = no data (NaN). encoding must not be kGrey.
// @throws ImportError naming `file` for a greyscale or 16-bit image.
Eigen::MatrixXd decode_terrain_rgb(const std::filesystem::path& file, const cv::Mat& image, PixelEncoding encoding);

}  // namespace hj

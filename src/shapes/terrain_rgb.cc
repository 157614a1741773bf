#include "shapes/terrain_rgb.h"

#include <limits>
#include <string>

namespace hj {

Eigen::MatrixXd decode_terrain_rgb(const std::filesystem::path& file, const cv::Mat& image, PixelEncoding encoding) {
  const std::string name = encoding == PixelEncoding::kTerrainRgb ? "terrain-rgb" : "terrarium";
  if (image.channels() != 3 && image.channels() != 4)
    throw ImportError(file, "the " + name + " encoding needs an RGB or RGBA image, this one has " +
                                std::to_string(image.channels()) + " channel(s)");
  if (image.depth() != CV_8U) throw ImportError(file, "the " + name + " encoding needs 8 bits per channel");
  const bool alpha = image.channels() == 4;
  Eigen::MatrixXd z(image.rows, image.cols);
  for (int r = 0; r < image.rows; ++r) {
    const unsigned char* p = image.ptr<unsigned char>(r);
    for (int c = 0; c < image.cols; ++c, p += image.channels()) {
      const double b = p[0], g = p[1], red = p[2];  // OpenCV stores BGR(A)
      if (alpha && p[3] == 0) {
        z(r, c) = std::numeric_limits<double>::quiet_NaN();
        continue;
      }
      z(r, c) = encoding == PixelEncoding::kTerrainRgb ? -10000.0 + (red * 65536.0 + g * 256.0 + b) * 0.1
                                                       : red * 256.0 + g + b / 256.0 - 32768.0;
    }
  }
  return z;
}

}  // namespace hj

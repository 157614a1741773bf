// Goal import from a PNG or TIFF (OpenCV): grey level = height, in the file's
// own units (8-bit, 16-bit, signed or float, NaN kept); colour by luminance,
// or by hue for colour topographic maps (ImportOptions::hue).
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include "shapes/image_importer.h"
#include "shapes/image_header.h"
#include "shapes/terrain_rgb.h"

namespace hj {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// Hue inversion for colour topographic maps, whose tints run red (high),
// orange, yellow, green, cyan, blue to purple (low). With the hue H in degrees
// [0, 360) of OpenCV's HSV:
//   H' = H - 360 if H > kHueWrapDeg (pinks and crimsons count as red), else H
//   height = clamp((kHueMaxDeg - H') / kHueMaxDeg, 0, 1)
// so red 0 -> 1, orange 30 -> 0.89, yellow 60 -> 0.79, green 120 -> 0.57,
// cyan 180 -> 0.36, blue 240 -> 0.14, violet 280 and magenta up to 320 -> 0.
// Pixels with no clear hue (saturation or value below kMinHueSaturation:
// greys, white background, black lines and labels) become NaN (no data).
constexpr double kHueMaxDeg = 280.0;
constexpr double kHueWrapDeg = 320.0;
constexpr double kMinHueSaturation = 0.15;

void check_pixel_count(const std::filesystem::path& file, long rows, long cols, const ImportOptions& options) {
  if (double(rows) * double(cols) > double(options.max_pixels))
    throw ImportError(file, std::to_string(cols) + " x " + std::to_string(rows) + " pixels is over the limit of " +
                                std::to_string(options.max_pixels) + " (ImportOptions.max_pixels)");
}

// Decodes only what its header sized first: OpenCV picks the decoder by
// the bytes, not the name, so a JPEG, BMP or PNM named .png would be
// decoded at any size; only PNG and classic TIFF signatures are accepted.
cv::Mat decode(const std::filesystem::path& file, const ImportOptions& options) {
  const auto size = peek_image_size(file);
  if (!size)
    throw ImportError(file, "not a readable PNG or TIFF image by its content (its header is missing, cut short or "
                            "of another format)");
  check_pixel_count(file, size->rows, size->cols, options);
  cv::Mat image;
  try {
    image = cv::imread(file.string(), cv::IMREAD_UNCHANGED);
  } catch (const cv::Exception& e) {
    throw ImportError(file, "OpenCV cannot decode it: " + e.msg);
  }
  if (image.empty()) throw ImportError(file, "not a readable PNG or TIFF image (corrupt, truncated or another format)");
  return image;
}

Eigen::MatrixXd to_eigen(const cv::Mat& single_channel) {
  cv::Mat f;
  single_channel.convertTo(f, CV_64F);
  Eigen::MatrixXd z(f.rows, f.cols);
  for (int r = 0; r < f.rows; ++r)
    for (int c = 0; c < f.cols; ++c) z(r, c) = f.at<double>(r, c);
  return z;
}

// Grey value, or luminance (0.299 R + 0.587 G + 0.114 B) of a colour image.
Eigen::MatrixXd grey_heights(const cv::Mat& image) {
  if (image.channels() <= 2) {
    cv::Mat grey;
    cv::extractChannel(image, grey, 0);
    return to_eigen(grey);
  }
  cv::Mat f, grey;
  image.convertTo(f, CV_32F);
  cv::cvtColor(f, grey, image.channels() == 4 ? cv::COLOR_BGRA2GRAY : cv::COLOR_BGR2GRAY);
  return to_eigen(grey);
}

Eigen::MatrixXd hue_heights(const std::filesystem::path& file, const cv::Mat& image) {
  if (image.channels() < 3) throw ImportError(file, "hue mode needs a colour image, this one is greyscale");
  // BGR in [0, 1], as OpenCV's float HSV conversion expects.
  const double scale = image.depth() == CV_8U ? 1.0 / 255.0 : image.depth() == CV_16U ? 1.0 / 65535.0 : 1.0;
  cv::Mat f, bgr, hsv;
  image.convertTo(f, CV_32F, scale);
  if (image.channels() == 4) cv::cvtColor(f, bgr, cv::COLOR_BGRA2BGR);
  else bgr = f;
  cv::cvtColor(bgr, hsv, cv::COLOR_BGR2HSV);
  Eigen::MatrixXd z(hsv.rows, hsv.cols);
  for (int r = 0; r < hsv.rows; ++r) {
    for (int c = 0; c < hsv.cols; ++c) {
      const cv::Vec3f p = hsv.at<cv::Vec3f>(r, c);
      if (!(p[1] >= kMinHueSaturation && p[2] >= kMinHueSaturation)) {
        z(r, c) = kNaN;
        continue;
      }
      const double h = p[0] > kHueWrapDeg ? p[0] - 360.0 : p[0];
      z(r, c) = std::clamp((kHueMaxDeg - h) / kHueMaxDeg, 0.0, 1.0);
    }
  }
  return z;
}

// Transparent pixels (alpha 0) carry no data.
void apply_alpha(const cv::Mat& image, Eigen::MatrixXd& z) {
  if (image.channels() != 2 && image.channels() != 4) return;
  cv::Mat alpha;
  cv::extractChannel(image, alpha, image.channels() - 1);
  const Eigen::MatrixXd a = to_eigen(alpha);
  z = (a.array() == 0.0).select(kNaN, z);
}

// NAME_validmask.png next to NAME.ext: pixels where the mask is 0 carry no data.
void apply_validmask(const std::filesystem::path& file, const ImportOptions& options, Eigen::MatrixXd& z) {
  const auto mask_file = file.parent_path() / (file.stem().string() + "_validmask.png");
  if (!std::filesystem::is_regular_file(mask_file)) return;
  const cv::Mat mask = decode(mask_file, options);
  if (mask.rows != z.rows() || mask.cols != z.cols())
    throw ImportError(file, "its validity mask \"" + mask_file.string() + "\" is " + std::to_string(mask.cols) +
                                " x " + std::to_string(mask.rows) + " pixels, the image " +
                                std::to_string(z.cols()) + " x " + std::to_string(z.rows()));
  cv::Mat first;
  cv::extractChannel(mask, first, 0);
  const Eigen::MatrixXd m = to_eigen(first);
  z = (m.array() == 0.0).select(kNaN, z);
}

class PngImporter final : public GoalImporter {
 public:
  std::string name() const override { return "png"; }
  // TIFF goes through the GeoTIFF importer (geotiff_importer.cc), which
  // hands plain TIFFs back to import_image.
  std::vector<std::string> extensions() const override { return {".png"}; }
  HeightMap import(const std::filesystem::path& file, const ImportOptions& options) const override {
    return import_image(file, options);
  }
};

}  // namespace

HeightMap import_image(const std::filesystem::path& file, const ImportOptions& options) {
  const cv::Mat image = decode(file, options);
  check_pixel_count(file, image.rows, image.cols, options);
  if (image.channels() > 4) throw ImportError(file, std::to_string(image.channels()) + " channels, at most 4 are understood");
  HeightMap map;
  if (options.encoding != PixelEncoding::kGrey) {
    map.z = decode_terrain_rgb(file, image, options.encoding);
    map.units = "m";
  } else {
    map.z = options.hue ? hue_heights(file, image) : grey_heights(image);
    apply_alpha(image, map.z);
  }
  apply_validmask(file, options, map.z);
  if (map.z.array().isNaN().all())
    throw ImportError(file, options.hue ? "no pixel has a clear hue (hue mode needs saturated colours)"
                                        : "every pixel is NaN, transparent or masked out (no data)");
  map.source = file.string();
  return map;
}

HJ_REGISTER_GOAL_IMPORTER(PngImporter);

}  // namespace hj

// The pixel size of a PNG or TIFF read from its header alone, so an absurdly
// large image is refused before it is decoded (OpenCV 4.6 has no header-only
// read). PNG: the IHDR chunk; TIFF: ImageWidth/ImageLength of the first IFD.
#pragma once

#include <filesystem>
#include <optional>

namespace hj {

struct ImageSize {
  long rows = 0;
  long cols = 0;
};

// nullopt when the file is neither a PNG nor a classic TIFF by its signature,
// or its header is cut short: the caller decodes and checks afterwards.
std::optional<ImageSize> peek_image_size(const std::filesystem::path& file);

}  // namespace hj

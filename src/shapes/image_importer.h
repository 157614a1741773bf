// PNG and plain TIFF goals decoded by OpenCV (image_importer.cc): the
// importer of .png, and the path the GeoTIFF importer hands a TIFF without
// georeferencing or no-data value to, so both read it the same way.
#pragma once

#include <filesystem>

#include "shapes/goal_importer.h"

namespace hj {

// Grey level (luminance, hue, or a terrain RGB encoding per options) =
// height; alpha 0 and a NAME_validmask.png mark no data.
// @throws ImportError naming the file.
HeightMap import_image(const std::filesystem::path& file, const ImportOptions& options);

}  // namespace hj

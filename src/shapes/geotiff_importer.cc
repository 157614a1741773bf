// Goal import from a TIFF through GDAL: a GeoTIFF DEM keeps its
// georeferencing (geotransform + CRS), its no-data value and mask become NaN,
// its scale / offset are applied and feet become metres. A plain TIFF (no
// georeferencing, no no-data value, no scale) is handed to the OpenCV image
// path (image_importer.h), so greyscale, colour, hue and validity-mask
// handling is the same as for a PNG; one OpenCV cannot decode falls back here.
#include <gdal_priv.h>
#include <ogr_spatialref.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include "shapes/gdal_support.h"
#include "shapes/goal_importer.h"
#include "shapes/image_importer.h"

namespace hj {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// Metres per unit of a band's unit name; 0 when unknown.
double metres_per_unit(const std::string& unit) {
  std::string u;
  for (char c : unit) u += char(std::tolower(static_cast<unsigned char>(c)));
  if (u == "m" || u == "metre" || u == "metres" || u == "meter" || u == "meters") return 1.0;
  if (u == "ft" || u == "foot" || u == "feet" || u == "international foot") return 0.3048;
  if (u == "us survey foot" || u == "ftus" || u == "us-ft" || u == "us_survey_foot") return 1200.0 / 3937.0;
  return 0.0;
}

class GeoTiffImporter final : public GoalImporter {
 public:
  std::string name() const override { return "geotiff"; }
  std::vector<std::string> extensions() const override { return {".tif", ".tiff"}; }

  HeightMap import(const std::filesystem::path& file, const ImportOptions& options) const override {
    gdal::ensure_registered();
    gdal::QuietErrors errors;
    const char* const tiff_only[] = {"GTiff", nullptr};
    GDALDatasetUniquePtr ds(GDALDataset::Open(file.string().c_str(), GDAL_OF_RASTER | GDAL_OF_READONLY, tiff_only));
    if (!ds) throw ImportError(file, "not a readable TIFF (corrupt, truncated or another format): " + errors.message());
    const long cols = ds->GetRasterXSize(), rows = ds->GetRasterYSize();
    if (double(rows) * double(cols) > double(options.max_pixels))
      throw ImportError(file, std::to_string(cols) + " x " + std::to_string(rows) + " pixels is over the limit of " +
                                  std::to_string(options.max_pixels) + " (ImportOptions.max_pixels)");
    if (ds->GetRasterCount() < 1) throw ImportError(file, "it has no raster band");
    GDALRasterBand* band = ds->GetRasterBand(1);

    int has_nodata = 0, has_scale = 0, has_offset = 0;
    const double nodata = band->GetNoDataValue(&has_nodata);
    const double scale = band->GetScale(&has_scale), offset = band->GetOffset(&has_offset);
    double gt[6];
    const bool has_geotransform = ds->GetGeoTransform(gt) == CE_None;
    const bool plain = !has_geotransform && !has_nodata && scale == 1.0 && offset == 0.0;
    if (plain || options.hue || options.encoding != PixelEncoding::kGrey) {
      try {
        return import_image(file, options);
      } catch (const ImportError&) {
        if (!plain) throw;  // a hue / RGB-encoded read that failed: its own message
      }
    }

    // The elevation band as doubles, row-major.
    std::vector<double> values(std::size_t(rows) * std::size_t(cols));
    if (band->RasterIO(GF_Read, 0, 0, int(cols), int(rows), values.data(), int(cols), int(rows), GDT_Float64, 0, 0) !=
        CE_None)
      throw ImportError(file, "its pixels cannot be read (corrupt or truncated): " + errors.message());
    std::vector<unsigned char> valid;
    if ((band->GetMaskFlags() & GMF_ALL_VALID) == 0) {
      valid.resize(values.size());
      if (band->GetMaskBand()->RasterIO(GF_Read, 0, 0, int(cols), int(rows), valid.data(), int(cols), int(rows),
                                        GDT_Byte, 0, 0) != CE_None)
        throw ImportError(file, "its validity mask cannot be read: " + errors.message());
    }
    const std::string unit = band->GetUnitType() ? band->GetUnitType() : "";
    const double to_metres = unit.empty() ? 1.0 : metres_per_unit(unit);

    HeightMap map;
    map.z.resize(rows, cols);
    for (long r = 0; r < rows; ++r)
      for (long c = 0; c < cols; ++c) {
        const std::size_t k = std::size_t(r) * std::size_t(cols) + std::size_t(c);
        double v = values[k];
        if ((has_nodata && (v == nodata || (std::isnan(nodata) && std::isnan(v)))) || (!valid.empty() && valid[k] == 0))
          v = kNaN;
        else
          v = (v * scale + offset) * (to_metres > 0.0 ? to_metres : 1.0);
        map.z(r, c) = v;
      }
    if (map.z.array().isNaN().all())
      throw ImportError(file, "every pixel is no data" +
                                  (has_nodata ? " (the no-data value " + std::to_string(nodata) + ")" : std::string()));
    map.units = unit.empty() ? "" : to_metres > 0.0 ? "m" : unit;  // an unknown unit is kept as named
    if (has_geotransform) {
      GeoReference ref;
      std::copy(gt, gt + 6, ref.geotransform.begin());
      if (const OGRSpatialReference* srs = ds->GetSpatialRef()) {
        char* wkt = nullptr;
        if (srs->exportToWkt(&wkt) == OGRERR_NONE && wkt) ref.crs_wkt = wkt;
        CPLFree(wkt);
      }
      map.georef = ref;
    }
    map.source = file.string();
    return map;
  }
};

}  // namespace

HJ_REGISTER_GOAL_IMPORTER(GeoTiffImporter);

}  // namespace hj

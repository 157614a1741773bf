// Goal import from an SRTM .hgt tile: raw big-endian signed 16-bit metres,
// row 0 the northern edge, 1201 x 1201 samples (3 arc-seconds) or 3601 x 3601
// (1 arc-second), -32768 = void (NaN). Samples sit on whole multiples of the
// spacing, the last row and column on the next tile's first. The file name
// (N37W122.hgt, case-insensitive, anything after the seven characters
// ignored) gives the south-west corner and so the georeferencing (WGS 84); a
// tile with any other name is imported without georeferencing.
#include <cctype>
#include <cstdint>
#include <fstream>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include "shapes/goal_importer.h"

namespace hj {
namespace {

struct Corner {
  int lat, lon;  // south-west corner, degrees
};

std::optional<Corner> corner_from_name(const std::string& stem) {
  if (stem.size() < 7) return std::nullopt;
  const char ns = char(std::toupper(static_cast<unsigned char>(stem[0])));
  const char ew = char(std::toupper(static_cast<unsigned char>(stem[3])));
  if ((ns != 'N' && ns != 'S') || (ew != 'E' && ew != 'W')) return std::nullopt;
  for (int i : {1, 2, 4, 5, 6})
    if (!std::isdigit(static_cast<unsigned char>(stem[i]))) return std::nullopt;
  const int lat = std::stoi(stem.substr(1, 2)), lon = std::stoi(stem.substr(4, 3));
  if (lat > 89 || lon > 180) return std::nullopt;
  return Corner{ns == 'N' ? lat : -lat, ew == 'E' ? lon : -lon};
}

class SrtmHgtImporter final : public GoalImporter {
 public:
  std::string name() const override { return "srtm-hgt"; }
  std::vector<std::string> extensions() const override { return {".hgt"}; }

  HeightMap import(const std::filesystem::path& file, const ImportOptions& options) const override {
    const auto bytes = std::filesystem::file_size(file);
    long n = 0;
    if (bytes == 1201ull * 1201ull * 2ull) n = 1201;
    else if (bytes == 3601ull * 3601ull * 2ull) n = 3601;
    else
      throw ImportError(file, std::to_string(bytes) + " bytes is not an SRTM tile: one holds 2884802 bytes (1201 x 1201, "
                              "3 arc-seconds) or 25934402 (3601 x 3601, 1 arc-second)");
    if (double(n) * double(n) > double(options.max_pixels))
      throw ImportError(file, std::to_string(n) + " x " + std::to_string(n) + " pixels is over the limit of " +
                                  std::to_string(options.max_pixels) + " (ImportOptions.max_pixels)");
    std::vector<unsigned char> raw(bytes);
    std::ifstream in(file, std::ios::binary);
    if (!in.read(reinterpret_cast<char*>(raw.data()), std::streamsize(bytes)))
      throw ImportError(file, "reading the tile failed");
    HeightMap map;
    map.z.resize(n, n);
    for (long r = 0; r < n; ++r)
      for (long c = 0; c < n; ++c) {
        const std::size_t k = 2 * std::size_t(r * n + c);
        const auto v = static_cast<std::int16_t>(std::uint16_t(raw[k]) << 8 | raw[k + 1]);
        map.z(r, c) = v == -32768 ? std::numeric_limits<double>::quiet_NaN() : double(v);
      }
    if (map.z.array().isNaN().all()) throw ImportError(file, "every sample is void (-32768, no data)");
    if (const auto corner = corner_from_name(file.stem().string())) {
      // Pixel (0, 0)'s centre is the north-west sample at (lon, lat + 1).
      const double step = 1.0 / double(n - 1);
      map.georef = GeoReference{{corner->lon - 0.5 * step, step, 0.0, corner->lat + 1 + 0.5 * step, 0.0, -step}, "EPSG:4326"};
    }
    map.units = "m";
    map.source = file.string();
    return map;
  }
};

}  // namespace

HJ_REGISTER_GOAL_IMPORTER(SrtmHgtImporter);

}  // namespace hj

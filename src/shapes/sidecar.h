// The JSON sidecar beside a goal (NAME.json next to NAME.csv / NAME.png /
// NAME.tif, the format of shared/data/dem/*.json): turns the map north-up
// and, for a CSV, supplies its georeferencing.
#pragma once

#include <filesystem>
#include <optional>
#include <utility>
#include <string>

#include "shapes/height_map.h"

namespace hj {

// Reads NAME.json beside `goal_file` if it exists and applies, in this order:
//  - "georef": {"geotransform": [6 numbers], "crs": TEXT}, if the importer
//    found no georeferencing: the geotransform of the map in file order;
//    crs "WGS 84" means EPSG:4326, any other text is passed to GDAL as is
//    (a georef block in another form, without "geotransform", is ignored);
//  - "units" beginning "metre" or "meter": units "m" (if not already set);
//  - "orientation": {"north_up_numpy": EXPR}: reorient(map, EXPR).
// A sidecar without these keys changes nothing.
// @throws ImportError naming the sidecar when it is not valid JSON, or a key
//         above has the wrong type or an expression reorient() refuses.
void apply_sidecar(const std::filesystem::path& goal_file, HeightMap& map);

// Applies a numpy expression that makes the array `a` (file order) north-up:
// `a` followed by any sequence of `.T` (transpose) and slices `[::-1]`,
// `[::-1, :]`, `[:, ::-1]`, `[::-1, ::-1]`, `[:, :]`; blanks are ignored and
// anything from a "(" or "#" on is a comment ("a[::-1, ::-1]  (i.e. rotate 180 deg)"). The
// georeference, if any, is transformed along, so every pixel keeps its place.
// @throws std::invalid_argument naming the expression and the part not understood.
HeightMap reorient(const HeightMap& map, const std::string& numpy_expression);

// A mesh's up axis from NAME.json beside it (shared/data/mesh/*.json):
// "up_axis": "+Y", "-z (...)", ...: the axis letter and whether it is
// negative; empty when there is no sidecar or it has no "up_axis".
// @throws ImportError naming the sidecar when it is not valid JSON or the
//         axis is not one of +-x, +-y, +-z.
std::optional<std::pair<char, bool>> sidecar_up_axis(const std::filesystem::path& mesh_file);

}  // namespace hj

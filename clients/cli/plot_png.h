// Draws a Plot (plot.h) as a PNG with OpenCV: axes with rounded ticks, each
// series in its colour with a legend, fitted lines dashed.
#pragma once

#include <filesystem>

#include "calib/report/plot.h"

namespace hj::cli {

// std::runtime_error naming the file if it cannot be written.
void write_plot_png(const std::filesystem::path& file, const Plot& plot);

}  // namespace hj::cli

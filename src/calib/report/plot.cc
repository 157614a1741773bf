#include "calib/report/plot.h"

#include <iterator>

namespace hj {

std::string series_colour(const PlotSeries& series, std::size_t index) {
  static const char* const kPalette[] = {"#1f77b4", "#ff7f0e", "#2ca02c", "#d62728", "#9467bd",
                                         "#8c564b", "#e377c2", "#7f7f7f", "#bcbd22", "#17becf"};
  return series.colour.empty() ? kPalette[index % std::size(kPalette)] : series.colour;
}

}  // namespace hj

#pragma once
/// \file chart_png.h
/// \brief Line and bar charts written as PNG with VTK's charts (vtkChartXY in an offscreen
/// vtkContextView). Needs an X display, like every VTK render here (display.h).

#include <array>
#include <cstdint>
#include <string>
#include <vector>

namespace sadsplat {
namespace viz {

/// \brief One series of a chart.
struct ChartSeries {
  std::string name;
  std::vector<double> x;
  std::vector<double> y;
  std::array<std::uint8_t, 3> color{31, 119, 180};
  bool markers_only = false;  ///< points (events), not a line
};

/// \brief The frame of a chart.
struct ChartFrame {
  std::string title;
  std::string x_label;
  std::string y_label;
  int width = 900;
  int height = 500;
  bool log_y = false;
};

/// \brief Writes a line chart (series with markers_only as points) to `path` (atomically).
/// \throws sadsplat::Error when a series' x and y differ in length, all are empty, there is no
/// display, or the file cannot be written
void writeLineChart(const std::string& path, const ChartFrame& frame,
                    const std::vector<ChartSeries>& series);

/// \brief Writes a grouped bar chart: one bar per group (`series`, their x unused) and category.
/// \param[in] categories the category names on the x axis
/// \param[in] series one per group, y[i] the value for categories[i]
void writeBarChart(const std::string& path, const ChartFrame& frame,
                   const std::vector<std::string>& categories,
                   const std::vector<ChartSeries>& series);

}  // namespace viz
}  // namespace sadsplat

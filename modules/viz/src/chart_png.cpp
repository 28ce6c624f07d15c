#include "sadsplat/viz/chart_png.h"

#include <vtkAxis.h>
#include <vtkChartLegend.h>
#include <vtkChartXY.h>
#include <vtkContextScene.h>
#include <vtkContextView.h>
#include <vtkDoubleArray.h>
#include <vtkNew.h>
#include <vtkPen.h>
#include <vtkPlot.h>
#include <vtkPlotBar.h>
#include <vtkRenderWindow.h>
#include <vtkRenderer.h>
#include <vtkStringArray.h>
#include <vtkTable.h>
#include <vtkTextProperty.h>

#include "sadsplat/common/error.h"
#include "sadsplat/io/atomic_file.h"
#include "sadsplat/viz/display.h"
#include "window_png.h"

namespace sadsplat {
namespace viz {
namespace {

void setupChart(vtkChartXY* chart, const ChartFrame& f) {
  chart->SetTitle(f.title);
  chart->GetTitleProperties()->SetFontSize(18);
  chart->GetAxis(vtkAxis::BOTTOM)->SetTitle(f.x_label);
  chart->GetAxis(vtkAxis::LEFT)->SetTitle(f.y_label);
  chart->GetAxis(vtkAxis::LEFT)->SetLogScale(f.log_y);
  chart->SetShowLegend(true);
  chart->GetLegend()->SetHorizontalAlignment(vtkChartLegend::RIGHT);
  chart->GetLegend()->SetVerticalAlignment(vtkChartLegend::TOP);
}

void render(const std::string& path, vtkContextView* view, const ChartFrame& f) {
  requireDisplay(path);
  view->GetRenderer()->SetBackground(1.0, 1.0, 1.0);
  view->GetRenderWindow()->SetOffScreenRendering(1);
  view->GetRenderWindow()->SetSize(f.width, f.height);
  view->GetRenderWindow()->SetMultiSamples(0);
  saveWindowPng(view->GetRenderWindow(), path);
}

}  // namespace

void writeLineChart(const std::string& path, const ChartFrame& frame,
                    const std::vector<ChartSeries>& series) {
  bool any = false;
  for (const auto& s : series) {
    if (s.x.size() != s.y.size()) {
      throw Error(path, "series " + s.name, "as many x as y values",
                  std::to_string(s.x.size()) + " x and " + std::to_string(s.y.size()) + " y");
    }
    any = any || !s.x.empty();
  }
  if (!any) throw Error(path, "chart " + frame.title, "at least one data point", "none");
  vtkNew<vtkContextView> view;
  vtkNew<vtkChartXY> chart;
  view->GetScene()->AddItem(chart);
  setupChart(chart, frame);
  for (const auto& s : series) {
    if (s.x.empty()) continue;
    vtkNew<vtkTable> table;
    vtkNew<vtkDoubleArray> xs, ys;
    xs->SetName("x");
    ys->SetName("y");
    for (std::size_t i = 0; i < s.x.size(); ++i) {
      xs->InsertNextValue(s.x[i]);
      ys->InsertNextValue(s.y[i]);
    }
    table->AddColumn(xs);
    table->AddColumn(ys);
    vtkPlot* plot = chart->AddPlot(s.markers_only ? vtkChart::POINTS : vtkChart::LINE);
    plot->SetInputData(table, 0, 1);
    plot->SetLabel(s.name);
    plot->SetColor(s.color[0], s.color[1], s.color[2], 255);
    plot->SetWidth(s.markers_only ? 6.0f : 2.0f);
  }
  render(path, view, frame);
}

void writeBarChart(const std::string& path, const ChartFrame& frame,
                   const std::vector<std::string>& categories,
                   const std::vector<ChartSeries>& series) {
  if (categories.empty() || series.empty()) {
    throw Error(path, "chart " + frame.title, "at least one category and one series", "none");
  }
  for (const auto& s : series) {
    if (s.y.size() != categories.size()) {
      throw Error(path, "series " + s.name,
                  std::to_string(categories.size()) + " values (one per category)",
                  std::to_string(s.y.size()));
    }
  }
  vtkNew<vtkContextView> view;
  vtkNew<vtkChartXY> chart;
  view->GetScene()->AddItem(chart);
  setupChart(chart, frame);
  chart->SetBarWidthFraction(0.8f);
  vtkNew<vtkTable> table;
  vtkNew<vtkDoubleArray> xs;
  xs->SetName("category");
  for (std::size_t i = 0; i < categories.size(); ++i) xs->InsertNextValue(static_cast<double>(i));
  table->AddColumn(xs);
  // Columns get their own names (a vtkTable replaces a column of the same name); the series'
  // names are the plots' labels.
  for (std::size_t k = 0; k < series.size(); ++k) {
    const auto& s = series[k];
    vtkNew<vtkDoubleArray> ys;
    ys->SetName(("series " + std::to_string(k)).c_str());
    for (double v : s.y) ys->InsertNextValue(v);
    table->AddColumn(ys);
  }
  for (std::size_t k = 0; k < series.size(); ++k) {
    vtkPlot* plot = chart->AddPlot(vtkChart::BAR);
    plot->SetInputData(table, 0, static_cast<vtkIdType>(k + 1));
    plot->SetLabel(series[k].name);
    plot->SetColor(series[k].color[0], series[k].color[1], series[k].color[2], 255);
  }
  vtkNew<vtkDoubleArray> ticks;
  vtkNew<vtkStringArray> labels;
  for (std::size_t i = 0; i < categories.size(); ++i) {
    ticks->InsertNextValue(static_cast<double>(i));
    labels->InsertNextValue(categories[i]);
  }
  vtkAxis* bottom = chart->GetAxis(vtkAxis::BOTTOM);
  bottom->SetCustomTickPositions(ticks, labels);
  bottom->SetBehavior(vtkAxis::FIXED);
  bottom->SetRange(-0.6, static_cast<double>(categories.size()) - 0.4);
  render(path, view, frame);
}

}  // namespace viz
}  // namespace sadsplat

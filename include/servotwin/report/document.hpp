#pragma once
/// \file
/// Self-contained interactive HTML reports. A report is a Document: sections with text, tables
/// and charts. write_html() turns it into one HTML file that carries everything it needs (the
/// charting library uPlot, its glue code and the chart data as embedded JSON), so it opens
/// offline in any current browser. Charts zoom (drag a box; double-click resets) and show the
/// values under the cursor.
///
/// Long series are decimated for display only (display_indices, display_path_indices): the
/// numbers a report states in its text and tables are computed by the caller from the full data.
/// This module does no file I/O: the caller opens the stream (the CLI writes files whole or not
/// at all).

#include <cstddef>
#include <iosfwd>
#include <span>
#include <string>
#include <vector>

namespace servotwin::report {

/// One curve: y over x, both of the same length. Non-finite y values are drawn as gaps; points
/// whose x is not finite (or not positive on a logarithmic x axis) are left out; on a
/// logarithmic y axis non-positive y values are gaps.
struct Series {
  std::string label;
  std::vector<double> x, y;
};

enum class Scale { Linear, Log };

/// A chart with one x and one y axis.
///
/// `equal_axes == false` (a line chart): each series is sorted by ascending x (time series,
/// frequency responses); the series of one chart may have different x (they are aligned for
/// display) and hovering shows every series' value at the cursor's x. Series longer than
/// HtmlOptions::max_points are decimated with display_indices().
///
/// `equal_axes == true` (a path chart, e.g. a toolpath in the XY plane): every series is drawn in
/// sample order (x need not be sorted), both axes have the same length per pixel (the chart is
/// square), and drag-zoom works in x and y. Series longer than HtmlOptions::max_path_points are
/// decimated with display_path_indices(). The chart's scales are linear whatever x_scale and
/// y_scale say.
struct Chart {
  std::string title;
  std::string x_label, y_label;  ///< with the unit, e.g. "time [s]"
  Scale x_scale = Scale::Linear;
  Scale y_scale = Scale::Linear;
  std::vector<Series> series;
  bool equal_axes = false;
};

/// A table of text cells (the builder formats numbers). Rows may be shorter than the header.
struct Table {
  std::string title;
  std::vector<std::string> header;
  std::vector<std::vector<std::string>> rows;
};

/// A titled part of the report: text (paragraphs separated by blank lines), then the tables, then
/// the charts.
struct Section {
  std::string title;
  std::string text;
  std::vector<Table> tables;
  std::vector<Chart> charts;
};

struct Document {
  std::string title;
  std::string subtitle;  ///< one line under the title, e.g. the input files
  std::vector<Section> sections;
};

/// Limits of the HTML writer.
struct HtmlOptions {
  /// Points drawn per series of a line chart (display_indices); >= kMinDisplayPoints.
  std::size_t max_points = 4000;
  /// Points drawn per series of a path chart (display_path_indices); >= kMinDisplayPoints and
  /// <= kMaxPathPoints.
  std::size_t max_path_points = 2000;
};

/// Smallest accepted display budget per series.
inline constexpr std::size_t kMinDisplayPoints = 16;
/// Largest display budget per series of a path chart. The chart library redraws a series with 4
/// or more points per pixel column with its own pixel-column decimation, which is only correct for
/// x-sorted data; a path chart is made wide enough (up to 600 pixels for this budget) to stay
/// below that threshold.
inline constexpr std::size_t kMaxPathPoints = 2400;

/// Writes `doc` as one self-contained HTML5 file (UTF-8). Every string of the document is
/// escaped, for HTML and inside the embedded JSON (no "</script>" can break out); invalid UTF-8 is
/// replaced by U+FFFD. Chart data are written with 9 significant digits, non-finite values as
/// JSON null. Output size: about 70 kB of page, embedded library and glue, plus at most
/// 2 x (points drawn) numbers of at most 16 characters per series.
///
/// core::InputError (field "sections[i].charts[j].series[k]" and the chart's title) when a series'
/// x and y differ in length, (field "max_points" / "max_path_points") for budgets out of range.
void write_html(std::ostream& out, const Document& doc, const HtmlOptions& options = {});

/// Number of charts in `doc` (what a browser test expects to see drawn).
std::size_t chart_count(const Document& doc);

/// Indices of the samples of an x-sorted series to draw when at most `max_points` may be drawn:
/// all of them when y.size() <= max_points; else the first and last sample and, in equal index
/// buckets, the minimum and the maximum (so peaks survive and the envelope is exact), plus the
/// first non-finite sample of a bucket that has one (so gaps stay visible). Ascending, no
/// duplicates. core::InputError (field "max_points") when max_points < kMinDisplayPoints.
std::vector<std::size_t> display_indices(std::span<const double> y, std::size_t max_points);

/// Indices of the points of a path (x[k], y[k]) to draw, at most `max_points`: all of them when
/// they fit; else the path is simplified by Douglas-Peucker with a point budget (the point
/// farthest from its current chord, measured to the segment so that reversals on a line are
/// kept, is added until the budget is spent or the simplified path is exact), run separately on
/// each stretch of finite points, with one non-finite sample kept per gap. When the gaps alone
/// would need more than half the budget, the path falls back to the extremes of x and y per index
/// bucket. Ascending, no duplicates. core::InputError (field "x") when x and y differ in length,
/// (field "max_points") when max_points < kMinDisplayPoints.
std::vector<std::size_t> display_path_indices(std::span<const double> x, std::span<const double> y,
                                              std::size_t max_points);

}  // namespace servotwin::report

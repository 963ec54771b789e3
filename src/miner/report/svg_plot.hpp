#pragma once
/// Static line and box plots as inline SVG for the HTML reports: no script, the same
/// bytes for the same data, readable in any browser or by a text diff.

#include <string>
#include <vector>

namespace miner::report {

struct Series {
  std::string name;
  std::string color;  ///< CSS colour
  std::vector<double> x, y;
};

struct PlotAxes {
  std::string title, x_label, y_label;
  int width = 560, height = 260;
};

/// A line plot of every series on shared axes with "nice" ticks (1, 2, 5 x 10^k) and a
/// legend. Non-finite points break the line. Throws miner::Error when a series' x and y
/// differ in length.
std::string svg_line_plot(const PlotAxes& axes, const std::vector<Series>& series);

/// One box per group (median, quartiles, whiskers at the extreme values within 1.5 IQR,
/// outliers as dots), like the paper's Fig. Map1-3. Every box is labelled with its n.
/// `missed` runs (a stage never reached) are shown, not dropped: they count as +inf in
/// the quartiles, sit as crosses on the top edge of the plot, and the label says how many;
/// a quartile or whisker that lands on a miss reaches the top edge. A group with neither
/// values nor misses is drawn as "n/a".
struct BoxGroup {
  std::string name;
  std::vector<double> values;
  int missed = 0;
};
std::string svg_box_plot(const PlotAxes& axes, const std::vector<BoxGroup>& groups, bool log_scale = false);

/// "Nice" tick positions covering [lo, hi] with about `target` intervals.
std::vector<double> nice_ticks(double lo, double hi, int target = 5);

/// Text escaped for HTML element content and attribute values.
std::string html_escape(const std::string& text);

}  // namespace miner::report

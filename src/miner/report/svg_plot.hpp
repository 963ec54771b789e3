#pragma once
/// Static line and box plots as inline SVG for the HTML reports: no script, the same
/// bytes for the same data, readable in any browser or by a text diff.

#include <string>
#include <utility>
#include <vector>

namespace miner::report {

struct Series {
  std::string name;
  std::string color;  ///< CSS colour
  std::vector<double> x, y;
  /// SVG stroke-dasharray ("4 3"); empty: a solid line.
  std::string dash = {};
  /// Non-empty (as long as x): a band filled between y_low and y instead of a line.
  std::vector<double> y_low = {};
};

struct PlotAxes {
  std::string title, x_label, y_label;
  int width = 560, height = 260;
  /// Non-empty: the svg's id, its x mapping as data attributes (data-x0/x1: the data range,
  /// data-px0/px1: where it lies in px) and a hidden time cursor (<line class="cursor">)
  /// that the report's viewer script moves with its playback slider.
  std::string id = {};
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

/// An event timeline: one lane per kind of event, a bar over each interval [t0, t1] in which
/// it was active (an instant event gets a bar of at least 2 px), the lane's label with the
/// count and total time, "none" on an empty lane; x is time over [0, t_end]. Bars that overlap
/// or touch once drawn are one rectangle, so a lane has at most about the plot's width of them
/// whatever the number of intervals; a non-finite interval is refused (miner::Error).
struct EventLane {
  std::string name;
  std::string color;
  std::vector<std::pair<double, double>> intervals;
};
std::string svg_event_timeline(const PlotAxes& axes, const std::vector<EventLane>& lanes, double t_end);

/// "Nice" tick positions covering [lo, hi] with about `target` intervals.
std::vector<double> nice_ticks(double lo, double hi, int target = 5);

/// Text escaped for HTML element content and attribute values.
std::string html_escape(const std::string& text);

}  // namespace miner::report

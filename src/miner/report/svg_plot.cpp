#include "miner/report/svg_plot.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>

#include "miner/core/error.hpp"
#include "miner/core/text.hpp"

namespace miner::report {

namespace {

/// Plot area margins (px): room for tick labels, axis labels and the title.
constexpr double kLeft = 62, kRight = 12, kTop = 26, kBottom = 42;

std::string fmt(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.1f", v);
  return buf;
}

std::string tick_label(double v) {
  char buf[32];
  if (v == 0.0) return "0";
  const double a = std::abs(v);
  if (a >= 1e4 || a < 1e-3) std::snprintf(buf, sizeof buf, "%.0e", v);
  else std::snprintf(buf, sizeof buf, "%g", v);
  return buf;
}

struct Range {
  double lo = std::numeric_limits<double>::infinity();
  double hi = -std::numeric_limits<double>::infinity();
  void add(double v) {
    if (!std::isfinite(v)) return;
    lo = std::min(lo, v);
    hi = std::max(hi, v);
  }
  /// An empty or zero-width range widened so the axes are still drawable.
  void settle() {
    if (!(lo <= hi)) lo = 0.0, hi = 1.0;
    if (hi - lo < 1e-12 * std::max(1.0, std::abs(hi))) lo -= 0.5, hi += 0.5;
  }
};

struct Frame {
  const PlotAxes& axes;
  double x0, x1, y0, y1;  // data range after ticks
  double sx(double x) const { return kLeft + (x - x0) / (x1 - x0) * (axes.width - kLeft - kRight); }
  double sy(double y) const { return axes.height - kBottom - (y - y0) / (y1 - y0) * (axes.height - kTop - kBottom); }
};

std::string open_svg(const PlotAxes& a, const std::string& attributes = {}) {
  return "<svg xmlns=\"http://www.w3.org/2000/svg\" class=\"plot\"" +
         (a.id.empty() ? std::string() : " id=\"" + html_escape(a.id) + "\"" + attributes) + " width=\"" + std::to_string(a.width) +
         "\" height=\"" + std::to_string(a.height) + "\" viewBox=\"0 0 " + std::to_string(a.width) + " " +
         std::to_string(a.height) + "\" font-family=\"sans-serif\" font-size=\"11\">\n<text x=\"" +
         fmt(a.width / 2.0) + "\" y=\"16\" text-anchor=\"middle\" font-size=\"13\" font-weight=\"bold\">" +
         html_escape(a.title) + "</text>\n";
}

/// Grid lines, tick labels and axis labels; x ticks are skipped when `x_ticks` is empty.
std::string draw_axes(const Frame& f, const std::vector<double>& x_ticks, const std::vector<double>& y_ticks,
                      bool log_y) {
  std::string s;
  const auto& a = f.axes;
  for (double t : y_ticks) {
    const double y = f.sy(t);
    s += "<line x1=\"" + fmt(kLeft) + "\" x2=\"" + fmt(a.width - kRight) + "\" y1=\"" + fmt(y) + "\" y2=\"" + fmt(y) +
         "\" stroke=\"#ddd\"/><text x=\"" + fmt(kLeft - 4) + "\" y=\"" + fmt(y + 4) + "\" text-anchor=\"end\">" +
         tick_label(log_y ? std::pow(10.0, t) : t) + "</text>\n";
  }
  for (double t : x_ticks) {
    const double x = f.sx(t);
    s += "<line x1=\"" + fmt(x) + "\" x2=\"" + fmt(x) + "\" y1=\"" + fmt(kTop) + "\" y2=\"" +
         fmt(a.height - kBottom) + "\" stroke=\"#eee\"/><text x=\"" + fmt(x) + "\" y=\"" +
         fmt(a.height - kBottom + 14) + "\" text-anchor=\"middle\">" + tick_label(t) + "</text>\n";
  }
  s += "<rect x=\"" + fmt(kLeft) + "\" y=\"" + fmt(kTop) + "\" width=\"" + fmt(a.width - kLeft - kRight) +
       "\" height=\"" + fmt(a.height - kTop - kBottom) + "\" fill=\"none\" stroke=\"#888\"/>\n";
  s += "<text x=\"" + fmt((kLeft + a.width - kRight) / 2) + "\" y=\"" + fmt(a.height - 8.0) +
       "\" text-anchor=\"middle\">" + html_escape(a.x_label) + "</text>\n";
  s += "<text transform=\"translate(14 " + fmt((kTop + a.height - kBottom) / 2) +
       ") rotate(-90)\" text-anchor=\"middle\">" + html_escape(a.y_label) + "</text>\n";
  return s;
}

}  // namespace

std::string html_escape(const std::string& text) {
  std::string out;
  out.reserve(text.size());
  for (char c : text) {
    switch (c) {
      case '&': out += "&amp;"; break;
      case '<': out += "&lt;"; break;
      case '>': out += "&gt;"; break;
      case '"': out += "&quot;"; break;
      case '\'': out += "&#39;"; break;
      default: out += c;
    }
  }
  return out;
}

std::vector<double> nice_ticks(double lo, double hi, int target) {
  if (!(hi > lo) || !std::isfinite(lo) || !std::isfinite(hi) || target < 1)
    throw Error("nice_ticks: needs a finite range lo < hi and target >= 1");
  const double raw = (hi - lo) / target;
  // Tenth campaign L6: a finite range whose width overflows (-1e308 .. 1e308) or is a denormal
  // (0 .. 5e-324) gave an infinite or zero step and a crash; such data cannot be drawn.
  if (!std::isfinite(raw) || !(raw >= 1e-300))
    throw Error("nice_ticks: the range [" + short_number(lo) + ", " + short_number(hi) +
                "] is too wide or too narrow for a double's ticks");
  const double mag = std::pow(10.0, std::floor(std::log10(raw)));
  double step = mag;
  for (double m : {1.0, 2.0, 5.0, 10.0})
    if (m * mag >= raw) {
      step = m * mag;
      break;
    }
  std::vector<double> ticks;
  for (double t = std::floor(lo / step) * step; t <= hi + 1e-9 * step; t += step) {
    ticks.push_back(std::abs(t) < 1e-12 * step ? 0.0 : t);
    if (ticks.size() > 100) break;  // unreachable with the step above; keeps the loop finite
  }
  if (ticks.back() < hi - 1e-9 * step) ticks.push_back(ticks.back() + step);
  return ticks;
}

std::string svg_line_plot(const PlotAxes& axes, const std::vector<Series>& series) {
  Range rx, ry;
  for (const auto& s : series) {
    if (s.x.size() != s.y.size())
      throw Error("plot \"" + axes.title + "\": series \"" + s.name + "\" has " + std::to_string(s.x.size()) +
                  " x values and " + std::to_string(s.y.size()) + " y values");
    if (!s.y_low.empty() && s.y_low.size() != s.x.size())
      throw Error("plot \"" + axes.title + "\": band \"" + s.name + "\" has " + std::to_string(s.x.size()) +
                  " x values and " + std::to_string(s.y_low.size()) + " lower values");
    for (std::size_t i = 0; i < s.x.size(); ++i)
      if (std::isfinite(s.x[i]) && std::isfinite(s.y[i])) {
        rx.add(s.x[i]), ry.add(s.y[i]);
        if (!s.y_low.empty()) ry.add(s.y_low[i]);
      }
  }
  rx.settle();
  ry.settle();
  const auto xt = nice_ticks(rx.lo, rx.hi), yt = nice_ticks(ry.lo, ry.hi);
  const Frame f{axes, rx.lo, rx.hi, yt.front(), yt.back()};
  std::vector<double> x_inside;
  for (double t : xt)
    if (t >= rx.lo - 1e-12 && t <= rx.hi + 1e-12) x_inside.push_back(t);
  const std::string mapping = " data-x0=\"" + tick_label(f.x0) + "\" data-x1=\"" + tick_label(f.x1) +
                              "\" data-px0=\"" + fmt(f.sx(f.x0)) + "\" data-px1=\"" + fmt(f.sx(f.x1)) + "\"";
  std::string s = open_svg(axes, mapping) + draw_axes(f, x_inside, yt, false);
  double legend_x = kLeft + 8;
  for (const auto& se : series) {
    const bool band = !se.y_low.empty();
    std::string d;
    bool pen_down = false;
    // A band: along y, then back along y_low (one closed outline per finite run).
    std::string back;
    auto close_band = [&] {
      if (!back.empty()) d += back + "Z";
      back.clear();
    };
    for (std::size_t i = 0; i < se.x.size(); ++i) {
      if (!std::isfinite(se.x[i]) || !std::isfinite(se.y[i]) || (band && !std::isfinite(se.y_low[i]))) {
        if (band) close_band();
        pen_down = false;
        continue;
      }
      d += (pen_down ? "L" : "M") + fmt(f.sx(se.x[i])) + " " + fmt(f.sy(se.y[i]));
      if (band) back = "L" + fmt(f.sx(se.x[i])) + " " + fmt(f.sy(se.y_low[i])) + back;
      pen_down = true;
    }
    if (band) {
      close_band();
      s += "<path class=\"band\" d=\"" + d + "\" fill=\"" + html_escape(se.color) + "\" fill-opacity=\"0.25\" stroke=\"none\"/>\n";
    } else {
      s += "<path d=\"" + d + "\" fill=\"none\" stroke=\"" + html_escape(se.color) + "\" stroke-width=\"1.3\"" +
           (se.dash.empty() ? std::string() : " stroke-dasharray=\"" + html_escape(se.dash) + "\"") + "/>\n";
    }
    s += "<rect x=\"" + fmt(legend_x) + "\" y=\"" + fmt(band ? kTop + 3 : kTop + 6) + "\" width=\"12\" height=\"" +
         (band ? "9\" fill-opacity=\"0.35" : "3") + "\" fill=\"" + html_escape(se.color) + "\"/><text x=\"" +
         fmt(legend_x + 16) + "\" y=\"" + fmt(kTop + 11) + "\">" + html_escape(se.name) + "</text>\n";
    legend_x += 30 + 6.5 * static_cast<double>(se.name.size());
  }
  if (!axes.id.empty())
    s += "<line class=\"cursor\" x1=\"" + fmt(f.sx(f.x0)) + "\" x2=\"" + fmt(f.sx(f.x0)) + "\" y1=\"" + fmt(kTop) +
         "\" y2=\"" + fmt(axes.height - kBottom) + "\" stroke=\"#000\" stroke-width=\"1\" visibility=\"hidden\"/>\n";
  return s + "</svg>\n";
}

std::string svg_box_plot(const PlotAxes& axes, const std::vector<BoxGroup>& groups, bool log_scale) {
  auto tr = [&](double v) { return log_scale ? (v > 0 ? std::log10(v) : NAN) : v; };
  Range ry;
  for (const auto& g : groups)
    for (double v : g.values) ry.add(tr(v));
  ry.settle();
  if (log_scale) ry.lo = std::floor(ry.lo), ry.hi = std::ceil(ry.hi);
  ry.settle();
  const auto yt = nice_ticks(ry.lo, ry.hi);
  const double n = static_cast<double>(std::max<std::size_t>(groups.size(), 1));
  const Frame f{axes, 0.0, n, yt.front(), yt.back()};
  std::string s = open_svg(axes) + draw_axes(f, {}, yt, log_scale);
  const double slot = (axes.width - kLeft - kRight) / n;
  const double top = f.sy(f.y1);  // where a missed run (+inf) is drawn
  for (std::size_t gi = 0; gi < groups.size(); ++gi) {
    const BoxGroup& g = groups[gi];
    const double cx = f.sx(static_cast<double>(gi) + 0.5);
    const std::size_t runs = g.values.size() + static_cast<std::size_t>(std::max(g.missed, 0));
    s += "<text x=\"" + fmt(cx) + "\" y=\"" + fmt(axes.height - kBottom + 14) +
         "\" text-anchor=\"middle\" font-size=\"10\">" + html_escape(g.name) + "</text>\n";
    s += "<text x=\"" + fmt(cx) + "\" y=\"" + fmt(axes.height - kBottom + 26) +
         "\" text-anchor=\"middle\" font-size=\"9\">n=" + std::to_string(runs) +
         (g.missed > 0 ? ", " + std::to_string(g.missed) + " missed" : std::string()) + "</text>\n";
    std::vector<double> v;
    for (double x : g.values)
      if (std::isfinite(tr(x))) v.push_back(tr(x));
    const std::size_t finite = v.size();
    for (int k = 0; k < g.missed; ++k) v.push_back(std::numeric_limits<double>::infinity());
    if (v.empty()) {
      s += "<text x=\"" + fmt(cx) + "\" y=\"" + fmt(f.sy((f.y0 + f.y1) / 2)) + "\" text-anchor=\"middle\">n/a</text>\n";
      continue;
    }
    std::sort(v.begin(), v.end());
    // Quartiles by linear interpolation between order statistics (Hyndman-Fan type 7);
    // one that touches a miss is +inf (drawn at the top edge).
    auto q = [&](double p) {
      const double h = (static_cast<double>(v.size()) - 1.0) * p;
      const auto lo = static_cast<std::size_t>(std::floor(h));
      const std::size_t hi = std::min(lo + 1, v.size() - 1);
      const double frac = h - static_cast<double>(lo);
      if (!std::isfinite(v[lo]) || (frac > 0.0 && !std::isfinite(v[hi]))) return std::numeric_limits<double>::infinity();
      return v[lo] + frac * (v[hi] - v[lo]);
    };
    const auto y = [&](double value) { return std::isfinite(value) ? f.sy(value) : top; };
    const double q1 = q(0.25), med = q(0.5), q3 = q(0.75), iqr = q3 - q1;
    double wlo = med, whi = med;
    for (double x : v)
      if (x >= q1 - 1.5 * iqr) { wlo = x; break; }
    for (auto it = v.rbegin(); it != v.rend(); ++it)
      if (*it <= q3 + 1.5 * iqr) { whi = *it; break; }
    const double hw = std::min(slot * 0.3, 24.0);
    s += "<line x1=\"" + fmt(cx) + "\" x2=\"" + fmt(cx) + "\" y1=\"" + fmt(y(wlo)) + "\" y2=\"" + fmt(y(whi)) +
         "\" stroke=\"#333\"/>\n";
    s += "<rect x=\"" + fmt(cx - hw) + "\" y=\"" + fmt(y(q3)) + "\" width=\"" + fmt(2 * hw) + "\" height=\"" +
         fmt(std::max(y(q1) - y(q3), 0.5)) + "\" fill=\"#9ecae1\" stroke=\"#333\"/>\n";
    s += "<line x1=\"" + fmt(cx - hw) + "\" x2=\"" + fmt(cx + hw) + "\" y1=\"" + fmt(y(med)) + "\" y2=\"" +
         fmt(y(med)) + "\" stroke=\"#d62728\" stroke-width=\"2\"/>\n";
    for (std::size_t k = 0; k < finite; ++k)
      if (v[k] < wlo || v[k] > whi)
        s += "<circle cx=\"" + fmt(cx) + "\" cy=\"" + fmt(f.sy(v[k])) + "\" r=\"2\" fill=\"none\" stroke=\"#555\"/>\n";
    if (g.missed > 0)
      s += "<text class=\"miss\" x=\"" + fmt(cx) + "\" y=\"" + fmt(top + 4) +
           "\" text-anchor=\"middle\" fill=\"#d62728\" font-size=\"12\">&#215;</text>\n";
  }
  return s + "</svg>\n";
}

std::string svg_event_timeline(const PlotAxes& axes, const std::vector<EventLane>& lanes, double t_end) {
  if (!(t_end > 0.0) || !std::isfinite(t_end)) t_end = 1.0;
  const auto xt = nice_ticks(0.0, t_end);
  // The lanes' labels need more room than a y axis' ticks: a wider left margin.
  constexpr double kLabels = 200;
  PlotAxes a = axes;
  const double lane_h = 22;
  a.height = static_cast<int>(kTop + kBottom + lane_h * static_cast<double>(std::max<std::size_t>(lanes.size(), 1)));
  const double px0 = kLabels, px1 = a.width - kRight;
  auto sx = [&](double t) { return px0 + t / t_end * (px1 - px0); };
  const std::string mapping = " data-x0=\"0\" data-x1=\"" + tick_label(t_end) + "\" data-px0=\"" + fmt(px0) +
                              "\" data-px1=\"" + fmt(px1) + "\"";
  std::string s = open_svg(a, mapping);
  const double bottom = a.height - kBottom;
  for (double t : xt) {
    if (t > t_end + 1e-12) break;
    s += "<line x1=\"" + fmt(sx(t)) + "\" x2=\"" + fmt(sx(t)) + "\" y1=\"" + fmt(kTop) + "\" y2=\"" + fmt(bottom) +
         "\" stroke=\"#eee\"/><text x=\"" + fmt(sx(t)) + "\" y=\"" + fmt(bottom + 14) + "\" text-anchor=\"middle\">" +
         tick_label(t) + "</text>\n";
  }
  s += "<rect x=\"" + fmt(px0) + "\" y=\"" + fmt(kTop) + "\" width=\"" + fmt(px1 - px0) + "\" height=\"" +
       fmt(bottom - kTop) + "\" fill=\"none\" stroke=\"#888\"/>\n";
  s += "<text x=\"" + fmt((px0 + px1) / 2) + "\" y=\"" + fmt(a.height - 8.0) + "\" text-anchor=\"middle\">" +
       html_escape(a.x_label) + "</text>\n";
  for (std::size_t k = 0; k < lanes.size(); ++k) {
    const auto& lane = lanes[k];
    for (std::size_t i = 0; i < lane.intervals.size(); ++i)
      if (!std::isfinite(lane.intervals[i].first) || !std::isfinite(lane.intervals[i].second))
        throw Error("event timeline: lane \"" + lane.name + "\": interval " + std::to_string(i) + " [" +
                    short_number(lane.intervals[i].first) + ", " + short_number(lane.intervals[i].second) +
                    "] is not finite");
    const double y = kTop + lane_h * static_cast<double>(k);
    double total = 0.0;
    for (const auto& [t0, t1] : lane.intervals) total += std::max(0.0, t1 - t0);
    char summary[64];
    std::snprintf(summary, sizeof summary, ": %zu, %.2f s", lane.intervals.size(), total);
    s += "<text x=\"" + fmt(px0 - 6) + "\" y=\"" + fmt(y + lane_h / 2 + 4) + "\" text-anchor=\"end\">" +
         html_escape(lane.name) + (lane.intervals.empty() ? ": none" : summary) + "</text>\n";
    if (k > 0)
      s += "<line x1=\"" + fmt(px0) + "\" x2=\"" + fmt(px1) + "\" y1=\"" + fmt(y) + "\" y2=\"" + fmt(y) +
           "\" stroke=\"#ddd\"/>\n";
    // Bars in pixels, at least kMinBar wide, in time order; bars that overlap or touch are drawn
    // as one (the same picture: the fill is opaque). A lane's bars are then at most the plot's
    // width in number, whatever the intervals (tenth campaign recheck: 10^6 intervals wrote 10^6
    // rectangles, > 20 s and ~100 MB of SVG).
    constexpr double kMinBar = 2.0;  // px: an instant event stays visible
    std::vector<std::pair<double, double>> bars;
    bars.reserve(lane.intervals.size());
    for (const auto& [t0, t1] : lane.intervals) {
      const double x0 = sx(std::clamp(t0, 0.0, t_end)), x1 = sx(std::clamp(t1, 0.0, t_end));
      bars.emplace_back(x0, x0 + std::max(x1 - x0, kMinBar));
    }
    std::sort(bars.begin(), bars.end());
    for (std::size_t i = 0; i < bars.size();) {
      const double x0 = bars[i].first;
      double x1 = bars[i].second;
      for (++i; i < bars.size() && bars[i].first <= x1; ++i) x1 = std::max(x1, bars[i].second);
      s += "<rect class=\"event\" x=\"" + fmt(x0) + "\" y=\"" + fmt(y + 4) + "\" width=\"" + fmt(x1 - x0) +
           "\" height=\"" + fmt(lane_h - 8) + "\" fill=\"" + html_escape(lane.color) + "\"/>\n";
    }
  }
  if (!a.id.empty())
    s += "<line class=\"cursor\" x1=\"" + fmt(px0) + "\" x2=\"" + fmt(px0) + "\" y1=\"" + fmt(kTop) + "\" y2=\"" +
         fmt(bottom) + "\" stroke=\"#000\" stroke-width=\"1\" visibility=\"hidden\"/>\n";
  return s + "</svg>\n";
}

}  // namespace miner::report

#include <cmath>
#include <limits>
#include <string>

#include <catch2/catch.hpp>

#include "miner/report/svg_plot.hpp"

using Catch::Matchers::Contains;
using namespace miner::report;

namespace {
std::size_t count(const std::string& text, const std::string& what) {
  std::size_t n = 0;
  for (std::size_t p = text.find(what); p != std::string::npos; p = text.find(what, p + 1)) ++n;
  return n;
}
}  // namespace

TEST_CASE("nice ticks are 1-2-5 steps that cover the range", "[REQ-REPORT-004]") {
  const auto t = nice_ticks(0.013, 0.87);
  REQUIRE(t.size() >= 2);
  CHECK(t.front() <= 0.013);
  CHECK(t.back() >= 0.87);
  const double step = t[1] - t[0];
  const double mantissa = step / std::pow(10.0, std::floor(std::log10(step)));
  CHECK((std::abs(mantissa - 1) < 1e-9 || std::abs(mantissa - 2) < 1e-9 || std::abs(mantissa - 5) < 1e-9));
  for (std::size_t i = 1; i < t.size(); ++i) CHECK(t[i] - t[i - 1] == Approx(step));
  CHECK(nice_ticks(-3, 3, 6) == std::vector<double>{-3, -2, -1, 0, 1, 2, 3});
  CHECK_THROWS(nice_ticks(1, 1));
  CHECK_THROWS(nice_ticks(0, NAN));
}

TEST_CASE("line plots draw every series, break at NaN, escape text and are deterministic", "[REQ-REPORT-004]") {
  const Series a{"a <b>", "#123456", {0, 1, 2, 3}, {0, 1, NAN, 3}};
  const Series b{"b", "red", {0, 3}, {3, 0}};
  const std::string svg = svg_line_plot({"T & U", "x", "y"}, {a, b});
  CHECK_THAT(svg, Contains("<svg") && Contains("</svg>") && Contains("T &amp; U") && Contains("a &lt;b&gt;"));
  CHECK(count(svg, "<path d=\"") == 2);
  // The NaN splits series a into two pieces: two move-to commands.
  const auto first_path = svg.substr(svg.find("<path d=\""), svg.find("\" fill", svg.find("<path d=\"")) - svg.find("<path d=\""));
  CHECK(count(first_path, "M") == 2);
  CHECK(svg == svg_line_plot({"T & U", "x", "y"}, {a, b}));
  CHECK_THROWS_WITH(svg_line_plot({"P", "x", "y"}, {Series{"bad", "red", {0, 1}, {0}}}),
                    Contains("\"P\"") && Contains("\"bad\"") && Contains("2 x values and 1 y values"));
  // Degenerate data still make a drawable plot.
  CHECK_THAT(svg_line_plot({"flat", "x", "y"}, {Series{"c", "red", {1, 1}, {2, 2}}}), Contains("</svg>"));
  CHECK_THAT(svg_line_plot({"empty", "x", "y"}, {}), Contains("</svg>"));
}

TEST_CASE("box plots draw median, quartiles, whiskers and outliers", "[REQ-REPORT-004]") {
  // 1..9 and an outlier at 100: type-7 quartiles of {1..9, 100} are 3.25 and 7.75,
  // IQR 4.5, upper fence 14.5: the whisker ends at 9 and 100 is an outlier.
  BoxGroup g{"g", {1, 2, 3, 4, 5, 6, 7, 8, 9, 100}};
  const std::string svg = svg_box_plot({"box", "", "value"}, {g, BoxGroup{"none", {}}});
  CHECK(count(svg, "<circle") == 1);
  CHECK(count(svg, "<rect x=") >= 2);  // frame + box
  CHECK_THAT(svg, Contains(">n/a<") && Contains(">none<"));
  CHECK(svg == svg_box_plot({"box", "", "value"}, {g, BoxGroup{"none", {}}}));
  const std::string log_svg = svg_box_plot({"log", "", "ms"}, {BoxGroup{"x", {0.1, 1, 10, 100}}}, true);
  CHECK_THAT(log_svg, Contains(">100<") && Contains(">0.1<"));
  CHECK_THAT(svg, Contains(">n=10</text>"));
}

TEST_CASE("box plots show missed runs instead of dropping them", "[REQ-REPORT-004]") {
  // 3 values and 2 misses: n = 5; type-7 quartiles over {1, 2, 3, inf, inf} are 2 and inf,
  // so the box reaches the top edge; without the misses it would end at 2.5.
  const BoxGroup with{"p", {1, 2, 3}, 2};
  const std::string svg = svg_box_plot({"t", "", "ms"}, {with});
  CHECK_THAT(svg, Contains(">n=5, 2 missed</text>"));
  CHECK(count(svg, "class=\"miss\"") == 1);
  const std::string dropped = svg_box_plot({"t", "", "ms"}, {BoxGroup{"p", {1, 2, 3}}});
  CHECK_THAT(dropped, Contains(">n=3</text>"));
  CHECK(count(dropped, "class=\"miss\"") == 0);
  // The box's top (its y) differs: with misses it is the plot's top edge (kTop = 26).
  const auto box_y = [](const std::string& s) {
    const auto at = s.find("fill=\"#9ecae1\"");
    const auto rect = s.rfind("<rect x=", at);
    const auto y = s.find(" y=\"", rect) + 4;
    return std::stod(s.substr(y, s.find('"', y) - y));
  };
  CHECK(box_y(svg) == Approx(26.0));
  CHECK(box_y(dropped) > 26.0 + 1.0);
  // Only misses: still drawn (not "n/a").
  CHECK_THAT(svg_box_plot({"t", "", "ms"}, {BoxGroup{"m", {}, 3}}), !Contains(">n/a<") && Contains(">n=3, 3 missed<"));
}

TEST_CASE("html_escape escapes the five special characters", "[REQ-REPORT-004]") {
  CHECK(html_escape("<a href=\"x\">'&'</a>") == "&lt;a href=&quot;x&quot;&gt;&#39;&amp;&#39;&lt;/a&gt;");
}

TEST_CASE("line plots draw bands and dashes, and carry their time mapping and cursor when named",
          "[REQ-REPORT-004][REQ-REPORT-011]") {
  Series band{"+-3 sigma", "#9467bd", {0, 1, 2, 3}, {1, 2, NAN, 1}, {}, {-1, -2, NAN, -1}};
  const Series dashed{"ref", "#1f77b4", {0, 3}, {0, 5}, "5 3"};
  PlotAxes axes{"Band", "time (s)", "m"};
  const std::string plain = svg_line_plot(axes, {band, dashed});
  // A band is one filled outline per finite run (the NaN splits it), closed with Z.
  CHECK(count(plain, "class=\"band\"") == 1);
  const auto b0 = plain.find("class=\"band\" d=\"");
  const std::string d = plain.substr(b0, plain.find("\" fill", b0) - b0);
  CHECK(count(d, "M") == 2);
  CHECK(count(d, "Z") == 2);
  CHECK_THAT(plain, Contains("stroke-dasharray=\"5 3\""));
  // The band's lower edge counts for the axes: -2 is inside the y ticks.
  CHECK_THAT(plain, Contains(">-2</text>"));
  // Unnamed: no id, mapping or cursor (the bench plots keep their bytes).
  CHECK_THAT(plain, !Contains("data-px0") && !Contains("class=\"cursor\"") && !Contains(" id=\""));
  axes.id = "plot-band";
  const std::string named = svg_line_plot(axes, {band, dashed});
  CHECK_THAT(named, Contains("id=\"plot-band\"") && Contains("data-x0=\"0\" data-x1=\"3\"") &&
                        Contains("data-px0=\"62.0\" data-px1=\"548.0\"") && Contains("class=\"cursor\""));
  CHECK(named == svg_line_plot(axes, {band, dashed}));
  band.y_low.pop_back();
  CHECK_THROWS_WITH(svg_line_plot(axes, {band}), Contains("Band") && Contains("+-3 sigma"));
}

TEST_CASE("the event timeline has a lane per kind, a bar per interval, counts and 'none'", "[REQ-REPORT-012]") {
  PlotAxes axes{"Events", "time (s)", ""};
  axes.width = 1200;
  axes.id = "plot-events";
  const std::vector<EventLane> lanes{{"failsafe", "#d62728", {{2.0, 4.5}}},
                                     {"collision", "#000000", {{1.0, 1.0}, {8.0, 9.0}}},
                                     {"pose dropout", "#9467bd", {}}};
  const std::string svg = svg_event_timeline(axes, lanes, 10.0);
  CHECK(count(svg, "class=\"event\"") == 3);
  CHECK_THAT(svg, Contains("failsafe: 1, 2.50 s") && Contains("collision: 2, 1.00 s") && Contains("pose dropout: none"));
  CHECK_THAT(svg, Contains("id=\"plot-events\"") && Contains("data-x1=\"10\"") && Contains("class=\"cursor\""));
  // An instant event is still 2 px wide.
  CHECK_THAT(svg, Contains("width=\"2.0\""));
  // Three lanes: the svg's height grows with them.
  CHECK_THAT(svg, Contains("height=\"134\""));
  CHECK(svg == svg_event_timeline(axes, lanes, 10.0));
}

TEST_CASE("the event timeline draws overlapping bars as one, so its size is bounded by the plot, and refuses NaN",
          "[REQ-LIB-003][REQ-REPORT-012]") {
  PlotAxes axes{"Events", "time (s)", ""};
  axes.width = 1200;
  // Two intervals that overlap, and one instant inside another: two bars, not four.
  const std::vector<EventLane> overlapping{{"failsafe", "#d62728", {{2.0, 4.5}, {4.0, 6.0}, {8.0, 9.0}, {8.5, 8.5}}}};
  const std::string two = svg_event_timeline(axes, overlapping, 10.0);
  CHECK(count(two, "class=\"event\"") == 2);
  CHECK_THAT(two, Contains("failsafe: 4,"));  // the label still counts every interval
  // Tenth campaign recheck: 10^6 intervals drew 10^6 rectangles (> 20 s). Now at most one bar per
  // pixel column of the 1200 px plot, whatever their number and order.
  EventLane many{"collision", "#000000", {}};
  for (int i = 0; i < 1000000; ++i) {
    const double t = 10.0 * static_cast<double>((static_cast<long long>(i) * 7919) % 1000000) / 1e6;  // every 10 us, shuffled
    many.intervals.emplace_back(t, t);
  }
  const std::string dense = svg_event_timeline(axes, {many}, 10.0);
  CHECK(count(dense, "class=\"event\"") == 1);  // 2 px bars every 0.012 px touch: one bar
  CHECK_THAT(dense, Contains("collision: 1000000,"));
  CHECK(dense.size() < 10000);
  // Bars farther apart than 2 px stay apart.
  EventLane sparse{"dropout", "#9467bd", {}};
  for (int i = 0; i < 100; ++i) sparse.intervals.emplace_back(0.1 * i, 0.1 * i);
  CHECK(count(svg_event_timeline(axes, {sparse}, 10.0), "class=\"event\"") == 100);
  const double nan = std::numeric_limits<double>::quiet_NaN();
  CHECK_THROWS_WITH(svg_event_timeline(axes, {EventLane{"failsafe", "#000", {{1.0, nan}}}}, 10.0),
                    Contains("lane \"failsafe\": interval 0") && Contains("not finite"));
}

TEST_CASE("Ticks of a finite range too wide or too narrow for a double are refused, not a crash",
          "[REQ-LIB-003][REQ-REPORT-004]") {
  // Tenth campaign L6: -1e308 .. 1e308 (its width overflows) and 0 .. 5e-324 (a denormal step)
  // crashed nice_ticks and every plot drawing such data.
  CHECK_THROWS_WITH(nice_ticks(-1e308, 1e308), Contains("too wide or too narrow"));
  CHECK_THROWS_WITH(nice_ticks(0.0, 5e-324), Contains("too wide or too narrow"));
  CHECK_THROWS_WITH(svg_line_plot(PlotAxes{}, {Series{"a", "red", {0, 1e-300, 1e300}, {-1e308, 0, 1e308}}}),
                    Contains("nice_ticks"));
  CHECK(nice_ticks(0.0, 10.0).size() >= 3);
}

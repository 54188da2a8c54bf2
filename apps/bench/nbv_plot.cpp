#include "nbv_plot.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

namespace scenewatch::bench {

namespace {

constexpr int kPanelWidth = 500, kHeight = 450;
constexpr int kPlotLeft = 88, kPlotRight = 18, kPlotTop = 72, kPlotBottom = 350;  // margins inside a panel
constexpr int kFont = cv::FONT_HERSHEY_SIMPLEX;
const cv::Scalar kBlack(0, 0, 0), kGrid(225, 225, 225), kAxis(90, 90, 90);
// BGR, the colour-blind-safe Okabe-Ito set; markers tell curves apart where they lie on each other.
const cv::Scalar kColours[] = {{0, 0, 0}, {178, 114, 0}, {0, 159, 230}, {115, 158, 0}, {167, 121, 204}, {0, 94, 213}};
enum class Marker { kDisc, kSquare, kTriangle, kDiamond };
constexpr int kNumMarkers = 4;

struct Tick {
  double value;
  bool labelled;
};

// "2e-4", "0.5", "180": short labels for ticks.
std::string tick_label(double v) {
  char buf[32];
  const double a = std::abs(v);
  if (a == 0.0 || (a >= 0.1 && a < 1e4)) {
    std::snprintf(buf, sizeof buf, "%g", v);
  } else {
    int exponent = static_cast<int>(std::floor(std::log10(a)));
    double mantissa = v / std::pow(10.0, exponent);
    if (std::abs(mantissa) >= 9.995) mantissa /= 10.0, ++exponent;  // 9.999e-5 prints as 1e-4
    std::snprintf(buf, sizeof buf, "%.3ge%d", mantissa, exponent);
  }
  return buf;
}

// 1, 2 or 5 times a power of ten, giving about `count` intervals over `span`.
double nice_step(double span, int count) {
  const double raw = span / count, p = std::pow(10.0, std::floor(std::log10(raw)));
  for (double m : {1.0, 2.0, 5.0})
    if (m * p >= raw) return m * p;
  return 10.0 * p;
}

// The vertical axis of one panel: linear or log10, mapped onto the plot's rows.
struct YAxis {
  bool log = false;
  double lo = 0.0, hi = 1.0;  // in axis units (log10 of the value when log)
  int top = 0, bottom = 0;

  double unit(double v) const { return log ? std::log10(v) : v; }
  int row(double v) const { return static_cast<int>(std::lround(bottom - (unit(v) - lo) / (hi - lo) * (bottom - top))); }

  std::vector<Tick> ticks() const {
    std::vector<Tick> out;
    if (!log) {
      const double step = nice_step(hi - lo, 8);
      for (double t = std::ceil(lo / step) * step; t <= hi + 1e-9 * step; t += step) out.push_back({std::abs(t) < 1e-12 * step ? 0.0 : t, true});
      return out;
    }
    // Decades labelled; 2 and 5 labelled too when few decades are shown; the other digits unlabelled.
    const bool few = hi - lo < 3.0;
    for (int e = static_cast<int>(std::floor(lo)); e <= static_cast<int>(std::ceil(hi)); ++e)
      for (int d = 1; d <= 9; ++d) {
        const double u = e + std::log10(static_cast<double>(d));
        if (u >= lo && u <= hi) out.push_back({d * std::pow(10.0, e), d == 1 || (few && (d == 2 || d == 5))});
      }
    return out;
  }
};

YAxis fit_y_axis(const std::vector<StepCurve>& curves, const StepRange& r, int top, int bottom) {
  double vmin = INFINITY, vmax = -INFINITY;
  for (const auto& c : curves)
    for (int s = r.first; s <= r.last; ++s) vmin = std::min(vmin, c.values[s - 1]), vmax = std::max(vmax, c.values[s - 1]);
  YAxis y;
  y.top = top;
  y.bottom = bottom;
  y.log = vmin > 0.0 && vmax > 10.0 * vmin;
  y.lo = y.unit(vmin);
  y.hi = y.unit(vmax);
  if (y.hi - y.lo < 1e-12 * std::max(1.0, std::abs(y.hi))) y.lo -= 0.5, y.hi += 0.5;  // a flat panel
  const double pad = 0.06 * (y.hi - y.lo);
  y.lo -= pad;
  y.hi += pad;
  return y;
}

void put_text(cv::Mat& img, const std::string& text, cv::Point at, double scale, int thickness = 1, const cv::Scalar& colour = kBlack) {
  cv::putText(img, text, at, kFont, scale, colour, thickness, cv::LINE_AA);
}

// `at` is where the text's box is anchored: ax 0 left, 0.5 centre, 1 right; ay 0 baseline, 0.5 middle.
void put_text_anchored(cv::Mat& img, const std::string& text, cv::Point at, double ax, double ay, double scale, int thickness = 1) {
  int baseline = 0;
  const cv::Size size = cv::getTextSize(text, kFont, scale, thickness, &baseline);
  put_text(img, text, {at.x - static_cast<int>(ax * size.width), at.y + static_cast<int>(ay * size.height)}, scale, thickness);
}

void draw_marker(cv::Mat& img, cv::Point p, Marker m, const cv::Scalar& colour) {
  switch (m) {
    case Marker::kDisc:
      cv::circle(img, p, 4, colour, cv::FILLED, cv::LINE_AA);
      break;
    case Marker::kSquare:
      cv::rectangle(img, p - cv::Point(6, 6), p + cv::Point(6, 6), colour, 2, cv::LINE_AA);
      break;
    case Marker::kTriangle: {
      const std::vector<cv::Point> tri{p + cv::Point(0, -6), p + cv::Point(6, 5), p + cv::Point(-6, 5)};
      cv::fillConvexPoly(img, tri, colour, cv::LINE_AA);
      break;
    }
    case Marker::kDiamond:
      cv::polylines(img, std::vector<cv::Point>{p + cv::Point(0, -7), p + cv::Point(7, 0), p + cv::Point(0, 7), p + cv::Point(-7, 0)}, true, colour,
                    2, cv::LINE_AA);
      break;
  }
}

void draw_panel(cv::Mat& img, int x0, const std::vector<StepCurve>& curves, const StepRange& r, const std::string& y_label) {
  const int left = x0 + kPlotLeft, right = x0 + kPanelWidth - kPlotRight;
  const YAxis y = fit_y_axis(curves, r, kPlotTop, kPlotBottom);
  const double x_lo = r.first - 0.5, x_hi = r.last + 0.5;
  auto col = [&](double step) { return static_cast<int>(std::lround(left + (step - x_lo) / (x_hi - x_lo) * (right - left))); };

  for (const Tick& t : y.ticks()) {
    const int v = y.row(t.value);
    if (t.labelled) {
      cv::line(img, {left, v}, {right, v}, kGrid, 1);
      cv::line(img, {left - 6, v}, {left, v}, kAxis, 1);
      put_text_anchored(img, tick_label(t.value), {left - 9, v}, 1.0, 0.5, 0.45);
    } else {
      cv::line(img, {left - 3, v}, {left, v}, kAxis, 1);
    }
  }
  const double x_step = std::max(1.0, nice_step(r.last - r.first, 7));
  for (int s = r.first; s <= r.last; ++s) {
    const int u = col(s);
    const bool labelled = std::fmod(s, x_step) == 0.0;
    cv::line(img, {u, kPlotBottom}, {u, kPlotBottom + (labelled ? 6 : 3)}, kAxis, 1);
    if (labelled) put_text_anchored(img, std::to_string(s), {u, kPlotBottom + 22}, 0.5, 0.0, 0.45);
  }
  cv::rectangle(img, {left, kPlotTop}, {right, kPlotBottom}, kAxis, 1);
  put_text_anchored(img, "step", {(left + right) / 2, kPlotBottom + 44}, 0.5, 0.0, 0.5);
  char heading[96];
  std::snprintf(heading, sizeof heading, "steps %d-%d, %s y axis", r.first, r.last, y.log ? "log" : "linear");
  put_text_anchored(img, heading, {(left + right) / 2, kPlotTop - 10}, 0.5, 0.0, 0.5);

  // The y label, turned a quarter left, left of the tick labels.
  int baseline = 0;
  const cv::Size size = cv::getTextSize(y_label, kFont, 0.45, 1, &baseline);
  cv::Mat label(size.height + baseline + 4, size.width + 4, img.type(), cv::Scalar::all(255));
  put_text(label, y_label, {2, size.height + 2}, 0.45);
  cv::rotate(label, label, cv::ROTATE_90_COUNTERCLOCKWISE);
  const int top = std::max(0, (kPlotTop + kPlotBottom - label.rows) / 2);
  label.copyTo(img(cv::Rect(x0 + 4, top, label.cols, std::min(label.rows, img.rows - top))));

  for (std::size_t i = 0; i < curves.size(); ++i) {
    const cv::Scalar& colour = kColours[i % std::size(kColours)];
    std::vector<cv::Point> points;
    for (int s = r.first; s <= r.last; ++s) points.emplace_back(col(s), y.row(curves[i].values[s - 1]));
    cv::polylines(img, points, false, colour, 2, cv::LINE_AA);
    for (const auto& p : points) draw_marker(img, p, static_cast<Marker>(i % kNumMarkers), colour);
  }
}

void draw_legend(cv::Mat& img, const std::vector<StepCurve>& curves, int baseline_y) {
  constexpr int kSwatch = 34, kGap = 8, kSpacing = 30;
  int total = 0;
  std::vector<int> widths;
  for (const auto& c : curves) {
    int baseline = 0;
    widths.push_back(kSwatch + kGap + cv::getTextSize(c.name, kFont, 0.5, 1, &baseline).width);
    total += widths.back() + kSpacing;
  }
  int x = (img.cols - (total - kSpacing)) / 2;
  for (std::size_t i = 0; i < curves.size(); ++i) {
    const cv::Scalar& colour = kColours[i % std::size(kColours)];
    const int mid_y = baseline_y - 5;
    cv::line(img, {x, mid_y}, {x + kSwatch, mid_y}, colour, 2, cv::LINE_AA);
    draw_marker(img, {x + kSwatch / 2, mid_y}, static_cast<Marker>(i % kNumMarkers), colour);
    put_text(img, curves[i].name, {x + kSwatch + kGap, baseline_y}, 0.5);
    x += widths[i] + kSpacing;
  }
}

}  // namespace

bool write_step_plot(const std::filesystem::path& png, const std::string& title, const std::string& y_label,
                     const std::vector<StepCurve>& curves, const std::vector<StepRange>& panels) {
  std::size_t steps = curves.empty() ? 0 : curves.front().values.size();
  for (const auto& c : curves) steps = std::min(steps, c.values.size());
  cv::Mat img(kHeight, kPanelWidth * static_cast<int>(std::max<std::size_t>(1, panels.size())), CV_8UC3, cv::Scalar::all(255));
  put_text_anchored(img, title, {img.cols / 2, 30}, 0.5, 0.0, 0.6, 1);
  for (std::size_t p = 0; p < panels.size(); ++p) {
    const StepRange r{std::max(1, panels[p].first), std::min(panels[p].last, static_cast<int>(steps))};
    if (r.first > r.last) continue;  // nothing computed in this range
    draw_panel(img, static_cast<int>(p) * kPanelWidth, curves, r, y_label);
  }
  draw_legend(img, curves, kHeight - 18);
  try {
    return cv::imwrite(png.string(), img);
  } catch (const cv::Exception&) {
    return false;
  }
}

}  // namespace scenewatch::bench

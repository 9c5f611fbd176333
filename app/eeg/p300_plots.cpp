#include "eeg/p300_plots.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "support/cli_error.h"

namespace arbci::app {
namespace {

const cv::Scalar kBlack(0, 0, 0), kGrey(200, 200, 200), kTarget(40, 40, 220), kOther(180, 110, 30),
    kWhite(255, 255, 255), kWindow(215, 245, 250);

std::string format(double value, int decimals) {
  char text[32];
  std::snprintf(text, sizeof text, "%.*f", decimals, value);
  return text;
}

void text(cv::Mat& image, const std::string& s, cv::Point at, double scale = 0.4,
          const cv::Scalar& colour = kBlack) {
  cv::putText(image, s, at, cv::FONT_HERSHEY_SIMPLEX, scale, colour, 1, cv::LINE_AA);
}

// One panel: axes, a zero line, ticks, and curves of (x, y) points.
struct Panel {
  cv::Rect area;
  double x0, x1, y0, y1;
  cv::Point map(double x, double y) const {
    return {
        area.x + static_cast<int>(std::lround((x - x0) / (x1 - x0) * area.width)),
        area.y + area.height - static_cast<int>(std::lround((y - y0) / (y1 - y0) * area.height))};
  }
  void axes(cv::Mat& image, const std::string& title, int x_decimals, int y_decimals) const {
    cv::rectangle(image, area, kGrey, 1);
    if (y0 < 0.0 && y1 > 0.0) cv::line(image, map(x0, 0.0), map(x1, 0.0), kGrey, 1);
    text(image, title, {area.x, area.y - 6}, 0.45);  // above: curves reach the top
    text(image, format(y1, y_decimals), {area.x - 42, area.y + 10}, 0.35);
    text(image, format(y0, y_decimals), {area.x - 42, area.y + area.height}, 0.35);
    text(image, format(x0, x_decimals), {area.x - 4, area.y + area.height + 14}, 0.35);
    text(image, format(x1, x_decimals), {area.x + area.width - 20, area.y + area.height + 14},
         0.35);
  }
  void curve(cv::Mat& image, const std::vector<double>& xs, const std::vector<double>& ys,
             const cv::Scalar& colour, bool dots = false, int thickness = 2) const {
    std::vector<cv::Point> points;
    for (size_t i = 0; i < xs.size(); ++i) points.push_back(map(xs[i], ys[i]));
    cv::polylines(image, points, false, colour, thickness, cv::LINE_AA);
    if (dots) {
      for (const cv::Point& p : points) cv::circle(image, p, 3, colour, cv::FILLED, cv::LINE_AA);
    }
  }
  void band(cv::Mat& image, const std::vector<double>& xs, const std::vector<double>& ys,
            const std::vector<double>& half_widths, const cv::Scalar& colour) const;
};

// A translucent band of ys +/- half_widths.
void Panel::band(cv::Mat& image, const std::vector<double>& xs, const std::vector<double>& ys,
                 const std::vector<double>& half_widths, const cv::Scalar& colour) const {
  std::vector<cv::Point> outline;
  for (size_t i = 0; i < xs.size(); ++i) outline.push_back(map(xs[i], ys[i] + half_widths[i]));
  for (size_t i = xs.size(); i-- > 0;) outline.push_back(map(xs[i], ys[i] - half_widths[i]));
  cv::Mat layer = image.clone();
  cv::fillPoly(layer, std::vector<std::vector<cv::Point>>{outline}, colour, cv::LINE_AA);
  cv::addWeighted(layer, 0.25, image, 0.75, 0.0, image);
}

void save(const std::filesystem::path& path, const cv::Mat& image) {
  if (!cv::imwrite(path.string(), image)) throw CliError("cannot write " + path.string());
}

// Blue (negative) through white to red (positive), for `v` in [-1, 1].
cv::Scalar diverging(double v) {
  v = std::clamp(v, -1.0, 1.0);
  const double fade = 255.0 * (1.0 - std::abs(v));
  return v < 0.0 ? cv::Scalar(255, fade, fade) : cv::Scalar(fade, fade, 255);
}

// A colour bar from -limit to +limit at `area`, labelled.
void colourBar(cv::Mat& image, const cv::Rect& area, double limit, const std::string& unit,
               int decimals) {
  for (int y = 0; y < area.height; ++y) {
    const double v = 1.0 - 2.0 * y / std::max(1, area.height - 1);
    cv::line(image, {area.x, area.y + y}, {area.x + area.width, area.y + y}, diverging(v), 1);
  }
  cv::rectangle(image, area, kGrey, 1);
  char top[32];
  std::snprintf(top, sizeof top, "%+.*f", decimals, limit);
  text(image, top, {area.x + area.width + 4, area.y + 10}, 0.35);
  text(image, "0", {area.x + area.width + 4, area.y + area.height / 2 + 4}, 0.35);
  text(image, format(-limit, decimals), {area.x + area.width + 4, area.y + area.height}, 0.35);
  text(image, unit, {area.x - 4, area.y - 8}, 0.35);
}

// Signed r^2 per channel (rows) and time (columns).
std::filesystem::path writeR2Figure(const std::filesystem::path& folder, const bci::ErpCurves& erp,
                                    const ClassNames& names) {
  const int channels = static_cast<int>(erp.channels.size()), samples = erp.samples();
  if (channels == 0 || samples < 2) return {};
  const int left = 80, top = 60, row_h = std::clamp(320 / channels, 6, 28), width = 720;
  cv::Mat image(top + channels * row_h + 70, left + width + 120, CV_8UC3, kWhite);
  text(image,
       "signed r^2 (" + names.target + " vs " + names.other +
           ") per channel and time: " + std::to_string(erp.targets) + " " + names.target + ", " +
           std::to_string(erp.others) + " " + names.other + " epochs",
       {left, 28}, 0.5);
  const double limit = std::max(1e-6, erp.signed_r2.cwiseAbs().maxCoeff());
  const int label_every = (14 + row_h - 1) / row_h;
  const double t0 = erp.timeS(0) * 1000.0, t1 = erp.timeS(samples - 1) * 1000.0;
  for (int c = 0; c < channels; ++c) {
    for (int s = 0; s < samples; ++s) {
      const int x0 = left + s * width / samples, x1 = left + (s + 1) * width / samples;
      cv::rectangle(image, cv::Rect(x0, top + c * row_h, std::max(1, x1 - x0), row_h),
                    diverging(erp.signed_r2(c, s) / limit), cv::FILLED);
    }
    if (c % label_every == 0)  // as many names as fit
      text(image, erp.channels[static_cast<size_t>(c)], {8, top + c * row_h + row_h / 2 + 4}, 0.35);
  }
  const int bottom = top + channels * row_h;
  cv::rectangle(image, cv::Rect(left, top, width, channels * row_h), kGrey, 1);
  for (double t = 0.0; t <= t1; t += 200.0) {
    const int x = left + static_cast<int>(std::lround((t - t0) / (t1 - t0) * width));
    cv::line(image, {x, top}, {x, bottom + 4}, t == 0.0 ? kBlack : kGrey, 1);
    text(image, format(t, 0), {x - 10, bottom + 18}, 0.35);
  }
  text(image, "ms after the stimulus", {left + width / 2 - 60, bottom + 40}, 0.4);
  colourBar(image, cv::Rect(left + width + 20, top, 16, std::max(60, channels * row_h)), limit,
            "r^2", 3);
  const std::filesystem::path path = folder / "r2.png";
  save(path, image);
  return path;
}

// The difference wave at its peak on a head map, where the channels' 10-20 positions are known.
std::filesystem::path writeScalpMap(const std::filesystem::path& folder, const bci::ErpCurves& erp,
                                    const ClassNames& names) {
  const std::optional<bci::ScalpMap> map = bci::scalpMapAtPeak(erp);
  if (!map) return {};
  const int size = 360, margin = 50;
  cv::Mat image(size + 2 * margin + 40, size + 2 * margin + 90, CV_8UC3, kWhite);
  const cv::Point centre(margin + size / 2, margin + 30 + size / 2);
  const double radius = size / 2.0, head = 0.55;  // the map's edge, in position units
  for (int y = -size / 2; y <= size / 2; ++y) {
    for (int x = -size / 2; x <= size / 2; ++x) {
      const double px = x / radius * head, py = -y / radius * head;
      if (px * px + py * py > head * head) continue;
      const cv::Scalar c = diverging(map->at(px, py) / map->limit_uv);
      image.at<cv::Vec3b>(centre.y + y, centre.x + x) =
          cv::Vec3b(static_cast<uchar>(c[0]), static_cast<uchar>(c[1]), static_cast<uchar>(c[2]));
    }
  }
  cv::circle(image, centre, static_cast<int>(radius), kBlack, 1, cv::LINE_AA);
  const std::vector<cv::Point> nose = {centre + cv::Point(-12, -static_cast<int>(radius) + 2),
                                       centre + cv::Point(0, -static_cast<int>(radius) - 16),
                                       centre + cv::Point(12, -static_cast<int>(radius) + 2)};
  cv::polylines(image, nose, false, kBlack, 1, cv::LINE_AA);
  for (const bci::ScalpMap::Electrode& e : map->electrodes) {
    const cv::Point p = centre + cv::Point(static_cast<int>(std::lround(e.x / head * radius)),
                                           static_cast<int>(-std::lround(e.y / head * radius)));
    cv::circle(image, p, 3, kBlack, cv::FILLED, cv::LINE_AA);
    text(image, e.name, p + cv::Point(5, -4), 0.35);
  }
  text(image,
       names.target + " - " + names.other + " at " + format(map->time_s * 1000.0, 0) +
           " ms (the difference's peak over channels)",
       {10, 24}, 0.45);
  colourBar(image, cv::Rect(size + 2 * margin + 10, margin + 40, 16, size - 40), map->limit_uv,
            "uV", 1);
  const std::filesystem::path path = folder / "scalp.png";
  save(path, image);
  return path;
}

// The ERP figure: per channel, target and non-target averages overlaid on one scale with their
// standard-error bands, the difference wave, the baseline and the analysis window marked.
std::filesystem::path writeErpFigure(const std::filesystem::path& folder, const bci::ErpCurves& erp,
                                     const ClassNames& names) {
  const int channels = static_cast<int>(erp.channels.size());
  const int samples = erp.samples();
  if (channels == 0 || samples < 2) return {};
  const int columns = std::min(4, channels), rows = (channels + columns - 1) / columns;
  const int panel_w = 300, panel_h = 190, left = 70, gap_x = 70, gap_y = 62, top = 84;
  cv::Mat image(top + rows * (panel_h + gap_y), left + columns * (panel_w + gap_x), CV_8UC3,
                kWhite);
  text(image,
       "ERP averages (mean +/- 1.96 SE over epochs, baseline " + format(erp.start_s * 1000.0, 0) +
           " to " + format((erp.start_s + erp.baseline_s) * 1000.0, 0) +
           " ms subtracted): " + std::to_string(erp.targets) + " " + names.target + ", " +
           std::to_string(erp.others) + " " + names.other + " epochs",
       {left, 26}, 0.5);
  // Legend.
  const std::pair<std::string, cv::Scalar> legend[] = {
      {names.target, kTarget}, {names.other, kOther}, {"difference", kBlack}};
  int x = left;
  for (const auto& [name, colour] : legend) {
    cv::line(image, {x, 48}, {x + 24, 48}, colour, 2, cv::LINE_AA);
    text(image, name, {x + 30, 52}, 0.45);
    x += 150;
  }
  cv::rectangle(image, cv::Rect(x, 41, 24, 14), kWindow, cv::FILLED);
  text(image, "analysis window", {x + 30, 52}, 0.45);

  const Eigen::MatrixXd difference = erp.difference();
  const Eigen::MatrixXd band_t = 1.96 * erp.target_se, band_o = 1.96 * erp.other_se;
  const double limit = erp.scaleUv();
  std::vector<double> ms(static_cast<size_t>(samples));
  for (int s = 0; s < samples; ++s) ms[static_cast<size_t>(s)] = erp.timeS(s) * 1000.0;
  for (int c = 0; c < channels; ++c) {
    const Panel panel{{left + (c % columns) * (panel_w + gap_x),
                       top + (c / columns) * (panel_h + gap_y), panel_w, panel_h},
                      ms.front(),
                      ms.back(),
                      -limit,
                      limit};
    cv::rectangle(image,
                  cv::Rect(panel.map(erp.window_start_s * 1000.0, limit),
                           panel.map(std::min(erp.window_end_s * 1000.0, ms.back()), -limit)),
                  kWindow, cv::FILLED);
    panel.axes(image, erp.channels[static_cast<size_t>(c)], 0, 0);
    // Time ticks every 200 ms; the stimulus (0 ms) is the vertical line.
    for (double t = 0.0; t <= ms.back(); t += 200.0) {
      const cv::Point at = panel.map(t, -limit);
      cv::line(image, at, at + cv::Point(0, 4), kBlack, 1);
      if (t > 0.0 && t < ms.back() - 60.0) text(image, format(t, 0), at + cv::Point(-12, 16), 0.35);
    }
    cv::line(image, panel.map(0.0, -limit), panel.map(0.0, limit), kGrey, 1);
    text(image, "ms", panel.map(ms.back(), -limit) + cv::Point(-18, 30), 0.35);
    text(image, "uV", panel.map(ms.front(), 0.0) + cv::Point(-30, 4), 0.35);
    panel.band(image, ms, bci::ErpCurves::row(erp.other_mean, c), bci::ErpCurves::row(band_o, c),
               kOther);
    panel.band(image, ms, bci::ErpCurves::row(erp.target_mean, c), bci::ErpCurves::row(band_t, c),
               kTarget);
    panel.curve(image, ms, bci::ErpCurves::row(erp.other_mean, c), kOther);
    panel.curve(image, ms, bci::ErpCurves::row(erp.target_mean, c), kTarget);
    panel.curve(image, ms, bci::ErpCurves::row(difference, c), kBlack, false, 1);
  }
  const std::filesystem::path path = folder / "erp.png";
  save(path, image);
  return path;
}

}  // namespace

nlohmann::json erpJson(const bci::ErpCurves& erp) {
  const Eigen::MatrixXd difference = erp.difference();
  std::vector<double> ms(static_cast<size_t>(erp.samples()));
  for (int s = 0; s < erp.samples(); ++s) ms[static_cast<size_t>(s)] = erp.timeS(s) * 1000.0;
  nlohmann::json channels = nlohmann::json::array();
  for (int c = 0; c < static_cast<int>(erp.channels.size()); ++c) {
    channels.push_back({{"name", erp.channels[static_cast<size_t>(c)]},
                        {"time_ms", ms},
                        {"target", bci::ErpCurves::row(erp.target_mean, c)},
                        {"non_target", bci::ErpCurves::row(erp.other_mean, c)},
                        {"difference", bci::ErpCurves::row(difference, c)},
                        {"target_se", bci::ErpCurves::row(erp.target_se, c)},
                        {"non_target_se", bci::ErpCurves::row(erp.other_se, c)},
                        {"signed_r2", bci::ErpCurves::row(erp.signed_r2, c)}});
  }
  return {{"units", "uV"},
          {"rate_hz", erp.rate_hz},
          {"baseline_ms", {erp.start_s * 1000.0, (erp.start_s + erp.baseline_s) * 1000.0}},
          {"window_ms", {erp.window_start_s * 1000.0, erp.window_end_s * 1000.0}},
          {"target_epochs", erp.targets},
          {"non_target_epochs", erp.others},
          {"peak_ms", erp.samples() > 0 ? erp.timeS(erp.peakSample()) * 1000.0 : 0.0},
          {"channels", channels}};
}

std::vector<std::filesystem::path> writeP300Plots(const std::filesystem::path& folder,
                                                  const bci::P300Dataset& data,
                                                  const bci::EvaluationReport& report,
                                                  const std::string& title,
                                                  const ClassNames& names) {
  std::error_code error;
  std::filesystem::create_directories(folder, error);
  if (error)
    throw CliError(folder.string() + ": cannot create the plot folder (" + error.message() + ")");
  std::vector<std::filesystem::path> written;

  const std::filesystem::path erp_png = writeErpFigure(folder, data.erp, names);
  if (!erp_png.empty()) {
    written.push_back(erp_png);
    for (const auto& extra :
         {writeR2Figure(folder, data.erp, names), writeScalpMap(folder, data.erp, names)})
      if (!extra.empty()) written.push_back(extra);
    written.push_back(folder / "erp.json");
    std::ofstream out(written.back());
    out << erpJson(data.erp).dump() << "\n";
    if (!out) throw CliError("cannot write " + written.back().string());
  }

  // Accuracy and bit rate against the number of sequences, where codes are choices.
  if (!report.selection_metrics || report.max_sequences < 1) return written;
  std::vector<double> n, percent;
  for (int k = 1; k <= report.max_sequences; ++k) {
    n.push_back(k);
    percent.push_back(100.0 * report.accuracy[static_cast<size_t>(k - 1)]);
  }
  cv::Mat image(330, 820, CV_8UC3, kWhite);
  text(image, "Selection accuracy and bit rate by number of sequences (" + title + ")", {50, 24},
       0.5);
  const double x1 = std::max(2.0, static_cast<double>(report.max_sequences));
  const Panel accuracy{{60, 50, 320, 230}, 1.0, x1, 0.0, 100.0};
  accuracy.axes(image, "accuracy % (95 % intervals)", 0, 0);
  // Guessing: the chance level, and the accuracy that beats it at p < 0.05 (dashed).
  cv::line(image, accuracy.map(1.0, 100.0 * report.chance), accuracy.map(x1, 100.0 * report.chance),
           kGrey, 1);
  for (double x = 1.0; x < x1; x += (x1 - 1.0) / 40.0) {
    cv::line(image, accuracy.map(x, 100.0 * report.chance_95),
             accuracy.map(std::min(x1, x + (x1 - 1.0) / 80.0), 100.0 * report.chance_95), kBlack,
             1);
  }
  text(image, "p < 0.05", accuracy.map(x1, 100.0 * report.chance_95) + cv::Point(-60, -4), 0.35);
  for (int k = 1; k <= report.max_sequences; ++k) {
    const bci::Interval& i = report.accuracy_interval[static_cast<size_t>(k - 1)];
    cv::line(image, accuracy.map(k, 100.0 * i.low), accuracy.map(k, 100.0 * i.high), kTarget, 1);
  }
  accuracy.curve(image, n, percent, kTarget, true);
  const double top = std::max(
      1.0, *std::max_element(report.bits_per_minute.begin(), report.bits_per_minute.end()) * 1.1);
  const Panel bits{{470, 50, 320, 230}, 1.0, x1, 0.0, top};
  bits.axes(image, "bits/min (Wolpaw)", 0, 1);
  bits.curve(image, n, report.bits_per_minute, kOther, true);
  text(image, "sequences", {190, 310});
  text(image, "sequences", {600, 310});
  written.push_back(folder / "accuracy.png");
  save(written.back(), image);
  return written;
}

}  // namespace arbci::app

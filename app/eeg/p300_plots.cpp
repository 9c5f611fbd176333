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
  // The frame, the zero line, the title above, and ticks: every `x_step` and `y_step` from the
  // first multiple inside the range (zero among them where the range holds it), each labelled,
  // and the axes' names with their units.
  void axes(cv::Mat& image, const std::string& title, double x_step, double y_step,
            const std::string& x_name, const std::string& y_name) const {
    cv::rectangle(image, area, kGrey, 1);
    if (y0 < 0.0 && y1 > 0.0) cv::line(image, map(x0, 0.0), map(x1, 0.0), kGrey, 1);
    text(image, title, {area.x, area.y - 6}, 0.45);  // above: curves reach the top
    const int x_decimals = x_step < 1.0 ? 1 : 0, y_decimals = y_step < 1.0 ? 1 : 0;
    for (double x = std::ceil(x0 / x_step - 1e-9) * x_step; x <= x1 + 1e-9; x += x_step) {
      const cv::Point at = map(x, y0);
      cv::line(image, at, at + cv::Point(0, 4), kBlack, 1);
      const std::string label = format(std::abs(x) < 1e-9 ? 0.0 : x, x_decimals);
      text(image, label, at + cv::Point(-4 * static_cast<int>(label.size()), 16), 0.35);
    }
    for (double y = std::ceil(y0 / y_step - 1e-9) * y_step; y <= y1 + 1e-9; y += y_step) {
      const cv::Point at = map(x0, y);
      cv::line(image, at, at - cv::Point(4, 0), kBlack, 1);
      const std::string label = format(std::abs(y) < 1e-9 ? 0.0 : y, y_decimals);
      text(image, label, at + cv::Point(-8 - 7 * static_cast<int>(label.size()), 4), 0.35);
    }
    text(image, x_name,
         {area.x + area.width / 2 - 4 * static_cast<int>(x_name.size()), area.y + area.height + 32},
         0.38);
    // The y axis' name, rotated to run up its side.
    int baseline = 0;
    const cv::Size size = cv::getTextSize(y_name, cv::FONT_HERSHEY_SIMPLEX, 0.38, 1, &baseline);
    cv::Mat label(size.height + baseline + 2, size.width + 2, CV_8UC3, kWhite);
    cv::putText(label, y_name, {1, size.height + 1}, cv::FONT_HERSHEY_SIMPLEX, 0.38, kBlack, 1,
                cv::LINE_AA);
    cv::rotate(label, label, cv::ROTATE_90_COUNTERCLOCKWISE);
    const cv::Rect where(area.x - 58, area.y + area.height / 2 - label.rows / 2, label.cols,
                         label.rows);
    if ((where & cv::Rect(0, 0, image.cols, image.rows)) == where) label.copyTo(image(where));
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

// A tick spacing of 1, 2 or 5 times a power of ten giving about `ticks` intervals over `range`.
double niceStep(double range, int ticks) {
  const double raw = range / std::max(1, ticks);
  const double power = std::pow(10.0, std::floor(std::log10(raw)));
  for (const double m : {1.0, 2.0, 5.0})
    if (m * power >= raw) return m * power;
  return 10.0 * power;
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

}  // namespace

std::string analysisText(const bci::ErpCurves& erp) {
  std::string out = "filter: " + erp.filterText() + "; reference: " + erp.referenceText();
  for (size_t i = 0; i < erp.excluded.size(); ++i)
    out += (i == 0 ? "; left out: " : ", ") + erp.excluded[i].first + " (" +
           erp.excluded[i].second + ")";
  return out;
}

nlohmann::json analysisJson(const bci::ErpCurves& erp) {
  nlohmann::json filter = {{"type", erp.filtered() ? "butterworth" : "none"},
                           {"order", erp.filtered() ? erp.filter_order : 0},
                           {"highpass_hz", erp.highpass_hz},
                           {"lowpass_hz", erp.lowpass_hz},
                           {"notch_hz", erp.notch_hz},
                           {"notch_q", erp.notch_hz > 0.0 ? erp.notch_q : 0.0},
                           {"zero_phase", erp.filtered() && erp.zero_phase},
                           {"text", erp.filterText()}};
  nlohmann::json excluded = nlohmann::json::array();
  for (const auto& [name, why] : erp.excluded) excluded.push_back({{"name", name}, {"why", why}});
  return {{"reference", erp.common_average ? "common_average" : "as_recorded"},
          {"filter", filter},
          {"baseline_ms", {erp.start_s * 1000.0, (erp.start_s + erp.baseline_s) * 1000.0}},
          {"epoch_ms", {erp.timeS(0) * 1000.0, erp.timeS(std::max(0, erp.samples() - 1)) * 1000.0}},
          {"window_ms", {erp.window_start_s * 1000.0, erp.window_end_s * 1000.0}},
          {"excluded_channels", excluded},
          {"selections", erp.selections},
          {"target_epochs", erp.targets},
          {"non_target_epochs", erp.others}};
}

namespace {

// "96 target, 283 non-target epochs from 8 selections".
std::string epochsText(const bci::ErpCurves& erp, const ClassNames& names) {
  return std::to_string(erp.targets) + " " + names.target + ", " + std::to_string(erp.others) +
         " " + names.other + " epochs" +
         (erp.selections > 0 ? " from " + std::to_string(erp.selections) + " selections" : "");
}

// Signed r^2 per channel (rows) and time (columns).
std::filesystem::path writeR2Figure(const std::filesystem::path& folder, const bci::ErpCurves& erp,
                                    const ClassNames& names) {
  const int channels = static_cast<int>(erp.channels.size()), samples = erp.samples();
  if (channels == 0 || samples < 2) return {};
  const int left = 80, top = 60, row_h = std::clamp(320 / channels, 6, 28), width = 720;
  cv::Mat image(top + channels * row_h + 70, left + width + 120, CV_8UC3, kWhite);
  text(image, "signed r^2, " + names.target + " vs " + names.other + ": " + epochsText(erp, names),
       {left, 24}, 0.5);
  text(image, analysisText(erp), {left, 44}, 0.4);
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
                                    const ClassNames& names, const bci::ScalpTime& when) {
  const std::optional<bci::ScalpMap> map = bci::scalpMapAt(erp, when);
  if (!map) return {};
  const int size = 360, margin = 50;
  const int header = 50;  // four lines of text above the head
  cv::Mat image(size + 2 * margin + 40 + header, size + 2 * margin + 90, CV_8UC3, kWhite);
  const cv::Point centre(margin + size / 2, margin + 30 + header + size / 2);
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
  text(image, names.target + " - " + names.other + " at " + format(map->time_s * 1000.0, 0) + " ms",
       {10, 22}, 0.5);
  text(image,
       when.at_s ? std::string("(as given)")
                 : "(the difference's peak over channels in " + format(when.from_s * 1000.0, 0) +
                       "-" + format(when.to_s * 1000.0, 0) + " ms)",
       {10, 42}, 0.4);
  text(image, "filter: " + erp.filterText(), {10, 62}, 0.35);
  text(image, analysisText(erp).substr(analysisText(erp).find("reference:")), {10, 82}, 0.35);
  colourBar(image, cv::Rect(size + 2 * margin + 10, margin + 40 + header, 16, size - 40),
            map->limit_uv, "uV", 1);
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
  const int panel_w = 300, panel_h = 190, left = 80, gap_x = 90, gap_y = 72, top = 100;
  cv::Mat image(top + rows * (panel_h + gap_y), left + columns * (panel_w + gap_x), CV_8UC3,
                kWhite);
  text(image,
       "ERP averages (mean +/- 1.96 SE over epochs, baseline " + format(erp.start_s * 1000.0, 0) +
           " to " + format((erp.start_s + erp.baseline_s) * 1000.0, 0) +
           " ms subtracted): " + epochsText(erp, names),
       {left, 26}, 0.5);
  text(image, analysisText(erp), {left, 46}, 0.45);
  // Legend.
  const std::pair<std::string, cv::Scalar> legend[] = {
      {names.target, kTarget}, {names.other, kOther}, {"difference", kBlack}};
  int x = left;
  for (const auto& [name, colour] : legend) {
    cv::line(image, {x, 68}, {x + 24, 68}, colour, 2, cv::LINE_AA);
    text(image, name, {x + 30, 72}, 0.45);
    x += 150;
  }
  cv::rectangle(image, cv::Rect(x, 61, 24, 14), kWindow, cv::FILLED);
  text(image,
       "the classifier's window, " + format(erp.window_start_s * 1000.0, 0) + "-" +
           format(erp.window_end_s * 1000.0, 0) + " ms",
       {x + 30, 72}, 0.45);

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
    panel.axes(image, erp.channels[static_cast<size_t>(c)], 100.0, niceStep(2.0 * limit, 4),
               "ms after the stimulus", "amplitude (uV)");
    cv::line(image, panel.map(0.0, -limit), panel.map(0.0, limit), kGrey, 1);  // the stimulus
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

nlohmann::json erpJson(const bci::ErpCurves& erp, const bci::ScalpTime& when) {
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
  nlohmann::json scalp = {{"time_ms", erp.timeS(bci::scalpSample(erp, when)) * 1000.0}};
  if (when.at_s)
    scalp["given_ms"] = *when.at_s * 1000.0;
  else
    scalp["search_ms"] = {when.from_s * 1000.0, when.to_s * 1000.0};
  nlohmann::json out = analysisJson(erp);
  out.update({{"units", "uV"},
              {"rate_hz", erp.rate_hz},
              {"peak_ms", erp.samples() > 0 ? erp.timeS(erp.peakSample()) * 1000.0 : 0.0},
              {"scalp_map", scalp},
              {"channels", channels}});
  return out;
}

std::vector<std::filesystem::path> writeP300Plots(const std::filesystem::path& folder,
                                                  const bci::P300Dataset& data,
                                                  const bci::EvaluationReport& report,
                                                  const std::string& title, const ClassNames& names,
                                                  const bci::ScalpTime& when) {
  std::error_code error;
  std::filesystem::create_directories(folder, error);
  if (error)
    throw CliError(folder.string() + ": cannot create the plot folder (" + error.message() + ")");
  std::vector<std::filesystem::path> written;

  const std::filesystem::path erp_png = writeErpFigure(folder, data.erp, names);
  if (!erp_png.empty()) {
    written.push_back(erp_png);
    for (const auto& extra :
         {writeR2Figure(folder, data.erp, names), writeScalpMap(folder, data.erp, names, when)})
      if (!extra.empty()) written.push_back(extra);
    written.push_back(folder / "erp.json");
    std::ofstream out(written.back());
    out << erpJson(data.erp, when).dump() << "\n";
    if (!out) throw CliError("cannot write " + written.back().string());
  }

  // Accuracy and bit rate against the number of sequences, where codes are choices.
  if (!report.selection_metrics || report.max_sequences < 1) return written;
  std::vector<double> n, percent;
  for (int k = 1; k <= report.max_sequences; ++k) {
    n.push_back(k);
    percent.push_back(100.0 * report.accuracy[static_cast<size_t>(k - 1)]);
  }
  cv::Mat image(380, 940, CV_8UC3, kWhite);
  text(image, "Selection accuracy and bit rate by number of sequences (" + title + ")", {50, 24},
       0.5);
  const double x1 = std::max(2.0, static_cast<double>(report.max_sequences));
  const double x_step = niceStep(x1 - 1.0, 10) < 1.0 ? 1.0 : niceStep(x1 - 1.0, 10);
  const Panel accuracy{{90, 70, 320, 230}, 1.0, x1, 0.0, 100.0};
  // How many selections the accuracy rests on: with a handful, the intervals are wide.
  accuracy.axes(
      image,
      "accuracy, " + std::to_string(report.selections_with_truth) + " selections (95 % intervals)",
      x_step, 20.0, "sequences", "accuracy (%)");
  // Guessing: the chance level, and the accuracy that beats it at p < 0.05 (dashed).
  cv::line(image, accuracy.map(1.0, 100.0 * report.chance), accuracy.map(x1, 100.0 * report.chance),
           kGrey, 1);
  text(image, "chance", accuracy.map(x1, 100.0 * report.chance) + cv::Point(-48, -4), 0.35, kGrey);
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
  const Panel bits{{540, 70, 320, 230}, 1.0, x1, 0.0, top};
  bits.axes(image, "bit rate (Wolpaw)", x_step, niceStep(top, 5), "sequences", "bits/min");
  bits.curve(image, n, report.bits_per_minute, kOther, true);
  // The legend: the flashes alone, and with the recording's cues and pauses where it has them.
  // Selections cut short count with the sequences they have: say where a point stands on fewer.
  const std::vector<int>& counted = report.selections_by_sequences;
  const auto fewer = std::find_if(counted.begin(), counted.end(),
                                  [&](int c) { return c < report.selections_with_truth; });
  if (fewer != counted.end()) {
    text(image,
         "from " + std::to_string(fewer - counted.begin() + 1) +
             " sequences: " + std::to_string(counted.back()) + " of " +
             std::to_string(report.selections_with_truth) + " selections at " +
             std::to_string(report.max_sequences) + " (others cut short)",
         {50, 360}, 0.38);
  }
  cv::line(image, {540, 356}, {564, 356}, kOther, 2, cv::LINE_AA);
  text(image, "flashes only", {570, 360}, 0.38);
  if (!report.bits_per_minute_with_pauses.empty()) {
    bits.curve(image, n, report.bits_per_minute_with_pauses, kBlack, true);
    cv::line(image, {670, 356}, {694, 356}, kBlack, 2, cv::LINE_AA);
    text(image, "+ " + format(report.pause_seconds_per_selection, 1) + " s cues and pauses",
         {700, 360}, 0.38);
  }
  written.push_back(folder / "accuracy.png");
  save(written.back(), image);
  return written;
}

}  // namespace arbci::app

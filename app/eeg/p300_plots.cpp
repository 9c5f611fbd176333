#include "eeg/p300_plots.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "support/cli_error.h"

namespace arbci::app {
namespace {

const cv::Scalar kBlack(0, 0, 0), kGrey(200, 200, 200), kTarget(40, 40, 220), kOther(180, 110, 30),
    kWhite(255, 255, 255);

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
    text(image, title, {area.x + 4, area.y + 14}, 0.45);
    text(image, format(y1, y_decimals), {area.x - 42, area.y + 10}, 0.35);
    text(image, format(y0, y_decimals), {area.x - 42, area.y + area.height}, 0.35);
    text(image, format(x0, x_decimals), {area.x - 4, area.y + area.height + 14}, 0.35);
    text(image, format(x1, x_decimals), {area.x + area.width - 20, area.y + area.height + 14},
         0.35);
  }
  void curve(cv::Mat& image, const std::vector<double>& xs, const std::vector<double>& ys,
             const cv::Scalar& colour, bool dots = false) const {
    std::vector<cv::Point> points;
    for (size_t i = 0; i < xs.size(); ++i) points.push_back(map(xs[i], ys[i]));
    cv::polylines(image, points, false, colour, 2, cv::LINE_AA);
    if (dots) {
      for (const cv::Point& p : points) cv::circle(image, p, 3, colour, cv::FILLED, cv::LINE_AA);
    }
  }
};

void save(const std::filesystem::path& path, const cv::Mat& image) {
  if (!cv::imwrite(path.string(), image)) throw CliError("cannot write " + path.string());
}

}  // namespace

std::vector<std::filesystem::path> writeP300Plots(const std::filesystem::path& folder,
                                                  const bci::P300Dataset& data,
                                                  const bci::EvaluationReport& report,
                                                  const std::string& title) {
  std::error_code error;
  std::filesystem::create_directories(folder, error);
  if (error)
    throw CliError(folder.string() + ": cannot create the plot folder (" + error.message() + ")");
  std::vector<std::filesystem::path> written;

  // ERPs: one panel per channel, target red, non-target blue, microvolts against milliseconds.
  const int channels = static_cast<int>(data.erp_target.rows());
  const int samples = static_cast<int>(data.erp_target.cols());
  if (channels > 0 && samples > 1) {
    const int columns = std::min(4, channels), rows = (channels + columns - 1) / columns;
    const int panel_w = 260, panel_h = 170, margin = 50;
    cv::Mat image(rows * (panel_h + margin) + 60, columns * (panel_w + margin) + margin, CV_8UC3,
                  kWhite);
    // The ERPs are plain averages of every epoch; `title` names the accuracy figure's source.
    text(image, "ERP averages of all epochs: target (red) vs non-target (blue), uV against ms",
         {margin, 28}, 0.5);
    const double limit = std::max(
        {1.0, data.erp_target.cwiseAbs().maxCoeff(), data.erp_other.cwiseAbs().maxCoeff()});
    std::vector<double> ms(static_cast<size_t>(samples));
    for (int s = 0; s < samples; ++s)
      ms[static_cast<size_t>(s)] = (data.erp_start_s + s / data.info.rate_hz) * 1000.0;
    for (int c = 0; c < channels; ++c) {
      const Panel panel{{margin + (c % columns) * (panel_w + margin),
                         50 + (c / columns) * (panel_h + margin), panel_w, panel_h},
                        ms.front(),
                        ms.back(),
                        -limit,
                        limit};
      panel.axes(image, data.info.channels[static_cast<size_t>(c)], 0, 1);
      // A row of a column-major matrix is strided: read it element by element.
      const auto target_row = data.erp_target.row(c), other_row = data.erp_other.row(c);
      std::vector<double> t(target_row.begin(), target_row.end());
      std::vector<double> o(other_row.begin(), other_row.end());
      panel.curve(image, ms, o, kOther);
      panel.curve(image, ms, t, kTarget);
    }
    written.push_back(folder / "erp.png");
    save(written.back(), image);
  }

  // Accuracy and bit rate against the number of sequences.
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
  accuracy.axes(image, "accuracy %", 0, 0);
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

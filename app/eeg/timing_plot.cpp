#include "eeg/timing_plot.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <opencv2/imgproc.hpp>

#include "support/png.h"

namespace arbci::app {

void writeTimingHistogram(const std::filesystem::path& path, const bci::PhotodiodeReport& report) {
  const int width = 800, height = 500;
  const int left = 80, right = 30, top = 60, bottom = 70;
  cv::Mat image(height, width, CV_8UC3, cv::Scalar(255, 255, 255));
  const double bin = 1000.0 / report.rate_hz;  // one sample period
  // Bins centred on whole samples, from two below the least offset to two above the largest.
  const int first = static_cast<int>(std::floor(report.min_ms / bin + 0.5)) - 2;
  const int last = static_cast<int>(std::floor(report.max_ms / bin + 0.5)) + 2;
  const int bins = std::max(1, last - first + 1);
  std::vector<int> counts(static_cast<size_t>(bins), 0);
  for (double o : report.offsets_ms) {
    const int k = static_cast<int>(std::floor(o / bin + 0.5)) - first;
    if (k >= 0 && k < bins) ++counts[static_cast<size_t>(k)];
  }
  const int most = std::max(1, *std::max_element(counts.begin(), counts.end()));
  const int plot_w = width - left - right, plot_h = height - top - bottom;
  const double bar_w = static_cast<double>(plot_w) / bins;
  const cv::Scalar black(0, 0, 0), grey(200, 200, 200), bar(180, 110, 40);
  const auto font = cv::FONT_HERSHEY_SIMPLEX;
  // Count axis with gridlines.
  for (int i = 0; i <= 4; ++i) {
    const int value = static_cast<int>(std::lround(most * i / 4.0));
    const int y = top + plot_h - static_cast<int>(std::lround(plot_h * value / double(most)));
    cv::line(image, {left, y}, {left + plot_w, y}, grey, 1);
    cv::putText(image, std::to_string(value), {left - 50, y + 5}, font, 0.45, black, 1,
                cv::LINE_AA);
  }
  for (int k = 0; k < bins; ++k) {
    const int x0 = left + static_cast<int>(std::lround(k * bar_w)) + 2;
    const int x1 = left + static_cast<int>(std::lround((k + 1) * bar_w)) - 2;
    const int h = static_cast<int>(
        std::lround(plot_h * counts[static_cast<size_t>(k)] / static_cast<double>(most)));
    if (h > 0) cv::rectangle(image, {x0, top + plot_h - h}, {x1, top + plot_h}, bar, cv::FILLED);
    char label[32];
    std::snprintf(label, sizeof label, "%.1f", (first + k) * bin);
    const int step = std::max(1, bins / 12);
    if (k % step == 0)
      cv::putText(image, label, {(x0 + x1) / 2 - 14, top + plot_h + 20}, font, 0.42, black, 1,
                  cv::LINE_AA);
  }
  cv::line(image, {left, top + plot_h}, {left + plot_w, top + plot_h}, black, 1);
  cv::line(image, {left, top}, {left, top + plot_h}, black, 1);
  // Zero offset.
  const double zero_x = left + (0.0 - (first - 0.5)) * bar_w;
  cv::line(image, {static_cast<int>(zero_x), top}, {static_cast<int>(zero_x), top + plot_h},
           cv::Scalar(40, 40, 200), 1);
  char title[200];
  std::snprintf(title, sizeof title,
                "photodiode edge - recorded onset: mean %.2f ms, SD %.2f ms, n = %d of %d flashes",
                report.mean_ms, report.sd_ms, report.count, report.flashes);
  cv::putText(image, title, {left - 40, 30}, font, 0.5, black, 1, cv::LINE_AA);
  cv::putText(image,
              "offset (ms; one bar per EEG sample, " + std::to_string(bin).substr(0, 4) + " ms)",
              {left + plot_w / 2 - 170, height - 20}, font, 0.5, black, 1, cv::LINE_AA);
  cv::putText(image, "flashes", {8, top - 12}, font, 0.5, black, 1, cv::LINE_AA);
  writePng(path, image);
}

}  // namespace arbci::app

#include "hmd/rest_screen.h"

#include <opencv2/imgproc.hpp>

namespace arbci::app {

std::string restText(bci::Phase phase) {
  switch (phase) {
    case bci::Phase::Paused:
      return "Paused: rest your eyes. It goes on shortly.";
    case bci::Phase::Training:
      return "Well done. Rest while the computer learns.";
    default:
      return "";
  }
}

const cv::Mat& RestScreen::image(cv::Size size, const std::string& text) {
  if (!image_.empty() && image_.size() == size && text == text_) return image_;
  text_ = text;
  image_ = cv::Mat(size, CV_8UC3, cv::Scalar(40, 40, 40));
  // Large enough to read in an HMD, centred in the eye's image.
  const double scale = size.width / 640.0;
  const int thickness = std::max(1, static_cast<int>(2 * scale));
  int baseline = 0;
  const cv::Size extent =
      cv::getTextSize(text, cv::FONT_HERSHEY_SIMPLEX, 0.8 * scale, thickness, &baseline);
  const cv::Point at((size.width - extent.width) / 2, (size.height + extent.height) / 2);
  cv::putText(image_, text, at, cv::FONT_HERSHEY_SIMPLEX, 0.8 * scale, cv::Scalar(230, 230, 230),
              thickness, cv::LINE_AA);
  return image_;
}

}  // namespace arbci::app

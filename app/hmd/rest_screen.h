// What the subject sees while nothing is asked of them: during a pause and while the calibration
// is trained and reviewed, each eye shows a dark screen with a line of instruction instead of the
// scene, so that nobody stares at flashes that stopped or wonders whether to keep counting.
#pragma once

#include <optional>
#include <string>

#include <opencv2/core/mat.hpp>

#include "arbci/bci/paradigm.h"

namespace arbci::app {

// The instruction for `phase` ("" when the scene is shown).
std::string restText(bci::Phase phase);

class RestScreen {
 public:
  // The rest screen at `size` with `text`, made once per size and text.
  const cv::Mat& image(cv::Size size, const std::string& text);

 private:
  cv::Mat image_;
  std::string text_;
};

}  // namespace arbci::app

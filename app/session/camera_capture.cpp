#include "session/camera_capture.h"

#include <chrono>
#include <stdexcept>

namespace arbci::app {

CameraCapture::CameraCapture(int device, const std::string& video, const std::string& what)
    : file_(device < 0) {
  const bool opened = device >= 0 ? capture_.open(device, cv::CAP_V4L2) : capture_.open(video);
  if (!opened)
    throw std::runtime_error(what + ": cannot open " +
                             (device >= 0 ? "/dev/video" + std::to_string(device) : video));
  const double fps = capture_.get(cv::CAP_PROP_FPS);
  const auto interval = std::chrono::duration<double>(file_ && fps > 0 ? 1.0 / fps : 0.0);
  thread_ = std::thread([this, interval] {
    auto next = std::chrono::steady_clock::now();
    while (!stop_) {
      cv::Mat frame;
      if (!capture_.read(frame) || frame.empty()) {
        finished_ = true;
        break;
      }
      {
        std::lock_guard lock(mutex_);
        frame_ = frame;
        ++count_;
      }
      if (file_) {  // a video file plays at its own rate
        next += std::chrono::duration_cast<std::chrono::steady_clock::duration>(interval);
        std::this_thread::sleep_until(next);
      }
    }
  });
}

CameraCapture::~CameraCapture() {
  stop_ = true;
  if (thread_.joinable()) thread_.join();
}

std::pair<cv::Mat, std::uint64_t> CameraCapture::latest() const {
  std::lock_guard lock(mutex_);
  return {frame_, count_};
}

}  // namespace arbci::app

#include "arbci/session/camera_capture.h"

#include <chrono>
#include <stdexcept>

namespace arbci::session {

CameraCapture::CameraCapture(int device, const std::string& video, const std::string& what) {
  try {
    source_ = device >= 0 ? vision::camera(device, 0) : vision::videoFile(video, 0);
  } catch (const std::exception& error) {
    throw std::runtime_error(what + ": " + error.what());
  }
  const double fps = source_->fileRateHz();
  const auto interval = std::chrono::duration<double>(fps > 0 ? 1.0 / fps : 0.0);
  thread_ = std::thread([this, interval, fps] {
    auto next = std::chrono::steady_clock::now();
    while (!stop_) {
      std::optional<vision::Frame> frame = source_->next();
      if (!frame) {
        finished_ = true;
        break;
      }
      {
        std::lock_guard lock(mutex_);
        frame_ = frame->image;
        ++count_;
      }
      if (fps > 0) {  // a video file plays at its own rate
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

}  // namespace arbci::session

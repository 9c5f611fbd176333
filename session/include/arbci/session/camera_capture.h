// A real camera (V4L2 device or video file, opened by support/frame_source, the one reader) read
// on its own thread, so the cycle never waits for a frame: latest() returns the newest frame at
// once. A video file plays at its own frame rate.
#pragma once

#include <atomic>
#include <mutex>
#include <string>
#include <thread>

#include <memory>
#include <opencv2/core/mat.hpp>

#include "arbci/vision/frame_source.h"

namespace arbci::session {

class CameraCapture {
 public:
  // `device` >= 0 opens /dev/video<device>; otherwise `video`. Throws std::runtime_error naming
  // what could not be opened.
  CameraCapture(int device, const std::string& video, const std::string& what);
  ~CameraCapture();
  CameraCapture(const CameraCapture&) = delete;
  CameraCapture& operator=(const CameraCapture&) = delete;

  // The newest frame and its number (0: none yet).
  std::pair<cv::Mat, std::uint64_t> latest() const;
  bool finished() const { return finished_; }

 private:
  std::unique_ptr<vision::FrameSource> source_;
  mutable std::mutex mutex_;
  cv::Mat frame_;
  std::uint64_t count_ = 0;
  std::atomic<bool> stop_{false}, finished_{false};
  std::thread thread_;
};

}  // namespace arbci::session

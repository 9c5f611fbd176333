// Writes images (PNG) on a background thread, so encoding a screenshot never costs the cycle.
#pragma once

#include <condition_variable>
#include <deque>
#include <filesystem>
#include <mutex>
#include <thread>
#include <utility>

#include <opencv2/core/mat.hpp>

namespace arbci::app {

class ImageWriter {
 public:
  ImageWriter();
  ~ImageWriter();  // writes what is queued, then stops
  ImageWriter(const ImageWriter&) = delete;
  ImageWriter& operator=(const ImageWriter&) = delete;

  void write(const std::filesystem::path& path, cv::Mat image);
  void flush();  // waits until everything queued is on disk

 private:
  std::mutex mutex_;
  std::condition_variable wake_, idle_;
  std::deque<std::pair<std::filesystem::path, cv::Mat>> queue_;
  bool busy_ = false, stop_ = false;
  std::thread thread_;
};

}  // namespace arbci::app

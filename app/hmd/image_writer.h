// Writes images (PNG) on a background thread, so encoding a screenshot never costs the cycle.
// A write that fails is counted and its reason kept, never thrown on that thread.
#pragma once

#include <condition_variable>
#include <deque>
#include <filesystem>
#include <mutex>
#include <optional>
#include <string>
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
  // Images written, images that could not be (a full disk, an I/O error), and why the last
  // failed ("" if none did).
  int written() const;
  int failed() const;
  std::optional<std::string> failure() const;

 private:
  mutable std::mutex mutex_;
  int written_ = 0, failed_ = 0;
  std::optional<std::string> failure_;
  std::condition_variable wake_, idle_;
  std::deque<std::pair<std::filesystem::path, cv::Mat>> queue_;
  bool busy_ = false, stop_ = false;
  std::thread thread_;
};

}  // namespace arbci::app

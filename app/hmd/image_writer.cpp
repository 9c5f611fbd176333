#include "hmd/image_writer.h"

#include <sys/resource.h>
#include <unistd.h>

#include <vector>

#include <opencv2/imgcodecs.hpp>

#include "arbci/core/whole_file.h"

namespace arbci::app {
namespace {

// "" when the image is on disk; else why not, with the system's reason (a full disk). Written
// whole or not at all: no half image is left to be taken for a whole one.
std::string encodeAndWrite(const std::filesystem::path& path, const cv::Mat& image) {
  std::vector<std::uint8_t> bytes;
  try {
    if (!cv::imencode(path.extension().string(), image, bytes)) return "cannot encode";
  } catch (const cv::Exception& error) {
    return std::string("cannot encode: ") + error.what();
  }
  return core::writeWholeFile(path, std::string(bytes.begin(), bytes.end()));
}

}  // namespace

ImageWriter::ImageWriter() {
  thread_ = std::thread([this] {
    // PNG encoding must not take the cores from the cycle: the lowest priority (Linux applies a
    // nice value to one thread). Nothing is lost: flush() waits for every image.
    setpriority(PRIO_PROCESS, static_cast<id_t>(gettid()), 19);
    std::unique_lock lock(mutex_);
    while (true) {
      wake_.wait(lock, [&] { return stop_ || !queue_.empty(); });
      if (queue_.empty() && stop_) break;
      auto [path, image] = std::move(queue_.front());
      queue_.pop_front();
      busy_ = true;
      lock.unlock();
      const std::string why = encodeAndWrite(path, image);
      lock.lock();
      if (why.empty()) {
        ++written_;
      } else {
        ++failed_;
        failure_ = why;
      }
      busy_ = false;
      idle_.notify_all();
    }
  });
}

ImageWriter::~ImageWriter() {
  {
    std::lock_guard lock(mutex_);
    stop_ = true;
  }
  wake_.notify_all();
  thread_.join();
}

void ImageWriter::write(const std::filesystem::path& path, cv::Mat image) {
  {
    std::lock_guard lock(mutex_);
    queue_.emplace_back(path, std::move(image));
  }
  wake_.notify_one();
}

int ImageWriter::written() const {
  std::lock_guard lock(mutex_);
  return written_;
}

int ImageWriter::failed() const {
  std::lock_guard lock(mutex_);
  return failed_;
}

std::optional<std::string> ImageWriter::failure() const {
  std::lock_guard lock(mutex_);
  return failure_;
}

void ImageWriter::flush() {
  std::unique_lock lock(mutex_);
  idle_.wait(lock, [&] { return queue_.empty() && !busy_; });
}

}  // namespace arbci::app

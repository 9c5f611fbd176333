#include "hmd/image_writer.h"

#include <fcntl.h>
#include <sys/resource.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <vector>

#include <opencv2/imgcodecs.hpp>

namespace arbci::app {
namespace {

// "" when the image is on disk; else why not, with the system's reason (a full disk).
std::string encodeAndWrite(const std::filesystem::path& path, const cv::Mat& image) {
  std::vector<std::uint8_t> bytes;
  try {
    if (!cv::imencode(path.extension().string(), image, bytes)) return "cannot encode";
  } catch (const cv::Exception& error) {
    return std::string("cannot encode: ") + error.what();
  }
  const int fd = ::open(path.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (fd < 0) return "cannot create " + path.string() + ": " + std::strerror(errno);
  size_t done = 0;
  std::string why;
  while (done < bytes.size() && why.empty()) {
    const ssize_t n = ::write(fd, bytes.data() + done, bytes.size() - done);
    if (n < 0 && errno != EINTR)
      why = "cannot write " + path.string() + ": " + std::strerror(errno);
    if (n > 0) done += static_cast<size_t>(n);
  }
  if (::close(fd) != 0 && why.empty())
    why = "cannot write " + path.string() + ": " + std::strerror(errno);
  if (!why.empty()) ::unlink(path.c_str());  // no half image left to be taken for a whole one
  return why;
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

#include "hmd/image_writer.h"

#include <sys/resource.h>
#include <unistd.h>

#include <opencv2/imgcodecs.hpp>

namespace arbci::app {

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
      cv::imwrite(path.string(), image);
      lock.lock();
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

void ImageWriter::flush() {
  std::unique_lock lock(mutex_);
  idle_.wait(lock, [&] { return queue_.empty() && !busy_; });
}

}  // namespace arbci::app

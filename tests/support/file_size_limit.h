// A file-size limit for this process while in scope: writes past it fail as on a full disk (EFBIG
// rather than ENOSPC; SIGXFSZ is ignored meanwhile so that the write returns the error).
#pragma once

#include <sys/resource.h>

#include <csignal>
#include <stdexcept>

namespace arbci::test {

class FileSizeLimit {
 public:
  explicit FileSizeLimit(rlim_t bytes) {
    if (::getrlimit(RLIMIT_FSIZE, &old_) != 0) throw std::runtime_error("getrlimit failed");
    handler_ = std::signal(SIGXFSZ, SIG_IGN);
    rlimit small = old_;
    small.rlim_cur = bytes;
    if (::setrlimit(RLIMIT_FSIZE, &small) != 0) throw std::runtime_error("setrlimit failed");
  }
  ~FileSizeLimit() { lift(); }
  FileSizeLimit(const FileSizeLimit&) = delete;
  FileSizeLimit& operator=(const FileSizeLimit&) = delete;
  void lift() {
    if (lifted_) return;
    ::setrlimit(RLIMIT_FSIZE, &old_);
    std::signal(SIGXFSZ, handler_);
    lifted_ = true;
  }

 private:
  rlimit old_{};
  void (*handler_)(int) = nullptr;
  bool lifted_ = false;
};

}  // namespace arbci::test

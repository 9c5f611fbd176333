#include "arbci/session/session_log.h"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <stdexcept>

namespace arbci::session {

SessionLog::SessionLog(const std::filesystem::path& path)
    : path_(path), fd_(::open(path.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644)) {
  if (fd_ < 0)
    throw std::runtime_error(path.string() + ": cannot write the session log (" +
                             std::strerror(errno) + ")");
}

SessionLog::~SessionLog() {
  if (fd_ >= 0) ::close(fd_);
}

bool SessionLog::writeAll(const std::string& line) {
  size_t done = 0;
  while (done < line.size()) {
    const ssize_t n = ::write(fd_, line.data() + done, line.size() - done);
    if (n > 0) {
      done += static_cast<size_t>(n);
      continue;
    }
    if (n < 0 && errno == EINTR) continue;
    const int error = n < 0 ? errno : ENOSPC;
    // A reader of JSON lines must never meet half a line: what was written of it goes.
    if (::ftruncate(fd_, good_size_) == 0) ::lseek(fd_, good_size_, SEEK_SET);
    errno = error;
    return false;
  }
  good_size_ += static_cast<long long>(line.size());
  return true;
}

void SessionLog::write(const std::string& event, double t, nlohmann::json fields) {
  fields["event"] = event;
  fields["t"] = t;
  const std::string line = fields.dump() + '\n';
  if (!failing_) {
    if (writeAll(line)) return;
    failing_ = true;
    news_ = path_.filename().string() + ": cannot write (" + std::strerror(errno) +
            "): its lines are lost until there is room; the recording and the summary are "
            "written apart";
  } else {
    // Room again? The gap and the line together, or neither: a gap said for a line that then
    // does not fit would be said again.
    const nlohmann::json gap = {{"event", "log_lines_lost"}, {"t", t}, {"lines", lost_now_}};
    if (writeAll(gap.dump() + '\n' + line)) {
      failing_ = false;
      news_ = path_.filename().string() + ": writing again; " + std::to_string(lost_now_) +
              " line" + (lost_now_ == 1 ? " was" : "s were") + " lost";
      lost_now_ = 0;
      return;
    }
  }
  ++lost_now_;
  ++lost_total_;
}

std::string SessionLog::news() {
  std::string out;
  out.swap(news_);
  return out;
}

}  // namespace arbci::session

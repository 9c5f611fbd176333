#include "support/status_line.h"

#include <atomic>

namespace arbci::app {
namespace {
std::atomic<bool> open_line{false};
}  // namespace

void setStatusLineOpen(bool open) {
  open_line = open;
}

bool statusLineOpen() {
  return open_line;
}

}  // namespace arbci::app

#include "support/interrupt.h"

#include <atomic>
#include <csignal>

namespace arbci::app {
namespace {

std::atomic<bool> requested{false};

void onSignal(int) {
  requested = true;
}

}  // namespace

void watchInterrupts() {
  std::signal(SIGINT, onSignal);
  std::signal(SIGTERM, onSignal);
}

bool interruptRequested() {
  return requested.load();
}

}  // namespace arbci::app

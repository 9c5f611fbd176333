// Raising the calling thread's scheduling priority as far as this process may: what the client's
// heartbeat and the backend's loop ask for, so that a busy machine does not starve the watchdog's
// two ends.
#pragma once

#include <string>

namespace arbci::robot {

// Real-time FIFO at the highest priority where permitted, else the lowest nice value allowed,
// else none. Returns what the thread got ("real-time (FIFO 99)", "nice -20", "normal (...)").
std::string raiseThreadPriority();

}  // namespace arbci::robot

#include "arbci/robot/thread_priority.h"

#include <pthread.h>
#include <sched.h>
#include <sys/resource.h>
#include <unistd.h>

namespace arbci::robot {

std::string raiseThreadPriority() {
  sched_param param{};
  param.sched_priority = sched_get_priority_max(SCHED_FIFO);
  if (pthread_setschedparam(pthread_self(), SCHED_FIFO, &param) == 0)
    return "real-time (FIFO " + std::to_string(param.sched_priority) + ")";
  rlimit limit{};
  int lowest = 0;
  if (getrlimit(RLIMIT_NICE, &limit) == 0 && limit.rlim_cur != RLIM_INFINITY)
    lowest = 20 - static_cast<int>(limit.rlim_cur);  // RLIMIT_NICE is 20 - the lowest nice
  for (int nice = -20; nice < 0; ++nice) {
    if (nice < lowest) continue;
    if (setpriority(PRIO_PROCESS, static_cast<id_t>(gettid()), nice) == 0)
      return "nice " + std::to_string(nice);
  }
  return "normal (the process may not raise a thread's priority)";
}

}  // namespace arbci::robot

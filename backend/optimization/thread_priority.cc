#include "backend/optimization/thread_priority.h"

#include <cerrno>
#include <cstring>

#ifdef __linux__
#include <sched.h>
#include <sys/resource.h>
#include <sys/syscall.h>
#include <unistd.h>
#endif

namespace pldvo {

std::string SetCurrentThreadPriority(ThreadPriority priority) {
  if (priority == ThreadPriority::kNormal) return "";
#ifdef __linux__
  // With a thread id, both calls change that thread only (setpriority(2), sched(7)).
  const auto thread_id = static_cast<pid_t>(syscall(SYS_gettid));
  if (priority == ThreadPriority::kLow) {
    if (setpriority(PRIO_PROCESS, static_cast<id_t>(thread_id), 19) != 0) {
      return std::string("setpriority: ") + std::strerror(errno);
    }
    return "";
  }
  sched_param param{};
  param.sched_priority = 0;
  if (sched_setscheduler(thread_id, SCHED_IDLE, &param) != 0) {
    return std::string("sched_setscheduler(SCHED_IDLE): ") + std::strerror(errno);
  }
  return "";
#else
  return "thread priorities need Linux";
#endif
}

}  // namespace pldvo

// The scheduling priority of a background solver's thread (the windowed BA's worker), so that it
// takes the cores only when tracking and mapping leave them (docs/windowed_ba.md, "In the
// odometry").
#ifndef PLDVO_BACKEND_OPTIMIZATION_THREAD_PRIORITY_H_
#define PLDVO_BACKEND_OPTIMIZATION_THREAD_PRIORITY_H_

#include <string>

#include "core/options.h"

namespace pldvo {

enum class ThreadPriority {
  kNormal,  // as the thread that started it
  kLow,     // nice 19: the smallest share of a contended core among normal threads
  kIdle,    // SCHED_IDLE: runs only on a core no normal thread wants
};
inline const ChoiceNames<ThreadPriority>& ThreadPriorityNames() {
  static const ChoiceNames<ThreadPriority> names = {{"normal", ThreadPriority::kNormal},
                                                    {"low", ThreadPriority::kLow},
                                                    {"idle", ThreadPriority::kIdle}};
  return names;
}

// Sets the calling thread's priority (Linux keeps nice values and policies per thread; lowering
// them needs no privilege). Returns "" on success, else what failed (also on a platform without
// per-thread priorities, for anything but kNormal).
std::string SetCurrentThreadPriority(ThreadPriority priority);

}  // namespace pldvo

#endif  // PLDVO_BACKEND_OPTIMIZATION_THREAD_PRIORITY_H_

// SetCurrentThreadPriority and the windowed BA's worker_priority: the calling thread's nice value
// or policy changes, the others' (tracking's) do not.
#include "backend/optimization/thread_priority.h"

#include <dirent.h>
#include <gtest/gtest.h>
#include <sched.h>
#include <sys/resource.h>
#include <sys/syscall.h>
#include <unistd.h>

#include <chrono>
#include <fstream>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "backend/windowed_ba/windowed_ba_adjuster.h"

namespace pldvo {
namespace {

struct Scheduling {
  int nice = 0;
  int policy = 0;
};

Scheduling CurrentThreadScheduling() {
  const auto thread_id = static_cast<pid_t>(syscall(SYS_gettid));
  return {getpriority(PRIO_PROCESS, static_cast<id_t>(thread_id)), sched_getscheduler(thread_id)};
}

Scheduling OnNewThread(ThreadPriority priority, std::string* error) {
  Scheduling scheduling;
  std::thread thread([&] {
    *error = SetCurrentThreadPriority(priority);
    scheduling = CurrentThreadScheduling();
  });
  thread.join();
  return scheduling;
}

// Every thread of this process, from /proc/self/task/*/stat (fields 19 and 41).
std::vector<Scheduling> ProcessThreads() {
  std::vector<Scheduling> threads;
  DIR* tasks = opendir("/proc/self/task");
  if (tasks == nullptr) return threads;
  while (const dirent* entry = readdir(tasks)) {
    if (entry->d_name[0] == '.') continue;
    std::ifstream stat(std::string("/proc/self/task/") + entry->d_name + "/stat");
    std::string line;
    if (!std::getline(stat, line)) continue;
    // The command name (field 2) is in parentheses and may hold spaces: count from its end.
    std::istringstream fields(line.substr(line.rfind(')') + 2));
    std::string field;
    Scheduling scheduling;
    for (int i = 3; i <= 41 && fields >> field; ++i) {
      if (i == 19) scheduling.nice = std::stoi(field);
      if (i == 41) scheduling.policy = std::stoi(field);
    }
    threads.push_back(scheduling);
  }
  closedir(tasks);
  return threads;
}

TEST(ThreadPriorityTest, ChangesTheCallingThreadOnly) {
  const Scheduling before = CurrentThreadScheduling();
  ASSERT_EQ(before.policy, SCHED_OTHER);
  ASSERT_LT(before.nice, 19);
  std::string error = "not run";
  const Scheduling low = OnNewThread(ThreadPriority::kLow, &error);
  EXPECT_EQ(error, "");
  EXPECT_EQ(low.nice, 19);
  EXPECT_EQ(low.policy, SCHED_OTHER);
  const Scheduling idle = OnNewThread(ThreadPriority::kIdle, &error);
  EXPECT_EQ(error, "");
  EXPECT_EQ(idle.policy, SCHED_IDLE);
  const Scheduling normal = OnNewThread(ThreadPriority::kNormal, &error);
  EXPECT_EQ(error, "");
  EXPECT_EQ(normal.nice, before.nice);
  EXPECT_EQ(normal.policy, SCHED_OTHER);
  const Scheduling after = CurrentThreadScheduling();
  EXPECT_EQ(after.nice, before.nice);
  EXPECT_EQ(after.policy, before.policy);
}

// The adjuster's worker sets its priority when it starts: wait for it (at most 5 s).
int ThreadsMatching(bool (*matches)(const Scheduling&)) {
  int count = 0;
  for (int attempt = 0; attempt < 500 && count == 0; ++attempt) {
    for (const Scheduling& thread : ProcessThreads()) count += matches(thread);
    if (count == 0) std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  return count;
}

TEST(ThreadPriorityTest, WindowedBAWorkerRunsAtWorkerPriority) {
  const Scheduling tracking = CurrentThreadScheduling();
  ASSERT_EQ(tracking.policy, SCHED_OTHER);
  {
    WindowedBAOptions options;
    EXPECT_EQ(options.worker_priority, ThreadPriority::kIdle);
    WindowedBundleAdjuster adjuster(options);
    EXPECT_EQ(ThreadsMatching([](const Scheduling& s) { return s.policy == SCHED_IDLE; }), 1);
  }
  {
    WindowedBAOptions options;
    options.worker_priority = ThreadPriority::kLow;
    WindowedBundleAdjuster adjuster(options);
    EXPECT_EQ(ThreadsMatching([](const Scheduling& s) { return s.nice == 19; }), 1);
  }
  const Scheduling after = CurrentThreadScheduling();
  EXPECT_EQ(after.nice, tracking.nice);
  EXPECT_EQ(after.policy, tracking.policy);
}

}  // namespace
}  // namespace pldvo

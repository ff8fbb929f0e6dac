// Wall-clock timing for the per-component timing reports (docs/odometry.md, Table III).
#ifndef PLDVO_CORE_WALL_CLOCK_H_
#define PLDVO_CORE_WALL_CLOCK_H_

#include <chrono>

namespace pldvo {

using WallClock = std::chrono::steady_clock;

// Milliseconds elapsed since `start`.
inline double MsSince(WallClock::time_point start) {
  return std::chrono::duration<double, std::milli>(WallClock::now() - start).count();
}

}  // namespace pldvo

#endif  // PLDVO_CORE_WALL_CLOCK_H_

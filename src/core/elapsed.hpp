#pragma once
// Wall time since a steady-clock instant, in milliseconds: the one definition the stage timings share.
#include <chrono>

namespace varslam {

inline double ms_since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
}

}  // namespace varslam

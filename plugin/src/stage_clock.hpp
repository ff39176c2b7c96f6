// SPDX-License-Identifier: MIT
// Internal: a scope timer for the simulation's stage timing (simulation.hpp, StageTimes). It adds
// the wall-clock seconds of its scope to a counter; with a null counter it reads no clock at all,
// so timing that is switched off costs one pointer test.
#pragma once

#include <chrono>

namespace rheofeed {

class StageClock {
 public:
  /// Adds the seconds from now to the end of the scope to `*seconds`; nullptr: does nothing.
  explicit StageClock(double* seconds) : seconds_(seconds) {
    if (seconds_) start_ = std::chrono::steady_clock::now();
  }
  ~StageClock() {
    if (seconds_) {
      *seconds_ += std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
    }
  }
  StageClock(const StageClock&) = delete;
  StageClock& operator=(const StageClock&) = delete;

 private:
  double* seconds_;
  std::chrono::steady_clock::time_point start_;
};

}  // namespace rheofeed

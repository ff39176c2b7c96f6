// SPDX-License-Identifier: MIT
#include "study/bowl_phases.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace rheofeed::demo {

const char* toString(BowlPhase phase) {
  switch (phase) {
    case BowlPhase::Floor:
      return "floor";
    case BowlPhase::Ramp:
      return "ramp";
    case BowlPhase::Other:
      return "other";
  }
  return "?";
}

BowlPhase bowlPhase(const Vec3& p) {
  const double r = std::hypot(p.x, p.y);
  double azimuth = std::atan2(p.y, p.x);
  if (azimuth < 0) azimuth += 2 * kPi;
  const double first_turn_top = kBowlFloorTop + kBowlRampPitch * azimuth / (2 * kPi);
  if (r >= kBowlRampRadius && p.z > first_turn_top + kBowlRampMargin) return BowlPhase::Ramp;
  return p.z < kBowlFloorHeight ? BowlPhase::Floor : BowlPhase::Other;
}

void BowlPhaseObserver::onStep(const scene::Simulation& sim, long, bool sample) {
  if (!sample) return;
  const double t = sim.time();
  const int n = sim.numParts();
  if (static_cast<int>(parts_.size()) < n) parts_.resize(static_cast<std::size_t>(n));
  for (int i = 0; i < n; ++i) {
    const scene::PartState s = sim.part(i);
    Part& p = parts_[static_cast<std::size_t>(i)];
    if (!s.active) {
      p.seen = false;
      p.window_turn = p.window_seconds = 0;
      continue;
    }
    const BowlPhase phase = bowlPhase(s.position);
    double angle = std::atan2(s.position.y, s.position.x);
    if (p.seen) {  // unwrap against the last sample (a part turns far less than pi per sample)
      angle += 2 * kPi * std::round((p.angle - angle) / (2 * kPi));
      if (phase == p.phase && p.time >= warmup_) {
        const auto k = static_cast<std::size_t>(phase);
        p.turn[k] += angle - p.angle;
        p.seconds[k] += t - p.time;
        p.window_turn += angle - p.angle;
        p.window_seconds += t - p.time;
        if (p.window_seconds >= kStallWindow - 1e-9) {
          Windows& w = windows_[k];
          if (p.window_turn < kStallDrift * p.window_seconds) {
            ++w.stalled;
          } else {
            ++w.moving;
            w.moving_turn += p.window_turn;
            w.moving_seconds += p.window_seconds;
          }
          p.window_turn = p.window_seconds = 0;
        }
      } else {  // a window lies in one phase
        p.window_turn = p.window_seconds = 0;
      }
    }
    p.seen = true;
    p.time = t;
    p.angle = angle;
    p.phase = phase;
    if (keep_trace_) {
      char line[160];
      std::snprintf(line, sizeof line, "%.4f,%d,%.6f,%.6f,%.6f,%s\n", t, i, s.position.x,
                    s.position.y, s.position.z, toString(phase));
      trace_ += line;
    }
  }
}

PhaseDrift BowlPhaseObserver::drift(BowlPhase phase) const {
  const auto k = static_cast<std::size_t>(phase);
  PhaseDrift d;
  double turn = 0, sum = 0, sum2 = 0;
  for (const Part& p : parts_) {
    turn += p.turn[k];
    d.part_seconds += p.seconds[k];
    if (p.seconds[k] >= 1.0) {
      const double w = p.turn[k] / p.seconds[k];
      sum += w;
      sum2 += w * w;
      ++d.parts;
    }
  }
  if (d.part_seconds > 0) d.drift = turn / d.part_seconds;
  const Windows& w = windows_[k];
  d.windows = w.stalled + w.moving;
  if (d.windows > 0) d.stalled_share = static_cast<double>(w.stalled) / d.windows;
  if (w.moving_seconds > 0) d.moving_drift = w.moving_turn / w.moving_seconds;
  if (d.parts > 1) {
    const double mean = sum / d.parts;
    const double var = std::max(0.0, (sum2 - d.parts * mean * mean) / (d.parts - 1));
    d.ci95 = 1.96 * std::sqrt(var / d.parts);
  }
  return d;
}

}  // namespace rheofeed::demo

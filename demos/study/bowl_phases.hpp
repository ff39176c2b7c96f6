// SPDX-License-Identifier: MIT
// The primitive bowl's phases (issue 18): where each nut of bowl_feeder_primitives is at every
// metric sample - on the floor, on the helical ramp, or elsewhere (on the cone, on other nuts) -
// and the angular drift about the bowl's axis measured in each phase separately, so that a
// model that is slower on the floor and reaches the ramp later is still compared ramp against
// ramp. Geometry: demos/common/bowl_scene.cpp (floor top z = 10 mm, ramp r = 130..150 mm).
#pragma once

#include <string>
#include <vector>

#include "rheofeed/simulation/run.hpp"

namespace rheofeed::demo {

/// Where a part of the primitive bowl is (world frame, bowl axis = +z through the origin).
enum class BowlPhase { Floor, Ramp, Other };
constexpr int kBowlPhaseCount = 3;
/// "floor", "ramp", "other".
const char* toString(BowlPhase phase);

/// The ramp (bowl_scene.cpp): 2 turns counter-clockwise from the floor top (z = 10 mm) at
/// azimuth 0, rising 30 mm per turn, over r = 130..150 mm; its first turn leaves the floor
/// free under it from about 200 degrees on (the nuts are poured there).
constexpr double kBowlFloorTop = 0.010;    ///< (m)
constexpr double kBowlRampPitch = 0.030;   ///< (m per turn)
constexpr double kBowlRampRadius = 0.128;  ///< the ramp's inner edge (130 mm) less 2 mm (m)
/// A centre at radius >= kBowlRampRadius and above the first turn's top at its azimuth
/// (10 mm + 30 mm azimuth / 2 pi, azimuth in [0, 2 pi)) is on the ramp (a nut lying on it has
/// its centre 2.5 mm above the top, which falls 0.5 mm towards the wall: 1 mm margin). Else a
/// centre lower than kBowlFloorHeight is on the floor - the floor top is at 10 mm, a nut
/// (radius 5.25 mm, 5 mm thick) lying flat has its centre at 12.5 mm and one on edge at
/// 15.25 mm, a nut on another nut at 17.5 mm or more - and anything else is Other (on the cone,
/// riding on nuts).
constexpr double kBowlRampMargin = 0.001;   ///< (m)
constexpr double kBowlFloorHeight = 0.017;  ///< (m, world z)

/// The phase of a part whose centre of mass is at `position` (m, world).
BowlPhase bowlPhase(const Vec3& position);

/// The angular drift (rad/s, about +z, counter-clockwise positive) in one phase.
struct PhaseDrift {
  double drift = 0;         ///< sum of the parts' turns / sum of their times in the phase
  double ci95 = 0;          ///< 1.96 sd / sqrt(n) over the parts' own drifts (parts >= 1 s in it)
  double part_seconds = 0;  ///< time spent in the phase, summed over the parts (s)
  int parts = 0;            ///< parts that spent at least 1 s in it
  /// The phase's time cut into windows of kStallWindow per part: the share of windows in which
  /// the part turned slower than kStallDrift (stuck in a jam or a wedge), and the drift over the
  /// other windows (rad/s; 0 when none).
  double stalled_share = 0;
  double moving_drift = 0;
  int windows = 0;  ///< windows counted
};

/// Window (s) and drift below which a part counts as stalled (rad/s: 0.02 rad/s is 2.9 mm/s at
/// r = 145 mm, a fifth of a single nut's drift on the ramp).
constexpr double kStallWindow = 2.0;
constexpr double kStallDrift = 0.02;

/// Watches a run of the primitive bowl: on each metric sample after `warmup` (s), each active
/// part that is in the same phase at both ends of the sample interval adds its turn about +z
/// (unwrapped) and the interval to that phase. Optionally records every part's centre and phase
/// at every sample (trace()).
class BowlPhaseObserver : public scene::RunObserver {
 public:
  explicit BowlPhaseObserver(double warmup, bool keep_trace = false)
      : warmup_(warmup), keep_trace_(keep_trace) {}
  void onStep(const scene::Simulation& sim, long step, bool sample) override;
  /// The drift of each phase (indexed by BowlPhase).
  PhaseDrift drift(BowlPhase phase) const;
  /// CSV rows "time_s,part,x_m,y_m,z_m,phase" (no header), one per part and sample.
  const std::string& trace() const { return trace_; }

 private:
  struct Part {
    bool seen = false;
    double time = 0, angle = 0;  // last sample (s, unwrapped rad)
    BowlPhase phase = BowlPhase::Other;
    double turn[kBowlPhaseCount] = {}, seconds[kBowlPhaseCount] = {};
    double window_turn = 0, window_seconds = 0;  // the current stall window (its phase: phase)
  };
  struct Windows {
    int stalled = 0, moving = 0;
    double moving_turn = 0, moving_seconds = 0;
  };
  Windows windows_[kBowlPhaseCount];
  double warmup_;
  bool keep_trace_;
  std::vector<Part> parts_;
  std::string trace_;
};

}  // namespace rheofeed::demo

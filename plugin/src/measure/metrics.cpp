// SPDX-License-Identifier: MIT
#include "rheofeed/measure/metrics.hpp"
#include "rheofeed/measure/statistics.hpp"
#include "rheofeed/number_format.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <filesystem>
#include <sstream>
#include <stdexcept>

namespace rheofeed::scene {
namespace {

struct Track {
  double angle = 0;   // last angle about the drift axis (rad), for unwrapping
  double turned = 0;  // unwrapped angle since spawn (rad)
  double previous_turned = 0, start_turned = 0, end_turned = 0;
  Vec3 spawn;     // position when first seen (m)
  Vec3 previous;  // position at the previous sample (m)
  bool has_previous = false;
  Vec3 start;  // position when drift measurement started (m)
  double start_time = -1;
  Vec3 end;  // position when it stopped (exit or run end)
  double end_time = -1;
  bool exited = false;
  Vec3 last;              // position at the previous observation (every step) (m)
  double last_time = -1;  // time of that observation (s)
  bool crossed = false;   // crossed the exit plane (FeederMetrics)
  bool removed = false;   // taken out of the simulation before crossing
};

// Angle of p about the axis (origin o, unit direction k) in a frame fixed to the axis.
double angleAbout(const Vec3& p, const Vec3& o, const Vec3& k) {
  Vec3 e1 = std::abs(k.x) < 0.9 ? Vec3{1, 0, 0} : Vec3{0, 1, 0};
  e1 = tangentialPart(e1, k);
  e1 = (1.0 / norm(e1)) * e1;
  const Vec3 r = p - o;
  return std::atan2(dot(r, cross(k, e1)), dot(r, e1));
}

}  // namespace

const char* toString(UpAxis axis) {
  switch (axis) {
    case UpAxis::PlusX:
      return "+x";
    case UpAxis::MinusX:
      return "-x";
    case UpAxis::PlusY:
      return "+y";
    case UpAxis::MinusY:
      return "-y";
    case UpAxis::PlusZ:
      return "+z";
    case UpAxis::MinusZ:
      return "-z";
  }
  return "?";
}

UpAxis upAxis(const double rotation[9], const Vec3& up) {
  // Body axis k in the world is column k of R: its component along up is (R^T up)_k.
  int best = 0;
  double best_component = 0;
  for (int k = 0; k < 3; ++k) {
    const double c = rotation[k] * up.x + rotation[3 + k] * up.y + rotation[6 + k] * up.z;
    if (std::abs(c) > std::abs(best_component)) {
      best = k;
      best_component = c;
    }
  }
  return static_cast<UpAxis>(2 * best + (best_component < 0 ? 1 : 0));
}

Vec3 upDirection(const Vec3& gravity) {
  const double g = norm(gravity);
  if (!(g > 0)) return Vec3{0, 0, 1};
  const Vec3 up = (-1.0 / g) * gravity;
  return {up.x + 0.0, up.y + 0.0, up.z + 0.0};  // + 0.0: no negative zeros in the outputs
}

double exitRateWindow(double duration, double sample_interval) {
  return std::max(sample_interval, duration / kRateWindowsPerRun);
}

std::vector<RateWindow> exitRate(const std::vector<double>& exit_times, double end_time,
                                 double window) {
  auto require = [](const char* what, double value) {
    if (!(std::isfinite(value) && value > 0)) {
      std::ostringstream msg;
      msg << "exit rate: " << what << " = " << value << " s: must be a finite number > 0";
      throw std::invalid_argument(msg.str());
    }
  };
  require("window", window);
  require("end time", end_time);
  // The relative slack keeps round-off in end_time / window from adding a sliver window.
  const long n = std::max(1L, static_cast<long>(std::ceil(end_time / window - 1e-9)));
  std::vector<RateWindow> out(static_cast<std::size_t>(n));
  for (long k = 0; k < n; ++k) {
    RateWindow& w = out[static_cast<std::size_t>(k)];
    w.start = k * window;
    w.end = k == n - 1 ? end_time : (k + 1) * window;
  }
  for (double t : exit_times) {
    const long k = std::min(n - 1, std::max(0L, static_cast<long>(std::floor(t / window))));
    ++out[static_cast<std::size_t>(k)].exits;
  }
  int cumulative = 0;
  for (RateWindow& w : out) {
    cumulative += w.exits;
    w.cumulative = cumulative;
    w.rate_per_min = 60.0 * w.exits / (w.end - w.start);
  }
  return out;
}

std::vector<int> partFamilies(const Scene& scene) {
  // drawParts: parts family by family, then a stable sort on the spawn time i / rate.
  std::vector<std::pair<double, int>> order;
  for (std::size_t s = 0; s < scene.parts.size(); ++s) {
    const PartSpec& spec = scene.parts[s];
    for (int i = 0; i < spec.count; ++i) {
      order.emplace_back(spec.rate > 0 ? i / spec.rate : 0.0, static_cast<int>(s));
    }
  }
  std::stable_sort(order.begin(), order.end(),
                   [](const auto& a, const auto& b) { return a.first < b.first; });
  std::vector<int> family;
  family.reserve(order.size());
  for (const auto& entry : order) family.push_back(entry.second);
  return family;
}

namespace {

// The measurement of one run (metrics.hpp), observing the simulation after every step.
class RunMeter : public RunObserver {
 public:
  RunMeter(const Scene& scene, Method method, const RunSchedule& schedule)
      : scene_(scene),
        out_(scene.outputs),
        h_(scene.solver.time_step),
        every_(schedule.sample_every),
        family_(partFamilies(scene)) {
    m_.scene = scene.name;
    m_.scene_file = scene.source_file;
    m_.method = method;
    m_.time_step = h_;
    m_.seed = scene.seed;
    const std::vector<std::string> family_keys = familyKeys(scene.parts);
    for (const Fixture& f : scene.fixtures) {
      if (f.law.kind == FeederLaw::Kind::Vibration) {
        m_.drift_models.push_back(f.name + ": " + toString(f.law.drift_model));
        if (isFullVibration(method)) continue;  // it vibrates: no drift field drives it
        DriftField field;
        field.fixture = f.name;
        field.drift_model = toString(f.law.drift_model);
        if (f.law.drift_model == DriftModel::LocalSampled) {
          for (std::size_t k = 0; k < f.law.efficiency.size() && k < scene.parts.size(); ++k) {
            field.efficiency.emplace_back(family_keys[k], f.law.efficiency[k]);
          }
        }
        if (f.law.drift_model == DriftModel::CalibratedDrift && f.law.has_calibrated_drift) {
          field.calibrated_drift = f.law.calibrated_drift;
        }
        m_.drift_fields.push_back(std::move(field));
      }
    }
    m_.angular = out_.angular_drift;
    FeederMetrics& feeder = m_.feeder;
    feeder.exit_plane = out_.exit_plane;
    feeder.up = upDirection(scene.gravity);
    for (std::size_t k = 0; k < scene.parts.size(); ++k) {
      const PartSpec& spec = scene.parts[k];
      FamilyExits f;
      f.name = family_keys[k];
      f.shape = spec.shape;
      f.orientation_meaningful = spec.shape != Shape::Kind::Sphere;
      feeder.families.push_back(f);
    }
  }

  void onStart(const Simulation& sim) override { observe(sim, 0.0, false); }
  void onStep(const Simulation& sim, long, bool sample) override {
    observe(sim, sim.time(), sample);
  }
  void onEnd(const Simulation& sim) override {
    m_.simulated_seconds = sim.time();
    m_.warmup = out_.warmup;
    m_.parts = sim.numParts();
    m_.health = sim.health();
    m_.solver = sim.appliedSolver();
    finishDrift(sim);
    finishFeeder();
  }

  RunMetrics& metrics() { return m_; }

 private:
  FamilyExits& familyOf(int i) {
    return m_.feeder.families[static_cast<std::size_t>(family_.at(static_cast<std::size_t>(i)))];
  }
  bool crossed(const Vec3& x) const { return beyondExitPlane(out_, x); }
  // A crossing between the previous observation and this one at time t: the time where the
  // signed distance to the plane, linear between the two, is zero.
  double crossingTime(const Track& tr, const Vec3& x, double t) const {
    const double d0 = dot(tr.last - out_.exit_point, out_.exit_normal);
    const double d1 = dot(x - out_.exit_point, out_.exit_normal);
    if (tr.last_time < 0 || !(d0 < 0) || !(d1 > d0)) return t;
    return tr.last_time + (t - tr.last_time) * (-d0 / (d1 - d0));
  }
  // Drift coordinate progress of a part between two observations: along d, or the unwrapped
  // angle about the axis.
  void turn(Track& tr, const Vec3& x) const {
    if (!out_.angular_drift) return;
    const double a = angleAbout(x, out_.axis_origin, out_.axis_direction);
    double da = a - tr.angle;
    da -= 2 * kPi * std::round(da / (2 * kPi));
    tr.turned += da;
    tr.angle = a;
  }
  void endMeasurement(Track& tr, double t) {
    tr.end_turned = tr.turned;
    tr.end_time = t;
    tr.exited = true;
  }
  void addNewParts(const Simulation& sim, double t) {
    const int n = sim.numParts();
    for (int i = static_cast<int>(tracks_.size()); i < n; ++i) {
      Track tr;
      tr.spawn = tr.previous = sim.part(i).position;
      tr.has_previous = true;
      if (out_.angular_drift)
        tr.angle = angleAbout(tr.spawn, out_.axis_origin, out_.axis_direction);
      tr.exited = out_.exit_plane && crossed(tr.spawn);  // spawned beyond the exit: never counted
      if (tr.exited) ++m_.feeder.spawned_beyond_exit;
      tr.last = tr.spawn;
      tr.last_time = t;
      ++familyOf(i).spawned;
      tracks_.push_back(tr);
    }
  }
  void observe(const Simulation& sim, double t, bool sample) {
    addNewParts(sim, t);
    const Vec3 d = out_.conveying_direction;
    const bool angular = out_.angular_drift;
    std::vector<double> v;
    double z = 0;
    int active = 0;
    for (int i = 0; i < sim.numParts(); ++i) {
      Track& tr = tracks_[static_cast<std::size_t>(i)];
      if (tr.exited) continue;
      const PartState state = sim.part(i);
      const Vec3 x = state.position;
      turn(tr, x);
      if (!state.active) {  // removed (fell out of the scene): its measurement ends here
        tr.removed = true;
        ++familyOf(i).removed_without_exit;
        tr.end = x;
        endMeasurement(tr, t);
        continue;
      }
      if (sim.partLost(i)) {  // counted lost and kept: its measurement ends here, no exit
        ++familyOf(i).lost_before_exit;
        tr.end = x;
        endMeasurement(tr, t);
        continue;
      }
      if (tr.start_time < 0 && t >= out_.warmup) {
        tr.start = x;
        tr.start_turned = tr.turned;
        tr.start_time = t;
      }
      if (out_.exit_plane && crossed(x)) {
        tr.crossed = true;
        m_.feeder.exit_times.push_back(crossingTime(tr, x, t));
        FamilyExits& f = familyOf(i);
        ++f.exited;
        ++f.up_axis[static_cast<std::size_t>(upAxis(state.rotation, m_.feeder.up))];
        tr.end = x;
        endMeasurement(tr, t);
        ++exited_total_;
        if (t > out_.warmup) ++exited_after_warmup_;
        continue;
      }
      tr.last = x;
      tr.last_time = t;
      if (sample) {
        const double advance = angular ? tr.turned - tr.previous_turned : dot(x - tr.previous, d);
        v.push_back(advance / (every_ * h_));
        tr.previous = x;
        tr.previous_turned = tr.turned;
        z += x.z;
        ++active;
      }
    }
    if (sample) addSample(sim.health(), t, v, z, active);
  }
  void addSample(const RunHealth& health, double t, const std::vector<double>& v, double z,
                 int active) {
    DriftSample s;
    s.time = t;
    s.parts = active;
    s.mean_velocity = mean(v);
    s.ci95 = ci95(v);
    s.mean_height = active ? z / active : 0;
    s.exited = exited_total_;
    s.fell = health.parts_fell;
    s.through_fixture = health.parts_through_fixture;
    s.out_of_bounds = health.parts_out_of_bounds;
    s.nonfinite = health.parts_nonfinite;
    s.too_fast = health.parts_too_fast;
    s.left_feeder = health.parts_left_feeder;
    m_.series.push_back(s);
  }
  void finishDrift(const Simulation& sim) {
    const Vec3 d = out_.conveying_direction;
    std::vector<double> drift;
    double dz = 0;
    int counted = 0;  // parts in the vertical displacement
    // Parts inside a fixture at the end are counted lost in the run's totals (RunHealth::
    // partsLost) though partLost() does not say so (they might still have come out): their
    // motion inside a fixture is not the feeder's either.
    std::vector<bool> inside(static_cast<std::size_t>(m_.parts), false);
    for (const PartEvent& e : sim.health().inside_fixture_now) {
      if (e.part >= 0 && e.part < m_.parts) inside[static_cast<std::size_t>(e.part)] = true;
    }
    for (int i = 0; i < m_.parts; ++i) {
      // a lost part's motion is not the feeder's
      if (sim.partLost(i) || inside[static_cast<std::size_t>(i)]) continue;
      ++counted;
      Track& tr = tracks_[static_cast<std::size_t>(i)];
      const Vec3 x = sim.part(i).position;
      if (!tr.exited || tr.end_time < 0) {
        if (tr.exited) continue;  // spawned beyond the exit
        tr.end = x;
        tr.end_turned = tr.turned;
        tr.end_time = m_.simulated_seconds;
      }
      dz += tr.end.z - tr.spawn.z;
      if (tr.start_time >= 0 && tr.end_time > tr.start_time) {
        const double advance =
            out_.angular_drift ? tr.end_turned - tr.start_turned : dot(tr.end - tr.start, d);
        drift.push_back(advance / (tr.end_time - tr.start_time));
      }
    }
    m_.mean_drift = mean(drift);
    m_.mean_drift_ci95 = ci95(drift);
    m_.drift_parts = static_cast<int>(drift.size());
    m_.vertical_displacement = counted ? dz / counted : 0;
    m_.displacement_parts = counted;
    const double window = m_.simulated_seconds - out_.warmup;
    m_.throughput = window > 0 ? exited_after_warmup_ / window : 0;
  }
  void finishFeeder() {
    FeederMetrics& feeder = m_.feeder;
    std::sort(feeder.exit_times.begin(), feeder.exit_times.end());
    if (!feeder.exit_times.empty()) feeder.first_exit_time = feeder.exit_times.front();
    if (feeder.exit_times.size() >= 2 && feeder.exit_times.back() > feeder.exit_times.front()) {
      feeder.mean_rate_per_min = 60.0 * double(feeder.exit_times.size() - 1) /
                                 (feeder.exit_times.back() - feeder.exit_times.front());
    }
    if (m_.simulated_seconds > 0) {
      feeder.rate_window = exitRateWindow(m_.simulated_seconds, out_.sample_interval);
      if (out_.exit_plane) {
        feeder.rate = exitRate(feeder.exit_times, m_.simulated_seconds, feeder.rate_window);
      }
    }
    char note[160];
    if (!out_.exit_plane) {
      feeder.note = "the scene has no exit plane (outputs.exit_plane is false): no exit metrics";
    } else if (feeder.exit_times.empty()) {
      std::snprintf(note, sizeof note, "no part reached the exit in %g s", m_.simulated_seconds);
      feeder.note = note;
    }
    if (out_.exit_plane && (feeder.exit_times.empty() || feeder.spawned_beyond_exit > 0)) {
      std::fprintf(stderr, "rheofeed: %s, %s: ", scene_.name.c_str(), toString(m_.method));
      if (feeder.exit_times.empty()) std::fprintf(stderr, "%s", feeder.note.c_str());
      if (feeder.spawned_beyond_exit > 0) {
        std::fprintf(stderr, "%s%d parts spawned beyond the exit plane (not counted as exits)",
                     feeder.exit_times.empty() ? "; " : "", feeder.spawned_beyond_exit);
      }
      std::fprintf(stderr, "\n");
    }
  }

  const Scene& scene_;
  const Outputs& out_;
  const double h_;
  const long every_;
  const std::vector<int> family_;
  RunMetrics m_;
  std::vector<Track> tracks_;
  int exited_total_ = 0, exited_after_warmup_ = 0;
};

}  // namespace

RunAnswer runAnswer(const RunMetrics& run, const std::string& bound_name) {
  RunAnswer a;
  const int lost = run.health.partsLost();
  const std::string spawned = std::to_string(run.parts);
  if (run.parts <= 0) {
    a.why.push_back("spawned no part");
  } else if (run.drift_parts == 0 && run.feeder.exit_times.empty() && lost >= run.parts) {
    a.why.push_back("lost all " + spawned + " parts it spawned");
  } else {
    if (run.drift_parts == 0 && run.feeder.exit_times.empty()) {
      a.why.push_back("measured none of its " + spawned + " parts (" + std::to_string(lost) +
                      " lost, " + std::to_string(run.feeder.spawned_beyond_exit) +
                      " spawned beyond the exit plane)");
    }
    // The share, not lost > bound x parts: 57 of 100 is not more than 0.57 (0.57 x 100 rounds
    // to 56.99999999999999).
    const double share = double(lost) / run.parts;
    if (!(run.max_lost_fraction >= 0 && run.max_lost_fraction <= 1)) {
      a.why.push_back("has no bound to judge its " + std::to_string(lost) + " lost parts by: " +
                      bound_name + " " + formatNumber(run.max_lost_fraction) + " is not in [0, 1]");
    } else if (share > run.max_lost_fraction) {
      a.why.push_back("lost " + std::to_string(lost) + " of " + spawned + " parts (" +
                      formatNumber(100 * share, 3) + " %), more than " + bound_name + " " +
                      formatNumber(run.max_lost_fraction));
    }
  }
  a.trusted = a.why.empty();
  return a;
}

RunMetrics measureRun(const Scene& scene, Method method, const Progress& progress,
                      const std::vector<RunObserver*>& observers) {
  std::unique_ptr<Simulation> sim = makeSimulation(scene, method);
  return measureRun(*sim, scene, progress, observers);
}

RunMetrics measureRun(Simulation& sim, const Scene& scene, const Progress& progress,
                      const std::vector<RunObserver*>& observers) {
  const RunSchedule schedule = runSchedule(scene);
  RunMeter meter(scene, sim.method(), schedule);
  HealthReport report(scene.name);
  std::vector<RunObserver*> all{&meter};
  all.insert(all.end(), observers.begin(), observers.end());
  all.push_back(&report);
  const std::clock_t cpu_start = std::clock();
  runSimulation(sim, schedule, all, progress);
  RunMetrics& m = meter.metrics();
  m.cpu_seconds = double(std::clock() - cpu_start) / CLOCKS_PER_SEC;
  m.real_time_factor = m.simulated_seconds > 0 ? m.cpu_seconds / m.simulated_seconds : 0;
  return std::move(m);
}

}  // namespace rheofeed::scene

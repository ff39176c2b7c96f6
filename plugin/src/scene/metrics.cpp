// SPDX-License-Identifier: MIT
#include "rheofeed/scene/metrics.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <filesystem>
#include <sstream>
#include <stdexcept>

#include "rheofeed/scene/animation.hpp"
#include "rheofeed/scene/check.hpp"
#include "rheofeed/scene/output.hpp"
#include "rheofeed/scene/plot.hpp"

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

constexpr double kPi = 3.14159265358979323846;

// Angle of p about the axis (origin o, unit direction k) in a frame fixed to the axis.
double angleAbout(const Vec3& p, const Vec3& o, const Vec3& k) {
  Vec3 e1 = std::abs(k.x) < 0.9 ? Vec3{1, 0, 0} : Vec3{0, 1, 0};
  e1 = tangentialPart(e1, k);
  e1 = (1.0 / norm(e1)) * e1;
  const Vec3 r = p - o;
  return std::atan2(dot(r, cross(k, e1)), dot(r, e1));
}

double mean(const std::vector<double>& v) {
  double s = 0;
  for (double x : v) s += x;
  return v.empty() ? 0 : s / v.size();
}

double ci95(const std::vector<double>& v) {
  if (v.size() < 2) return 0;
  const double m = mean(v);
  double ss = 0;
  for (double x : v) ss += (x - m) * (x - m);
  const double sd = std::sqrt(ss / (v.size() - 1));
  return studentT95(static_cast<int>(v.size()) - 1) * sd / std::sqrt(double(v.size()));
}

}  // namespace

double studentT95(int dof) {
  // Two-sided 95 % quantiles of Student's t.
  static const double table[] = {12.706, 4.303, 3.182, 2.776, 2.571, 2.447, 2.365, 2.306,
                                 2.262,  2.228, 2.201, 2.179, 2.160, 2.145, 2.131, 2.120,
                                 2.110,  2.101, 2.093, 2.086, 2.080, 2.074, 2.069, 2.064,
                                 2.060,  2.056, 2.052, 2.048, 2.045, 2.042};
  if (dof < 1) return 0;
  if (dof <= 30) return table[dof - 1];
  if (dof <= 60) return 2.042 + (2.000 - 2.042) * (dof - 30) / 30.0;
  if (dof <= 120) return 2.000 + (1.980 - 2.000) * (dof - 60) / 60.0;
  return 1.96;
}

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

RunMetrics measureRun(const Scene& scene, Method method, const Progress& progress,
                      AnimationRecorder* animation) {
  std::unique_ptr<Simulation> sim = makeSimulation(scene, method);
  const double h = scene.solver.time_step;
  const Outputs& out = scene.outputs;
  const Vec3 d = out.conveying_direction;
  const long steps = std::lround(scene.duration / h);
  const long every = std::max(1L, std::lround(out.sample_interval / h));
  const long report_every = std::max(1L, steps / 100);

  RunMetrics m;
  const std::vector<Hazard> hazards = checkScene(scene, method);
  for (const Hazard& hz : hazards) {
    m.scene_check.push_back(std::string(toString(hz.kind)) + " at " + hz.where + ": " + hz.message +
                            " (safe: " + hz.safe_setting + ")");
  }
  std::fprintf(
      stderr, "%s",
      formatHazards(hazards, "rheofeed: " + scene.name + ", " + toString(method) + ": ").c_str());
  m.scene = scene.name;
  m.method = method;
  m.time_step = h;
  m.seed = scene.seed;
  for (const Fixture& f : scene.fixtures) {
    if (f.law.kind == FeederLaw::Kind::Vibration) {
      m.drift_models.push_back(f.name + ": " + toString(f.law.drift_model));
    }
  }
  m.angular = out.angular_drift;
  std::vector<Track> tracks;
  int exited_total = 0, exited_after_warmup = 0;

  FeederMetrics& feeder = m.feeder;
  feeder.exit_plane = out.exit_plane;
  feeder.up = upDirection(scene.gravity);
  const std::vector<int> family = partFamilies(scene);
  for (const PartSpec& spec : scene.parts) {
    FamilyExits f;
    f.name = spec.name;
    f.shape = spec.shape;
    f.orientation_meaningful = spec.shape != Shape::Kind::Sphere;
    feeder.families.push_back(f);
  }
  auto familyOf = [&](int i) -> FamilyExits& {
    return feeder.families[static_cast<std::size_t>(family.at(static_cast<std::size_t>(i)))];
  };
  // A crossing between the previous observation and this one at time t: the time where the
  // signed distance to the plane, linear between the two, is zero.
  auto crossingTime = [&](const Track& tr, const Vec3& x, double t) {
    const double d0 = dot(tr.last - out.exit_point, out.exit_normal);
    const double d1 = dot(x - out.exit_point, out.exit_normal);
    if (tr.last_time < 0 || !(d0 < 0) || !(d1 > d0)) return t;
    return tr.last_time + (t - tr.last_time) * (-d0 / (d1 - d0));
  };

  auto crossed = [&](const Vec3& x) { return beyondExitPlane(out, x); };
  // Drift coordinate progress of a part between two observations: along d, or the unwrapped
  // angle about the axis.
  const bool angular = out.angular_drift;
  auto turn = [&](Track& tr, const Vec3& x) {
    if (!angular) return;
    const double a = angleAbout(x, out.axis_origin, out.axis_direction);
    double da = a - tr.angle;
    da -= 2 * kPi * std::round(da / (2 * kPi));
    tr.turned += da;
    tr.angle = a;
  };
  auto observe = [&](double t, bool sample) {
    const int n = sim->numParts();
    for (int i = static_cast<int>(tracks.size()); i < n; ++i) {
      Track tr;
      tr.spawn = tr.previous = sim->part(i).position;
      tr.has_previous = true;
      if (angular) tr.angle = angleAbout(tr.spawn, out.axis_origin, out.axis_direction);
      tr.exited = out.exit_plane && crossed(tr.spawn);  // spawned beyond the exit: never counted
      if (tr.exited) ++feeder.spawned_beyond_exit;
      tr.last = tr.spawn;
      tr.last_time = t;
      ++familyOf(i).spawned;
      tracks.push_back(tr);
    }
    std::vector<double> v;
    double z = 0;
    int active = 0;
    for (int i = 0; i < n; ++i) {
      Track& tr = tracks[static_cast<std::size_t>(i)];
      if (tr.exited) continue;
      const PartState state = sim->part(i);
      const Vec3 x = state.position;
      turn(tr, x);
      if (!state.active) {  // removed (fell out of the scene): its measurement ends here
        tr.exited = true;
        tr.removed = true;
        ++familyOf(i).removed_without_exit;
        tr.end = x;
        tr.end_turned = tr.turned;
        tr.end_time = t;
        continue;
      }
      if (tr.start_time < 0 && t >= out.warmup) {
        tr.start = x;
        tr.start_turned = tr.turned;
        tr.start_time = t;
      }
      if (out.exit_plane && crossed(x)) {
        tr.crossed = true;
        feeder.exit_times.push_back(crossingTime(tr, x, t));
        FamilyExits& f = familyOf(i);
        ++f.exited;
        ++f.up_axis[static_cast<std::size_t>(upAxis(state.rotation, feeder.up))];
        tr.exited = true;
        tr.end = x;
        tr.end_turned = tr.turned;
        tr.end_time = t;
        ++exited_total;
        if (t > out.warmup) ++exited_after_warmup;
        continue;
      }
      tr.last = x;
      tr.last_time = t;
      if (sample) {
        const double advance = angular ? tr.turned - tr.previous_turned : dot(x - tr.previous, d);
        v.push_back(advance / (every * h));
        tr.previous = x;
        tr.previous_turned = tr.turned;
        z += x.z;
        ++active;
      }
    }
    if (sample) {
      DriftSample s;
      s.time = t;
      s.parts = active;
      s.mean_velocity = mean(v);
      s.ci95 = ci95(v);
      s.mean_height = active ? z / active : 0;
      s.exited = exited_total;
      const RunHealth& health = sim->health();
      s.fell = health.parts_fell;
      s.through_fixture = health.parts_through_fixture;
      s.out_of_bounds = health.parts_out_of_bounds;
      s.nonfinite = health.parts_nonfinite;
      s.too_fast = health.parts_too_fast;
      m.series.push_back(s);
    }
  };

  const std::clock_t cpu_start = std::clock();
  observe(0.0, false);
  if (animation) animation->record(*sim);
  for (long k = 1; k <= steps; ++k) {
    sim->step();
    observe(sim->time(), k % every == 0);
    if (animation && (k % every == 0 || k == steps)) animation->record(*sim);
    if (progress && k % report_every == 0) progress(double(k) / steps);
  }
  m.cpu_seconds = double(std::clock() - cpu_start) / CLOCKS_PER_SEC;
  m.simulated_seconds = sim->time();
  m.real_time_factor = m.simulated_seconds > 0 ? m.cpu_seconds / m.simulated_seconds : 0;
  m.parts = sim->numParts();

  std::vector<double> drift;
  double dz = 0;
  for (int i = 0; i < m.parts; ++i) {
    Track& tr = tracks[static_cast<std::size_t>(i)];
    const Vec3 x = sim->part(i).position;
    if (!tr.exited || tr.end_time < 0) {
      if (tr.exited) continue;  // spawned beyond the exit
      tr.end = x;
      tr.end_turned = tr.turned;
      tr.end_time = m.simulated_seconds;
    }
    dz += tr.end.z - tr.spawn.z;
    if (tr.start_time >= 0 && tr.end_time > tr.start_time) {
      const double advance = angular ? tr.end_turned - tr.start_turned : dot(tr.end - tr.start, d);
      drift.push_back(advance / (tr.end_time - tr.start_time));
    }
  }
  m.mean_drift = mean(drift);
  m.mean_drift_ci95 = ci95(drift);
  m.vertical_displacement = m.parts ? dz / m.parts : 0;
  const double window = m.simulated_seconds - out.warmup;
  m.throughput = window > 0 ? exited_after_warmup / window : 0;
  m.health = sim->health();

  std::sort(feeder.exit_times.begin(), feeder.exit_times.end());
  if (!feeder.exit_times.empty()) feeder.first_exit_time = feeder.exit_times.front();
  if (feeder.exit_times.size() >= 2 && feeder.exit_times.back() > feeder.exit_times.front()) {
    feeder.mean_rate_per_min = 60.0 * double(feeder.exit_times.size() - 1) /
                               (feeder.exit_times.back() - feeder.exit_times.front());
  }
  if (m.simulated_seconds > 0) {
    feeder.rate_window = exitRateWindow(m.simulated_seconds, out.sample_interval);
    if (out.exit_plane) {
      feeder.rate = exitRate(feeder.exit_times, m.simulated_seconds, feeder.rate_window);
    }
  }
  char note[160];
  if (!out.exit_plane) {
    feeder.note = "the scene has no exit plane (outputs.exit_plane is false): no exit metrics";
  } else if (feeder.exit_times.empty()) {
    std::snprintf(note, sizeof note, "no part reached the exit in %g s", m.simulated_seconds);
    feeder.note = note;
  }
  if (out.exit_plane && (feeder.exit_times.empty() || feeder.spawned_beyond_exit > 0)) {
    std::fprintf(stderr, "rheofeed: %s, %s: ", scene.name.c_str(), toString(method));
    if (feeder.exit_times.empty()) std::fprintf(stderr, "%s", feeder.note.c_str());
    if (feeder.spawned_beyond_exit > 0) {
      std::fprintf(stderr, "%s%d parts spawned beyond the exit plane (not counted as exits)",
                   feeder.exit_times.empty() ? "; " : "", feeder.spawned_beyond_exit);
    }
    std::fprintf(stderr, "\n");
  }
  if (progress) progress(1.0);
  if (m.health.anything()) {
    std::fprintf(stderr, "rheofeed: %s, %s: %s\n", scene.name.c_str(), toString(method),
                 healthSummary(m.health, m.parts).c_str());
  }
  if (m.health.local_law_feeders > 0) {
    const LocalDriftStats& l = m.health.local_law;
    std::fprintf(stderr,
                 "rheofeed: %s, %s: local vibration law on %d feeder(s): %lld contacts driven "
                 "(%lld on walls or steep faces), %lld drift table cells, %lld point-mass runs\n",
                 scene.name.c_str(), toString(method), m.health.local_law_feeders,
                 static_cast<long long>(l.contacts), static_cast<long long>(l.wall_contacts),
                 static_cast<long long>(l.cells_computed), static_cast<long long>(l.model_runs));
  }
  return m;
}

Progress stderrProgress(const std::string& label) {
  auto last = std::make_shared<std::chrono::steady_clock::time_point>();
  return [label, last](double f) {
    const auto now = std::chrono::steady_clock::now();
    if (f < 1.0 && now - *last < std::chrono::milliseconds(500)) return;
    *last = now;
    std::fprintf(stderr, "\r%s: %3.0f %%%s", label.c_str(), 100 * f, f >= 1.0 ? "\n" : "");
    std::fflush(stderr);
  };
}

std::string seriesCsv(const RunMetrics& run) {
  std::ostringstream s;
  s << "time_s,parts,mean_velocity_mps,ci95_mps,mean_height_m,exited,lost_fell,"
       "lost_through_fixture,lost_out_of_bounds,lost_nonfinite,lost_too_fast\n";
  char line[256];
  for (const DriftSample& d : run.series) {
    std::snprintf(line, sizeof line, "%.6f,%d,%.8g,%.8g,%.8g,%d,%d,%d,%d,%d,%d\n", d.time, d.parts,
                  d.mean_velocity, d.ci95, d.mean_height, d.exited, d.fell, d.through_fixture,
                  d.out_of_bounds, d.nonfinite, d.too_fast);
    s << line;
  }
  return s.str();
}

std::string healthSummary(const RunHealth& h, int parts) {
  if (!h.anything()) return "nothing lost";
  std::ostringstream s;
  const char* separator = "";
  if (h.partsLost() > 0) {
    s << h.partsLost() << " of " << parts << " parts lost (";
    const std::pair<const char*, int> kinds[] = {{"fell", h.parts_fell},
                                                 {"through a fixture", h.parts_through_fixture},
                                                 {"out of bounds", h.parts_out_of_bounds},
                                                 {"non-finite", h.parts_nonfinite},
                                                 {"too fast", h.parts_too_fast},
                                                 {"inside a fixture now", h.parts_inside_fixture}};
    const char* comma = "";
    for (const auto& [name, count] : kinds) {
      if (count == 0) continue;
      s << comma << name << " " << count;
      comma = ", ";
    }
    s << ")";
    if (h.parts_too_fast > 0) {
      s << ", max speed " << h.max_part_speed << " m/s (bound " << h.speed_bound << " m/s)";
    }
    separator = "; ";
  }
  if (h.parts_sunk > 0) {
    s << separator << h.parts_sunk << (h.parts_sunk == 1 ? " part" : " parts")
      << " sank into a fixture by more than half their size "
      << "and came back";
    separator = "; ";
  }
  if (h.coulomb_fallback_steps > 0) {
    s << separator << h.coulomb_fallback_steps << " of " << h.steps << " steps used the Coulomb "
      << "fallback (" << 100.0 * h.coulomb_fallback_steps / std::max(1L, h.steps) << " %)";
    separator = "; ";
  }
  if (h.solver_unconverged_steps > 0) {
    s << separator << h.solver_unconverged_steps << " of " << h.steps
      << " steps with an unconverged contact solve";
    separator = "; ";
  }
  if (h.friction_dropped_contacts > 0) {
    s << separator << h.friction_dropped_contacts
      << " contact friction impulses dropped by the Coulomb fallback";
    separator = "; ";
  }
  if (h.gyroscopic_fallback_steps > 0) {
    s << separator << h.gyroscopic_fallback_steps
      << " steps with a dissipative gyroscopic fallback";
    separator = "; ";
  }
  if (!h.ignored_settings.empty()) {
    s << separator << h.ignored_settings.size() << " ignored setting"
      << (h.ignored_settings.size() > 1 ? "s" : "") << " (";
    for (std::size_t k = 0; k < h.ignored_settings.size(); ++k) {
      const std::string& line = h.ignored_settings[k];
      s << (k ? ", " : "") << line.substr(0, line.find(" ="));
    }
    s << ")";
  }
  return s.str();
}

std::string summaryJson(const RunMetrics& r) {
  char b[768];
  std::snprintf(b, sizeof b,
                ", \"method\": \"%s\", \"time_step_s\": %.8g, \"parts\": %d, "
                "\"drift_unit\": \"%s\", \"mean_drift\": %.8g, \"mean_drift_ci95\": %.8g, "
                "\"vertical_displacement_m\": %.8g, \"throughput_parts_per_s\": %.8g, "
                "\"cpu_seconds\": %.6g, \"simulated_seconds\": %.6g, \"real_time_factor\": %.6g",
                toString(r.method), r.time_step, r.parts, r.angular ? "rad/s" : "m/s", r.mean_drift,
                r.mean_drift_ci95, r.vertical_displacement, r.throughput, r.cpu_seconds,
                r.simulated_seconds, r.real_time_factor);
  std::string run = b;  // the run's own settings: seed and drift models
  run += ", \"seed\": " + std::to_string(r.seed) + ", \"drift_models\": [";
  for (std::size_t k = 0; k < r.drift_models.size(); ++k) {
    run += (k ? ", " : "") + jsonQuoted(r.drift_models[k]);
  }
  run += "]";
  const RunHealth& h = r.health;
  char c[1536];
  std::snprintf(
      c, sizeof c,
      ", \"health\": {\"steps\": %ld, \"parts_removed_after_exit\": %d, \"parts_lost\": %d, "
      "\"parts_fell\": %d, \"parts_through_fixture\": %d, \"parts_out_of_bounds\": %d, "
      "\"parts_nonfinite\": %d, \"parts_too_fast\": %d, \"parts_inside_fixture\": %d, "
      "\"parts_sunk\": %d, "
      "\"coulomb_fallback_steps\": %ld, "
      "\"coulomb_fallback_share\": %.6g, \"solver_unconverged_steps\": %ld, "
      "\"friction_dropped_contacts\": %ld, \"gyroscopic_fallback_steps\": %ld, "
      "\"max_part_speed_mps\": %.6g, \"speed_bound_mps\": %.6g, \"ignored_settings\": [",
      h.steps, h.parts_exited, h.partsLost(), h.parts_fell, h.parts_through_fixture,
      h.parts_out_of_bounds, h.parts_nonfinite, h.parts_too_fast, h.parts_inside_fixture,
      h.parts_sunk, h.coulomb_fallback_steps,
      h.steps > 0 ? double(h.coulomb_fallback_steps) / h.steps : 0.0, h.solver_unconverged_steps,
      h.friction_dropped_contacts, h.gyroscopic_fallback_steps, h.max_part_speed, h.speed_bound);
  std::string json = "{\"scene\": " + jsonQuoted(r.scene) + run + c;
  for (std::size_t k = 0; k < h.ignored_settings.size(); ++k) {
    json += (k ? ", " : "") + jsonQuoted(h.ignored_settings[k]);
  }
  json += "]}, \"scene_check\": [";
  for (std::size_t k = 0; k < r.scene_check.size(); ++k) {
    json += (k ? ", " : "") + jsonQuoted(r.scene_check[k]);
  }
  const LocalDriftStats& l = h.local_law;  // RunHealth::local_law (simulation.hpp)
  char d[256];
  std::snprintf(d, sizeof d,
                "{\"feeders\": %d, \"contacts\": %lld, \"wall_contacts\": %lld, "
                "\"cells_computed\": %lld, \"model_runs\": %lld}",
                h.local_law_feeders, static_cast<long long>(l.contacts),
                static_cast<long long>(l.wall_contacts), static_cast<long long>(l.cells_computed),
                static_cast<long long>(l.model_runs));
  return json + "], \"feeder\": " + feederJson(r.feeder) + ", \"local_law\": " + d + "}";
}

std::vector<std::string> writeRunOutputs(const RunMetrics& run, const std::string& folder,
                                         const std::string& stem) {
  const std::filesystem::path base = std::filesystem::path(folder) / stem;
  std::vector<std::string> written;
  const std::string csv = seriesCsv(run);
  writeFileAtomically(base.string() + ".csv", csv);
  written.push_back(base.string() + ".csv");
  writeFileAtomically(base.string() + ".json", summaryJson(run) + "\n");
  written.push_back(base.string() + ".json");

  std::ostringstream gp;
  gp << "set datafile separator ','\n"
     << "set key bottom right\nset grid\n"
     << "set xlabel 'time (s)'\nset ylabel '"
     << (run.angular ? "mean angular drift about the axis (rad/s)" : "mean drift velocity (m/s)")
     << "'\n"
     << "set title '" << run.scene << ": " << toString(run.method) << ", h = " << run.time_step
     << " s, " << run.parts << " parts'\n"
     << "plot $data using 1:($3-$4):($3+$4) with filledcurves fc rgb '#c0d0f0' title '95 % CI', "
        "$data using 1:3 with lines lw 2 lc rgb '#1040a0' title 'mean over parts'\n";
  const std::string png = base.string() + ".png";
  if (plotPng(gp.str(), {{"data", csv}}, png)) written.push_back(png);
  const std::string title = run.scene + ": " + toString(run.method);
  for (const std::string& path : writeFeederOutputs(run.feeder, folder, stem, title)) {
    written.push_back(path);
  }
  return written;
}

}  // namespace rheofeed::scene

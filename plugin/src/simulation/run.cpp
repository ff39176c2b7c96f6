// SPDX-License-Identifier: MIT
// The run loop (run.hpp) and the end-of-run health report.
#include "rheofeed/simulation/run.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <memory>
#include <sstream>

namespace rheofeed::scene {

RunSchedule runSchedule(const Scene& scene) {
  const double h = scene.solver.time_step;
  RunSchedule s;
  s.steps = std::lround(scene.duration / h);
  s.sample_every = std::max(1L, std::lround(scene.outputs.sample_interval / h));
  return s;
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

void runSimulation(Simulation& sim, const RunSchedule& schedule,
                   const std::vector<RunObserver*>& observers, const Progress& progress) {
  const long report_every = std::max(1L, schedule.steps / 100);
  for (RunObserver* o : observers) {
    if (o) o->onStart(sim);
  }
  for (long k = 1; k <= schedule.steps; ++k) {
    sim.step();
    const bool sample = k % schedule.sample_every == 0;
    for (RunObserver* o : observers) {
      if (o) o->onStep(sim, k, sample);
    }
    if (progress && k % report_every == 0) progress(double(k) / schedule.steps);
  }
  for (RunObserver* o : observers) {
    if (o) o->onEnd(sim);
  }
  if (progress) progress(1.0);
}

void HealthReport::onEnd(const Simulation& sim) {
  const RunHealth& h = sim.health();
  if (h.anything()) {
    std::fprintf(stderr, "rheofeed: %s, %s: %s\n", scene_name_.c_str(), toString(sim.method()),
                 healthSummary(h, sim.numParts()).c_str());
  }
  // The parts inside a fixture at the end are lost (partsLost) but were never reported as they
  // went in: name them (the first few; all are in the run JSON).
  constexpr std::size_t kInsideNamed = 5;
  for (std::size_t k = 0; k < h.inside_fixture_now.size() && k < kInsideNamed; ++k) {
    const PartEvent& e = h.inside_fixture_now[k];
    std::fprintf(stderr,
                 "rheofeed: %s, %s: part %d (%s) went into fixture %s at t = %g s and is inside "
                 "it at the end, x = (%g, %g, %g) m\n",
                 scene_name_.c_str(), toString(sim.method()), e.part, e.family.c_str(),
                 e.fixture.empty() ? "(unknown)" : e.fixture.c_str(), e.time, e.position.x,
                 e.position.y, e.position.z);
  }
  if (h.inside_fixture_now.size() > kInsideNamed) {
    std::fprintf(stderr, "rheofeed: %s, %s: ... and %zu more parts inside a fixture (run JSON)\n",
                 scene_name_.c_str(), toString(sim.method()),
                 h.inside_fixture_now.size() - kInsideNamed);
  }
  if (h.local_law_feeders > 0) {
    const LocalDriftStats& l = h.local_law;
    std::fprintf(stderr,
                 "rheofeed: %s, %s: local vibration law on %d feeder(s): %lld contacts driven "
                 "(%lld on walls or steep faces), %lld drift table cells, %lld point-mass runs "
                 "(%.3g s of CPU; %lld table corners known at the start)\n",
                 scene_name_.c_str(), toString(sim.method()), h.local_law_feeders,
                 static_cast<long long>(l.contacts), static_cast<long long>(l.wall_contacts),
                 static_cast<long long>(l.cells_computed), static_cast<long long>(l.model_runs),
                 l.model_cpu_seconds, static_cast<long long>(h.local_law_corners_at_start));
  }
}

std::string healthSummary(const RunHealth& h, int parts) {
  if (!h.anything()) return "nothing lost";
  std::ostringstream s;
  const char* separator = "";
  if (h.partsLost() > 0) {
    s << h.partsLost() << " of " << parts << " parts lost (";
    const std::pair<const char*, int> kinds[] = {{"fell", h.parts_fell},
                                                 {"through a fixture", h.parts_through_fixture},
                                                 {"left the feeder", h.parts_left_feeder},
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
      s << ", max speed " << h.max_part_speed << " m/s (blow-up bound " << h.speed_bound
        << " m/s), up to " << h.max_speed_ratio << " x a part's physical bound";
    }
    separator = "; ";
  }
  if (h.parts_sunk > 0) {
    s << separator << h.parts_sunk << (h.parts_sunk == 1 ? " part" : " parts")
      << " sank into a fixture (deeper than half their size, or a hollow part deeper than the "
      << "point it is followed by lies in its material) and came back";
    separator = "; ";
  }
  if (h.passes_stopped > 0) {
    s << separator << h.passes_stopped << (h.passes_stopped == 1 ? " pass" : " passes")
      << " through a fixture within a step stopped, the part put back (not lost)";
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
    if (h.ipm_second_solve_steps > 0) {
      s << " (" << h.ipm_second_solve_steps << " left unconverged by NSGS were solved again by "
        << "the interior-point fixed point and NSGS in turn, " << h.ipm_converged_steps
        << " of them converged)";
    }
    if (h.ipm_not_run_steps > 0) {
      s << " (" << h.ipm_not_run_steps << " of them without the interior-point rounds: too "
        << "many contacts or refused)";
    }
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

}  // namespace rheofeed::scene

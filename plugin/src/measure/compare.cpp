// SPDX-License-Identifier: MIT
#include "rheofeed/measure/compare.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <ctime>

namespace rheofeed::scene {

RunSummary runScene(const Scene& scene, Method method, int impulse_window) {
  const std::clock_t start = std::clock();
  std::unique_ptr<Simulation> sim = makeSimulation(scene, method);
  const long steps = std::lround(scene.duration / scene.solver.time_step);
  RunSummary r;
  r.method = method;
  int window = 0;
  for (long k = 0; k < steps; ++k) {
    sim->step();
    if (k >= steps - impulse_window) {
      const ContactTotals t = sim->contactTotals();
      r.normal_impulse += t.normal_impulse;
      r.impulse = r.impulse + t.impulse;
      ++window;
    }
  }
  if (window > 0) {
    r.normal_impulse /= window;
    r.impulse = (1.0 / window) * r.impulse;
  }
  r.parts = sim->numParts();
  for (int i = 0; i < r.parts; ++i) {
    const PartState s = sim->part(i);
    r.states.push_back(s);
    r.mean_velocity = r.mean_velocity + s.velocity;
    r.mean_position = r.mean_position + s.position;
    r.mean_angular_speed += norm(s.angular_velocity);
  }
  if (r.parts > 0) {
    r.mean_velocity = (1.0 / r.parts) * r.mean_velocity;
    r.mean_position = (1.0 / r.parts) * r.mean_position;
    r.mean_angular_speed /= r.parts;
  }
  r.cpu_seconds = double(std::clock() - start) / CLOCKS_PER_SEC;
  return r;
}

Comparison compare(const Scene& scene, Method a, Method b, int impulse_window) {
  Comparison c;
  c.scene = scene.name;
  c.a = runScene(scene, a, impulse_window);
  c.b = runScene(scene, b, impulse_window);
  const std::size_t n = std::min(c.a.states.size(), c.b.states.size());
  for (std::size_t i = 0; i < n; ++i) {
    c.max_velocity_difference =
        std::max(c.max_velocity_difference, norm(c.a.states[i].velocity - c.b.states[i].velocity));
    c.max_position_difference =
        std::max(c.max_position_difference, norm(c.a.states[i].position - c.b.states[i].position));
  }
  c.mean_velocity_difference = norm(c.a.mean_velocity - c.b.mean_velocity);
  const double j = std::max(std::abs(c.a.normal_impulse), std::abs(c.b.normal_impulse));
  c.normal_impulse_difference = j > 0 ? std::abs(c.a.normal_impulse - c.b.normal_impulse) / j : 0;
  return c;
}

}  // namespace rheofeed::scene

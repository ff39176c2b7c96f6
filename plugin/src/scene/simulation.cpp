// SPDX-License-Identifier: MIT
#include "rheofeed/scene/simulation.hpp"

#include <cmath>
#include <sstream>
#include <stdexcept>

#include "simulation_internal.hpp"

namespace rheofeed::scene {

void checkPart(int index, const Vec3& x, Method method, double time) {
  constexpr double kSceneRadius = 1e4;  // m: nothing in a feeder scene gets this far
  if (isFinite(x) && std::abs(x.x) < kSceneRadius && std::abs(x.y) < kSceneRadius &&
      std::abs(x.z) < kSceneRadius) {
    return;
  }
  std::ostringstream out;
  out << toString(method) << ": part " << index << " is at (" << x.x << ", " << x.y << ", " << x.z
      << ") m at t = " << time
      << " s: the step is unstable (reduce solver.time_step, raise solver.iterations, or check "
         "for parts spawned inside fixtures)";
  throw std::runtime_error(out.str());
}

PartSimulation::PartSimulation(const Scene& scene, Method method)
    : scene_(scene), method_(method), instances_(drawParts(scene)) {}

void PartSimulation::spawnDue() {
  while (next_ < instances_.size() && instances_[next_].spawn_time <= time_ + 1e-12) {
    addPart(instances_[next_++]);
    active_.push_back(true);
  }
}

void PartSimulation::step() {
  const double h = scene_.solver.time_step;
  advance(h);
  time_ = ++steps_ * h;
  for (std::size_t i = 0; i < active_.size(); ++i) {
    if (!active_[i]) continue;
    const Vec3 x = partState(static_cast<int>(i)).position;
    checkPart(static_cast<int>(i), x, method_, time_);
    if (x.z < scene_.removal_height) {  // left the scene: out of the simulation for good
      removePart(static_cast<int>(i));
      active_[i] = false;
    }
  }
  totals_ = fixtureImpulses(h);
  spawnDue();
}

PartState PartSimulation::part(int index) const {
  PartState s = partState(index);
  s.active = active_.at(static_cast<std::size_t>(index));
  return s;
}

double PartSimulation::partMass(int index) const {
  return instances_.at(static_cast<std::size_t>(index)).mass;
}

std::unique_ptr<Simulation> makeSimulation(const Scene& scene, Method method) {
  scene.validate();
  if (method == Method::OdeRheonomic || method == Method::OdeFullVibration) {
    return makeOdeSimulation(scene, method);
  }
  return makeReferenceSimulation(scene, method);
}

}  // namespace rheofeed::scene

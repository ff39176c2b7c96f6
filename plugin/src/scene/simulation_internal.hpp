// SPDX-License-Identifier: MIT
// Internal: the two engines' factories and helpers shared by them.
#pragma once

#include <ode/ode.h>

#include <memory>
#include <unordered_set>
#include <vector>

#include "rheofeed/scene/simulation.hpp"

namespace rheofeed::scene {

/// What the ODE and the reference simulations share: the parts drawn from the scene, spawning
/// them when due, taking out those below Scene::removal_height, refusing unstable states, time
/// keeping. An engine implements the hooks; its constructor builds the fixtures and then calls
/// spawnDue().
class PartSimulation : public Simulation {
 public:
  void step() final;
  double time() const final { return time_; }
  int numParts() const final { return static_cast<int>(active_.size()); }
  PartState part(int index) const final;
  double partMass(int index) const final;
  ContactTotals contactTotals() const final { return totals_; }
  Method method() const final { return method_; }
  const RunHealth& health() const final { return health_; }

 protected:
  PartSimulation(const Scene& scene, Method method);
  /// Creates the parts whose spawn time has come.
  void spawnDue();
  /// One dynamics step of h seconds.
  virtual void advance(double h) = 0;
  /// Adds a part (its index is numParts() before the call).
  virtual void addPart(const PartInstance& part) = 0;
  /// The state of part `index` (the `active` flag is filled in by part()).
  virtual PartState partState(int index) const = 0;
  /// Takes part `index` out of the simulation for good.
  virtual void removePart(int index) = 0;
  /// Impulses from fixtures on parts during the last step of h seconds.
  virtual ContactTotals fixtureImpulses(double h) const = 0;
  /// Whether `geom` belongs to a fixture (for fixtureImpulses).
  bool isFixture(dGeomID geom) const { return fixture_geoms_.count(geom) != 0; }
  void addFixtureGeom(dGeomID geom) { fixture_geoms_.insert(geom); }

  const Scene scene_;
  RunHealth health_;

 private:
  const Method method_;
  const std::vector<PartInstance> instances_;
  std::size_t next_ = 0;
  std::vector<bool> active_;
  std::unordered_set<dGeomID> fixture_geoms_;
  double time_ = 0;
  long steps_ = 0;
  ContactTotals totals_;
};

std::unique_ptr<Simulation> makeOdeSimulation(const Scene& scene, Method method);
std::unique_ptr<Simulation> makeReferenceSimulation(const Scene& scene, Method method);

/// Throws std::runtime_error if part `index` at position `x` (m) is non-finite or beyond
/// 1e4 m: an unstable step, caught before ODE's collision asserts on it.
void checkPart(int index, const Vec3& x, Method method, double time);

}  // namespace rheofeed::scene

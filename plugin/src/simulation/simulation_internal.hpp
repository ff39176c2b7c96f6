// SPDX-License-Identifier: MIT
// Internal: the two engines' factories and helpers shared by them.
#pragma once

#include <ode/ode.h>

#include <memory>
#include <string>
#include <unordered_map>
#include <unordered_set>
#include <vector>

#include "rheofeed/simulation/simulation.hpp"

namespace rheofeed::scene {

/// A contact of a part with a fixture geom in the last step (RunHealth, "Left the feeder").
struct FixtureContact {
  dGeomID part = nullptr, fixture = nullptr;
  Vec3 normal_on_part;  ///< unit contact normal pushing the part (world)
};

/// Smallest half-size (m) and bounding radius about the centre of mass (m) of a part of shape
/// `s` (a mesh: of its bounding box and its farthest vertex; 0 for a plane).
void partSizes(const Shape& s, double& min_half, double& radius);

/// What the ODE and the reference simulations share: the parts drawn from the scene, spawning
/// them when due, the checks after each step that take out and count lost parts (RunHealth),
/// the tunnelling test against the fixture geoms, time keeping. An engine implements the
/// hooks; its constructor builds the fixtures (registering each geom with addFixtureGeom) and
/// then calls spawnDue().
class PartSimulation : public Simulation {
 public:
  ~PartSimulation() override;
  void step() final;
  double time() const final { return time_; }
  int numParts() const final { return static_cast<int>(tracks_.size()); }
  PartState part(int index) const final;
  double partMass(int index) const final;
  ContactTotals contactTotals() const final { return totals_; }
  Method method() const final { return method_; }
  const RunHealth& health() const final { return health_; }
  const AppliedSolver& appliedSolver() const final { return applied_; }
  bool partLost(int index) const final { return tracks_.at(static_cast<std::size_t>(index)).lost; }
  void setStageTiming(bool on) final { stage_timing_ = on; }
  const StageTimes& stageTimes() const final { return stage_times_; }

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
  /// Takes part `index` out of the simulation for good; `last` is a finite state the engine
  /// may park it in (its state may be non-finite).
  virtual void removePart(int index, const PartState& last) = 0;
  /// Impulses from fixtures on parts during the last step of h seconds.
  virtual ContactTotals fixtureImpulses(double h) const = 0;
  /// The contacts of parts with fixtures in the last step (either geom order).
  virtual std::vector<FixtureContact> fixtureContacts() const = 0;
  /// Whether `geom` belongs to a fixture (for fixtureImpulses).
  bool isFixture(dGeomID geom) const { return fixture_set_.count(geom) != 0; }
  /// Registers a geom (placed at its rest pose) of fixture `fixture` (index in Scene::fixtures)
  /// for isFixture, the tunnelling test and the feeder contacts.
  void addFixtureGeom(dGeomID geom, int fixture);
  /// Registers the geom of part `index` (for fixtureContacts).
  void addPartGeom(dGeomID geom, int index) { part_of_geom_[geom] = index; }
  /// Lists a setting the engine ignores (health_.ignored_settings) and prints it on stderr.
  void ignoreSetting(const std::string& message);
  /// Prints one line on stderr the first time `kind` (a short name) is seen in this run.
  void reportFirst(const std::string& kind, const std::string& line);
  /// The law of fixture `fixture` in a rheonomic run (rheonomicLaw); a local law is
  /// remembered, and its counts are summed into health_.local_law after every step.
  MotionLaw feederLaw(int fixture);
  /// The efficiency factor of part family `spec` on the local-law feeders (partEfficiencies;
  /// 1 in full-vibration runs and without local_sampled feeders). Engines set it on a part
  /// that is not 1 (FeederSet::setPartEfficiency, World::setBodyEfficiency).
  double partEfficiency(int spec) const;
  /// The engine found part `index` non-finite and took it out itself (the reference world
  /// disables such a body at its last finite pose): the next check counts it as non-finite.
  void markNonFinite(int index);

  const Scene scene_;
  const std::vector<std::string> family_keys_ = familyKeys(scene_.parts);  // familyName
  RunHealth health_;
  /// Filled by the engine's constructor (appliedSolver).
  AppliedSolver applied_;
  /// Stage timing (Simulation::setStageTiming): engines add their stages' seconds and contact
  /// counts to stage_times_ only while stageTiming() is true; StageClock reads no clock when
  /// given nullptr (`stageTiming() ? &stage_times_.solve : nullptr`).
  bool stageTiming() const { return stage_timing_; }
  StageTimes stage_times_;

 private:
  struct Track {
    PartState last;  // state after the previous check (finite)
    // The point the tunnelling test follows (partAnchor): body frame (m); off_centre when it is
    // not the centre of mass (the messages then name it); its clearance (m).
    Vec3 anchor;
    bool off_centre = false;
    double clearance = 0;
    double radius = 0;  // bounding radius about the centre of mass (m)
    bool active = true;
    bool engine_nonfinite = false;  // the engine reported the state non-finite (markNonFinite)
    bool beyond_exit = false;       // has been beyond the exit plane
    bool counted = false;           // counted in a RunHealth loss (or as an exit) already
    bool lost = false;              // counted in a RunHealth loss (partLost)
    bool sunk_counted = false;      // counted in parts_sunk already
    // Anchor inside a fixture: where it entered (m) and the entry surface's outward normal.
    bool inside = false;
    Vec3 entry_point, entry_normal;
    int entry_fixture = -1;        // the fixture it went into (index in the scene), -1 unknown
    dGeomID entry_geom = nullptr;  // ... and the geom
    Vec3 outside_point;            // the last anchor outside before it went in (m)
    double entry_time = 0;         // when it went in (s)
    // Left the feeder (RunHealth): touched a feeder; fixtures that supported it before that;
    // a fixture not among its carriers supported it in the last step.
    bool on_feeder = false;
    std::vector<int> carriers;
    int stranger = -1;
  };
  // A fixture geom's footprint box at rest (empty: none, a plane or a mesh not loaded) and its
  // vibration reach (m).
  struct Footprint {
    Bounds box;
    double reach = 0;
  };
  // Records feeder contacts and supports of the last step (Track::on_feeder, carriers, stranger).
  void noteContacts();
  // Whether part i has left the feeder (RunHealth rule); `where` receives how.
  bool leftFeeder(std::size_t i, const PartState& s, std::string& where) const;
  // The physical speed check of part i in state s (counts and reports; keeps it).
  void checkPhysicalSpeed(std::size_t i, const PartState& s);
  // Distance (m) from a along the segment a -> b to the first fixture surface it crosses
  // (ODE ray test at the geoms' current poses); infinity when it crosses none. `normal`
  // (optional) receives the surface normal there (unit, either orientation), `fixture` and
  // `geom` (optional) the index of the fixture crossed and its geom.
  double firstCrossing(const Vec3& a, const Vec3& b, Vec3* normal = nullptr, int* fixture = nullptr,
                       dGeomID* geom = nullptr);
  // Whether point x is inside a fixture geom whose inside ODE can test exactly (box, sphere,
  // capsule, plane: yes/no); `unknown` is set when x lies in the bounding box of a geom it cannot
  // test (cylinder, mesh), where the ray parity of trackCrossings decides instead.
  bool insideFixture(const Vec3& x, bool* unknown) const;
  // Where part i's anchor is (m, world) in state s: position + R anchor.
  Vec3 anchorAt(std::size_t i, const PartState& s) const;
  // The tunnelling test of part i, whose anchor moved from `from` to `to` (m, world) in a step
  // that left it in state s (simulation.cpp).
  void trackCrossings(std::size_t i, const Vec3& from, const Vec3& to, const PartState& s);
  // Takes part i out, parked at `park`, and counts it under `check` (unless counted already);
  // `state` is the state that failed the check.
  void remove(std::size_t i, PartCheck check, const PartState& state, const PartState& park);
  // Counts part i under `counter` unless it was counted already; reports the first of `kind`
  // and records the event (RunHealth::part_events) under `key`.
  void countLoss(std::size_t i, const char* key, const std::string& kind, const std::string& what,
                 int& counter, const PartState& state);
  // The family name of part i (PartSpec::name of its spec).
  const std::string& familyName(std::size_t i) const;
  // Appends an event to RunHealth::part_events (or counts it dropped beyond the cap).
  void recordEvent(std::size_t i, const char* key, const std::string& what, const PartState& state);

  const Method method_;
  const std::vector<PartInstance> instances_;
  std::unordered_map<int, PartAnchor> unit_anchors_;  // by part family: partAnchor at scale 1
  // The distinct drift tables of the local-law feeders (feeders and runs may share one) and their
  // counts when this run took them: the run reports the difference.
  std::vector<std::pair<std::shared_ptr<LocalDriftTable>, LocalDriftStats>> local_tables_;
  std::vector<double> part_efficiency_;  // per part family; empty in full-vibration runs
  const SceneLimits limits_;
  std::size_t next_ = 0;
  std::vector<Track> tracks_;
  std::unordered_set<dGeomID> fixture_set_;  // lookups only: never iterated
  std::vector<dGeomID> fixture_geoms_;       // in creation order (deterministic iteration)
  std::unordered_map<dGeomID, int> fixture_of_geom_, part_of_geom_;  // lookups only
  std::vector<std::vector<Footprint>> footprints_;                   // per fixture, per geom
  std::vector<int> feeders_;                                         // fixtures with a law
  Vec3 up_{0, 0, 1};                                                 // -gravity, unit
  double top_spawn_height_ = 0;  // the highest spawn point along up_ (m; physical speed bound)
  dGeomID ray_ = nullptr;        // for firstCrossing, in no space
  std::vector<std::string> reported_;  // kinds already reported on stderr
  double time_ = 0;
  long steps_ = 0;
  ContactTotals totals_;
  bool stage_timing_ = false;
};

/// "(x, y, z) m" with 6 significant digits (stderr reports).
std::string formatPosition(const Vec3& x);

/// Axis-aligned bounding box (m, world) of a fixture geom at its pose; empty (min > max) for a
/// plane or a mesh that is not loaded. Shared by the scene limits and the scene check.
Bounds fixtureGeomBounds(const Fixture::Geom& g);

std::unique_ptr<Simulation> makeOdeSimulation(const Scene& scene, Method method);
std::unique_ptr<Simulation> makeReferenceSimulation(const Scene& scene, Method method);

}  // namespace rheofeed::scene

// SPDX-License-Identifier: MIT
// A scene run in ODE: stationary feeders driven by the plugin (rheonomic), or feeders on
// kinematic bodies that really vibrate (full vibration; NOTES section 2 and 4: each step the
// body is put on its law at t and given the secant velocity to its pose at t + h).
//
// Determinism: quickstep reorders its constraint rows at random with ODE's process-wide
// generator (dRand). Each simulation keeps its own generator state, seeded from Scene::seed,
// and swaps it in around its collide + step only (simulation.hpp, makeSimulation).
#include <ode/ode.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <memory>
#include <sstream>
#include <stdexcept>

#include "geom_factory.hpp"
#include "ode_vec.hpp"
#include "rheofeed/collision_space.hpp"
#include "rheofeed/contact_collider.hpp"
#include "rheofeed/feeder_set.hpp"
#include "rheofeed/reference/world.hpp"
#include "simulation_internal.hpp"
#include "stage_clock.hpp"

namespace rheofeed::scene {
namespace {

class OdeSimulation final : public PartSimulation {
 public:
  OdeSimulation(const Scene& scene, Method method) : PartSimulation(scene, method) {
    static const bool initialised = (dInitODE2(0), true);
    (void)initialised;
    // First: a broad phase this ODE cannot give is refused before anything is allocated.
    space_ = rheofeed::createCollisionSpace(nullptr, scene.solver.broad_phase);
    world_ = dWorldCreate();
    dWorldSetGravity(world_, scene.gravity.x, scene.gravity.y, scene.gravity.z);
    dWorldSetERP(world_, scene.solver.erp);
    dWorldSetCFM(world_, scene.solver.cfm);
    dWorldSetQuickStepNumIterations(world_, scene.solver.iterations);
    dWorldSetContactMaxCorrectingVel(world_, scene.solver.max_correcting_velocity);
    dWorldSetContactSurfaceLayer(world_, scene.solver.surface_layer);
    const FrictionModel friction = odeFrictionModel(scene.solver);
    health_.friction_model = toString(friction);
    health_.broad_phase = toString(broadPhaseOf(space_));
    FeederSet::Options options;
    options.friction = friction;
    feeders_ = std::make_unique<FeederSet>(options);

    for (std::size_t fi = 0; fi < scene.fixtures.size(); ++fi) {
      const Fixture& f = scene.fixtures[fi];
      const bool vibrates = isFullVibration(method) && f.law.kind == FeederLaw::Kind::Vibration;
      dBodyID body = nullptr;
      if (vibrates) {
        body = dBodyCreate(world_);
        dBodySetKinematic(body);
        vibrating_.push_back({body, f.law.vibration});
      }
      MotionLaw law;  // one law per fixture: its geoms share the local law's table
      if (!body && f.law.kind != FeederLaw::Kind::None) law = feederLaw(static_cast<int>(fi));
      for (const Fixture::Geom& g : f.geoms) {
        dGeomID geom = createGeom(space_, g.shape, meshes_);
        if (g.shape.kind != Shape::Kind::Plane) setGeomPose(geom, g.pose);
        if (body) {
          dGeomSetBody(geom, body);
          dGeomSetOffsetWorldPosition(geom, g.pose.position.x, g.pose.position.y,
                                      g.pose.position.z);
          dMatrix3 r;
          toOdeMatrix(g.pose.rotation, r);
          dGeomSetOffsetWorldRotation(geom, r);
        } else if (f.law.kind != FeederLaw::Kind::None) {
          feeders_->add(geom, law);
        }
        addFixtureGeom(geom, static_cast<int>(fi));
      }
    }

    ContactCollider::Settings cs;
    cs.feedback = true;
    cs.friction = friction;
    cs.speculative = scene.solver.speculative_contacts.value_or(true);
    cs.clamp_passes = cs.speculative;
    cs.warm_start = odeWarmStartsContacts(scene);
    collider_ = std::make_unique<ContactCollider>(world_, *feeders_, cs);
    const double mu = scene.material.mu, bounce = scene.material.restitution;
    const int mode =
        withFrictionModel(dContactApprox1 | (bounce > 0 ? dContactBounce : 0), friction);
    collider_->setSurfaceCallback([mu, bounce, mode](dGeomID, dGeomID, dContact* c, int n) {
      for (int i = 0; i < n; ++i) {
        c[i].surface.mode = mode;
        c[i].surface.mu = mu;
        c[i].surface.bounce = bounce;
        c[i].surface.bounce_vel = 0;
      }
      return true;
    });
    rows_per_contact_ = mu > 0 ? 3 : 1;
    recordApplied(cs, mu, bounce);
    random_state_ = randomSeed(scene.seed);
    listIgnoredSettings();
    spawnDue();
  }

  ~OdeSimulation() override {
    collider_.reset();
    dSpaceDestroy(space_);
    dWorldDestroy(world_);
  }

  // The time at the start of the step is needed by the kinematic law and the plugin.
  // Stage timing (StageTimes): collision is collide() less the collider's contact creation.
  void advance(double h) override {
    const double t = time();
    StageTimes& times = stage_times_;
    const bool timing = stageTiming();
    collider_->setContactTimer(timing ? &times.contacts : nullptr);
    const double contacts_before = times.contacts;
    {
      const StageClock solve(timing ? &times.solve : nullptr);
      for (const auto& [body, vibration] : vibrating_) driveKinematic(body, vibration, t, h);
    }
    const unsigned long outside = dRandGetSeed();  // the application's generator state
    dRandSetSeed(random_state_);
    {
      double collide_seconds = 0;
      {
        const StageClock collide(timing ? &collide_seconds : nullptr);
        collider_->collide(space_, t, h);  // laws frozen on [t, t + h] (secant surface velocity)
      }
      health_.speculative_contacts += collider_->speculativeContactCount();
      health_.warm_started_contacts += collider_->warmStartedContactCount();
      times.collision += collide_seconds - (times.contacts - contacts_before);
    }
    {
      const StageClock solve(timing ? &times.solve : nullptr);
      if (scene_.solver.ode_quickstep) {
        dWorldQuickStep(world_, h);
      } else {
        dWorldStep(world_, h);
      }
    }
    random_state_ = dRandGetSeed();
    dRandSetSeed(outside);
    for (const ContactCollider::ThroughPass& p : collider_->stopPassesThroughStaticGeoms()) {
      ++health_.passes_stopped;
      if (health_.passes_stopped == 1) {
        const auto it = std::find(parts_.begin(), parts_.end(), p.body);
        std::ostringstream line;
        line << "part " << (it - parts_.begin()) << "'s centre passed through a fixture within "
             << "the step to t = " << t + h << " s, from " << formatPosition(p.from) << " to "
             << formatPosition(p.to) << ": put back where it was, its velocity into the "
             << "fixture and its spin removed (not lost; a part stopped in one step is not "
             << "stopped in the next)";
        reportFirst("stopped pass", line.str());
      }
    }
    if (timing) {
      times.contact_count += collider_->contactCount();
      times.constraint_rows += long(collider_->contactCount()) * rows_per_contact_;
    }
  }

  PartState partState(int i) const override {
    dBodyID b = parts_.at(static_cast<std::size_t>(i));
    PartState s;
    s.position = toVec3(dBodyGetPosition(b));
    s.velocity = toVec3(dBodyGetLinearVel(b));
    s.angular_velocity = toVec3(dBodyGetAngularVel(b));
    fromOdeMatrix(dBodyGetRotation(b), s.rotation);
    return s;
  }

  // The body is parked at `last` (finite) with no velocity, so that no NaN reaches ODE again.
  void removePart(int i, const PartState& last) override {
    dBodyID b = parts_.at(static_cast<std::size_t>(i));
    dBodySetPosition(b, last.position.x, last.position.y, last.position.z);
    dMatrix3 r;
    toOdeMatrix(last.rotation, r);
    dBodySetRotation(b, r);
    dBodySetLinearVel(b, 0, 0, 0);
    dBodySetAngularVel(b, 0, 0, 0);
    dBodyDisable(b);
    dGeomDisable(dBodyGetFirstGeom(b));
  }

 private:
  // ODE's generator is 32 bits wide: the scene seed mixed (splitmix64) and cut to 32 bits.
  static unsigned long randomSeed(std::uint64_t seed) {
    std::uint64_t z = seed + 0x9e3779b97f4a7c15ULL;
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
    return static_cast<unsigned long>((z ^ (z >> 31)) & 0xffffffffULL);
  }

  // What the world and the collider took (AppliedSolver): the world's settings read back from
  // ODE (in its precision), the collider's as given, the surface as the callback sets it.
  void recordApplied(const ContactCollider::Settings& cs, double mu, double bounce) {
    AppliedSolver& a = applied_;
    a.engine = "ode";
    a.mode = scene_.solver.ode_quickstep ? "quickstep" : "world_step";
    if (scene_.solver.ode_quickstep) a.iterations = dWorldGetQuickStepNumIterations(world_);
    a.warm_start = cs.warm_start;
    a.speculative_contacts = cs.speculative;
    a.erp = dWorldGetERP(world_);
    a.cfm = dWorldGetCFM(world_);
    a.max_correcting_velocity = dWorldGetContactMaxCorrectingVel(world_);
    a.surface_layer = dWorldGetContactSurfaceLayer(world_);
    a.mu = mu;
    a.restitution = bounce;
    a.bounce_velocity = 0;
  }

  // Settings of the scene ODE does not read, when they differ from their defaults.
  void listIgnoredSettings() {
    const SolverSettings defaults;
    const SolverSettings& s = scene_.solver;
    auto ignored = [this](const char* name, const auto& value, const char* why) {
      std::ostringstream line;
      line << std::boolalpha << "solver." << name << " = " << value << ": ignored by ODE (" << why
           << ")";
      ignoreSetting(line.str());
    };
    if (s.coulomb_iterations != defaults.coulomb_iterations) {
      ignored("coulomb_iterations", s.coulomb_iterations, "reference solver only");
    }
    if (s.tolerance != defaults.tolerance) {
      ignored("tolerance", s.tolerance, "reference solver only; quickstep runs its iterations");
    }
    if (s.apgd != defaults.apgd) ignored("apgd", s.apgd, "reference solver only");
    if (!s.ode_quickstep && s.iterations != defaults.iterations) {
      ignored("iterations", s.iterations, "ode_quickstep = false: dWorldStep is a direct solver");
    }
    if (!s.ode_quickstep && s.warm_start.value_or(false)) {
      ignored("warm_start", true, "ode_quickstep = false: dWorldStep is a direct solver");
    }
  }

  // Puts the kinematic body on its law at t and gives it the secant velocity to t + h.
  static void driveKinematic(dBodyID body, const Vibration& v, double t, double h) {
    const Pose p0 = v.displacement(t), p1 = v.displacement(t + h);
    dBodySetPosition(body, p0.position.x, p0.position.y, p0.position.z);
    dMatrix3 r;
    toOdeMatrix(p0.rotation, r);
    dBodySetRotation(body, r);
    const Vec3 lin = (1.0 / h) * (p1.position - p0.position);
    dBodySetLinearVel(body, lin.x, lin.y, lin.z);
    const Vec3 ang = secantAngularVelocity(p0, p1, h);
    dBodySetAngularVel(body, ang.x, ang.y, ang.z);
  }

  void addPart(const PartInstance& p) override {
    dBodyID b = dBodyCreate(world_);
    dMass m;
    dMassSetParameters(&m, p.mass, 0, 0, 0, p.inertia[0], p.inertia[4], p.inertia[8], p.inertia[1],
                       p.inertia[2], p.inertia[5]);
    dBodySetMass(b, &m);
    dBodySetPosition(b, p.pose.position.x, p.pose.position.y, p.pose.position.z);
    dMatrix3 r;
    toOdeMatrix(p.pose.rotation, r);
    dBodySetRotation(b, r);
    dBodySetLinearVel(b, p.velocity.x, p.velocity.y, p.velocity.z);
    dGeomID geom = createGeom(space_, p.shape, meshes_);
    dGeomSetBody(geom, b);
    addPartGeom(geom, static_cast<int>(parts_.size()));
    const double efficiency = partEfficiency(p.spec);
    if (efficiency != 1.0) feeders_->setPartEfficiency(b, efficiency);
    parts_.push_back(b);
  }

  ContactTotals fixtureImpulses(double h) const override {
    ContactTotals totals;
    for (const ContactCollider::Joint& j : collider_->joints()) {
      const bool f1 = isFixture(j.g1), f2 = isFixture(j.g2);
      if (f1 == f2 || !j.feedback) continue;  // part-part or fixture-fixture
      const dGeomID part = f1 ? j.g2 : j.g1;
      // f1 acts on the joint's first body (Joint::first_body_is_g1 says whose), which is the
      // part whenever the fixture has no body; dJointGetBody(joint, 0) would not do: on a joint
      // attached with a null first body it returns that null, whose f2 is zero.
      const bool f1_on_part = (part == j.g1) == j.first_body_is_g1;
      const dReal* f = f1_on_part ? j.feedback->f1 : j.feedback->f2;
      const Vec3 impulse = h * toVec3(f);
      const Vec3 n_into_part = part == j.g1 ? j.normal : -j.normal;
      ++totals.count;
      totals.normal_impulse += dot(impulse, n_into_part);
      totals.impulse = totals.impulse + impulse;
    }
    return totals;
  }

  std::vector<FixtureContact> fixtureContacts() const override {
    std::vector<FixtureContact> out;
    for (const ContactCollider::Joint& j : collider_->joints()) {
      const bool f1 = isFixture(j.g1), f2 = isFixture(j.g2);
      if (f1 == f2) continue;  // part-part or fixture-fixture
      out.push_back(f1 ? FixtureContact{j.g2, j.g1, -j.normal}
                       : FixtureContact{j.g1, j.g2, j.normal});
    }
    return out;
  }

  TriMeshStore meshes_;  // trimesh data of the mesh geoms; outlives space_ (see the destructor)
  dWorldID world_;
  dSpaceID space_;
  std::unique_ptr<FeederSet> feeders_;
  std::unique_ptr<ContactCollider> collider_;
  std::vector<std::pair<dBodyID, Vibration>> vibrating_;
  std::vector<dBodyID> parts_;
  unsigned long random_state_ = 0;  // this simulation's state of ODE's generator
  // Constraint rows of one contact joint (StageTimes::constraint_rows): every contact gets the
  // scene's mu (the surface callback), so 1 normal row plus 2 friction rows when mu > 0.
  int rows_per_contact_ = 1;
};

}  // namespace

std::unique_ptr<Simulation> makeOdeSimulation(const Scene& scene, Method method) {
  return std::make_unique<OdeSimulation>(scene, method);
}

}  // namespace rheofeed::scene

// SPDX-License-Identifier: MIT
// A scene run in the reference world (rheofeed::reference::World, cone complementarity).
#include <memory>
#include <unordered_set>

#include "geom_factory.hpp"
#include "rheofeed/reference/world.hpp"
#include "simulation_internal.hpp"

namespace rheofeed::scene {
namespace {

using reference::BodyId;

class ReferenceSimulation final : public PartSimulation {
 public:
  ReferenceSimulation(const Scene& scene, Method method) : PartSimulation(scene, method) {
    reference::Settings s;
    s.gravity = scene.gravity;
    s.erp = scene.solver.erp;
    s.cfm = scene.solver.cfm;
    s.default_mu = scene.material.mu;
    s.solver.method = scene.solver.apgd ? ccp::Method::Apgd : ccp::Method::Pgs;
    s.solver.max_iterations = scene.solver.iterations;
    s.solver.tolerance = scene.solver.tolerance;
    s.solver.coulomb_outer_iterations = scene.solver.coulomb_iterations;
    s.max_correcting_velocity = scene.solver.max_correcting_velocity;
    s.surface_layer = scene.solver.surface_layer;
    world_ = std::make_unique<reference::World>(s);

    for (const Fixture& f : scene.fixtures) {
      const bool vibrates = isFullVibration(method) && f.law.kind == FeederLaw::Kind::Vibration;
      BodyId body = reference::kStatic;
      if (vibrates) {
        const Vibration v = f.law.vibration;
        body = world_->addKinematicBody([v](double t) { return v.displacement(t); });
      }
      for (const Fixture::Geom& g : f.geoms) {
        dGeomID geom = createGeom(world_->space(), g.shape, meshes_);
        if (g.shape.kind != Shape::Kind::Plane) setGeomPose(geom, g.pose);
        if (body != reference::kStatic) {
          world_->attachGeom(geom, body, g.pose);  // the body's rest pose is the identity
        } else if (f.law.kind != FeederLaw::Kind::None) {
          world_->setFeeder(geom, rheonomicLaw(f));
        }
        addFixtureGeom(geom);
      }
    }
    spawnDue();
  }

  void advance(double h) override { world_->step(h); }

  void removePart(int i) override { world_->disableBody(parts_.at(static_cast<std::size_t>(i))); }

  PartState partState(int i) const override {
    const reference::BodyState& b = world_->state(parts_.at(static_cast<std::size_t>(i)));
    PartState s;
    s.position = b.position;
    s.velocity = b.linear_velocity;
    s.angular_velocity = b.angular_velocity;
    const reference::Quat& q = b.orientation;
    double* r = s.rotation;
    r[0] = 1 - 2 * (q.y * q.y + q.z * q.z);
    r[1] = 2 * (q.x * q.y - q.z * q.w);
    r[2] = 2 * (q.x * q.z + q.y * q.w);
    r[3] = 2 * (q.x * q.y + q.z * q.w);
    r[4] = 1 - 2 * (q.x * q.x + q.z * q.z);
    r[5] = 2 * (q.y * q.z - q.x * q.w);
    r[6] = 2 * (q.x * q.z - q.y * q.w);
    r[7] = 2 * (q.y * q.z + q.x * q.w);
    r[8] = 1 - 2 * (q.x * q.x + q.y * q.y);
    return s;
  }

 private:
  void addPart(const PartInstance& p) override {
    reference::BodyState state;
    state.position = p.pose.position;
    state.linear_velocity = p.velocity;
    state.orientation = quatOf(p.pose);
    const BodyId body = world_->addBody(p.mass, p.inertia, state);
    world_->attachGeom(createGeom(world_->space(), p.shape, meshes_), body);
    parts_.push_back(body);
  }

  static reference::Quat quatOf(const Pose& pose) {
    const double* m = pose.rotation;
    reference::Quat q;
    const double tr = m[0] + m[4] + m[8];
    if (tr > 0) {
      const double s = 0.5 / std::sqrt(tr + 1.0);
      q = {0.25 / s, (m[7] - m[5]) * s, (m[2] - m[6]) * s, (m[3] - m[1]) * s};
    } else if (m[0] > m[4] && m[0] > m[8]) {
      const double s = 2.0 * std::sqrt(1.0 + m[0] - m[4] - m[8]);
      q = {(m[7] - m[5]) / s, 0.25 * s, (m[1] + m[3]) / s, (m[2] + m[6]) / s};
    } else if (m[4] > m[8]) {
      const double s = 2.0 * std::sqrt(1.0 + m[4] - m[0] - m[8]);
      q = {(m[2] - m[6]) / s, (m[1] + m[3]) / s, 0.25 * s, (m[5] + m[7]) / s};
    } else {
      const double s = 2.0 * std::sqrt(1.0 + m[8] - m[0] - m[4]);
      q = {(m[3] - m[1]) / s, (m[2] + m[6]) / s, (m[5] + m[7]) / s, 0.25 * s};
    }
    return q;
  }

  ContactTotals fixtureImpulses(double) const override {
    ContactTotals totals;
    for (const reference::ContactImpulse& c : world_->contacts()) {
      const bool f1 = isFixture(c.g1), f2 = isFixture(c.g2);
      if (f1 == f2) continue;
      // Impulse on body1 (g1) is gamma_n n + gamma_t; on g2 its opposite.
      const Vec3 on_g1 = c.normal_impulse * c.normal + c.tangential_impulse;
      const Vec3 impulse = f1 ? -on_g1 : on_g1;
      ++totals.count;
      totals.normal_impulse += c.normal_impulse;
      totals.impulse = totals.impulse + impulse;
    }
    return totals;
  }

  TriMeshStore meshes_;  // declared before world_: destroyed after the world's space and geoms
  std::unique_ptr<reference::World> world_;
  std::vector<BodyId> parts_;
};

}  // namespace

std::unique_ptr<Simulation> makeReferenceSimulation(const Scene& scene, Method method) {
  return std::make_unique<ReferenceSimulation>(scene, method);
}

}  // namespace rheofeed::scene

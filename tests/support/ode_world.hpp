// SPDX-License-Identifier: MIT
// Test fixture: a small ODE world (gravity -z) stepped with a FeederSet and ContactCollider,
// plus the few vector helpers the tests use to compute their expectations. Expected values are
// computed by the tests themselves with these helpers (plain formulas), never by the plugin.
// Including this header puts every test of the binary under an OdeMessageGuard
// (ode_message_guard.hpp): any ODE error, debug or warning message fails the test.
#pragma once

#include <ode/ode.h>

#include <array>
#include <cmath>
#include <initializer_list>
#include <memory>
#include <utility>

#include "ode_message_guard.hpp"
#include "rheofeed/collision_space.hpp"
#include "rheofeed/contact_collider.hpp"
#include "rheofeed/feeder_set.hpp"

namespace rheofeed::test {

constexpr double kGravity = 9.81;   // m/s^2, along -z
constexpr double kWorldErp = 0.2;   // dWorldSetERP of every test world
constexpr double kWorldCfm = 1e-9;  // dWorldSetCFM of every test world (m/s per N of force)

/// A body's state as plain numbers: position (m), quaternion (w, x, y, z), linear velocity
/// (m/s), angular velocity (rad/s), all in the world frame.
struct BodyState {
  std::array<double, 3> position;
  std::array<double, 4> quaternion;
  std::array<double, 3> linear;
  std::array<double, 3> angular;
};

inline BodyState stateOf(dBodyID b) {
  const dReal* p = dBodyGetPosition(b);
  const dReal* q = dBodyGetQuaternion(b);
  const dReal* v = dBodyGetLinearVel(b);
  const dReal* w = dBodyGetAngularVel(b);
  return {{p[0], p[1], p[2]}, {q[0], q[1], q[2], q[3]}, {v[0], v[1], v[2]}, {w[0], w[1], w[2]}};
}

/// Largest absolute difference between two states, over every component.
inline double maxDifference(const BodyState& a, const BodyState& b) {
  double d = 0.0;
  for (int i = 0; i < 3; ++i) {
    d = std::fmax(d, std::fabs(a.position[i] - b.position[i]));
    d = std::fmax(d, std::fabs(a.linear[i] - b.linear[i]));
    d = std::fmax(d, std::fabs(a.angular[i] - b.angular[i]));
  }
  for (int i = 0; i < 4; ++i) d = std::fmax(d, std::fabs(a.quaternion[i] - b.quaternion[i]));
  return d;
}

inline bool allFinite(const BodyState& s) {
  for (double x : s.position)
    if (!std::isfinite(x)) return false;
  for (double x : s.quaternion)
    if (!std::isfinite(x)) return false;
  for (double x : s.linear)
    if (!std::isfinite(x)) return false;
  for (double x : s.angular)
    if (!std::isfinite(x)) return false;
  return true;
}

inline Vec3 linearVelocity(dBodyID b) {
  const dReal* v = dBodyGetLinearVel(b);
  return {v[0], v[1], v[2]};
}
inline Vec3 angularVelocity(dBodyID b) {
  const dReal* w = dBodyGetAngularVel(b);
  return {w[0], w[1], w[2]};
}
inline Vec3 position(dBodyID b) {
  const dReal* p = dBodyGetPosition(b);
  return {p[0], p[1], p[2]};
}

/// Owns ODE's world, space, the plugin objects; ODE is initialised once per process.
class OdeWorld {
 public:
  explicit OdeWorld(FeederSet::Options options = {},
                    ContactCollider::Settings settings = ContactCollider::Settings{}) {
    static const bool initialised = (dInitODE2(0), true);
    (void)initialised;
    world = dWorldCreate();
    dWorldSetGravity(world, 0, 0, -kGravity);
    dWorldSetERP(world, kWorldErp);
    dWorldSetCFM(world, kWorldCfm);
    space = rheofeed::createCollisionSpace(nullptr);
    feeders = std::make_unique<FeederSet>(options);
    collider = std::make_unique<ContactCollider>(world, *feeders, settings);
  }
  ~OdeWorld() {
    collider.reset();
    dSpaceDestroy(space);
    dWorldDestroy(world);
  }
  OdeWorld(const OdeWorld&) = delete;
  OdeWorld& operator=(const OdeWorld&) = delete;

  /// Every contact gets surface `mode` (dContact* flags) and friction `mu`, nothing else.
  void setSurface(int mode, double mu) {
    collider->setSurfaceCallback([mode, mu](dGeomID, dGeomID, dContact* c, int n) {
      for (int i = 0; i < n; ++i) {
        c[i].surface = {};
        c[i].surface.mode = mode;
        c[i].surface.mu = mu;
      }
      return true;
    });
  }

  /// A dynamic box of the given size (m) and mass (kg), centred at (x, y, z).
  dBodyID box(double lx, double ly, double lz, double mass, double x, double y, double z) {
    dBodyID b = dBodyCreate(world);
    dMass m;
    dMassSetBoxTotal(&m, mass, lx, ly, lz);
    dBodySetMass(b, &m);
    dBodySetPosition(b, x, y, z);
    dGeomSetBody(dCreateBox(space, lx, ly, lz), b);
    return b;
  }
  /// A static box geom (no body).
  dGeomID staticBox(double lx, double ly, double lz, double x, double y, double z) {
    dGeomID g = dCreateBox(space, lx, ly, lz);
    dGeomSetPosition(g, x, y, z);
    return g;
  }
  /// A static box geom turned by `angle` (rad) about the axis (ax, ay, az).
  dGeomID staticBox(double lx, double ly, double lz, double x, double y, double z, double ax,
                    double ay, double az, double angle) {
    dGeomID g = staticBox(lx, ly, lz, x, y, z);
    dMatrix3 r;
    dRFromAxisAndAngle(r, ax, ay, az, angle);
    dGeomSetRotation(g, r);
    return g;
  }

  /// One step of `h` seconds with dWorldStep (Dantzig LCP) or dWorldQuickStep.
  void step(double h, bool quick = false) {
    collider->collide(space, time);
    if (quick) {
      dWorldQuickStep(world, h);
    } else {
      dWorldStep(world, h);
    }
    time += h;
  }
  /// One step in which only the listed pairs collide, each as dCollide(first, second), so a
  /// test controls which geom is g1. Joints are attached (body(g1), body(g2)); when the
  /// FeederSet's Options::attach_order is G2First they are attached (body(g2), body(g1)) with
  /// the normal negated, as such an application must do (ODE's normal points into g1, and a
  /// joint pushes its first body along the normal). Every contact gets surface mode `mode` and
  /// friction `mu`.
  void stepPairs(std::initializer_list<std::pair<dGeomID, dGeomID>> pairs, double h, double mu,
                 int mode = 0, bool quick = false) {
    collider->clearJoints();
    feeders->beginStep(time);
    for (const auto& [g1, g2] : pairs) {
      dContact c[8];
      int n = dCollide(g1, g2, 8, &c[0].geom, sizeof(dContact));
      for (int i = 0; i < n; ++i) {
        c[i].surface = {};
        c[i].surface.mode = mode;
        c[i].surface.mu = mu;
      }
      n = feeders->driveContacts(c, n);
      for (int i = 0; i < n; ++i) {
        if (feeders->options().attach_order == AttachOrder::G2First) {
          for (int k = 0; k < 3; ++k) c[i].geom.normal[k] = -c[i].geom.normal[k];
          dJointID j = dJointCreateContact(world, collider->jointGroup(), &c[i]);
          dJointAttach(j, dGeomGetBody(g2), dGeomGetBody(g1));
        } else {
          dJointID j = dJointCreateContact(world, collider->jointGroup(), &c[i]);
          dJointAttach(j, dGeomGetBody(g1), dGeomGetBody(g2));
        }
      }
    }
    if (quick) {
      dWorldQuickStep(world, h);
    } else {
      dWorldStep(world, h);
    }
    time += h;
  }

  void run(double duration, double h, bool quick = false) {
    const int n = static_cast<int>(duration / h + 0.5);
    for (int i = 0; i < n; ++i) step(h, quick);
  }

  dWorldID world;
  dSpaceID space;
  double time = 0.0;
  std::unique_ptr<FeederSet> feeders;
  std::unique_ptr<ContactCollider> collider;
};

}  // namespace rheofeed::test

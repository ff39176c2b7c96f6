// SPDX-License-Identifier: MIT
// Test fixture: a small ODE world (gravity -z) stepped with a FeederSet and ContactCollider.
#pragma once

#include <ode/ode.h>

#include <initializer_list>
#include <memory>
#include <utility>

#include "rheofeed/contact_collider.hpp"
#include "rheofeed/feeder_set.hpp"

namespace rheofeed::test {

constexpr double kGravity = 9.81;  // m/s^2, along -z

/// Owns ODE's world, space, the plugin objects; ODE is initialised once per process.
class OdeWorld {
 public:
  explicit OdeWorld(FeederSet::Options options = {}) {
    static const bool initialised = (dInitODE2(0), true);
    (void)initialised;
    world = dWorldCreate();
    dWorldSetGravity(world, 0, 0, -kGravity);
    dWorldSetERP(world, 0.2);
    dWorldSetCFM(world, 1e-9);
    space = dHashSpaceCreate(nullptr);
    feeders = std::make_unique<FeederSet>(options);
    collider = std::make_unique<ContactCollider>(world, *feeders);
  }
  ~OdeWorld() {
    collider.reset();
    dSpaceDestroy(space);
    dWorldDestroy(world);
  }
  OdeWorld(const OdeWorld&) = delete;
  OdeWorld& operator=(const OdeWorld&) = delete;

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
  /// test controls which geom is g1. Joints are attached (body(g1), body(g2)).
  void stepPairs(std::initializer_list<std::pair<dGeomID, dGeomID>> pairs, double h,
                 double mu) {
    collider->clearJoints();
    feeders->beginStep(time);
    for (const auto& [g1, g2] : pairs) {
      dContact c[8];
      int n = dCollide(g1, g2, 8, &c[0].geom, sizeof(dContact));
      for (int i = 0; i < n; ++i) {
        c[i].surface = {};
        c[i].surface.mu = mu;
      }
      n = feeders->driveContacts(c, n);
      for (int i = 0; i < n; ++i) {
        dJointID j = dJointCreateContact(world, collider->jointGroup(), &c[i]);
        dJointAttach(j, dGeomGetBody(g1), dGeomGetBody(g2));
      }
    }
    dWorldStep(world, h);
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

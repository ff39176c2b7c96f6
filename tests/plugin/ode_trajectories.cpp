// SPDX-License-Identifier: MIT
// Records trajectories of the plugin's test scenes (pyramid friction, the cone off) as hex
// floats, for Plugin.StockOde.PatchedOdeWithTheConeOffIsBitIdentical: the same source is linked
// once against the patched ODE and once against Debian's stock libode, and the two outputs must
// be equal byte for byte (patches/0002 leaves every row without dContactFrictionCone on the
// stock code path). The first line names the library's configuration (it differs: the patched
// one has ODE_EXT_friction_cone); the rest is the trajectories.
//
// Scenes (those of tests/plugin): a box on a belt (dWorldQuickStep and dWorldStep); parts on a
// turntable (secant law, h = 0.01 s); a pile of 27 boxes and spheres falling on a belt
// (quickstep with its random row order); a part on a kinematic trough vibrating at 50 Hz.
#include <ode/ode.h>

#include <cmath>
#include <cstdio>
#include <vector>

#include "rheofeed/contact_collider.hpp"
#include "rheofeed/feeder_set.hpp"

namespace {

constexpr double kPi = 3.14159265358979323846;

struct Scene {
  Scene() {
    world = dWorldCreate();
    dWorldSetGravity(world, 0, 0, -9.81);
    dWorldSetERP(world, 0.2);
    dWorldSetCFM(world, 1e-9);
    dWorldSetContactSurfaceLayer(world, 1e-4);
    space = dHashSpaceCreate(nullptr);
    collider = new rheofeed::ContactCollider(world, feeders);
    collider->setSurfaceCallback([](dGeomID, dGeomID, dContact* c, int n) {
      for (int i = 0; i < n; ++i) {
        c[i].surface = {};
        c[i].surface.mode = dContactApprox1;
        c[i].surface.mu = 0.4;
      }
      return true;
    });
  }
  ~Scene() {
    delete collider;
    dSpaceDestroy(space);
    dWorldDestroy(world);
  }
  dBodyID box(double edge, double x, double y, double z) {
    dBodyID b = dBodyCreate(world);
    dMass m;
    dMassSetBoxTotal(&m, 1.0, edge, edge, edge);
    dBodySetMass(b, &m);
    dBodySetPosition(b, x, y, z);
    dGeomSetBody(dCreateBox(space, edge, edge, edge), b);
    bodies.push_back(b);
    return b;
  }
  dBodyID sphere(double r, double x, double y, double z) {
    dBodyID b = dBodyCreate(world);
    dMass m;
    dMassSetSphereTotal(&m, 0.5, r);
    dBodySetMass(b, &m);
    dBodySetPosition(b, x, y, z);
    dGeomSetBody(dCreateSphere(space, r), b);
    bodies.push_back(b);
    return b;
  }
  void step(double h, bool quick) {
    collider->collide(space, time, h);
    if (quick) {
      dWorldQuickStep(world, h);
    } else {
      dWorldStep(world, h);
    }
    time += h;
  }
  void print(const char* name, int step) const {
    std::printf("%s step %d\n", name, step);
    for (dBodyID b : bodies) {
      const dReal* v[4] = {dBodyGetPosition(b), dBodyGetQuaternion(b), dBodyGetLinearVel(b),
                           dBodyGetAngularVel(b)};
      const int n[4] = {3, 4, 3, 3};
      for (int k = 0; k < 4; ++k) {
        for (int i = 0; i < n[k]; ++i) std::printf(" %a", static_cast<double>(v[k][i]));
      }
      std::printf("\n");
    }
  }
  void run(const char* name, int steps, double h, bool quick, int every = 50) {
    for (int i = 1; i <= steps; ++i) {
      step(h, quick);
      if (i % every == 0) print(name, i);
    }
  }

  dWorldID world;
  dSpaceID space;
  rheofeed::FeederSet feeders;
  rheofeed::ContactCollider* collider;
  std::vector<dBodyID> bodies;
  double time = 0.0;
};

void beltBox(bool quick) {
  Scene s;
  dGeomID belt = dCreateBox(s.space, 4, 1, 0.1);
  dGeomSetPosition(belt, 0, 0, -0.05);
  s.feeders.add(belt, rheofeed::MotionLaw::belt({1, 0, 0}, 0.3));
  dBodyID b = s.box(0.1, 0, 0, 0.05 - 1e-4);
  dBodySetLinearVel(b, 0, 0.2, 0);
  s.run(quick ? "belt_quickstep" : "belt_dantzig", 400, 0.001, quick);
}

void turntable() {
  Scene s;
  dGeomID table = dCreateCylinder(s.space, 1.0, 0.1);
  dGeomSetPosition(table, 0, 0, -0.05);
  s.feeders.add(table, rheofeed::MotionLaw::rotation({0, 0, 2.0}, {0, 0, 0}));
  for (int i = 0; i < 4; ++i) {
    const double a = i * kPi / 2 + 0.3;
    s.box(0.08, 0.5 * std::cos(a), 0.5 * std::sin(a), 0.04 - 1e-4);
  }
  s.run("turntable", 300, 0.01, true);
}

void pile() {
  Scene s;
  dGeomID belt = dCreateBox(s.space, 4, 1, 0.1);
  dGeomSetPosition(belt, 0, 0, -0.05);
  s.feeders.add(belt, rheofeed::MotionLaw::belt({1, 0, 0}, 0.2));
  for (int i = 0; i < 27; ++i) {
    const double x = (i % 3) * 0.07 - 0.07, y = ((i / 3) % 3) * 0.07 - 0.07;
    const double z = 0.05 + (i / 9) * 0.08;
    if (i % 2) {
      s.sphere(0.03, x + 0.003 * (i % 5), y, z);
    } else {
      s.box(0.05, x, y + 0.002 * (i % 7), z);
    }
  }
  s.run("pile", 400, 0.005, true);
}

void vibratingTrough() {
  Scene s;
  dBodyID trough = dBodyCreate(s.world);
  dBodySetKinematic(trough);
  dGeomSetBody(dCreateBox(s.space, 2, 0.5, 0.1), trough);
  dBodySetPosition(trough, 0, 0, -0.05);
  dBodyID part = s.box(0.05, 0, 0, 0.025 - 1e-4);
  (void)part;
  const double f = 50, amplitude = 0.2e-3, beta = 25 * kPi / 180, h = 1e-4;
  const double dir[2] = {std::cos(beta), std::sin(beta)};
  for (int i = 1; i <= 4000; ++i) {
    // The secant of x(t) = A sin(2 pi f t) over the step keeps the trough on its law.
    const double t0 = s.time, t1 = s.time + h;
    const double v = amplitude * (std::sin(2 * kPi * f * t1) - std::sin(2 * kPi * f * t0)) / h;
    dBodySetLinearVel(trough, v * dir[0], 0, v * dir[1]);
    s.step(h, true);
    if (i % 200 == 0) s.print("vibrating_trough", i);
  }
}

}  // namespace

int main() {
  dInitODE2(0);
  std::printf("configuration: %s\n", dGetConfiguration());
  beltBox(true);
  beltBox(false);
  turntable();
  pile();
  vibratingTrough();
  dCloseODE();
  return 0;
}

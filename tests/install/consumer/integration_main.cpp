// SPDX-License-Identifier: MIT
// Runs the README's integration example (integration.cpp) on a box dropped on the belt and
// checks what the README promises: the box ends up carried at the belt's 0.3 m/s along +x.
//
// Coulomb friction accelerates the box at mu g = 0.5 * 9.81 m/s^2, so it reaches the belt speed
// after 0.3 / 4.9 = 0.06 s and then sticks; after 1 s it must move with the belt.
#include <ode/ode.h>

#include <cmath>
#include <cstdio>
#include <rheofeed/feeder_set.hpp>

extern dWorldID world;
extern dJointGroupID contact_group;
extern rheofeed::FeederSet feeders;
void addFeeders(dGeomID belt, dGeomID bowl);
void step(dSpaceID space, double t, double h);

namespace {
constexpr double kBeltSpeed = 0.3;  // m/s, the speed integration.cpp gives the belt
constexpr double kStep = 0.01;      // s
constexpr double kDuration = 1.0;   // s: 16 times the 0.06 s the box needs to reach belt speed
// QuickStep (20 iterations) solves the sticking friction row to a few 1e-5 m/s on one resting
// box; 1 mm/s is far above that and far below the belt speed (a box left behind gives 0.3 m/s).
constexpr double kSpeedTolerance = 1e-3;  // m/s
}  // namespace

int main() {
  dInitODE2(0);
  world = dWorldCreate();
  dWorldSetGravity(world, 0, 0, -9.81);
  contact_group = dJointGroupCreate(0);
  dSpaceID space = dSimpleSpaceCreate(nullptr);
  dGeomID belt = dCreateBox(space, 4.0, 1.0, 0.1);  // static, top face at z = 0
  dGeomSetPosition(belt, 0, 0, -0.05);
  dGeomID bowl = dCreateCylinder(space, 0.3, 0.1);  // static, far from the belt: never touched
  dGeomSetPosition(bowl, 0, 10, 0);
  addFeeders(belt, bowl);

  dBodyID box = dBodyCreate(world);
  dMass m;
  dMassSetBoxTotal(&m, 0.1, 0.05, 0.05, 0.05);
  dBodySetMass(box, &m);
  dBodySetPosition(box, -1.0, 0, 0.025);
  dGeomSetBody(dCreateBox(space, 0.05, 0.05, 0.05), box);

  const int steps = static_cast<int>(std::lround(kDuration / kStep));
  for (int k = 0; k < steps; ++k) step(space, k * kStep, kStep);

  const dReal* v = dBodyGetLinearVel(box);
  const int driven = feeders.stats(belt).contacts_driven;
  const bool ok = std::abs(v[0] - kBeltSpeed) < kSpeedTolerance &&
                  std::abs(v[1]) < kSpeedTolerance && driven > 0;
  std::printf(
      "integration: box velocity (%.6f, %.6f, %.6f) m/s after %.1f s, belt %.1f m/s, "
      "%d belt contacts driven: %s\n",
      v[0], v[1], v[2], kDuration, kBeltSpeed, driven, ok ? "ok" : "FAILED");
  dSpaceDestroy(space);
  dJointGroupDestroy(contact_group);
  dWorldDestroy(world);
  dCloseODE();
  return ok ? 0 : 1;
}

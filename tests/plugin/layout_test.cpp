// SPDX-License-Identifier: MIT
#include <gtest/gtest.h>

#include "ode_world.hpp"

namespace rheofeed::test {
namespace {
constexpr double kBeltSpeed = 0.3;  // m/s along +x
constexpr double kMu = 0.5;

struct Layout {
  bool kinematic;   // feeder carried by a kinematic body at rest
  bool feeder_g1;   // feeder geom created first in the collision pair
};

// Runs a box on a belt and returns its x velocity after 1 s.
double beltVelocity(Layout layout) {
  OdeWorld w;
  w.collider->setSurfaceCallback([](dGeomID, dGeomID, dContact* c, int n) {
    for (int i = 0; i < n; ++i) { c[i].surface.mode = 0; c[i].surface.mu = kMu; }
    return true;
  });
  dGeomID belt = dCreateBox(nullptr, 4, 1, 0.1);
  dBodyID part = w.box(0.1, 0.1, 0.1, 1.0, 0, 0, 0.1);
  dGeomID part_geom = dBodyGetFirstGeom(part);
  dSpaceRemove(w.space, part_geom);
  if (layout.feeder_g1) { dSpaceAdd(w.space, belt); dSpaceAdd(w.space, part_geom); }
  else { dSpaceAdd(w.space, part_geom); dSpaceAdd(w.space, belt); }
  if (layout.kinematic) {
    dBodyID kb = dBodyCreate(w.world);
    dBodySetKinematic(kb);
    dGeomSetBody(belt, kb);
    dBodySetPosition(kb, 0, 0, 0);
  } else {
    dGeomSetPosition(belt, 0, 0, 0);
  }
  w.feeders->add(belt, MotionLaw::belt({1, 0, 0}, kBeltSpeed));
  for (int i = 0; i < 200; ++i) {
    if (layout.feeder_g1) w.stepPairs({{belt, part_geom}}, 0.005, kMu);
    else w.stepPairs({{part_geom, belt}}, 0.005, kMu);
  }
  EXPECT_NEAR(dBodyGetPosition(part)[2], 0.1, 1e-3);
  return dBodyGetLinearVel(part)[0];
}
}  // namespace

TEST(Layouts, AllFourLayoutsCarryThePartAtBeltSpeed) {
  for (bool kin : {false, true}) for (bool g1 : {false, true}) {
    SCOPED_TRACE(testing::Message() << "kinematic=" << kin << " feeder_g1=" << g1);
    EXPECT_NEAR(beltVelocity({kin, g1}), kBeltSpeed, 1e-6);
  }
}
}  // namespace rheofeed::test

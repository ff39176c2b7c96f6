// SPDX-License-Identifier: MIT
// rheofeed in an ODE application. The README quotes this file; the install test runs it.
#include <ode/ode.h>
#include <rheofeed/feeder_set.hpp>

dWorldID world;  // the application's own world and contact group
dJointGroupID contact_group;
rheofeed::FeederSet feeders;  // owned by the application

void addFeeders(dGeomID belt, dGeomID bowl) {
  feeders.add(belt, rheofeed::MotionLaw::belt({1, 0, 0}, 0.3));              // 0.3 m/s along +x
  feeders.add(bowl, rheofeed::MotionLaw::rotation({0, 0, 2.0}, {0, 0, 0}));  // 2 rad/s about +z
}

void nearCallback(void*, dGeomID o1, dGeomID o2) {  // the application's own near callback
  // two static geoms: nothing to move
  if (!dGeomGetBody(o1) && !dGeomGetBody(o2)) return;
  dContact contact[8] = {};
  int n = dCollide(o1, o2, 8, &contact[0].geom, sizeof(dContact));
  for (int i = 0; i < n; ++i) {  // ... the surface as usual; Approx1: mu is a coefficient
    contact[i].surface.mode = dContactApprox1;
    contact[i].surface.mu = 0.5;
  }
  n = feeders.driveContacts(contact, n);  // feeder contacts get fdir1, motion1 (m/s)
  for (int i = 0; i < n; ++i)
    dJointAttach(dJointCreateContact(world, contact_group, &contact[i]), dGeomGetBody(o1),
                 dGeomGetBody(o2));
}

// Each step, t and h in s (h makes rotating laws use the secant over the step, so a part that
// sticks to a turntable stays on its circle):
void step(dSpaceID space, double t, double h) {
  feeders.beginStep(t, h);
  dSpaceCollide(space, nullptr, nearCallback);
  dWorldQuickStep(world, h);
  dJointGroupEmpty(contact_group);
}

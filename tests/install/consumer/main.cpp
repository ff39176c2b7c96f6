// SPDX-License-Identifier: MIT
// Drives one contact of a part on a belt through the installed C++ API.
#include <ode/ode.h>

#include <cmath>
#include <cstdio>

#include "rheofeed/feeder_set.hpp"

int main() {
  dInitODE2(0);
  dGeomID belt = dCreateBox(nullptr, 2, 1, 0.1);
  dGeomID part = dCreateBox(nullptr, 0.1, 0.1, 0.1);
  dGeomSetPosition(part, 0, 0, 0.099);
  rheofeed::FeederSet feeders;
  feeders.add(belt, rheofeed::MotionLaw::belt({1, 0, 0}, 0.25));
  feeders.beginStep(0.0);
  dContact c[4] = {};
  int n = dCollide(part, belt, 4, &c[0].geom, sizeof(dContact));
  for (int i = 0; i < n; ++i) c[i].surface.mu = 0.5;
  n = feeders.driveContacts(c, n);
  const bool ok = n > 0 && std::abs(c[0].surface.motion1 - 0.25) < 1e-12 &&
                  std::abs(c[0].fdir1[0] - 1.0) < 1e-12;
  std::printf("consumer_cpp: %d contacts, motion1 = %g: %s\n", n, n ? c[0].surface.motion1 : 0.0,
              ok ? "ok" : "FAILED");
  dGeomDestroy(part);
  dGeomDestroy(belt);
  dCloseODE();
  return ok ? 0 : 1;
}

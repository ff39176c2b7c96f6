/* SPDX-License-Identifier: MIT */
/* Drives one contact of a part on a belt through the installed C API. */
#include <math.h>
#include <ode/ode.h>
#include <stdio.h>
#include <string.h>

#include "rheofeed/rheofeed.h"

int main(void) {
  dInitODE2(0);
  dGeomID belt = dCreateBox(0, 2, 1, 0.1);
  dGeomID part = dCreateBox(0, 0.1, 0.1, 0.1);
  dGeomSetPosition(part, 0, 0, 0.099);
  rfFeederSetID feeders = rfFeederSetCreate();
  const double dir[3] = {0, 1, 0};
  int ok = feeders && rfFeederSetAddBelt(feeders, belt, dir, 0.25, rfFrameWorld) == rfOK;
  dContact c[4];
  memset(c, 0, sizeof c);
  int n = dCollide(part, belt, 4, &c[0].geom, sizeof(dContact));
  for (int i = 0; i < n; ++i) c[i].surface.mu = 0.5;
  ok = ok && rfFeederSetBeginStep(feeders, 0.0) == rfOK;
  n = rfFeederSetDriveContacts(feeders, c, n);
  ok = ok && n > 0 && fabs(c[0].surface.motion1 - 0.25) < 1e-12 && fabs(c[0].fdir1[1] - 1) < 1e-12;
  printf("consumer_c: %d contacts: %s\n", n, ok ? "ok" : "FAILED");
  rfFeederSetDestroy(feeders);
  dGeomDestroy(part);
  dGeomDestroy(belt);
  dCloseODE();
  return ok ? 0 : 1;
}

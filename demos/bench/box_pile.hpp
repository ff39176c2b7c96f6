// SPDX-License-Identifier: MIT
// The benchmarks' pile: `boxes` cubes of 0.1 m and 0.1 kg in layers of 10 x 10 over a static
// ground box (top at z = 0), stepped with dWorldQuickStep (20 sweeps by default) in a hash space
// with the application's own near callback: every contact gets `mode` (dContact* flags) and
// mu = 0.5, then goes through `feeders` when there is one. Shared by plugin_overhead_bench and
// friction_cone_bench so that both time the same work.
#pragma once

#include <ode/ode.h>

#include "rheofeed/collision_space.hpp"
#include "rheofeed/feeder_set.hpp"

namespace rheofeed::demo {

class BoxPile {
 public:
  static constexpr int kMaxContacts = 8;

  BoxPile(int boxes, int mode, int sweeps = 20) : mode_(mode) {
    world_ = dWorldCreate();
    dWorldSetGravity(world_, 0, 0, -9.81);
    dWorldSetQuickStepNumIterations(world_, sweeps);
    space_ = rheofeed::createCollisionSpace(nullptr);
    group_ = dJointGroupCreate(0);
    ground_ = dCreateBox(space_, 10, 10, 0.2);
    dGeomSetPosition(ground_, 0, 0, -0.1);
    const int side = 10;
    for (int i = 0; i < boxes; ++i) {
      const int layer = i / (side * side), k = i % (side * side);
      dBodyID b = dBodyCreate(world_);
      dMass m;
      dMassSetBoxTotal(&m, 0.1, 0.1, 0.1, 0.1);
      dBodySetMass(b, &m);
      dBodySetPosition(b, (k % side) * 0.12 + 0.01 * (layer % 2), (k / side) * 0.12,
                       0.06 + layer * 0.11);
      dGeomSetBody(dCreateBox(space_, 0.1, 0.1, 0.1), b);
    }
  }
  ~BoxPile() {
    dJointGroupDestroy(group_);
    dSpaceDestroy(space_);
    dWorldDestroy(world_);
  }
  BoxPile(const BoxPile&) = delete;
  BoxPile& operator=(const BoxPile&) = delete;

  dSpaceID space() const { return space_; }
  dGeomID ground() const { return ground_; }
  /// The feeders the near callback drives contacts with (null: none; not owned).
  void setFeeders(FeederSet* feeders) { feeders_ = feeders; }
  /// Contact joints created since construction or the last resetJointCount.
  long jointCount() const { return joints_; }
  void resetJointCount() { joints_ = 0; }

  /// One step of h seconds (the feeders' beginStep gets `step_to_feeders`: 0 or h).
  void step(double h, double step_to_feeders = 0.0) {
    if (feeders_) feeders_->beginStep(time_, step_to_feeders);
    dSpaceCollide(space_, this, &nearCallback);
    dWorldQuickStep(world_, h);
    dJointGroupEmpty(group_);
    time_ += h;
  }

 private:
  static void nearCallback(void* data, dGeomID o1, dGeomID o2) {
    auto* self = static_cast<BoxPile*>(data);
    dBodyID b1 = dGeomGetBody(o1), b2 = dGeomGetBody(o2);
    dContact contact[kMaxContacts];
    int n = dCollide(o1, o2, kMaxContacts, &contact[0].geom, sizeof(dContact));
    for (int i = 0; i < n; ++i) {
      contact[i].surface.mode = self->mode_;
      contact[i].surface.mu = 0.5;
    }
    if (self->feeders_) n = self->feeders_->driveContacts(contact, n);
    for (int i = 0; i < n; ++i) {
      dJointID c = dJointCreateContact(self->world_, self->group_, contact + i);
      dJointAttach(c, b1, b2);
    }
    self->joints_ += n;
  }

  dWorldID world_;
  dSpaceID space_;
  dJointGroupID group_;
  dGeomID ground_;
  FeederSet* feeders_ = nullptr;
  int mode_;
  long joints_ = 0;
  double time_ = 0.0;
};

}  // namespace rheofeed::demo

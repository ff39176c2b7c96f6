// SPDX-License-Identifier: MIT
#include "rheofeed/contact_collider.hpp"

#include <stdexcept>
#include <string>
#include <utility>

#include "stage_clock.hpp"

namespace rheofeed {

ContactCollider::ContactCollider(dWorldID world, FeederSet& feeders)
    : ContactCollider(world, feeders, Settings{}) {}

ContactCollider::ContactCollider(dWorldID world, FeederSet& feeders, const Settings& settings)
    : world_(world), feeders_(feeders), settings_(settings), group_(nullptr) {
  if (!world) throw std::invalid_argument("rheofeed::ContactCollider: world is null");
  if (settings.max_contacts_per_pair < 1 || settings.max_contacts_per_pair > 0xffff) {
    throw std::invalid_argument("rheofeed::ContactCollider: Settings::max_contacts_per_pair = " +
                                std::to_string(settings.max_contacts_per_pair) +
                                " must be in 1..65535");
  }
  requireFrictionModel(settings.friction, "rheofeed::ContactCollider: Settings::friction");
  settings_.default_surface.mode =
      withFrictionModel(settings.default_surface.mode, settings.friction);
  buffer_.resize(static_cast<std::size_t>(settings.max_contacts_per_pair));
  group_ = dJointGroupCreate(0);
}

ContactCollider::~ContactCollider() {
  dJointGroupDestroy(group_);
}

void ContactCollider::setSurfaceCallback(SurfaceCallback callback) {
  surface_ = std::move(callback);
}

void ContactCollider::clearJoints() {
  dJointGroupEmpty(group_);
  joints_.clear();
  feedback_used_ = 0;
}

void ContactCollider::rethrowPendingError() {
  if (!error_) return;
  std::exception_ptr error = std::move(error_);
  error_ = nullptr;
  std::rethrow_exception(error);
}

void ContactCollider::collide(dSpaceID space, double time, double step) {
  rethrowPendingError();           // an error of a manual pass is not lost
  feeders_.beginStep(time, step);  // first: a refused time or step leaves everything as it was
  clearJoints();
  collideWithin(space);
  if (error_) {
    // The pass stopped at the first exception: drop its partial joints and records, then
    // throw it here, outside ODE.
    clearJoints();
    feeders_.records().clear();
    rethrowPendingError();
  }
}

void ContactCollider::collideWithin(dSpaceID space) {
  // Pairs inside `space` (a sub-space against a geom or another sub-space is split further by
  // nearCallback), then the pairs inside each sub-space, each exactly once.
  dSpaceCollide(space, this, &ContactCollider::nearCallback);
  const int count = dSpaceGetNumGeoms(space);
  for (int i = 0; i < count && !error_; ++i) {
    dGeomID child = dSpaceGetGeom(space, i);
    if (dGeomIsSpace(child)) collideWithin(reinterpret_cast<dSpaceID>(child));
  }
}

void ContactCollider::nearCallback(void* data, dGeomID o1, dGeomID o2) {
  auto* self = static_cast<ContactCollider*>(data);
  if (self->error_) return;  // the pass already failed: no more work
  try {
    if (dGeomIsSpace(o1) || dGeomIsSpace(o2)) {
      dSpaceCollide2(o1, o2, data, &ContactCollider::nearCallback);
      return;
    }
    self->handlePair(o1, o2);
  } catch (...) {
    // ODE's frames must not be unwound: keep the first error for collide() to rethrow.
    if (!self->error_) self->error_ = std::current_exception();
  }
}

void ContactCollider::handlePair(dGeomID o1, dGeomID o2) {
  dBodyID b1 = dGeomGetBody(o1);
  dBodyID b2 = dGeomGetBody(o2);
  if (!b1 && !b2) return;  // two static geoms: nothing to constrain
  if (settings_.skip_connected_bodies && b1 && b2 &&
      dAreConnectedExcluding(b1, b2, dJointTypeContact)) {
    return;
  }
  dContact* contacts = buffer_.data();
  int n = dCollide(o1, o2, settings_.max_contacts_per_pair, &contacts[0].geom, sizeof(dContact));
  if (n <= 0) return;
  const StageClock creation(contact_seconds_);  // contact creation (setContactTimer)
  for (int i = 0; i < n; ++i) contacts[i].surface = settings_.default_surface;
  if (surface_ && !surface_(o1, o2, contacts, n)) return;
  if (!odeHasFrictionCone()) {
    for (int i = 0; i < n; ++i) {
      if (contacts[i].surface.mode & kContactFrictionCone) {
        throw std::invalid_argument(
            "rheofeed::ContactCollider: the SurfaceCallback set dContactFrictionCone (mode "
            "bit 0x8000) but the linked ODE has no friction cone (a stock library would "
            "silently solve the pyramid): clear the bit, or link the patched ODE");
      }
    }
  }

  std::vector<ContactRecord>& records = feeders_.records();
  const std::size_t first_record = records.size();
  n = feeders_.driveContacts(contacts, n);
  const bool recorded = records.size() > first_record;
  std::size_t next_record = first_record;
  const bool feeder_pair = recorded && (feeders_.contains(o1) || feeders_.contains(o2));

  const bool g2_first = feeders_.options().attach_order == AttachOrder::G2First;
  for (int i = 0; i < n; ++i) {
    dBodyID a = dGeomGetBody(contacts[i].geom.g1);
    dBodyID b = dGeomGetBody(contacts[i].geom.g2);
    dJointID joint;
    if (g2_first) {
      // ODE's normal points into g1 and the joint pushes its first body along it: attaching
      // body(g2) first needs the negated normal, or the contact pulls the bodies together.
      dContact reversed = contacts[i];
      for (int k = 0; k < 3; ++k) reversed.geom.normal[k] = -reversed.geom.normal[k];
      joint = dJointCreateContact(world_, group_, &reversed);
      std::swap(a, b);
    } else {
      joint = dJointCreateContact(world_, group_, &contacts[i]);
    }
    dJointAttach(joint, a, b);
    dJointFeedback* fb = nullptr;
    if (settings_.feedback) {
      if (feedback_used_ == feedback_.size()) feedback_.emplace_back();
      fb = &feedback_[feedback_used_++];
      dJointSetFeedback(joint, fb);
    }
    const dReal* n_i = contacts[i].geom.normal;
    joints_.push_back(
        {contacts[i].geom.g1, contacts[i].geom.g2, {n_i[0], n_i[1], n_i[2]}, joint, fb});
    if (feeder_pair && next_record < records.size()) {
      ContactRecord& r = records[next_record++];
      r.joint = joint;
      r.feedback = fb;
    }
  }
}

}  // namespace rheofeed

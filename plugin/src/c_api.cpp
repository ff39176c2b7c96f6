// SPDX-License-Identifier: MIT
// The C API: a thin shell over rheofeed::FeederSet that turns exceptions into result codes.
#include "rheofeed/rheofeed.h"

#include <new>
#include <optional>
#include <stdexcept>
#include <string>
#include <unordered_map>
#include <utility>

#include "rheofeed/feeder_set.hpp"

struct rfFeederSet {
  rheofeed::FeederSet set;
  std::string last_error;
  /// The profiles rfFeederSetSetRamp and rfFeederSetSetOnOff gave a feeder, one of each kind
  /// (a second ramp or window replaces the first; the two multiply), over the law it had before
  /// the first of them (`base`). Dropped when the feeder's law is set again or it is removed.
  struct Profiles {
    rheofeed::MotionLaw base;
    std::optional<rheofeed::TimeProfile> ramp, on_off;
  };
  std::unordered_map<dGeomID, Profiles> profiles;
  explicit rfFeederSet(const rheofeed::FeederSet::Options& options) : set(options) {}
};

namespace {

// Gives `geom` a new law (registering it first when `add`): any ramp or window of the C API's
// goes with the old one.
void newLaw(rfFeederSet& set, dGeomID geom, rheofeed::MotionLaw law, bool add) {
  if (add) {
    set.set.add(geom, std::move(law));
  } else {
    set.set.setLaw(geom, std::move(law));
  }
  set.profiles.erase(geom);
}

// Gives `geom` its ramp (is_ramp) or its on/off window, replacing the one of that kind it had
// and keeping the other (rfFeederSet::Profiles).
void setProfile(rfFeederSet& set, dGeomID geom, rheofeed::TimeProfile profile, bool is_ramp) {
  auto it = set.profiles.find(geom);
  rfFeederSet::Profiles p =
      it != set.profiles.end() ? it->second : rfFeederSet::Profiles{set.set.law(geom), {}, {}};
  (is_ramp ? p.ramp : p.on_off) = std::move(profile);
  rheofeed::MotionLaw law = p.base;
  if (p.ramp) law = law.withProfile(*p.ramp);
  if (p.on_off) law = law.withProfile(*p.on_off);
  set.set.setLaw(geom, law);  // throws for a bad profile: nothing changes then
  set.profiles[geom] = std::move(p);
}

using rheofeed::Frame;
using rheofeed::MotionLaw;
using rheofeed::Vec3;

Vec3 vec(const double* a) {
  return a ? Vec3{a[0], a[1], a[2]} : Vec3{};
}

// Runs `action` and maps exceptions onto result codes, keeping the message.
template <class Action>
int guarded(rfFeederSetID set, Action&& action) {
  if (!set) return rfErrorInvalidArgument;
  set->last_error.clear();
  try {
    action();
    return rfOK;
  } catch (const std::invalid_argument& e) {
    set->last_error = e.what();
    return rfErrorInvalidArgument;
  } catch (const std::bad_alloc&) {
    set->last_error = "out of memory";
    return rfErrorOutOfMemory;
  } catch (const std::exception& e) {
    set->last_error = e.what();
    return rfErrorInternal;
  } catch (...) {
    set->last_error = "unknown error";
    return rfErrorInternal;
  }
}

Frame frameOf(int frame) {
  if (frame == rfFrameWorld) return Frame::World;
  if (frame == rfFrameBody) return Frame::Body;
  throw std::invalid_argument("frame = " + std::to_string(frame) +
                              " is neither rfFrameWorld (0) nor rfFrameBody (1)");
}

void requireVector(const double* a, const char* name) {
  if (!a) throw std::invalid_argument(std::string(name) + " is a null pointer");
}

MotionLaw twistLaw(const double* linear, const double* angular, const double* origin, int frame) {
  requireVector(linear, "linear");
  requireVector(angular, "angular");
  requireVector(origin, "origin");
  return MotionLaw::twist({vec(linear), vec(angular), vec(origin)}, frameOf(frame));
}

MotionLaw beltLaw(const double* direction, double speed, int frame) {
  requireVector(direction, "direction");
  return MotionLaw::belt(vec(direction), speed, frameOf(frame));
}

MotionLaw localVibrationLaw(double frequency, const double* amplitude, double torsion_amplitude,
                            const double* axis_origin, const double* axis_direction,
                            const double* gravity, double efficiency) {
  requireVector(amplitude, "amplitude");
  requireVector(gravity, "gravity");
  if (torsion_amplitude != 0) {
    requireVector(axis_origin, "axis_origin (a torsion needs its axis)");
    requireVector(axis_direction, "axis_direction (a torsion needs its axis)");
  }
  rheofeed::LocalVibration v;
  v.frequency = frequency;
  v.amplitude = vec(amplitude);
  v.torsion_amplitude = torsion_amplitude;
  if (axis_origin) v.axis_origin = vec(axis_origin);
  if (axis_direction) v.axis_direction = vec(axis_direction);
  v.gravity = vec(gravity);
  v.efficiency = efficiency;
  v.validate("local vibration");
  return MotionLaw::localVibration(v);
}

}  // namespace

extern "C" {

rfFeederSetID rfFeederSetCreate(void) {
  return rfFeederSetCreateWithOptions(1, 0, 1e-9);
}

rfFeederSetID rfFeederSetCreateWithOptions(int force_approx1, int attach_order,
                                           double min_surface_speed) {
  if (attach_order != rfAttachG1First && attach_order != rfAttachG2First) return nullptr;
  rheofeed::FeederSet::Options options;
  options.force_approx1 = force_approx1 != 0;
  options.attach_order = attach_order == rfAttachG1First ? rheofeed::AttachOrder::G1First
                                                         : rheofeed::AttachOrder::G2First;
  options.min_surface_speed = min_surface_speed;
  try {
    return new rfFeederSet(options);
  } catch (...) {
    return nullptr;
  }
}

void rfFeederSetDestroy(rfFeederSetID set) {
  delete set;
}

int rfFeederSetSetFrictionModel(rfFeederSetID set, int model) {
  return guarded(set, [&] {
    if (model != rfFrictionPyramid && model != rfFrictionCone) {
      throw std::invalid_argument("rfFeederSetSetFrictionModel: model = " + std::to_string(model) +
                                  " must be rfFrictionPyramid (0) or rfFrictionCone (1)");
    }
    set->set.setFrictionModel(model == rfFrictionCone ? rheofeed::FrictionModel::Cone
                                                      : rheofeed::FrictionModel::Pyramid);
  });
}

int rfOdeHasFrictionCone(void) {
  return rheofeed::odeHasFrictionCone() ? 1 : 0;
}

int rfFeederSetAddTwist(rfFeederSetID set, dGeomID geom, const double linear[3],
                        const double angular[3], const double origin[3], int frame) {
  return guarded(set, [&] { newLaw(*set, geom, twistLaw(linear, angular, origin, frame), true); });
}

int rfFeederSetAddBelt(rfFeederSetID set, dGeomID geom, const double direction[3], double speed,
                       int frame) {
  return guarded(set, [&] { newLaw(*set, geom, beltLaw(direction, speed, frame), true); });
}

int rfFeederSetAddField(rfFeederSetID set, dGeomID geom, rfFieldFunction* field, void* user,
                        int time_varying) {
  return guarded(set, [&] {
    if (!field) throw std::invalid_argument("field function is a null pointer");
    auto wrapped = [field, user](const Vec3& p, const Vec3& n, double t) {
      const double pa[3] = {p.x, p.y, p.z}, na[3] = {n.x, n.y, n.z};
      double out[3] = {0, 0, 0};
      field(user, pa, na, t, out);
      return Vec3{out[0], out[1], out[2]};
    };
    newLaw(*set, geom, MotionLaw::field(wrapped, time_varying != 0), true);
  });
}

int rfFeederSetAddLocalVibration(rfFeederSetID set, dGeomID geom, double frequency,
                                 const double amplitude[3], double torsion_amplitude,
                                 const double axis_origin[3], const double axis_direction[3],
                                 const double gravity[3], double efficiency) {
  return guarded(set, [&] {
    newLaw(*set, geom,
           localVibrationLaw(frequency, amplitude, torsion_amplitude, axis_origin, axis_direction,
                             gravity, efficiency),
           true);
  });
}

int rfFeederSetSetLocalVibration(rfFeederSetID set, dGeomID geom, double frequency,
                                 const double amplitude[3], double torsion_amplitude,
                                 const double axis_origin[3], const double axis_direction[3],
                                 const double gravity[3], double efficiency) {
  return guarded(set, [&] {
    newLaw(*set, geom,
           localVibrationLaw(frequency, amplitude, torsion_amplitude, axis_origin, axis_direction,
                             gravity, efficiency),
           false);
  });
}

int rfFeederSetSetPartEfficiency(rfFeederSetID set, dBodyID body, double factor) {
  return guarded(set, [&] {
    if (factor == 1.0 && body) {
      set->set.clearPartEfficiency(body);
    } else {
      set->set.setPartEfficiency(body, factor);
    }
  });
}

int rfFeederSetSetTwist(rfFeederSetID set, dGeomID geom, const double linear[3],
                        const double angular[3], const double origin[3], int frame) {
  return guarded(set, [&] { newLaw(*set, geom, twistLaw(linear, angular, origin, frame), false); });
}

int rfFeederSetSetBelt(rfFeederSetID set, dGeomID geom, const double direction[3], double speed,
                       int frame) {
  return guarded(set, [&] { newLaw(*set, geom, beltLaw(direction, speed, frame), false); });
}

int rfFeederSetSetRamp(rfFeederSetID set, dGeomID geom, double t_start, double t_end, double from,
                       double to) {
  return guarded(set, [&] {
    setProfile(*set, geom, rheofeed::TimeProfile::ramp(t_start, t_end, from, to), true);
  });
}

int rfFeederSetSetOnOff(rfFeederSetID set, dGeomID geom, double t_on, double t_off) {
  return guarded(set,
                 [&] { setProfile(*set, geom, rheofeed::TimeProfile::onOff(t_on, t_off), false); });
}

int rfFeederSetRemove(rfFeederSetID set, dGeomID geom) {
  return guarded(set, [&] {
    set->set.remove(geom);
    set->profiles.erase(geom);
  });
}

int rfFeederSetContains(rfFeederSetID set, dGeomID geom) {
  return set && set->set.contains(geom) ? 1 : 0;
}

int rfFeederSetBeginStep(rfFeederSetID set, double time) {
  return guarded(set, [&] { set->set.beginStep(time); });
}

int rfFeederSetBeginStepDt(rfFeederSetID set, double time, double step) {
  return guarded(set, [&] { set->set.beginStep(time, step); });
}

int rfFeederSetDriveContacts(rfFeederSetID set, dContact* contacts, int count) {
  if (!set) return rfErrorInvalidArgument;
  // No allocation on the good path: the near callback calls this for every geom pair.
  if (count < 0 || (count > 0 && !contacts)) {
    // The C++ call reports it through the diagnostic function and counts it.
    set->set.driveContacts(contacts, count);
    try {
      set->last_error = count < 0 ? "rfFeederSetDriveContacts: count = " + std::to_string(count) +
                                        " is negative: must be in [0, number of contacts]"
                                  : "rfFeederSetDriveContacts: contacts is a null pointer with "
                                    "count = " +
                                        std::to_string(count) +
                                        ": a count > 0 needs an array of that many contacts";
    } catch (...) {
      // Out of memory for the message: the code still says what happened.
    }
    return rfErrorInvalidArgument;
  }
  if (!set->last_error.empty()) set->last_error.clear();
  return set->set.driveContacts(contacts, count);
}

int rfFeederSetGetContactsDriven(rfFeederSetID set, dGeomID geom) {
  int driven = 0;
  const int rc = guarded(set, [&] { driven = set->set.stats(geom).contacts_driven; });
  return rc == rfOK ? driven : rc;
}

int rfFeederSetGetStats(rfFeederSetID set, dGeomID geom, rfFeederStats* out) {
  return guarded(set, [&] {
    if (!out) throw std::invalid_argument("rfFeederSetGetStats: out is a null pointer");
    if (out->size < sizeof(rfFeederStats)) {
      throw std::invalid_argument("rfFeederSetGetStats: out->size = " + std::to_string(out->size) +
                                  ": set it to sizeof(rfFeederStats), " +
                                  std::to_string(sizeof(rfFeederStats)) + " for this library");
    }
    const rheofeed::FeederStats& s = set->set.stats(geom);
    out->contacts_driven = s.contacts_driven;
    out->contacts_undriven = s.contacts_undriven;
    out->invalid_contacts = s.invalid_contacts;
    out->zero_friction = s.zero_friction;
    out->law_not_finite = s.law_not_finite;
    out->law_threw = s.law_threw;
    out->bodies_woken = s.bodies_woken;
  });
}

void rfFeederSetSetDiagnosticFunction(rfFeederSetID set, rfDiagnosticFunction* fn, void* user) {
  if (!set) return;
  if (!fn) {
    set->set.setDiagnosticHandler(nullptr);
    return;
  }
  set->set.setDiagnosticHandler([fn, user](const rheofeed::Diagnostic& d) {
    fn(user, rheofeed::toString(d.kind), d.feeder, d.message.c_str());
  });
}

const char* rfFeederSetGetLastError(rfFeederSetID set) {
  return set ? set->last_error.c_str() : "set is a null pointer";
}

}  // extern "C"

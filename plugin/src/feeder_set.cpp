// SPDX-License-Identifier: MIT
#include "rheofeed/feeder_set.hpp"

#include <cmath>
#include <cstdio>
#include <sstream>
#include <stdexcept>
#include <utility>

#include "current_exception.hpp"
#include "ode_vec.hpp"

namespace rheofeed {
namespace {

// Up to this many feeders a linear scan over a contiguous array beats hashing (the common case:
// one to a few feeders). More feeders switch to the hash map.
constexpr std::size_t kLinearLookupLimit = 8;
constexpr int kDiagnosticKinds = 6;
// A law accepted at |speed| = kMaxSurfaceSpeed may give |c_t| a few roundings above it (the
// belt's projection and renormalisation): the per-contact test allows this relative slack. It
// compares |c_t|^2 (no square root per contact; 1e200 is far from overflow).
// A feeder contact's normal must have |n|^2 within this of 1 (InvalidContact otherwise).
constexpr double kUnitNormalTolerance = 1e-4;
constexpr double kContactSpeedLimit = kMaxSurfaceSpeed * (1.0 + 1e-12);
constexpr double kContactSpeedLimit2 = kContactSpeedLimit * kContactSpeedLimit;

// The body of a contact's geom; 0 for a static geom and for a null geom (a hand-made contact
// against the static environment: ODE's contact joint never reads the geoms).
dBodyID bodyOf(dGeomID geom) {
  return geom ? dGeomGetBody(geom) : nullptr;
}

std::string geomName(dGeomID geom) {
  std::ostringstream out;
  out << "feeder geom " << static_cast<const void*>(geom);
  return out.str();
}

}  // namespace

bool odeHasFrictionCone() {
  static const bool has_cone = dCheckConfiguration("ODE_EXT_friction_cone") != 0;
  return has_cone;
}

void requireFrictionModel(FrictionModel model, const char* setting) {
  if (model != FrictionModel::Cone || odeHasFrictionCone()) return;
  throw std::invalid_argument(
      std::string(setting) +
      " = cone needs an ODE with rheofeed's friction-cone patch (patches/0002, "
      "dCheckConfiguration(\"ODE_EXT_friction_cone\")), but the linked ODE reports \"" +
      dGetConfiguration() +
      "\": use pyramid, or link an ODE built with rheofeed's patches/ (rheofeed's own build "
      "makes one for its tests and commands, RHEOFEED_ODE=patched, but does not install it: an "
      "application builds ODE 0.16.2 with those patches itself)");
}

void requireDoublePrecisionOde() {
  static const bool is_double = dCheckConfiguration("ODE_double_precision") != 0;
  if (!is_double) {
    throw std::runtime_error(
        std::string("rheofeed needs ODE built in double precision; the loaded ODE reports "
                    "configuration \"") +
        dGetConfiguration() + "\"");
  }
}

const char* toString(DiagnosticKind kind) {
  switch (kind) {
    case DiagnosticKind::InvalidContact:
      return "invalid_contact";
    case DiagnosticKind::ZeroFriction:
      return "zero_friction";
    case DiagnosticKind::LawNotFinite:
      return "law_not_finite";
    case DiagnosticKind::ForceCapFriction:
      return "force_cap_friction";
    case DiagnosticKind::LawThrew:
      return "law_threw";
    case DiagnosticKind::InvalidCall:
      return "invalid_call";
  }
  return "unknown";
}

struct FeederSet::Impl {
  struct Feeder {
    dGeomID geom = nullptr;
    MotionLaw law;
    StepLaw frozen;  // law frozen at `frozen_step`
    std::uint64_t frozen_step = ~std::uint64_t{0};
    bool replaced = true;  // law set or replaced since last frozen
    bool changed = false;  // frozen motion differs from the previous one: wake
    FeederStats stats;
    bool reported[kDiagnosticKinds] = {};
  };

  Options options;
  std::vector<std::unique_ptr<Feeder>> feeders;
  std::vector<dGeomID> geoms;  // parallel to feeders, for the linear lookup
  std::unordered_map<dGeomID, Feeder*> by_geom;
  double time = 0.0;
  double step_length = 0.0;  // h (s) of the current step; 0: instantaneous fields
  std::uint64_t step = 0;    // counts beginStep calls: every law is refrozen once per step
  std::vector<ContactRecord> records;
  std::function<void(const Diagnostic&)> handler;
  std::uint64_t invalid_calls = 0;
  bool invalid_call_reported = false;
  std::unordered_map<dBodyID, double> part_efficiency;  // setPartEfficiency

  double partEfficiency(dBodyID body) const {
    if (part_efficiency.empty() || !body) return 1.0;
    auto it = part_efficiency.find(body);
    return it == part_efficiency.end() ? 1.0 : it->second;
  }

  Feeder* find(dGeomID geom) const {
    if (feeders.size() <= kLinearLookupLimit) {
      for (std::size_t i = 0; i < geoms.size(); ++i) {
        if (geoms[i] == geom) return feeders[i].get();
      }
      return nullptr;
    }
    auto it = by_geom.find(geom);
    return it == by_geom.end() ? nullptr : it->second;
  }

  Feeder& require(dGeomID geom, const char* what) const {
    Feeder* f = geom ? find(geom) : nullptr;
    if (!f) {
      std::ostringstream out;
      out << "rheofeed::FeederSet::" << what << ": geom " << static_cast<const void*>(geom)
          << (geom ? " is not a registered feeder" : " is null");
      throw std::invalid_argument(out.str());
    }
    return *f;
  }

  void checkLaw(dGeomID geom, const MotionLaw& law, const char* what) const {
    const std::string where = std::string("rheofeed::FeederSet::") + what + ": " + geomName(geom);
    law.validate(where);
    if (law.frame() == Frame::Body && dGeomGetBody(geom) == nullptr) {
      throw std::invalid_argument(where + ": law uses Frame::Body but the geom has no body");
    }
  }

  // The law of `f` frozen at the current step; computed on the step's first contact.
  const StepLaw& frozen(Feeder& f) {
    if (f.frozen_step == step) return f.frozen;
    Pose pose;
    const Pose* body_pose = nullptr;
    if (f.law.frame() == Frame::Body) {
      if (dBodyID body = dGeomGetBody(f.geom)) {
        pose = poseOf(body);
        body_pose = &pose;
      }
    }
    StepLaw next = f.law.evaluate(time, body_pose, step_length);
    f.changed = f.replaced || !next.sameMotionAs(f.frozen);
    f.replaced = false;
    f.frozen = std::move(next);
    f.frozen_step = step;
    return f.frozen;
  }

  // Reports `message()` (a callable building the text, so that building it cannot throw out
  // either) through the handler, or prints the first report of each kind per feeder.
  template <class Message>
  void report(Feeder& f, DiagnosticKind kind, Message&& message) noexcept {
    try {
      Diagnostic d{kind, f.geom, geomName(f.geom) + ": " + message()};
      if (handler) {
        handler(d);
      } else if (!f.reported[static_cast<int>(kind)]) {
        std::fprintf(stderr,
                     "rheofeed [%s]: %s (further reports of this kind are counted in "
                     "FeederStats)\n",
                     toString(kind), d.message.c_str());
      }
    } catch (...) {
      // A diagnostic must never unwind into ODE.
    }
    f.reported[static_cast<int>(kind)] = true;
  }

  // A driveContacts call with bad arguments: counted, reported (no feeder involved).
  void reportInvalidCall(const dContact* contacts, int count) noexcept {
    ++invalid_calls;
    try {
      std::ostringstream out;
      out << "rheofeed::FeederSet::driveContacts: ";
      if (count < 0) {
        out << "count = " << count << " is negative: must be in [0, number of contacts]";
      } else {
        out << "contacts = " << static_cast<const void*>(contacts)
            << " is null with count = " << count
            << ": a count > 0 needs an array of that many contacts";
      }
      out << "; nothing driven, 0 returned (caller bug)";
      Diagnostic d{DiagnosticKind::InvalidCall, nullptr, out.str()};
      if (handler) {
        handler(d);
      } else if (!invalid_call_reported) {
        std::fprintf(stderr,
                     "rheofeed [%s]: %s (further reports of this kind are counted in "
                     "FeederSet::invalidCalls)\n",
                     toString(d.kind), d.message.c_str());
      }
    } catch (...) {
      // A diagnostic must never unwind into ODE.
    }
    invalid_call_reported = true;
  }

  static void wake(dBodyID body, Feeder& f) {
    if (body && !dBodyIsEnabled(body)) {
      dBodyEnable(body);
      ++f.stats.bodies_woken;
    }
  }

  // Whether the contact data is safe to hand to ODE (cheap: runs on every feeder contact).
  static bool contactValid(const dContact& c) {
    const dContactGeom& g = c.geom;
    bool ok = std::isfinite(g.depth) && c.surface.mu >= 0;  // false for NaN mu
    for (int k = 0; k < 3; ++k) ok = ok && std::isfinite(g.pos[k]) && std::isfinite(g.normal[k]);
    // a unit normal (dCollide's are, to rounding; a zero or scaled one has no tangent plane)
    const double n2 =
        g.normal[0] * g.normal[0] + g.normal[1] * g.normal[1] + g.normal[2] * g.normal[2];
    ok = ok && std::abs(n2 - 1) <= kUnitNormalTolerance;
    if (c.surface.mode & dContactMu2) ok = ok && c.surface.mu2 >= 0;
    return ok;
  }

  // driveContacts' stages (defined below the struct).
  struct PairCache;
  struct Sides;
  struct Velocities;
  void lookup(const dContact& c, PairCache& pair) const;
  Sides sides(const dContact& c, const PairCache& pair) const;
  Velocities surfaceVelocities(const dContact& c, const PairCache& pair, const Sides& sd);
  bool feederVelocity(Feeder& f, const dContact& c, bool feeder_is_g1, dBodyID other, const Vec3& p,
                      const Vec3& n, Vec3& value);
  bool write(dContact& c, Feeder& primary, const Velocities& v);
  void record(const dContact& c, const PairCache& pair, const Sides& sd, const Velocities& v,
              bool driven) noexcept;

  // Names the first bad value of an invalid contact.
  static std::string contactProblem(const dContact& c) {
    const dContactGeom& g = c.geom;
    std::ostringstream out;
    for (int k = 0; k < 3; ++k) {
      if (!std::isfinite(g.pos[k])) {
        out << "contact pos[" << k << "] = " << g.pos[k] << " is not finite";
        return out.str();
      }
      if (!std::isfinite(g.normal[k])) {
        out << "contact normal[" << k << "] = " << g.normal[k] << " is not finite";
        return out.str();
      }
    }
    if (!std::isfinite(g.depth)) {
      out << "contact depth = " << g.depth << " is not finite";
      return out.str();
    }
    if (const double n2 =
            g.normal[0] * g.normal[0] + g.normal[1] * g.normal[1] + g.normal[2] * g.normal[2];
        !(std::abs(n2 - 1) <= kUnitNormalTolerance)) {
      out << "contact normal = (" << g.normal[0] << ", " << g.normal[1] << ", " << g.normal[2]
          << ") has length " << std::sqrt(n2) << ": must be a unit vector";
      return out.str();
    }
    if (std::isnan(c.surface.mu) || c.surface.mu < 0) {
      out << "contact mu = " << c.surface.mu << (c.surface.mu < 0 ? " is negative" : " is NaN");
      return out.str();
    }
    if ((c.surface.mode & dContactMu2) && (std::isnan(c.surface.mu2) || c.surface.mu2 < 0)) {
      out << "contact mu2 = " << c.surface.mu2 << (c.surface.mu2 < 0 ? " is negative" : " is NaN");
      return out.str();
    }
    return {};
  }
};

// ---- driveContacts' stages (file comment of feeder_set.hpp for the physics) ----------------
struct FeederSet::Impl::PairCache {
  dGeomID g1 = nullptr, g2 = nullptr;
  Feeder* f1 = nullptr;  // g1's feeder, or null
  Feeder* f2 = nullptr;  // g2's feeder, or null
};

// ODE's row order: node0 is the body attached first (Options::attach_order), unless it is 0 and
// the other is not (ODE swaps them then).
struct FeederSet::Impl::Sides {
  dGeomID first, second;
  dBodyID b_first, b_second;
  Feeder* f_first;
  Feeder* f_second;
};

// Tangential surface velocity of each side's geom at the contact (m/s, world; 0 for a geom that
// is no feeder); `finite` is false when a law failed (the contact is then left undriven).
struct FeederSet::Impl::Velocities {
  Vec3 c_first, c_second;
  bool finite = true;
};

// Stage 1, lookup: which of the contact's geoms are feeders (cached while the pair repeats).
void FeederSet::Impl::lookup(const dContact& c, PairCache& pair) const {
  if (c.geom.g1 == pair.g1 && c.geom.g2 == pair.g2) return;
  pair.g1 = c.geom.g1;
  pair.g2 = c.geom.g2;
  pair.f1 = find(pair.g1);
  pair.f2 = find(pair.g2);
}

FeederSet::Impl::Sides FeederSet::Impl::sides(const dContact& c, const PairCache& pair) const {
  Sides sd;
  sd.first = options.attach_order == AttachOrder::G1First ? c.geom.g1 : c.geom.g2;
  sd.second = sd.first == c.geom.g1 ? c.geom.g2 : c.geom.g1;
  sd.b_first = bodyOf(sd.first);
  sd.b_second = bodyOf(sd.second);
  if (!sd.b_first && sd.b_second) {
    std::swap(sd.first, sd.second);
    std::swap(sd.b_first, sd.b_second);
  }
  sd.f_first = sd.first == c.geom.g1 ? pair.f1 : pair.f2;
  sd.f_second = sd.first == c.geom.g1 ? pair.f2 : pair.f1;
  return sd;
}

// Stage 2, surface velocity: each feeder's frozen law at the contact (contactSurfaceVelocity,
// shared with the reference world), checked against the limits; sleeping parts on a feeder
// whose law changed are woken.
FeederSet::Impl::Velocities FeederSet::Impl::surfaceVelocities(const dContact& c,
                                                               const PairCache& pair,
                                                               const Sides& sd) {
  const Vec3 p = toVec3(c.geom.pos);
  const Vec3 n = toVec3(c.geom.normal);
  Velocities out;
  for (Feeder* f : {sd.f_first, sd.f_second}) {
    if (!f) continue;
    Vec3 value;
    if (!feederVelocity(*f, c, f == pair.f1, f == sd.f_first ? sd.b_second : sd.b_first, p, n,
                        value)) {
      out.finite = false;
    }
    (f == sd.f_first ? out.c_first : out.c_second) = value;
    if (f->changed) {  // the law changed: wake sleeping parts on it
      wake(sd.b_first, *f);
      wake(sd.b_second, *f);
    }
  }
  return out;
}

// One feeder's law at the contact into `value`; false (reported, counted) when the law failed
// or threw. `feeder_is_g1`: the normal n (ODE's, from g2 into g1) points out of the feeder
// when it is g2. `other`: the body on the other side of the contact (0 if static).
bool FeederSet::Impl::feederVelocity(Feeder& f, const dContact& c, bool feeder_is_g1, dBodyID other,
                                     const Vec3& p, const Vec3& n, Vec3& value) {
  // User functions (field, twist function, profile) run in here: whatever they throw is caught,
  // and the contact is left undriven (no exception may unwind into ODE).
  try {
    const StepLaw& law = frozen(f);
    if (!law.finite()) {
      ++(law.threw() ? f.stats.law_threw : f.stats.law_not_finite);
      report(f, law.threw() ? DiagnosticKind::LawThrew : DiagnosticKind::LawNotFinite,
             [&] { return law.problem() + "; contact left undriven"; });
      value = Vec3{};
      return false;
    }
    Vec3 centre;  // the other body's centre of mass: carried by secant laws, local laws' point
    const bool carried = other && (law.needsContactSide() || law.usesCarriedPoint());
    if (carried) centre = toVec3(dBodyGetPosition(other));
    value = contactSurfaceVelocity(law, p, n, feeder_is_g1 ? -n : n, c.surface.mu,
                                   law.needsContactSide() ? partEfficiency(other) : 1.0,
                                   carried ? &centre : nullptr);
    // Non-finite, or beyond what ODE's motion1 can take (motion_law.hpp, Limits): a NaN
    // component, or an inf (also from squares of finite components that overflow), fails the
    // one comparison.
    if (!(dot(value, value) <= kContactSpeedLimit2)) {
      ++f.stats.law_not_finite;
      report(f, DiagnosticKind::LawNotFinite, [&] {
        std::ostringstream out;
        out << "law gave surface velocity (" << value.x << ", " << value.y << ", " << value.z
            << ") m/s at p = (" << p.x << ", " << p.y << ", " << p.z << "), t = " << time
            << ": not finite or beyond the limit |c_t| <= " << kMaxSurfaceSpeed
            << " m/s; contact left undriven";
        return out.str();
      });
      return false;
    }
    return true;
  } catch (...) {
    value = Vec3{};
    ++f.stats.law_threw;
    report(f, DiagnosticKind::LawThrew, [&] {
      std::ostringstream out;
      out << "law threw at p = (" << p.x << ", " << p.y << ", " << p.z << "), t = " << time << ": "
          << detail::currentExceptionMessage() << "; contact left undriven";
      return out.str();
    });
    return false;
  }
}

// Stage 3, write: the friction mode (Approx1, the friction model) and fdir1 / motion1 along the
// relative surface velocity c_rel = c_second - c_first (ODE's row: (v_node0 - v_node1) . fdir1 =
// motion1). Returns whether the contact was driven (|c_rel| above min_surface_speed).
bool FeederSet::Impl::write(dContact& c, Feeder& primary, const Velocities& v) {
  dSurfaceParameters& surf = c.surface;
  if (options.force_approx1) {
    surf.mode |= dContactApprox1;
  } else if ((surf.mode & dContactApprox1) == 0 &&
             !primary.reported[static_cast<int>(DiagnosticKind::ForceCapFriction)]) {
    report(primary, DiagnosticKind::ForceCapFriction, [&] {
      return "contact without dContactApprox1: mu = " + std::to_string(surf.mu) +
             " is a force cap in newtons, not a coefficient";
    });
  }
  surf.mode = withFrictionModel(surf.mode, options.friction);
  if (surf.mu == 0) {
    ++primary.stats.zero_friction;
    report(primary, DiagnosticKind::ZeroFriction, [] {
      return std::string(
          "contact mu = 0: ODE applies no friction, so the surface motion has no effect");
    });
  }
  const Vec3 n = toVec3(c.geom.normal);
  const Vec3 c_rel = tangentialPart(v.c_second - v.c_first, n);
  const double speed = v.finite ? norm(c_rel) : 0.0;
  surf.mode &= ~(dContactMotion2);
  surf.motion2 = 0;
  const bool driven = speed > options.min_surface_speed;
  if (!driven) {
    surf.mode &= ~(dContactFDir1 | dContactMotion1);
    surf.motion1 = 0;
  } else {
    const Vec3 t = (1.0 / speed) * c_rel;
    c.fdir1[0] = t.x;
    c.fdir1[1] = t.y;
    c.fdir1[2] = t.z;
    c.fdir1[3] = 0;
    surf.motion1 = speed;
    surf.mode |= dContactFDir1 | dContactMotion1;
  }
  return driven;
}

// Stage 4, record: the per-feeder counters and, with Options::record_contacts, the contact.
void FeederSet::Impl::record(const dContact& c, const PairCache& pair, const Sides& sd,
                             const Velocities& v, bool driven) noexcept {
  Feeder& primary = pair.f1 ? *pair.f1 : *pair.f2;
  int FeederStats::*counter =
      driven ? &FeederStats::contacts_driven : &FeederStats::contacts_undriven;
  ++(primary.stats.*counter);
  if (pair.f1 && pair.f2) ++(pair.f2->stats.*counter);
  if (!options.record_contacts) return;
  try {
    const dGeomID g1 = c.geom.g1, g2 = c.geom.g2;
    const bool feeder_is_g1 = pair.f1 != nullptr;
    const Vec3 c_g1 = sd.first == g1 ? v.c_first : v.c_second;
    const Vec3 c_g2 = sd.first == g1 ? v.c_second : v.c_first;
    ContactRecord r;
    r.feeder = feeder_is_g1 ? g1 : g2;
    r.part = feeder_is_g1 ? g2 : g1;
    r.position = toVec3(c.geom.pos);
    r.normal = toVec3(c.geom.normal);
    // An undriven contact imposes nothing (a non-finite law value never leaves here).
    if (v.finite) r.surface_velocity = feeder_is_g1 ? c_g1 - c_g2 : c_g2 - c_g1;
    records.push_back(r);
  } catch (...) {
    // Out of memory while recording: observation only, the contact stays driven.
  }
}

FeederSet::FeederSet() : FeederSet(Options{}) {}

FeederSet::FeederSet(const Options& options) : impl_(std::make_unique<Impl>()) {
  requireDoublePrecisionOde();
  if (!(options.min_surface_speed >= 0) || !std::isfinite(options.min_surface_speed)) {
    std::ostringstream out;
    out << "rheofeed::FeederSet: Options::min_surface_speed = " << options.min_surface_speed
        << " must be finite and >= 0 (m/s)";
    throw std::invalid_argument(out.str());
  }
  requireFrictionModel(options.friction, "rheofeed::FeederSet: Options::friction");
  impl_->options = options;
}

FeederSet::~FeederSet() = default;
FeederSet::FeederSet(FeederSet&&) noexcept = default;
FeederSet& FeederSet::operator=(FeederSet&&) noexcept = default;

void FeederSet::add(dGeomID geom, MotionLaw law) {
  if (!geom) throw std::invalid_argument("rheofeed::FeederSet::add: geom is null");
  if (impl_->find(geom)) {
    throw std::invalid_argument("rheofeed::FeederSet::add: " + geomName(geom) +
                                " is already registered (use setLaw to change its law)");
  }
  impl_->checkLaw(geom, law, "add");
  auto feeder = std::make_unique<Impl::Feeder>();
  feeder->geom = geom;
  feeder->law = std::move(law);
  impl_->by_geom.emplace(geom, feeder.get());
  impl_->geoms.push_back(geom);
  impl_->feeders.push_back(std::move(feeder));
}

void FeederSet::setLaw(dGeomID geom, MotionLaw law) {
  Impl::Feeder& f = impl_->require(geom, "setLaw");
  impl_->checkLaw(geom, law, "setLaw");
  f.law = std::move(law);
  f.replaced = true;
  f.frozen_step = ~std::uint64_t{0};
  // The frozen law points into the old law's field; it is recomputed before any use.
  f.frozen = StepLaw{};
}

void FeederSet::remove(dGeomID geom) {
  impl_->require(geom, "remove");
  for (std::size_t i = 0; i < impl_->geoms.size(); ++i) {
    if (impl_->geoms[i] != geom) continue;
    impl_->geoms.erase(impl_->geoms.begin() + static_cast<std::ptrdiff_t>(i));
    impl_->feeders.erase(impl_->feeders.begin() + static_cast<std::ptrdiff_t>(i));
    break;
  }
  impl_->by_geom.erase(geom);
}

void FeederSet::setPartEfficiency(dBodyID body, double factor) {
  const std::string where = "rheofeed::FeederSet::setPartEfficiency: ";
  if (!body) throw std::invalid_argument(where + "body is null");
  if (!(factor >= 0 && factor <= kMaxEfficiency)) {
    std::ostringstream out;
    out << where << "factor = " << factor << " must be in [0, " << kMaxEfficiency << "]";
    throw std::invalid_argument(out.str());
  }
  impl_->part_efficiency[body] = factor;
}

void FeederSet::clearPartEfficiency(dBodyID body) {
  impl_->part_efficiency.erase(body);
}

bool FeederSet::contains(dGeomID geom) const {
  return geom && impl_->find(geom) != nullptr;
}

const MotionLaw& FeederSet::law(dGeomID geom) const {
  return impl_->require(geom, "law").law;
}

int FeederSet::size() const {
  return static_cast<int>(impl_->feeders.size());
}

void FeederSet::beginStep(double time, double step) {
  if (!std::isfinite(time)) {
    std::ostringstream out;
    out << "rheofeed::FeederSet::beginStep: time = " << time << " is not finite";
    throw std::invalid_argument(out.str());
  }
  if (!(step >= 0.0) || !std::isfinite(step)) {
    std::ostringstream out;
    out << "rheofeed::FeederSet::beginStep: step = " << step
        << " must be finite and >= 0 (s; 0 for the instantaneous surface velocity)";
    throw std::invalid_argument(out.str());
  }
  impl_->time = time;
  impl_->step_length = step;
  ++impl_->step;
  for (auto& f : impl_->feeders) {
    f->stats.contacts_driven = 0;
    f->stats.contacts_undriven = 0;
  }
  impl_->records.clear();
}

double FeederSet::time() const {
  return impl_->time;
}

// driveContacts, one contact at a time, in four named stages (Impl): lookup (which of the
// contact's geoms are feeders), surface velocity (each feeder's law at the contact), write
// (fdir1 / motion1 / mode into the dContact) and record (stats and ContactRecords).
int FeederSet::driveContacts(dContact* contacts, int count) noexcept {
  Impl& s = *impl_;
  if (count < 0 || (count > 0 && !contacts)) {
    s.reportInvalidCall(contacts, count);
    return 0;
  }
  if (count == 0 || s.feeders.empty()) return count;

  Impl::PairCache pair;  // contacts of one dCollide call share their geoms: one lookup
  int kept = 0;
  for (int i = 0; i < count; ++i) {
    dContact& c = contacts[i];
    s.lookup(c, pair);
    if (!pair.f1 && !pair.f2) {  // not a feeder contact: untouched
      if (kept != i) contacts[kept] = c;
      ++kept;
      continue;
    }
    Impl::Feeder& primary = pair.f1 ? *pair.f1 : *pair.f2;
    if (!Impl::contactValid(c)) {
      ++primary.stats.invalid_contacts;
      s.report(primary, DiagnosticKind::InvalidContact,
               [&] { return Impl::contactProblem(c) + "; contact removed"; });
      continue;
    }
    const Impl::Sides sides = s.sides(c, pair);
    const Impl::Velocities velocities = s.surfaceVelocities(c, pair, sides);
    const bool driven = s.write(c, primary, velocities);
    s.record(c, pair, sides, velocities, driven);
    if (kept != i) contacts[kept] = c;
    ++kept;
  }
  return kept;
}

std::uint64_t FeederSet::invalidCalls() const {
  return impl_->invalid_calls;
}

FeederStats FeederSet::stats(dGeomID geom) const {
  return impl_->require(geom, "stats").stats;
}

const std::vector<ContactRecord>& FeederSet::records() const {
  return impl_->records;
}
std::vector<ContactRecord>& FeederSet::records() {
  return impl_->records;
}

Vec3 FeederSet::slip(const ContactRecord& r) const {
  const Vec3 v_part = pointVelocity(bodyOf(r.part), r.position);
  const Vec3 v_feeder = pointVelocity(bodyOf(r.feeder), r.position);
  return tangentialPart(v_part - v_feeder - r.surface_velocity, r.normal);
}

void FeederSet::setDiagnosticHandler(std::function<void(const Diagnostic&)> handler) {
  impl_->handler = std::move(handler);
}

const FeederSet::Options& FeederSet::options() const {
  return impl_->options;
}

void FeederSet::setFrictionModel(FrictionModel model) {
  requireFrictionModel(model, "rheofeed::FeederSet::setFrictionModel: friction");
  impl_->options.friction = model;
}

FrictionModel FeederSet::frictionModel() const {
  return impl_->options.friction;
}

}  // namespace rheofeed

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
    if (c.surface.mode & dContactMu2) ok = ok && c.surface.mu2 >= 0;
    return ok;
  }

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

FeederSet::FeederSet() : FeederSet(Options{}) {}

FeederSet::FeederSet(const Options& options) : impl_(std::make_unique<Impl>()) {
  requireDoublePrecisionOde();
  if (!(options.min_surface_speed >= 0) || !std::isfinite(options.min_surface_speed)) {
    std::ostringstream out;
    out << "rheofeed::FeederSet: Options::min_surface_speed = " << options.min_surface_speed
        << " must be finite and >= 0 (m/s)";
    throw std::invalid_argument(out.str());
  }
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

int FeederSet::driveContacts(dContact* contacts, int count) noexcept {
  Impl& s = *impl_;
  if (count < 0 || (count > 0 && !contacts)) {
    s.reportInvalidCall(contacts, count);
    return 0;
  }
  if (count == 0 || s.feeders.empty()) return count;
  const Options& opt = s.options;

  // Contacts of one dCollide call share their geoms: look the pair up once.
  dGeomID last_g1 = nullptr, last_g2 = nullptr;
  Impl::Feeder* f1 = nullptr;
  Impl::Feeder* f2 = nullptr;
  int kept = 0;
  for (int i = 0; i < count; ++i) {
    dContact& c = contacts[i];
    const dGeomID g1 = c.geom.g1, g2 = c.geom.g2;
    if (g1 != last_g1 || g2 != last_g2) {
      f1 = s.find(g1);
      f2 = s.find(g2);
      last_g1 = g1;
      last_g2 = g2;
    }
    if (!f1 && !f2) {  // not a feeder contact: untouched
      if (kept != i) contacts[kept] = c;
      ++kept;
      continue;
    }
    Impl::Feeder& primary = f1 ? *f1 : *f2;

    if (!Impl::contactValid(c)) {
      ++primary.stats.invalid_contacts;
      s.report(primary, DiagnosticKind::InvalidContact,
               [&] { return Impl::contactProblem(c) + "; contact removed"; });
      continue;
    }

    // ODE's row order: node0 is the body attached first, unless it is 0 and the other is not.
    dGeomID first = opt.attach_order == AttachOrder::G1First ? g1 : g2;
    dGeomID second = first == g1 ? g2 : g1;
    dBodyID b_first = bodyOf(first), b_second = bodyOf(second);
    if (!b_first && b_second) {
      std::swap(first, second);
      std::swap(b_first, b_second);
    }
    Impl::Feeder* f_first = first == g1 ? f1 : f2;
    Impl::Feeder* f_second = first == g1 ? f2 : f1;

    const Vec3 p = toVec3(c.geom.pos);
    const Vec3 n = toVec3(c.geom.normal);
    Vec3 c_first, c_second;
    bool finite = true;
    for (Impl::Feeder* f : {f_first, f_second}) {
      if (!f) continue;
      Vec3 value;
      // User functions (field, twist function, profile) run in here: whatever they throw is
      // caught, and the contact is left undriven (no exception may unwind into ODE).
      try {
        const StepLaw& law = s.frozen(*f);
        if (!law.finite()) {
          finite = false;
          ++(law.threw() ? f->stats.law_threw : f->stats.law_not_finite);
          s.report(*f, law.threw() ? DiagnosticKind::LawThrew : DiagnosticKind::LawNotFinite,
                   [&] { return law.problem() + "; contact left undriven"; });
        } else {
          if (law.needsContactSide()) {
            // A local vibration law: the normal out of this feeder (ODE's points from g2 into
            // g1), the contact's mu and the part's own efficiency.
            const bool feeder_is_g1 = f == f1;
            const dBodyID part = feeder_is_g1 ? bodyOf(g2) : bodyOf(g1);
            Vec3 centre;  // the part's centre of mass (StepLaw::contactVelocity)
            if (part) centre = toVec3(dBodyGetPosition(part));
            value = law.contactVelocity(p, feeder_is_g1 ? -n : n, c.surface.mu,
                                        s.partEfficiency(part), part ? &centre : nullptr);
          } else {
            value = law.tangentialVelocity(p, n);
          }
          // A secant law carries the body on the other side of the contact rigidly; it is then
          // evaluated again. (Written this way because the if/else and ?: forms made every belt
          // and translation contact ~15 ns slower with GCC 12 -O3, measured.)
          if (law.usesCarriedPoint()) {
            if (const dBodyID carried = f == f_first ? b_second : b_first) {
              value = law.tangentialVelocity(p, n, toVec3(dBodyGetPosition(carried)));
            }
          }
          // Non-finite, or beyond what ODE's motion1 can take (motion_law.hpp, Limits): a NaN
          // component, or an inf (also from squares of finite components that overflow), fails
          // the one comparison.
          if (!(dot(value, value) <= kContactSpeedLimit2)) {
            finite = false;
            ++f->stats.law_not_finite;
            s.report(*f, DiagnosticKind::LawNotFinite, [&] {
              std::ostringstream out;
              out << "law gave surface velocity (" << value.x << ", " << value.y << ", " << value.z
                  << ") m/s at p = (" << p.x << ", " << p.y << ", " << p.z << "), t = " << s.time
                  << ": not finite or beyond the limit |c_t| <= " << kMaxSurfaceSpeed
                  << " m/s; contact left undriven";
              return out.str();
            });
          }
        }
      } catch (...) {
        finite = false;
        value = Vec3{};
        ++f->stats.law_threw;
        s.report(*f, DiagnosticKind::LawThrew, [&] {
          std::ostringstream out;
          out << "law threw at p = (" << p.x << ", " << p.y << ", " << p.z << "), t = " << s.time
              << ": " << detail::currentExceptionMessage() << "; contact left undriven";
          return out.str();
        });
      }
      (f == f_first ? c_first : c_second) = value;
      if (f->changed) {  // the law changed: wake sleeping parts on it
        Impl::wake(b_first, *f);
        Impl::wake(b_second, *f);
      }
    }

    dSurfaceParameters& surf = c.surface;
    if (opt.force_approx1) {
      surf.mode |= dContactApprox1;
    } else if ((surf.mode & dContactApprox1) == 0 &&
               !primary.reported[static_cast<int>(DiagnosticKind::ForceCapFriction)]) {
      s.report(primary, DiagnosticKind::ForceCapFriction, [&] {
        return "contact without dContactApprox1: mu = " + std::to_string(surf.mu) +
               " is a force cap in newtons, not a coefficient";
      });
    }
    if (surf.mu == 0) {
      ++primary.stats.zero_friction;
      s.report(primary, DiagnosticKind::ZeroFriction, [] {
        return std::string(
            "contact mu = 0: ODE applies no friction, so the surface motion has no effect");
      });
    }

    const Vec3 c_rel = tangentialPart(c_second - c_first, n);
    const double speed = finite ? norm(c_rel) : 0.0;
    surf.mode &= ~(dContactMotion2);
    surf.motion2 = 0;
    if (!(speed > opt.min_surface_speed)) {
      surf.mode &= ~(dContactFDir1 | dContactMotion1);
      surf.motion1 = 0;
      ++primary.stats.contacts_undriven;
      if (f1 && f2) ++f2->stats.contacts_undriven;
    } else {
      const Vec3 t = (1.0 / speed) * c_rel;
      c.fdir1[0] = t.x;
      c.fdir1[1] = t.y;
      c.fdir1[2] = t.z;
      c.fdir1[3] = 0;
      surf.motion1 = speed;
      surf.mode |= dContactFDir1 | dContactMotion1;
      ++primary.stats.contacts_driven;
      if (f1 && f2) ++f2->stats.contacts_driven;
    }

    if (opt.record_contacts) {
      try {
        const bool feeder_is_g1 = f1 != nullptr;
        const Vec3 c_g1 = first == g1 ? c_first : c_second;
        const Vec3 c_g2 = first == g1 ? c_second : c_first;
        ContactRecord r;
        r.feeder = feeder_is_g1 ? g1 : g2;
        r.part = feeder_is_g1 ? g2 : g1;
        r.position = p;
        r.normal = n;
        // An undriven contact imposes nothing (a non-finite law value never leaves here).
        if (finite) r.surface_velocity = feeder_is_g1 ? c_g1 - c_g2 : c_g2 - c_g1;
        s.records.push_back(r);
      } catch (...) {
        // Out of memory while recording: observation only, the contact stays driven.
      }
    }
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

}  // namespace rheofeed

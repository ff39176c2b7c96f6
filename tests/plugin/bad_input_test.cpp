// SPDX-License-Identifier: MIT
// Bad input everywhere it can enter: refused where it is made with a message that names the
// value, or (inside the near callback) reported, counted and kept away from ODE.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <limits>
#include <stdexcept>
#include <string>
#include <vector>

#include "ode_world.hpp"

namespace rheofeed::test {
namespace {

constexpr double kNan = std::numeric_limits<double>::quiet_NaN();
constexpr double kInf = std::numeric_limits<double>::infinity();

/// The message of the std::invalid_argument that `action` throws ("" if it throws nothing).
template <class Action>
std::string refusal(Action&& action) {
  try {
    action();
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  return "";
}

/// Expects `message` to contain every one of `parts`.
void expectMentions(const std::string& message, std::initializer_list<const char*> parts) {
  EXPECT_FALSE(message.empty()) << "nothing was refused";
  for (const char* part : parts) {
    EXPECT_NE(message.find(part), std::string::npos)
        << "message \"" << message << "\" does not mention \"" << part << "\"";
  }
}

/// Geoms to register: a static one, one on a dynamic body, and a part.
class BadInput : public testing::Test {
 protected:
  void SetUp() override {
    static const bool initialised = (dInitODE2(0), true);
    (void)initialised;
    world_ = dWorldCreate();
    static_geom_ = dCreateBox(nullptr, 1, 1, 1);
    body_geom_ = dCreateBox(nullptr, 1, 1, 1);
    dGeomSetBody(body_geom_, dBodyCreate(world_));
    part_ = dCreateBox(nullptr, 1, 1, 1);
    dGeomSetBody(part_, dBodyCreate(world_));
    set_.setDiagnosticHandler([this](const Diagnostic& d) { diagnostics_.push_back(d); });
  }
  void TearDown() override {
    for (dGeomID g : {static_geom_, body_geom_, part_}) dGeomDestroy(g);
    dWorldDestroy(world_);
  }
  static dContact contact(dGeomID g1, dGeomID g2) {
    dContact c;
    std::memset(&c, 0, sizeof c);
    c.geom.g1 = g1;
    c.geom.g2 = g2;
    c.geom.normal[2] = 1.0;
    c.geom.depth = 1e-3;
    c.surface.mode = dContactApprox1;
    c.surface.mu = 0.5;
    return c;
  }
  int count(DiagnosticKind kind) const {
    int n = 0;
    for (const Diagnostic& d : diagnostics_) n += d.kind == kind ? 1 : 0;
    return n;
  }
  const Diagnostic* last(DiagnosticKind kind) const {
    for (auto it = diagnostics_.rbegin(); it != diagnostics_.rend(); ++it) {
      if (it->kind == kind) return &*it;
    }
    return nullptr;
  }

  dWorldID world_;
  dGeomID static_geom_, body_geom_, part_;
  FeederSet set_;
  std::vector<Diagnostic> diagnostics_;
};

struct BadLaw {
  const char* what;
  MotionLaw law;
  std::vector<const char*> mentions;
};

std::vector<BadLaw> badLaws() {
  const Vec3 nan_x{kNan, 0, 0};
  return {
      {"twist linear nan", MotionLaw::twist({nan_x, {}, {}}), {"twist.linear.x", "nan"}},
      {"twist angular inf", MotionLaw::twist({{}, {0, kInf, 0}, {}}), {"twist.angular.y", "inf"}},
      {"twist origin -inf",
       MotionLaw::twist({{}, {0, 0, 1}, {0, 0, -kInf}}),
       {"twist.origin.z", "-inf"}},
      {"translation nan", MotionLaw::translation({0, 0, kNan}), {"twist.linear.z", "nan"}},
      {"rotation nan", MotionLaw::rotation({kNan, 0, 0}, {}), {"twist.angular.x", "nan"}},
      {"belt speed nan", MotionLaw::belt({1, 0, 0}, kNan), {"belt.speed", "nan"}},
      {"belt speed inf", MotionLaw::belt({1, 0, 0}, kInf), {"belt.speed", "inf"}},
      {"belt direction nan", MotionLaw::belt({1, kNan, 0}, 0.3), {"belt.direction", "nan"}},
      {"belt direction inf", MotionLaw::belt({kInf, 0, 0}, 0.3), {"belt.direction", "inf"}},
      {"belt direction zero", MotionLaw::belt({0, 0, 0}, 0.3), {"belt.direction", "(0, 0, 0)"}},
      {"profile constant nan",
       MotionLaw::belt({1, 0, 0}, 0.3).withProfile(TimeProfile::constant(kNan)),
       {"profile.scale", "nan"}},
      {"ramp t_start nan",
       MotionLaw::belt({1, 0, 0}, 0.3).withProfile(TimeProfile::ramp(kNan, 1, 0, 1)),
       {"profile.ramp.t_start", "nan"}},
      {"ramp t_end inf",
       MotionLaw::belt({1, 0, 0}, 0.3).withProfile(TimeProfile::ramp(0, kInf, 0, 1)),
       {"profile.ramp.t_end", "inf"}},
      {"ramp from nan",
       MotionLaw::belt({1, 0, 0}, 0.3).withProfile(TimeProfile::ramp(0, 1, kNan, 1)),
       {"profile.ramp.from", "nan"}},
      {"ramp to -inf",
       MotionLaw::belt({1, 0, 0}, 0.3).withProfile(TimeProfile::ramp(0, 1, 0, -kInf)),
       {"profile.ramp.to", "-inf"}},
      {"ramp backwards",
       MotionLaw::belt({1, 0, 0}, 0.3).withProfile(TimeProfile::ramp(2, 1, 0, 1)),
       {"profile.ramp.t_end", "1", "greater"}},
      {"on/off t_on nan",
       MotionLaw::belt({1, 0, 0}, 0.3).withProfile(TimeProfile::onOff(kNan, 1)),
       {"profile.on_off.t_on", "nan"}},
      {"on/off t_off nan",
       MotionLaw::belt({1, 0, 0}, 0.3).withProfile(TimeProfile::onOff(0, kNan)),
       {"profile.on_off.t_off", "nan"}},
      {"on/off backwards",
       MotionLaw::belt({1, 0, 0}, 0.3).withProfile(TimeProfile::onOff(2, 1)),
       {"profile.on_off.t_off", "greater"}},
      {"empty field", MotionLaw::field(nullptr), {"field function is empty"}},
      {"empty twist function", MotionLaw::twistFunction(nullptr), {"twist function is empty"}},
      {"empty profile function",
       MotionLaw::belt({1, 0, 0}, 0.3).withProfile(TimeProfile::function(nullptr)),
       {"profile function is empty"}},
  };
}

}  // namespace

// ---------------------------------------------------------------------------------------------
// Refused where it is made

TEST_F(BadInput, NonFiniteOrInconsistentLawParametersAreRefusedByName) {
  for (const BadLaw& bad : badLaws()) {
    SCOPED_TRACE(bad.what);
    const std::string message = refusal([&] { set_.add(static_geom_, bad.law); });
    for (const char* part : bad.mentions) expectMentions(message, {part});
    expectMentions(message, {"FeederSet::add", "feeder geom"});
    EXPECT_FALSE(set_.contains(static_geom_));
    EXPECT_EQ(set_.size(), 0);
  }
}

TEST_F(BadInput, SetLawRefusesTheSameAndKeepsTheOldLaw) {
  set_.add(static_geom_, MotionLaw::belt({1, 0, 0}, 0.3));
  for (const BadLaw& bad : badLaws()) {
    SCOPED_TRACE(bad.what);
    const std::string message = refusal([&] { set_.setLaw(static_geom_, bad.law); });
    for (const char* part : bad.mentions) expectMentions(message, {part});
    expectMentions(message, {"FeederSet::setLaw"});
  }
  // Still the belt: drives a contact at 0.3 m/s.
  dContact c = contact(static_geom_, part_);
  set_.beginStep(0.0);
  set_.driveContacts(&c, 1);
  EXPECT_DOUBLE_EQ(c.surface.motion1, 0.3);
}

TEST_F(BadInput, NullGeomIsRefusedEverywhere) {
  const MotionLaw belt = MotionLaw::belt({1, 0, 0}, 0.3);
  expectMentions(refusal([&] { set_.add(nullptr, belt); }), {"add", "null"});
  expectMentions(refusal([&] { set_.setLaw(nullptr, belt); }), {"setLaw", "null"});
  expectMentions(refusal([&] { set_.remove(nullptr); }), {"remove", "null"});
  expectMentions(refusal([&] { set_.stats(nullptr); }), {"stats", "null"});
  expectMentions(refusal([&] { set_.law(nullptr); }), {"law", "null"});
  EXPECT_FALSE(set_.contains(nullptr));
}

TEST_F(BadInput, UnregisteredGeomIsRefusedEverywhere) {
  const MotionLaw belt = MotionLaw::belt({1, 0, 0}, 0.3);
  set_.add(body_geom_, belt);  // another geom is registered
  for (auto [what, action] : std::vector<std::pair<const char*, std::function<void()>>>{
           {"setLaw", [&] { set_.setLaw(static_geom_, belt); }},
           {"remove", [&] { set_.remove(static_geom_); }},
           {"stats", [&] { set_.stats(static_geom_); }},
           {"law", [&] { set_.law(static_geom_); }},
       }) {
    SCOPED_TRACE(what);
    expectMentions(refusal(action), {what, "not a registered feeder"});
  }
  // After remove, a geom is unregistered again.
  set_.remove(body_geom_);
  expectMentions(refusal([&] { set_.stats(body_geom_); }), {"not a registered feeder"});
}

TEST_F(BadInput, GeomRegisteredTwiceIsRefused) {
  set_.add(static_geom_, MotionLaw::belt({1, 0, 0}, 0.3));
  expectMentions(refusal([&] {
                   set_.add(static_geom_, MotionLaw::belt({0, 1, 0}, 0.1));
                 }),
                 {"already registered"});
  EXPECT_EQ(set_.size(), 1);
  EXPECT_EQ(set_.law(static_geom_).kind(), MotionLaw::Kind::Belt);
}

TEST_F(BadInput, BodyFrameOnAGeomWithoutBodyIsRefused) {
  for (const MotionLaw& law :
       {MotionLaw::belt({1, 0, 0}, 0.3, Frame::Body),
        MotionLaw::rotation({0, 0, 1}, {}, Frame::Body),
        MotionLaw::twistFunction([](double) { return Twist{}; }, Frame::Body)}) {
    expectMentions(refusal([&] { set_.add(static_geom_, law); }), {"Frame::Body", "no body"});
    set_.add(body_geom_, law);  // fine on a geom with a body
    set_.remove(body_geom_);
  }
  set_.add(static_geom_, MotionLaw::belt({1, 0, 0}, 0.3));
  expectMentions(refusal([&] {
                   set_.setLaw(static_geom_, MotionLaw::belt({1, 0, 0}, 0.3, Frame::Body));
                 }),
                 {"Frame::Body", "no body"});
}

TEST_F(BadInput, NonFiniteStepTimeIsRefused) {
  expectMentions(refusal([&] { set_.beginStep(kNan); }), {"beginStep", "time", "nan"});
  expectMentions(refusal([&] { set_.beginStep(kInf); }), {"beginStep", "time", "inf"});
  expectMentions(refusal([&] { set_.beginStep(-kInf); }), {"beginStep", "-inf"});
  set_.beginStep(2.5);
  EXPECT_EQ(set_.time(), 2.5);
}

TEST_F(BadInput, NegativeOrNonFiniteStepLengthIsRefusedAndChangesNothing) {
  set_.beginStep(1.0, 0.01);
  expectMentions(refusal([&] { set_.beginStep(2.0, -0.01); }), {"beginStep", "step = -0.01"});
  expectMentions(refusal([&] { set_.beginStep(2.0, kNan); }), {"beginStep", "step = nan"});
  expectMentions(refusal([&] { set_.beginStep(2.0, kInf); }), {"beginStep", "step = inf"});
  EXPECT_EQ(set_.time(), 1.0);
  set_.beginStep(2.0, 0.0);  // 0: the instantaneous field
  EXPECT_EQ(set_.time(), 2.0);
}

TEST(BadOptions, MinSurfaceSpeedMustBeFiniteAndNonNegative) {
  for (double bad : {kNan, -1e-9, kInf}) {
    FeederSet::Options options;
    options.min_surface_speed = bad;
    expectMentions(refusal([&] { FeederSet set(options); }), {"min_surface_speed"});
  }
}

TEST(BadOptions, ContactColliderRefusesNullWorldAndBadContactCount) {
  static const bool initialised = (dInitODE2(0), true);
  (void)initialised;
  FeederSet set;
  expectMentions(refusal([&] { ContactCollider c(nullptr, set); }), {"world", "null"});
  dWorldID world = dWorldCreate();
  for (int bad : {0, -1, 70000}) {
    ContactCollider::Settings settings;
    settings.max_contacts_per_pair = bad;
    expectMentions(refusal([&] { ContactCollider c(world, set, settings); }),
                   {"max_contacts_per_pair", std::to_string(bad).c_str()});
  }
  dWorldDestroy(world);
}

// ---------------------------------------------------------------------------------------------
// Bad contact data: reported, counted, removed

TEST_F(BadInput, ContactsWithBadDataAreRemovedAndReportedByValue) {
  set_.add(static_geom_, MotionLaw::belt({1, 0, 0}, 0.3));
  struct Case {
    const char* what;
    void (*spoil)(dContact&);
    std::vector<const char*> mentions;
  };
  const std::vector<Case> cases = {
      {"negative mu", [](dContact& c) { c.surface.mu = -0.2; }, {"mu = -0.2", "negative"}},
      {"nan mu", [](dContact& c) { c.surface.mu = kNan; }, {"mu = nan"}},
      {"negative mu2",
       [](dContact& c) {
         c.surface.mode |= dContactMu2;
         c.surface.mu2 = -1;
       },
       {"mu2 = -1", "negative"}},
      {"nan normal", [](dContact& c) { c.geom.normal[1] = kNan; }, {"normal[1] = nan"}},
      {"inf position", [](dContact& c) { c.geom.pos[2] = kInf; }, {"pos[2] = inf"}},
      {"nan depth", [](dContact& c) { c.geom.depth = kNan; }, {"depth = nan"}},
      {"zero normal",
       [](dContact& c) { c.geom.normal[0] = c.geom.normal[1] = c.geom.normal[2] = 0; },
       {"normal = (0, 0, 0) has length 0", "unit vector"}},
      {"scaled normal",
       [](dContact& c) {
         c.geom.normal[0] = c.geom.normal[1] = 0;
         c.geom.normal[2] = -5;
       },
       {"has length 5"}},
  };
  std::uint64_t removed = 0;
  for (const Case& bad : cases) {
    SCOPED_TRACE(bad.what);
    dContact c[2] = {contact(part_, static_geom_), contact(static_geom_, part_)};
    bad.spoil(c[0]);
    c[1].geom.pos[0] = 0.75;  // marks the good contact
    set_.beginStep(0.0);
    ASSERT_EQ(set_.driveContacts(c, 2), 1);
    EXPECT_EQ(c[0].geom.pos[0], 0.75);  // the good one moved forward
    EXPECT_EQ(set_.stats(static_geom_).invalid_contacts, ++removed);
    const Diagnostic* d = last(DiagnosticKind::InvalidContact);
    ASSERT_NE(d, nullptr);
    EXPECT_EQ(d->feeder, static_geom_);
    for (const char* part : bad.mentions) expectMentions(d->message, {part});
    diagnostics_.clear();
  }
}

TEST_F(BadInput, ZeroFrictionIsReportedAndCountedButKept) {
  set_.add(static_geom_, MotionLaw::belt({1, 0, 0}, 0.3));
  dContact c = contact(static_geom_, part_);
  c.surface.mu = 0.0;
  set_.beginStep(0.0);
  ASSERT_EQ(set_.driveContacts(&c, 1), 1);
  EXPECT_EQ(set_.stats(static_geom_).zero_friction, 1u);
  ASSERT_EQ(count(DiagnosticKind::ZeroFriction), 1);
  expectMentions(last(DiagnosticKind::ZeroFriction)->message, {"mu = 0"});
  EXPECT_STREQ(toString(DiagnosticKind::ZeroFriction), "zero_friction");
}

TEST(BadInputOptions, ContactWithoutApprox1IsReportedOnceWhenNotForced) {
  static const bool initialised = (dInitODE2(0), true);
  (void)initialised;
  FeederSet::Options options;
  options.force_approx1 = false;
  FeederSet set(options);
  std::vector<Diagnostic> seen;
  set.setDiagnosticHandler([&seen](const Diagnostic& d) { seen.push_back(d); });
  dGeomID feeder = dCreateBox(nullptr, 1, 1, 1);
  dGeomID other = dCreateBox(nullptr, 1, 1, 1);
  set.add(feeder, MotionLaw::belt({1, 0, 0}, 0.3));
  for (int i = 0; i < 3; ++i) {
    dContact c;
    std::memset(&c, 0, sizeof c);
    c.geom.g1 = feeder;
    c.geom.g2 = other;
    c.geom.normal[2] = 1;
    c.surface.mu = 2.0;
    set.beginStep(0.0);
    set.driveContacts(&c, 1);
    EXPECT_FALSE(c.surface.mode & dContactApprox1);  // the application's mode is kept
    EXPECT_TRUE(c.surface.mode & dContactMotion1);
  }
  ASSERT_EQ(seen.size(), 1u);
  EXPECT_EQ(seen[0].kind, DiagnosticKind::ForceCapFriction);
  expectMentions(seen[0].message, {"force cap", "mu = 2"});
  dGeomDestroy(feeder);
  dGeomDestroy(other);
}

// ---------------------------------------------------------------------------------------------
// Laws that return non-finite values at run time

namespace {

struct RuntimeBadLaw {
  const char* what;
  MotionLaw law;
  std::vector<const char*> mentions;
};

std::vector<RuntimeBadLaw> runtimeBadLaws() {
  return {
      {"field nan",
       MotionLaw::field([](const Vec3&, const Vec3&, double) {
         return Vec3{kNan, 0, 0};
       }),
       {"nan"}},
      {"field inf",
       MotionLaw::field([](const Vec3&, const Vec3&, double) {
         return Vec3{0, kInf, 0};
       }),
       {"inf"}},
      {"twist function inf",
       MotionLaw::twistFunction([](double) {
         return Twist{{kInf, 0, 0}, {}, {}};
       }),
       {"twist.linear", "inf"}},
      {"twist function nan angular",
       MotionLaw::twistFunction([](double) {
         return Twist{{}, {0, 0, kNan}, {}};
       }),
       {"twist.angular", "nan"}},
      {"profile function nan",
       MotionLaw::belt({1, 0, 0}, 0.3).withProfile(TimeProfile::function([](double) {
         return kNan;
       })),
       {"profile", "nan"}},
  };
}

}  // namespace

TEST_F(BadInput, NonFiniteLawValueLeavesTheContactUndrivenAndIsReportedByValue) {
  for (const RuntimeBadLaw& bad : runtimeBadLaws()) {
    SCOPED_TRACE(bad.what);
    FeederSet set;
    std::vector<Diagnostic> seen;
    set.setDiagnosticHandler([&seen](const Diagnostic& d) { seen.push_back(d); });
    set.add(static_geom_, bad.law);
    dContact c = contact(static_geom_, part_);
    c.surface.mode |= dContactMotion1;  // as if the application had set some
    c.surface.motion1 = 1.0;
    set.beginStep(0.0);
    ASSERT_EQ(set.driveContacts(&c, 1), 1);
    EXPECT_FALSE(c.surface.mode & (dContactMotion1 | dContactFDir1 | dContactMotion2));
    EXPECT_EQ(c.surface.motion1, 0.0);
    EXPECT_EQ(c.surface.motion2, 0.0);
    EXPECT_EQ(set.stats(static_geom_).law_not_finite, 1u);
    EXPECT_EQ(set.stats(static_geom_).contacts_driven, 0);
    ASSERT_EQ(seen.size(), 1u);
    EXPECT_EQ(seen[0].kind, DiagnosticKind::LawNotFinite);
    for (const char* part : bad.mentions) expectMentions(seen[0].message, {part});
    expectMentions(seen[0].message, {"undriven"});
  }
}

TEST_F(BadInput, NonFiniteLawIsCountedOnTheFeederWhoseLawFailed) {
  // Feeder against feeder: only g2's law fails. The contact is undriven; the count belongs to
  // g2 (the one whose law a user must fix), as does the diagnostic.
  set_.add(static_geom_, MotionLaw::belt({1, 0, 0}, 0.3));
  set_.add(body_geom_, MotionLaw::field([](const Vec3&, const Vec3&, double) {
             return Vec3{kNan, 0, 0};
           }));
  dContact c = contact(static_geom_, body_geom_);
  set_.beginStep(0.0);
  ASSERT_EQ(set_.driveContacts(&c, 1), 1);
  EXPECT_FALSE(c.surface.mode & dContactMotion1);
  EXPECT_EQ(set_.stats(body_geom_).law_not_finite, 1u);
  EXPECT_EQ(set_.stats(static_geom_).law_not_finite, 0u);
  ASSERT_NE(last(DiagnosticKind::LawNotFinite), nullptr);
  EXPECT_EQ(last(DiagnosticKind::LawNotFinite)->feeder, body_geom_);
}

TEST(BadLawInWorld, NoNonFiniteValueReachesOde) {
  // The same bad laws in a real world for 0.2 s: the part rests as on a plain geom, its state
  // stays finite, and every feeder contact of every step is counted.
  for (const RuntimeBadLaw& bad : runtimeBadLaws()) {
    SCOPED_TRACE(bad.what);
    OdeWorld w;
    w.setSurface(dContactApprox1, 0.5);
    std::uint64_t reports = 0;
    w.feeders->setDiagnosticHandler([&reports](const Diagnostic&) { ++reports; });
    dGeomID table = w.staticBox(2, 2, 0.1, 0, 0, -0.05);
    dBodyID part = w.box(0.1, 0.1, 0.1, 1.0, 0, 0, 0.05);
    w.feeders->add(table, bad.law);
    std::uint64_t contacts = 0;
    for (int i = 0; i < 200; ++i) {
      w.step(0.001);
      contacts += static_cast<std::uint64_t>(w.collider->contactCount());
      ASSERT_TRUE(allFinite(stateOf(part))) << "step " << i;
    }
    EXPECT_GT(contacts, 0u);
    EXPECT_EQ(w.feeders->stats(table).law_not_finite, contacts);
    EXPECT_EQ(reports, contacts);
    EXPECT_LT(norm(linearVelocity(part)), 1e-3);  // not driven: it just rests
  }
}

TEST(InfiniteFriction, DInfinityMuWithForcedApprox1StaysFiniteAndSticksAtOnce) {
  // ODE documents mu = dInfinity as "never slips"; the plugin forces dContactApprox1, whose
  // bound is mu * lambda_n. The result must stay finite and stick in the first step. A flat
  // part and a long step keep the impulsive start (V / h = 30 m/s^2) below tipping (g lx/lz).
  OdeWorld w;
  w.setSurface(0, dInfinity);
  dWorldSetContactSurfaceLayer(w.world, 1e-4);
  dGeomID belt = w.staticBox(4, 1, 0.1, 0, 0, -0.05);
  dBodyID part = w.box(0.1, 0.1, 0.02, 1.0, 0, 0, 0.01 - 1e-4);
  w.feeders->add(belt, MotionLaw::belt({1, 0, 0}, 0.3));
  w.step(0.01);
  // The start takes a friction force m V / h = 30 N; the rows yield CFM * 30 N = 3e-8 m/s.
  constexpr double kImpulsiveYield = 2 * kWorldCfm * 1.0 * 0.3 / 0.01;
  EXPECT_NEAR(linearVelocity(part).x, 0.3, kImpulsiveYield);
  for (int i = 0; i < 100; ++i) {
    w.step(0.01);
    ASSERT_TRUE(allFinite(stateOf(part)));
  }
  EXPECT_NEAR(linearVelocity(part).x, 0.3, 1e-9);
}

// ---------------------------------------------------------------------------------------------
// Speeds beyond what ODE can take (motion_law.hpp, Limits): refused where the law is made, or
// (user functions, long lever arms) left undriven at the contact

namespace {

// Speeds near sqrt(DBL_MAX) = 1.3e154 overflow |c|^2: before the limits, such a belt gave
// motion1 = inf and fdir1 = 0 with no word.
constexpr double kOverflowingSpeed = 1e154;

// A belt, field or twist contact as in a real step: drives `c` through `set`.
void driveOne(FeederSet& set, dContact& c) {
  set.beginStep(0.0, 0.01);
  ASSERT_EQ(set.driveContacts(&c, 1), 1);
}

// The contact imposes no surface motion (and ODE gets no non-finite or huge number).
void expectUndriven(const dContact& c) {
  EXPECT_FALSE(c.surface.mode & (dContactMotion1 | dContactFDir1 | dContactMotion2));
  EXPECT_EQ(c.surface.motion1, 0.0);
}

}  // namespace

TEST_F(BadInput, BeltSpeedBeyondTheLimitIsRefusedWithValueAndRange) {
  for (double speed : {kOverflowingSpeed, -kOverflowingSpeed, 1.01 * kMaxSurfaceSpeed, 1e300}) {
    SCOPED_TRACE(speed);
    expectMentions(refusal([&] {
                     set_.add(static_geom_, MotionLaw::belt({1, 0, 0}, speed));
                   }),
                   {"FeederSet::add", "feeder geom", "belt.speed = ", "m/s", "[-1e+100, 1e+100]"});
  }
  EXPECT_EQ(set_.size(), 0);
  set_.add(static_geom_, MotionLaw::belt({1, 0, 0}, kMaxSurfaceSpeed));  // the limit itself
  dContact c = contact(static_geom_, part_);
  driveOne(set_, c);
  EXPECT_EQ(c.surface.motion1, kMaxSurfaceSpeed);
  // ODE makes the part node0 (the static feeder has no body): (v_part - 0) . fdir1 = motion1.
  EXPECT_EQ(c.fdir1[0], 1.0);
  // A slanted belt at the limit is driven too, whatever the rounding of its projection.
  set_.setLaw(static_geom_, MotionLaw::belt({1, 1, 0.3}, kMaxSurfaceSpeed));
  c = contact(static_geom_, part_);
  driveOne(set_, c);
  EXPECT_TRUE(c.surface.mode & dContactMotion1);
  // The belt's normalisation, projection and renormalisation: a few roundings of 2.2e-16.
  constexpr double kFewRoundings = 8 * std::numeric_limits<double>::epsilon();
  EXPECT_NEAR(c.surface.motion1 / kMaxSurfaceSpeed, 1.0, kFewRoundings);
  EXPECT_EQ(set_.stats(static_geom_).law_not_finite, 0u);
}

TEST_F(BadInput, TranslationSpeedBeyondTheLimitIsRefusedByItsLength) {
  // Components each within the limit, length beyond it: 8e99 * sqrt(2) = 1.13e100 m/s.
  for (const Vec3& v : {Vec3{kOverflowingSpeed, 0, 0}, Vec3{0, 0, -1e200}, Vec3{8e99, 8e99, 0}}) {
    SCOPED_TRACE(v.x + v.y + v.z);
    expectMentions(refusal([&] { set_.add(static_geom_, MotionLaw::translation(v)); }),
                   {"|twist.linear| = ", "m/s", "[0, 1e+100] m/s"});
  }
  EXPECT_EQ(set_.size(), 0);
}

TEST_F(BadInput, AngularSpeedBeyondTheLimitIsRefused) {
  expectMentions(refusal([&] {
                   set_.add(static_geom_, MotionLaw::rotation({0, 0, kOverflowingSpeed}, {}));
                 }),
                 {"|twist.angular| = 1e+154 rad/s", "[0, 1e+100] rad/s"});
  expectMentions(refusal([&] {
                   set_.add(body_geom_, MotionLaw::twist({{}, {-1e101, 0, 0}, {}}, Frame::Body));
                 }),
                 {"|twist.angular| = 1e+101 rad/s"});
  EXPECT_EQ(set_.size(), 0);
}

TEST_F(BadInput, TwistOriginBeyondTheLimitIsRefused) {
  expectMentions(refusal([&] {
                   set_.add(static_geom_, MotionLaw::rotation({0, 0, 1}, {0, -1e120, 0}));
                 }),
                 {"twist.origin.y = -1e+120 m", "[-1e+100, 1e+100] m"});
}

TEST_F(BadInput, ProfileThatScalesASpeedBeyondTheLimitIsRefused) {
  // Each factor is fine alone; their product is not.
  expectMentions(
      refusal([&] {
        set_.add(static_geom_,
                 MotionLaw::belt({1, 0, 0}, 1e60).withProfile(TimeProfile::constant(1e60)));
      }),
      {"profile value 1e+60", "|belt.speed| = 1e+60", "gives 1e+120 m/s", "[0, 1e+100] m/s"});
  expectMentions(
      refusal([&] {
        set_.add(
            static_geom_,
            MotionLaw::rotation({0, 0, 1e50}, {}).withProfile(TimeProfile::ramp(0, 1, 0, -1e60)));
      }),
      {"profile value 1e+60", "|twist.angular| = 1e+50", "rad/s", "1e+100"});
  set_.add(
      static_geom_,
      MotionLaw::belt({1, 0, 0}, 2.0).withProfile(TimeProfile::constant(5e99)));  // 1e100 exactly
}

TEST_F(BadInput, SetLawWithASpeedBeyondTheLimitKeepsTheOldLaw) {
  set_.add(static_geom_, MotionLaw::belt({1, 0, 0}, 0.3));
  expectMentions(refusal([&] {
                   set_.setLaw(static_geom_, MotionLaw::belt({1, 0, 0}, kOverflowingSpeed));
                 }),
                 {"FeederSet::setLaw", "belt.speed = 1e+154"});
  dContact c = contact(static_geom_, part_);
  driveOne(set_, c);
  EXPECT_DOUBLE_EQ(c.surface.motion1, 0.3);
}

TEST_F(BadInput, FieldValueBeyondTheLimitLeavesTheContactUndriven) {
  // Finite but overflowing: |c|^2 = inf. Before the per-contact guard: motion1 = inf, fdir1 = 0.
  set_.add(static_geom_, MotionLaw::field([](const Vec3&, const Vec3&, double) {
             return Vec3{kOverflowingSpeed, kOverflowingSpeed, 0};
           }));
  dContact c = contact(static_geom_, part_);
  driveOne(set_, c);
  expectUndriven(c);
  EXPECT_EQ(set_.stats(static_geom_).law_not_finite, 1u);
  EXPECT_EQ(set_.stats(static_geom_).contacts_undriven, 1);
  ASSERT_NE(last(DiagnosticKind::LawNotFinite), nullptr);
  expectMentions(last(DiagnosticKind::LawNotFinite)->message,
                 {"(1e+154, 1e+154, 0) m/s", "1e+100 m/s", "undriven"});
}

TEST_F(BadInput, LongLeverArmBeyondTheLimitLeavesTheContactUndriven) {
  // |w| at the limit is accepted; 10 m from the axis w x r is 1e101 m/s, beyond the limit.
  set_.add(static_geom_, MotionLaw::rotation({0, 0, kMaxAngularSpeed}, {-10, 0, 0}));
  dContact c = contact(static_geom_, part_);
  set_.beginStep(0.0);  // the instantaneous field w x (p - O)
  ASSERT_EQ(set_.driveContacts(&c, 1), 1);
  expectUndriven(c);
  EXPECT_EQ(set_.stats(static_geom_).law_not_finite, 1u);
  expectMentions(last(DiagnosticKind::LawNotFinite)->message, {"1e+101", "1e+100 m/s"});
}

TEST_F(BadInput, TwistFunctionBeyondTheLimitLeavesTheContactUndriven) {
  set_.add(static_geom_, MotionLaw::twistFunction([](double) {
             return Twist{{0, 2e100, 0}, {}, {}};
           }));
  dContact c = contact(static_geom_, part_);
  driveOne(set_, c);
  expectUndriven(c);
  EXPECT_EQ(set_.stats(static_geom_).law_not_finite, 1u);
  expectMentions(last(DiagnosticKind::LawNotFinite)->message,
                 {"twist function at t = 0", "|twist.linear| = 2e+100 m/s", "[0, 1e+100] m/s"});
}

TEST_F(BadInput, FunctionProfileBeyondTheLimitLeavesTheContactUndriven) {
  set_.add(static_geom_,
           MotionLaw::belt({1, 0, 0}, 2.0).withProfile(TimeProfile::function([](double) {
             return 1e100;
           })));
  dContact c = contact(static_geom_, part_);
  driveOne(set_, c);
  expectUndriven(c);
  EXPECT_EQ(set_.stats(static_geom_).law_not_finite, 1u);
  expectMentions(last(DiagnosticKind::LawNotFinite)->message,
                 {"profile(0) = 1e+100", "belt.speed = 2 m/s", "gives 2e+100 m/s"});
}

// ---------------------------------------------------------------------------------------------
// User functions that throw inside driveContacts (noexcept, called from ODE's near callback):
// the contact is left undriven and counted, never std::terminate

TEST_F(BadInput, ThrowingFieldLeavesTheContactUndrivenAndIsCounted) {
  set_.add(static_geom_, MotionLaw::field([](const Vec3&, const Vec3&, double) -> Vec3 {
             throw std::runtime_error("field boom");
           }));
  dContact c[2] = {contact(static_geom_, part_), contact(static_geom_, part_)};
  set_.beginStep(0.0);
  ASSERT_EQ(set_.driveContacts(c, 2), 2);  // kept (the normal row is still needed)
  expectUndriven(c[0]);
  expectUndriven(c[1]);
  EXPECT_EQ(set_.stats(static_geom_).law_threw, 2u);
  EXPECT_EQ(set_.stats(static_geom_).law_not_finite, 0u);
  EXPECT_EQ(count(DiagnosticKind::LawThrew), 2);
  expectMentions(last(DiagnosticKind::LawThrew)->message, {"field boom", "undriven"});
  EXPECT_STREQ(toString(DiagnosticKind::LawThrew), "law_threw");
}

TEST_F(BadInput, ThrowingTwistFunctionLeavesTheContactUndriven) {
  set_.add(static_geom_, MotionLaw::twistFunction([](double) -> Twist {
             throw std::out_of_range("no twist at this time");
           }));
  dContact c = contact(static_geom_, part_);
  driveOne(set_, c);
  expectUndriven(c);
  EXPECT_EQ(set_.stats(static_geom_).law_threw, 1u);
  expectMentions(last(DiagnosticKind::LawThrew)->message,
                 {"twist function threw", "no twist at this time"});
}

TEST_F(BadInput, ProfileThrowingANonStandardExceptionLeavesTheContactUndriven) {
  set_.add(static_geom_,
           MotionLaw::belt({1, 0, 0}, 0.3).withProfile(TimeProfile::function([](double) -> double {
             throw 42;
           })));
  dContact c = contact(static_geom_, part_);
  driveOne(set_, c);
  expectUndriven(c);
  EXPECT_EQ(set_.stats(static_geom_).law_threw, 1u);
  expectMentions(last(DiagnosticKind::LawThrew)->message,
                 {"profile function threw", "not a std::exception"});
}

TEST_F(BadInput, ThrowingFieldAgainstAGoodFeederIsCountedOnTheThrowingOne) {
  set_.add(static_geom_, MotionLaw::belt({1, 0, 0}, 0.3));
  set_.add(body_geom_, MotionLaw::field([](const Vec3&, const Vec3&, double) -> Vec3 {
             throw std::runtime_error("boom");
           }));
  dContact c = contact(static_geom_, body_geom_);
  driveOne(set_, c);
  expectUndriven(c);
  EXPECT_EQ(set_.stats(body_geom_).law_threw, 1u);
  EXPECT_EQ(set_.stats(static_geom_).law_threw, 0u);
  EXPECT_EQ(last(DiagnosticKind::LawThrew)->feeder, body_geom_);
}

// ---------------------------------------------------------------------------------------------
// Caller bugs in driveContacts: nothing driven, 0 returned, reported

TEST_F(BadInput, NullContactArrayWithAPositiveCountReturnsZeroAndIsReported) {
  set_.add(static_geom_, MotionLaw::belt({1, 0, 0}, 0.3));
  set_.beginStep(0.0);
  EXPECT_EQ(set_.driveContacts(nullptr, 3), 0);  // was 3: joints made from a null array
  EXPECT_EQ(set_.invalidCalls(), 1u);
  ASSERT_EQ(count(DiagnosticKind::InvalidCall), 1);
  const Diagnostic& d = *last(DiagnosticKind::InvalidCall);
  EXPECT_EQ(d.feeder, nullptr);
  expectMentions(d.message, {"driveContacts", "null", "count = 3", "0 returned"});
  EXPECT_EQ(set_.driveContacts(nullptr, 0), 0);  // nothing to drive: not a bug
  EXPECT_EQ(set_.invalidCalls(), 1u);
  EXPECT_STREQ(toString(DiagnosticKind::InvalidCall), "invalid_call");
}

TEST_F(BadInput, NegativeCountReturnsZeroAndIsReportedWithAndWithoutFeeders) {
  dContact c = contact(static_geom_, part_);
  EXPECT_EQ(set_.driveContacts(&c, -1), 0);  // no feeder registered yet
  set_.add(static_geom_, MotionLaw::belt({1, 0, 0}, 0.3));
  set_.beginStep(0.0);
  EXPECT_EQ(set_.driveContacts(&c, -7), 0);
  EXPECT_EQ(set_.invalidCalls(), 2u);
  expectMentions(last(DiagnosticKind::InvalidCall)->message,
                 {"count = -7", "negative", "[0, number of contacts]"});
  EXPECT_FALSE(c.surface.mode & dContactMotion1);  // untouched
}

TEST(BadInputDefaultHandler, InvalidCallIsPrintedOnceOnStderrAndCountedAlways) {
  FeederSet set;
  testing::internal::CaptureStderr();
  for (int i = 0; i < 3; ++i) EXPECT_EQ(set.driveContacts(nullptr, 2), 0);
  const std::string printed = testing::internal::GetCapturedStderr();
  EXPECT_EQ(set.invalidCalls(), 3u);
  expectMentions(printed, {"rheofeed [invalid_call]", "count = 2", "invalidCalls"});
  EXPECT_EQ(printed.find("rheofeed [invalid_call]"), printed.rfind("rheofeed [invalid_call]"))
      << "printed more than once: " << printed;
}

}  // namespace rheofeed::test

// SPDX-License-Identifier: MIT
// The reference world: ODE collision in, Eigen cone complementarity out (see world.hpp).
#include "rheofeed/reference/world.hpp"

#include <Eigen/Core>
#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <Eigen/SparseCore>
#include <cmath>
#include <exception>
#include <map>
#include <sstream>
#include <stdexcept>
#include <tuple>
#include <unordered_map>
#include <utility>

#include "ode_vec.hpp"
#include "rheofeed/ccp/problem.hpp"

namespace rheofeed::reference {
namespace {

using Eigen::Matrix3d;
using Eigen::Vector3d;

Vector3d toEigen(const Vec3& v) {
  return {v.x, v.y, v.z};
}
Vec3 toVec3(const Vector3d& v) {
  return {v.x(), v.y(), v.z()};
}
Vec3 toVec3(const dReal* a) {
  return {a[0], a[1], a[2]};
}
Eigen::Quaterniond toEigen(const Quat& q) {
  return {q.w, q.x, q.y, q.z};
}
Quat toQuat(const Eigen::Quaterniond& q) {
  return {q.w(), q.x(), q.y(), q.z()};
}

Matrix3d rotationOf(const Pose& p) {
  Matrix3d r;
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) r(i, j) = p.rotation[3 * i + j];
  }
  return r;
}

Pose poseOf(const Vector3d& x, const Matrix3d& r) {
  Pose p;
  p.position = toVec3(x);
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) p.rotation[3 * i + j] = r(i, j);
  }
  return p;
}

// Two unit vectors completing the unit normal n to a right-handed frame (as ODE's dPlaneSpace).
void planeSpace(const Vector3d& n, Vector3d& t1, Vector3d& t2) {
  if (std::abs(n.z()) > M_SQRT1_2) {
    const double a = n.y() * n.y() + n.z() * n.z(), k = 1.0 / std::sqrt(a);
    t1 = {0, -n.z() * k, n.y() * k};
  } else {
    const double a = n.x() * n.x() + n.y() * n.y(), k = 1.0 / std::sqrt(a);
    t1 = {-n.y() * k, n.x() * k, 0};
  }
  t2 = n.cross(t1);
}

[[noreturn]] void refuse(const std::string& message) {
  throw std::invalid_argument("rheofeed::reference::World: " + message);
}

// Below this surface speed (m/s) the friction frame is ODE's plane space, not aligned with c.
constexpr double kMinSurfaceSpeed = 1e-12;
// Share of |g| h (the speed gravity takes away in one step) that an unsettled Coulomb step may
// leave as spurious separation at a pressed contact before the solver corrects its normal
// impulses (ccp::Settings::coulomb_max_separation): a part lifted at 0.01 |g| h rises
// (0.01 |g| h)^2 / (2 |g|) = 5e-5 |g| h^2, 5e-8 m at h = 0.01 s, and falls back within the step.
constexpr double kSpuriousSeparationShare = 0.01;

Matrix3d skew(const Vector3d& a) {
  Matrix3d m;
  m << 0, -a.z(), a.y(), a.z(), 0, -a.x(), -a.y(), a.x(), 0;
  return m;
}

// Newton iterations of the implicit midpoint gyroscopic solve; quadratic convergence needs a
// handful where h |w| < 1, the cap only stops a solve that does not converge.
constexpr int kGyroNewtonIterations = 30;

// Torque-free rotation over one step (inertia and w in one frame, here the world frame with the
// inertia frozen at the step's start; principal axes or not): Euler's equation
// I dw/dt + w x I w = 0 by the implicit midpoint rule,
//   I (w2 - w1) = -h wm x I wm,   wm = (w1 + w2) / 2,
// solved for wm by Newton on G(wm) = 2 I (wm - w1) + h wm x I wm with Jacobian
// 2 I + h (skew(wm) I - skew(I wm)), starting at wm = w1. Both first integrals are kept in exact
// arithmetic: dotting with wm gives w2.I w2 = w1.I w1 (energy), and with L = I w,
// L2 - L1 = -h wm x (L1 + L2) / 2 is orthogonal to L1 + L2, so |L2| = |L1| (a Cayley rotation).
// (ODE 0.16 takes one Newton step of implicit Euler instead, which dissipates both.) The world
// rotates the body about w2 afterwards, which leaves w2 . I w2 unchanged, so a free body's
// energy is carried from step to step. Should Newton not converge (h |w| far beyond 1), one Newton
// step of implicit Euler from w1 is used (`converged` false). Either way the energy may not grow: a
// result with w2.I w2 > w1.I w1 (round-off, or the fallback) is scaled back to w1's energy.
Vector3d gyroscopicStep(const Matrix3d& inertia, const Vector3d& w1, double h, bool& converged) {
  constexpr double kEps = std::numeric_limits<double>::epsilon();
  Vector3d wm = w1;
  converged = false;
  for (int k = 0; k < kGyroNewtonIterations; ++k) {
    const Vector3d iwm = inertia * wm;
    const Vector3d g = 2 * inertia * (wm - w1) + h * wm.cross(iwm);
    const Matrix3d jac = 2 * inertia + h * (skew(wm) * inertia - skew(iwm));
    const Vector3d dw = jac.fullPivLu().solve(g);
    if (!dw.allFinite()) break;
    wm -= dw;
    if (dw.norm() <= 8 * kEps * wm.norm()) {
      converged = true;
      break;
    }
  }
  Vector3d w2 = 2 * wm - w1;
  if (!converged || !w2.allFinite()) {
    const Vector3d iw = inertia * w1;
    const Matrix3d jac = inertia + h * (skew(w1) * inertia - skew(iw));
    w2 = w1 - jac.fullPivLu().solve(h * w1.cross(iw));
    converged = false;
  }
  const double e1 = w1.dot(inertia * w1), e2 = w2.dot(inertia * w2);
  if (e2 > e1) w2 *= std::sqrt(e1 / e2);
  return w2;
}

}  // namespace

struct World::Impl {
  struct Body {
    bool kinematic = false;
    bool disabled = false;  // taken out of the simulation: no motion, no contacts
    double mass = 0;
    Matrix3d inv_inertia_body = Matrix3d::Zero();
    Matrix3d inertia_body = Matrix3d::Zero();
    BodyState state;
    MotionOfTime motion;
    int dof = -1;           // first generalised velocity index (dynamic bodies only)
    double efficiency = 1;  // factor on local vibration laws (World::setBodyEfficiency)
    Vector3d force = Vector3d::Zero(), torque = Vector3d::Zero();
  };
  struct Attached {
    dGeomID geom;
    BodyId body;
    Pose offset;
  };
  struct Feeder {
    dGeomID geom;
    MotionLaw law;
    StepLaw frozen;
  };
  struct RawContact {
    dGeomID g1, g2;
    BodyId a, b;
    Vector3d p, n;
    double depth, mu;
    int index;  // position among the pair's contacts (warm start key)
  };

  Settings settings;
  dSpaceID space = nullptr;
  std::exception_ptr collide_error;  // first exception inside the near callback (rethrown)
  double time = 0;
  std::vector<Body> bodies;
  // Attached geoms and feeders in insertion order, with an index by geom for lookups. Loops run
  // over the vectors, never over the maps: placeGeoms calls dGeomSetPosition, which moves the
  // geom to the front of its space's list, so that order is the collision (and contact) order,
  // and an order by pointer hash would make runs depend on heap addresses.
  std::vector<Attached> attached;
  std::unordered_map<dGeomID, std::size_t> attached_index;
  std::vector<Feeder> feeders;
  std::unordered_map<dGeomID, std::size_t> feeder_index;
  FrictionCallback friction;
  ccp::Solver solver;
  std::vector<RawContact> raw;
  std::vector<ContactImpulse> contacts;
  std::map<std::tuple<dGeomID, dGeomID, int>, Vector3d> warm;
  std::vector<dContactGeom> scratch;
  ccp::Problem problem;  // the last step's contact problem

  BodyId bodyOf(dGeomID g) const {
    auto it = attached_index.find(g);
    return it == attached_index.end() ? kStatic : attached[it->second].body;
  }
  bool isDynamic(BodyId b) const { return b != kStatic && !bodies[b].kinematic; }

  // Takes a dynamic body out of the simulation: it stops where it is, its geoms no longer
  // collide.
  void disable(BodyId body) {
    Body& b = bodies[static_cast<std::size_t>(body)];
    b.disabled = true;
    b.state.linear_velocity = {};
    b.state.angular_velocity = {};
    b.force.setZero();
    b.torque.setZero();
    for (const Attached& a : attached) {
      if (a.body == body) dGeomDisable(a.geom);
    }
  }

  Matrix3d rotation(BodyId b) const {
    return toEigen(bodies[b].state.orientation).normalized().toRotationMatrix();
  }

  // Velocity (m/s, world) of body b's material point at p (0 for the static environment).
  Vector3d pointVelocity(BodyId b, const Vector3d& p, const Eigen::VectorXd& v) const {
    if (b == kStatic) return Vector3d::Zero();
    const Body& body = bodies[b];
    const Vector3d x = toEigen(body.state.position);
    if (body.kinematic) {
      return toEigen(body.state.linear_velocity) +
             toEigen(body.state.angular_velocity).cross(p - x);
    }
    return v.segment<3>(body.dof) + v.segment<3>(body.dof + 3).cross(p - x);
  }

  void placeGeoms() {
    for (const Attached& a : attached) {
      const dGeomID geom = a.geom;
      const Body& body = bodies[a.body];
      const Matrix3d rb = rotation(a.body);
      const Matrix3d r = rb * rotationOf(a.offset);
      const Vector3d x = toEigen(body.state.position) + rb * toEigen(a.offset.position);
      setGeomPose(geom, poseOf(x, r));
    }
  }

  // ODE calls this from dSpaceCollide (C code): nothing may unwind through it. The first
  // exception (a user friction callback, an allocation) is kept, the rest of the pass is skipped,
  // and step() rethrows it once dSpaceCollide has returned.
  static void nearCallback(void* data, dGeomID o1, dGeomID o2) noexcept {
    auto* self = static_cast<Impl*>(data);
    if (self->collide_error) return;
    try {
      self->collidePair(o1, o2);
    } catch (...) {
      self->collide_error = std::current_exception();
    }
  }

  void collidePair(dGeomID o1, dGeomID o2) {
    if (dGeomIsSpace(o1) || dGeomIsSpace(o2)) {
      dSpaceCollide2(o1, o2, this, &nearCallback);
      return;
    }
    const BodyId a = bodyOf(o1), b = bodyOf(o2);
    if (!isDynamic(a) && !isDynamic(b)) return;
    if (a == b) return;
    const int max = settings.max_contacts_per_pair;
    scratch.resize(static_cast<std::size_t>(max));
    const int n = dCollide(o1, o2, max, scratch.data(), sizeof(dContactGeom));
    if (n <= 0) return;
    const double mu = friction ? friction(o1, o2) : settings.default_mu;
    for (int i = 0; i < n; ++i) {
      const dContactGeom& c = scratch[static_cast<std::size_t>(i)];
      raw.push_back({c.g1, c.g2, bodyOf(c.g1), bodyOf(c.g2), toEigen(toVec3(c.pos)),
                     toEigen(toVec3(c.normal)), c.depth, mu, i});
    }
  }

  // Tangential surface velocity of geom g at p with normal n_out pointing out of g (0 if g is
  // no feeder), friction mu, carrying the body `carried` on the other side of the contact
  // (StepLaw::tangentialVelocity; a local vibration law uses n_out, mu and the body's
  // efficiency: StepLaw::contactVelocity).
  Vector3d surfaceVelocity(dGeomID g, const Vector3d& p, const Vector3d& n_out, double mu,
                           BodyId carried) const {
    auto it = feeder_index.find(g);
    if (it == feeder_index.end()) return Vector3d::Zero();
    const StepLaw& law = feeders[it->second].frozen;
    if (law.needsContactSide()) {
      if (carried == kStatic) return toEigen(law.contactVelocity(toVec3(p), toVec3(n_out), mu));
      const Body& body = bodies[static_cast<std::size_t>(carried)];
      return toEigen(
          law.contactVelocity(toVec3(p), toVec3(n_out), mu, body.efficiency, &body.state.position));
    }
    if (carried == kStatic) return toEigen(law.tangentialVelocity(toVec3(p), toVec3(n_out)));
    return toEigen(
        law.tangentialVelocity(toVec3(p), toVec3(n_out), bodies[carried].state.position));
  }

  void freezeLaws(double h) {
    for (Feeder& f : feeders) {
      Pose pose;
      const Pose* body_pose = nullptr;
      const BodyId b = bodyOf(f.geom);
      if (b != kStatic) {
        pose = poseOf(toEigen(bodies[b].state.position), rotation(b));
        body_pose = &pose;
      }
      f.frozen = f.law.evaluate(time, body_pose, h);
      if (!f.frozen.finite()) refuse("feeder law is not finite: " + f.frozen.problem());
    }
  }
};

namespace {

// Empty when `settings` are usable, else a message naming the first bad value. Checked by the
// constructor and again by every step, since World::settings() hands out a mutable reference.
std::string settingsProblem(const Settings& settings) {
  std::ostringstream bad;
  if (!(settings.erp >= 0 && settings.erp <= 1))
    bad << "Settings::erp = " << settings.erp << " must be in [0, 1]";
  else if (!(settings.cfm >= 0) || !std::isfinite(settings.cfm))
    bad << "Settings::cfm = " << settings.cfm << " must be finite and >= 0";
  else if (!(settings.max_correcting_velocity >= 0))
    bad << "Settings::max_correcting_velocity = " << settings.max_correcting_velocity
        << " must be >= 0";
  else if (!(settings.surface_layer >= 0) || !std::isfinite(settings.surface_layer))
    bad << "Settings::surface_layer = " << settings.surface_layer << " must be finite and >= 0";
  else if (settings.max_contacts_per_pair < 1)
    bad << "Settings::max_contacts_per_pair = " << settings.max_contacts_per_pair
        << " must be >= 1";
  else if (!(settings.default_mu >= 0) || !std::isfinite(settings.default_mu))
    bad << "Settings::default_mu = " << settings.default_mu << " must be finite and >= 0";
  else if (!(settings.restitution >= 0 && settings.restitution <= 1))
    bad << "Settings::restitution = " << settings.restitution << " must be in [0, 1]";
  else if (!(settings.bounce_velocity >= 0) || !std::isfinite(settings.bounce_velocity))
    bad << "Settings::bounce_velocity = " << settings.bounce_velocity
        << " must be finite and >= 0 (m/s)";
  else if (!isFinite(settings.gravity))
    bad << "Settings::gravity is not finite";
  else if (std::string m = settings.solver.validate(); !m.empty())
    bad << "Settings::solver: " << m;
  return bad.str();
}

}  // namespace

World::World(const Settings& settings) : impl_(std::make_unique<Impl>()) {
  if (std::string bad = settingsProblem(settings); !bad.empty()) refuse(bad);
  impl_->settings = settings;
  impl_->solver.settings() = settings.solver;
  // ODE's collision module must be initialised once per process before any geom is used.
  static const bool ode_initialised = (dInitODE2(0), true);
  (void)ode_initialised;
  impl_->space = dHashSpaceCreate(nullptr);
}

World::~World() {
  if (impl_ && impl_->space) dSpaceDestroy(impl_->space);
}

dSpaceID World::space() const {
  return impl_->space;
}

BodyId World::addBody(double mass, const double inertia[9], const BodyState& state) {
  if (!(mass > 0) || !std::isfinite(mass)) {
    std::ostringstream out;
    out << "addBody: mass = " << mass << " must be finite and > 0 (kg)";
    refuse(out.str());
  }
  Matrix3d i;
  for (int k = 0; k < 9; ++k) {
    if (!std::isfinite(inertia[k]))
      refuse("addBody: inertia[" + std::to_string(k) + "] is not finite");
    i(k / 3, k % 3) = inertia[k];
  }
  if ((i - i.transpose()).norm() > 1e-12 * i.norm()) refuse("addBody: inertia is not symmetric");
  Eigen::SelfAdjointEigenSolver<Matrix3d> eig(i);
  if (eig.eigenvalues().minCoeff() <= 0) {
    std::ostringstream out;
    out << "addBody: inertia has eigenvalue " << eig.eigenvalues().minCoeff()
        << " <= 0 (must be positive definite, kg m^2)";
    refuse(out.str());
  }
  if (!isFinite(state.position) || !isFinite(state.linear_velocity) ||
      !isFinite(state.angular_velocity)) {
    refuse("addBody: initial state is not finite");
  }
  Impl::Body b;
  b.mass = mass;
  b.inertia_body = i;
  b.inv_inertia_body = i.inverse();
  b.state = state;
  b.state.orientation = toQuat(toEigen(state.orientation).normalized());
  int dof = 0;
  for (const auto& other : impl_->bodies) dof += other.kinematic ? 0 : 6;
  b.dof = dof;
  impl_->bodies.push_back(b);
  return static_cast<BodyId>(impl_->bodies.size() - 1);
}

BodyId World::addKinematicBody(MotionOfTime motion) {
  if (!motion) refuse("addKinematicBody: motion function is empty");
  Impl::Body b;
  b.kinematic = true;
  b.mass = std::numeric_limits<double>::infinity();
  b.motion = std::move(motion);
  const Pose p = b.motion(impl_->time);
  if (!isFinite(p.position)) refuse("addKinematicBody: motion(t) position is not finite");
  b.state.position = p.position;
  b.state.orientation = toQuat(p);
  impl_->bodies.push_back(std::move(b));
  return static_cast<BodyId>(impl_->bodies.size() - 1);
}

void World::attachGeom(dGeomID geom, BodyId body, const Pose& offset) {
  if (!geom) refuse("attachGeom: geom is null");
  if (body < 0 || body >= numBodies())
    refuse("attachGeom: body " + std::to_string(body) + " does not exist");
  if (dGeomGetBody(geom))
    refuse("attachGeom: geom has an ODE body; reference geoms must have none");
  if (dGeomGetSpace(geom) != impl_->space) refuse("attachGeom: geom is not in World::space()");
  if (impl_->attached_index.count(geom)) refuse("attachGeom: geom is already attached");
  if (!isFinite(offset.position)) refuse("attachGeom: offset position is not finite");
  impl_->attached_index.emplace(geom, impl_->attached.size());
  impl_->attached.push_back(Impl::Attached{geom, body, offset});
}

void World::setFeeder(dGeomID geom, MotionLaw law) {
  if (!geom) refuse("setFeeder: geom is null");
  std::ostringstream where;
  where << "rheofeed::reference::World::setFeeder: geom " << static_cast<const void*>(geom);
  law.validate(where.str());
  auto it = impl_->feeder_index.find(geom);
  if (it != impl_->feeder_index.end()) {
    impl_->feeders[it->second].law = std::move(law);
    return;
  }
  impl_->feeder_index.emplace(geom, impl_->feeders.size());
  impl_->feeders.push_back(Impl::Feeder{geom, std::move(law), StepLaw{}});
}

void World::setBodyEfficiency(BodyId body, double factor) {
  if (body < 0 || body >= static_cast<BodyId>(impl_->bodies.size()) ||
      impl_->bodies[static_cast<std::size_t>(body)].kinematic) {
    refuse("setBodyEfficiency: body " + std::to_string(body) + " is not a dynamic body");
  }
  if (!(factor >= 0 && factor <= kMaxEfficiency)) {
    std::ostringstream out;
    out << "setBodyEfficiency: factor = " << factor << " must be in [0, " << kMaxEfficiency << "]";
    refuse(out.str());
  }
  impl_->bodies[static_cast<std::size_t>(body)].efficiency = factor;
}

void World::setFrictionCallback(FrictionCallback callback) {
  impl_->friction = std::move(callback);
}

void World::addForce(BodyId body, const Vec3& force, const Vec3& torque) {
  if (body < 0 || body >= numBodies())
    refuse("addForce: body " + std::to_string(body) + " does not exist");
  if (!isFinite(force) || !isFinite(torque)) refuse("addForce: force or torque is not finite");
  impl_->bodies[body].force += toEigen(force);
  impl_->bodies[body].torque += toEigen(torque);
}

Vec3 secantAngularVelocity(const Pose& p0, const Pose& p1, double h) {
  const Eigen::AngleAxisd rel(rotationOf(p1) * rotationOf(p0).transpose());
  return toVec3(rel.axis() * (rel.angle() / h));
}

Quat toQuat(const Pose& pose) {
  return toQuat(Eigen::Quaterniond(rotationOf(pose)).normalized());
}

Pose toPose(const Quat& q, const Vec3& position) {
  return poseOf(toEigen(position), toEigen(q).normalized().toRotationMatrix());
}

StepReport World::step(double h) {
  Impl& s = *impl_;
  if (!(h > 0) || !std::isfinite(h)) {
    std::ostringstream out;
    out << "step: h = " << h << " must be finite and > 0 (s)";
    refuse(out.str());
  }
  if (std::string bad = settingsProblem(s.settings); !bad.empty()) refuse("step: " + bad);
  const Settings& cfg = s.settings;

  // Kinematic bodies: secant velocity over [t, t + h], pose at t + h applied after the step.
  std::vector<Pose> next_pose(s.bodies.size());
  for (std::size_t k = 0; k < s.bodies.size(); ++k) {
    Impl::Body& b = s.bodies[k];
    if (!b.kinematic) continue;
    const Pose p0 = b.motion(s.time), p1 = b.motion(s.time + h);
    if (!isFinite(p0.position) || !isFinite(p1.position)) {
      const bool first = !isFinite(p0.position);
      const Vec3& x = first ? p0.position : p1.position;
      std::ostringstream out;
      out << "step: kinematic body " << k << ": motion(t = " << (first ? s.time : s.time + h)
          << ").position = (" << x.x << ", " << x.y << ", " << x.z << ") is not finite";
      refuse(out.str());
    }
    b.state.position = p0.position;
    b.state.orientation = toQuat(p0);
    b.state.linear_velocity = (1.0 / h) * (p1.position - p0.position);
    b.state.angular_velocity = secantAngularVelocity(p0, p1, h);
    next_pose[k] = p1;
  }

  // Free velocities of the dynamic bodies.
  StepReport report;
  int ndof = 0;
  for (const auto& b : s.bodies) ndof += b.kinematic ? 0 : 6;
  Eigen::VectorXd v_free(ndof);
  Eigen::VectorXd v_pre = Eigen::VectorXd::Zero(ndof);  // pre-step velocities, for restitution
  std::vector<Matrix3d> inv_inertia_world(s.bodies.size(), Matrix3d::Zero());
  for (std::size_t k = 0; k < s.bodies.size(); ++k) {
    Impl::Body& b = s.bodies[k];
    if (b.kinematic) continue;
    const Matrix3d r = s.rotation(static_cast<BodyId>(k));
    // A disabled body keeps its mass in M^-1 (it has no contacts) but does not move.
    inv_inertia_world[k] = r * b.inv_inertia_body * r.transpose();
    if (b.disabled) {
      v_free.segment<6>(b.dof).setZero();
      continue;
    }
    v_pre.segment<3>(b.dof) = toEigen(b.state.linear_velocity);
    v_pre.segment<3>(b.dof + 3) = toEigen(b.state.angular_velocity);
    // Solved in the world frame with I_world = R I R^T (Euler's equation reads the same there,
    // I_world dw/dt = -w x I_world w, with I_world frozen over the step). Mapping w to the body
    // and back instead would scale it by the rotation's round-off, twice per step, and that
    // bias accumulates (~3e-16 of the energy per step, measured).
    Matrix3d i_world = r * b.inertia_body * r.transpose();
    i_world = 0.5 * (i_world + i_world.transpose()).eval();
    bool converged = true;
    const Vector3d w = gyroscopicStep(i_world, toEigen(b.state.angular_velocity), h, converged);
    if (!converged) report.gyroscopic_fallbacks++;
    v_free.segment<3>(b.dof) =
        toEigen(b.state.linear_velocity) + h * (toEigen(cfg.gravity) + b.force / b.mass);
    v_free.segment<3>(b.dof + 3) = w + h * inv_inertia_world[k] * b.torque;
    if (!v_free.segment<6>(b.dof).allFinite()) {
      // E.g. forces or torques whose sum or effect overflows: the body stops where it is.
      v_free.segment<6>(b.dof).setZero();
      s.disable(static_cast<BodyId>(k));
      report.nonfinite_bodies.push_back(static_cast<BodyId>(k));
    }
  }

  // Collision after the free velocities, so that bodies found non-finite there no longer
  // collide.
  s.placeGeoms();
  s.freezeLaws(h);
  s.raw.clear();
  s.collide_error = nullptr;
  dSpaceCollide(s.space, &s, &Impl::nearCallback);
  if (s.collide_error) {
    s.raw.clear();
    std::rethrow_exception(std::exchange(s.collide_error, nullptr));
  }

  const int nc = static_cast<int>(s.raw.size());
  report.contacts = nc;
  Eigen::VectorXd v_next = v_free;
  std::vector<ContactImpulse> out(static_cast<std::size_t>(nc));
  if (nc > 0) {
    std::vector<Eigen::Triplet<double>> d_entries;
    d_entries.reserve(static_cast<std::size_t>(nc) * 3 * 12);
    Eigen::VectorXd r(3 * nc), mu(nc);
    std::vector<Matrix3d> frames(static_cast<std::size_t>(nc));  // columns n, t1, t2
    for (int i = 0; i < nc; ++i) {
      const Impl::RawContact& c = s.raw[static_cast<std::size_t>(i)];
      const Vector3d c_rel = s.surfaceVelocity(c.g2, c.p, c.n, c.mu, c.a) -
                             s.surfaceVelocity(c.g1, c.p, -c.n, c.mu, c.b);
      const Vector3d c_t = c_rel - c_rel.dot(c.n) * c.n;
      Vector3d t1, t2;
      const double speed = c_t.norm();
      if (speed > kMinSurfaceSpeed) {
        t1 = c_t / speed;
        t2 = c.n.cross(t1);
      } else {
        planeSpace(c.n, t1, t2);
      }
      Matrix3d& f = frames[static_cast<std::size_t>(i)];
      f.col(0) = c.n;
      f.col(1) = t1;
      f.col(2) = t2;
      const Vector3d rel_free =
          s.pointVelocity(c.a, c.p, v_free) - s.pointVelocity(c.b, c.p, v_free);
      const double push = std::min(cfg.erp * std::max(c.depth - cfg.surface_layer, 0.0) / h,
                                   cfg.max_correcting_velocity);
      // Restitution as ODE's dContactBounce: when the pre-step approach speed exceeds
      // bounce_velocity, the normal row targets u_n+ >= e * approach, or the ERP push if that is
      // larger (the push alone is capped by max_correcting_velocity, the bounce is not).
      double target = push;
      if (cfg.restitution > 0) {
        const double approach =
            -c.n.dot(s.pointVelocity(c.a, c.p, v_pre) - s.pointVelocity(c.b, c.p, v_pre));
        if (approach > cfg.bounce_velocity) target = std::max(target, cfg.restitution * approach);
      }
      r(3 * i) = c.n.dot(rel_free) - target;
      r(3 * i + 1) = t1.dot(rel_free) - t1.dot(c_t);
      r(3 * i + 2) = t2.dot(rel_free) - t2.dot(c_t);
      mu(i) = c.mu;
      for (int k = 0; k < 3; ++k) {
        const Vector3d dir = f.col(k);
        for (int side = 0; side < 2; ++side) {
          const BodyId b = side == 0 ? c.a : c.b;
          if (!s.isDynamic(b)) continue;
          const double sign = side == 0 ? 1.0 : -1.0;
          const Vector3d arm = c.p - toEigen(s.bodies[b].state.position);
          const Vector3d ang = arm.cross(dir);
          const int dof = s.bodies[b].dof;
          for (int q = 0; q < 3; ++q) {
            d_entries.emplace_back(dof + q, 3 * i + k, sign * dir(q));
            d_entries.emplace_back(dof + 3 + q, 3 * i + k, sign * ang(q));
          }
        }
      }
    }
    ccp::SparseMatrix d(ndof, 3 * nc);
    d.setFromTriplets(d_entries.begin(), d_entries.end());
    std::vector<Eigen::Triplet<double>> m_entries;
    m_entries.reserve(static_cast<std::size_t>(ndof) * 3);
    for (std::size_t k = 0; k < s.bodies.size(); ++k) {
      const Impl::Body& b = s.bodies[k];
      if (b.kinematic) continue;
      for (int q = 0; q < 3; ++q) m_entries.emplace_back(b.dof + q, b.dof + q, 1.0 / b.mass);
      for (int p = 0; p < 3; ++p) {
        for (int q = 0; q < 3; ++q) {
          m_entries.emplace_back(b.dof + 3 + p, b.dof + 3 + q, inv_inertia_world[k](p, q));
        }
      }
    }
    ccp::SparseMatrix minv(ndof, ndof);
    minv.setFromTriplets(m_entries.begin(), m_entries.end());

    const double compliance = cfg.cfm / h;
    ccp::Problem& problem = s.problem;
    if (nc <= cfg.dense_contact_limit) {
      Eigen::MatrixXd n = Eigen::MatrixXd(d.transpose() * (minv * d));
      n.diagonal().array() += compliance;
      problem = ccp::Problem::makeDense(std::move(n), r, mu);
    } else {
      // N + c I = [D; sqrt(c) I]^T blkdiag(M^-1, I) [D; sqrt(c) I]: the compliance enters the
      // matrix-free operator as 3 nc virtual unit-mass coordinates, one per contact row.
      const double root = std::sqrt(compliance);
      ccp::SparseMatrix d_aug(ndof + 3 * nc, 3 * nc), minv_aug(ndof + 3 * nc, ndof + 3 * nc);
      for (int k = 0; k < 3 * nc; ++k) {
        d_entries.emplace_back(ndof + k, k, root);
        m_entries.emplace_back(ndof + k, ndof + k, 1.0);
      }
      d_aug.setFromTriplets(d_entries.begin(), d_entries.end());
      minv_aug.setFromTriplets(m_entries.begin(), m_entries.end());
      problem = ccp::Problem::makeMatrixFree(std::move(d_aug), std::move(minv_aug), r, mu);
    }

    Eigen::VectorXd gamma = Eigen::VectorXd::Zero(3 * nc);
    if (cfg.warm_start) {
      for (int i = 0; i < nc; ++i) {
        const Impl::RawContact& c = s.raw[static_cast<std::size_t>(i)];
        auto it = s.warm.find({c.g1, c.g2, c.index});
        if (it != s.warm.end()) gamma.segment<3>(3 * i) = it->second;
      }
    }
    s.solver.settings() = cfg.solver;
    s.solver.settings().coulomb_max_separation =
        std::max(cfg.solver.coulomb_max_separation,
                 kSpuriousSeparationShare * toEigen(cfg.gravity).norm() * h);
    report.solve = s.solver.solve(problem, gamma);
    // When the true-Coulomb fixed point does not settle, the solver returns its outer iterate
    // with the lowest Coulomb residual, and the step uses it, normals corrected when it
    // separates a pressed contact faster than coulomb_max_separation (solver.cpp). The relaxed CCP
    // is no fallback: it separates every sliding contact at u_n = mu |u_t| (a box on a 10 m/s belt
    // with mu = 0.5 leaves at 5 m/s). A shifted iterate k + 1 separates a sliding contact only by
    // mu (|u_t^(k+1)| - |u_t^(k)|), the change of slip between iterates, and the Coulomb
    // residual (reported) bounds that: with rho = 1 a pressed contact's normal velocity error is
    // at most coulomb_residual (1 + |r|) (m/s).
    report.coulomb_fallback = cfg.solver.coulomb_outer_iterations > 0 &&
                              report.solve.status == ccp::Status::MaxIterations;
    report.coulomb_residual = report.solve.coulomb_distance;
    if (report.solve.status == ccp::Status::InvalidInput) {
      refuse("step: the contact problem was refused: " + report.solve.message);
    }
    if (!gamma.allFinite()) {
      // Not expected (the solver returns its last finite iterate), but never integrated: the
      // non-finite contact blocks apply no impulse and the step's status says so.
      for (int i = 0; i < 3 * nc; ++i) {
        if (!std::isfinite(gamma(i))) gamma.segment<3>(3 * (i / 3)).setZero();
      }
      report.solve.status = ccp::Status::NumericalIssue;
      report.solve.message += " (non-finite impulses were dropped)";
    }
    v_next = v_free + minv * (d * gamma);
    const Eigen::VectorXd u = d.transpose() * v_next + (r - d.transpose() * v_free);

    s.warm.clear();
    for (int i = 0; i < nc; ++i) {
      const Impl::RawContact& c = s.raw[static_cast<std::size_t>(i)];
      const Matrix3d& f = frames[static_cast<std::size_t>(i)];
      s.warm[{c.g1, c.g2, c.index}] = gamma.segment<3>(3 * i);
      ContactImpulse& ci = out[static_cast<std::size_t>(i)];
      ci.g1 = c.g1;
      ci.g2 = c.g2;
      ci.body1 = c.a;
      ci.body2 = c.b;
      ci.position = toVec3(c.p);
      ci.normal = toVec3(c.n);
      ci.depth = c.depth;
      ci.normal_impulse = gamma(3 * i);
      ci.tangential_impulse = toVec3(gamma(3 * i + 1) * f.col(1) + gamma(3 * i + 2) * f.col(2));
      ci.slip = toVec3(u(3 * i + 1) * f.col(1) + u(3 * i + 2) * f.col(2));
      ci.normal_velocity = u(3 * i);
    }
  } else {
    s.warm.clear();
  }
  s.contacts = std::move(out);

  // Integrate (semi-implicit Euler, as ODE's dxStepBody without finite rotation).
  for (std::size_t k = 0; k < s.bodies.size(); ++k) {
    Impl::Body& b = s.bodies[k];
    if (b.kinematic) {
      b.state.position = next_pose[k].position;
      b.state.orientation = toQuat(next_pose[k]);
      continue;
    }
    if (b.disabled) continue;
    const BodyState before = b.state;
    const Vector3d v = v_next.segment<3>(b.dof), w = v_next.segment<3>(b.dof + 3);
    b.state.linear_velocity = toVec3(v);
    b.state.angular_velocity = toVec3(w);
    b.state.position = toVec3(toEigen(b.state.position) + h * v);
    Eigen::Quaterniond q = toEigen(b.state.orientation);
    const Eigen::Quaterniond wq(0, w.x(), w.y(), w.z());
    Eigen::Quaterniond dq = wq * q;
    q.coeffs() += 0.5 * h * dq.coeffs();
    b.state.orientation = toQuat(q.normalized());
    b.force.setZero();
    b.torque.setZero();
    const Quat& q_new = b.state.orientation;
    if (!isFinite(b.state.position) || !isFinite(b.state.linear_velocity) ||
        !isFinite(b.state.angular_velocity) ||
        !(std::isfinite(q_new.w) && std::isfinite(q_new.x) && std::isfinite(q_new.y) &&
          std::isfinite(q_new.z))) {
      b.state = before;  // the last finite state; disable() zeroes the velocities
      s.disable(static_cast<BodyId>(k));
      report.nonfinite_bodies.push_back(static_cast<BodyId>(k));
    }
  }
  s.time += h;
  return report;
}

void World::disableBody(BodyId body) {
  if (body < 0 || body >= numBodies() || impl_->bodies[body].kinematic) {
    refuse("disableBody: " + std::to_string(body) + " is not a dynamic body");
  }
  impl_->disable(body);
}

double World::time() const {
  return impl_->time;
}
int World::numBodies() const {
  return static_cast<int>(impl_->bodies.size());
}
const BodyState& World::state(BodyId body) const {
  if (body < 0 || body >= numBodies())
    refuse("state: body " + std::to_string(body) + " does not exist");
  return impl_->bodies[body].state;
}
double World::mass(BodyId body) const {
  if (body < 0 || body >= numBodies())
    refuse("mass: body " + std::to_string(body) + " does not exist");
  return impl_->bodies[body].mass;
}
const std::vector<ContactImpulse>& World::contacts() const {
  return impl_->contacts;
}
const ccp::Problem& World::lastProblem() const {
  return impl_->problem;
}
Settings& World::settings() {
  return impl_->settings;
}

}  // namespace rheofeed::reference

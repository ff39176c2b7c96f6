// SPDX-License-Identifier: MIT
// Internal to the reference world (not installed): the world's state (WorldState), the context
// one step carries through its stages, the stages themselves (world_step.cpp: kinematics, free
// velocities, collision, integration; world_contacts.cpp: contact rows, the problem, warm start,
// the solve and the contact records) and the small conversions between the public types and
// Eigen they share.
#pragma once

#include <ode/ode.h>

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <Eigen/SparseCore>
#include <cmath>
#include <exception>
#include <map>
#include <string>
#include <tuple>
#include <unordered_map>
#include <vector>

#include "ode_vec.hpp"  // the ODE <-> rheofeed conversions (toVec3, setGeomPose)
#include "rheofeed/ccp/ipm.hpp"
#include "rheofeed/ccp/nsgs.hpp"
#include "rheofeed/ccp/problem.hpp"
#include "rheofeed/ccp/solver.hpp"
#include "rheofeed/narrow_phase.hpp"
#include "rheofeed/reference/world.hpp"

namespace rheofeed::reference {
namespace detail {

using Eigen::Matrix3d;
using Eigen::Vector3d;

inline Vector3d toEigen(const Vec3& v) {
  return {v.x, v.y, v.z};
}
inline Vec3 toVec3(const Vector3d& v) {
  return {v.x(), v.y(), v.z()};
}
using rheofeed::toVec3;  // of ODE's arrays (ode_vec.hpp)
inline Eigen::Quaterniond toEigen(const Quat& q) {
  return {q.w, q.x, q.y, q.z};
}
inline Quat toQuat(const Eigen::Quaterniond& q) {
  return {q.w(), q.x(), q.y(), q.z()};
}

inline Matrix3d rotationOf(const Pose& p) {
  Matrix3d r;
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) r(i, j) = p.rotation[3 * i + j];
  }
  return r;
}

inline Pose poseOf(const Vector3d& x, const Matrix3d& r) {
  Pose p;
  p.position = toVec3(x);
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) p.rotation[3 * i + j] = r(i, j);
  }
  return p;
}

// Two unit vectors completing the unit normal n to a right-handed frame (as ODE's dPlaneSpace).
inline void planeSpace(const Vector3d& n, Vector3d& t1, Vector3d& t2) {
  if (std::abs(n.z()) > M_SQRT1_2) {
    const double a = n.y() * n.y() + n.z() * n.z(), k = 1.0 / std::sqrt(a);
    t1 = {0, -n.z() * k, n.y() * k};
  } else {
    const double a = n.x() * n.x() + n.y() * n.y(), k = 1.0 / std::sqrt(a);
    t1 = {-n.y() * k, n.x() * k, 0};
  }
  t2 = n.cross(t1);
}

[[noreturn]] inline void refuse(const std::string& message) {
  throw std::invalid_argument("rheofeed::reference::World: " + message);
}

// Below this surface speed (m/s) the friction frame is ODE's plane space, not aligned with c.
inline constexpr double kMinSurfaceSpeed = 1e-12;
// Share of |g| h (the speed gravity takes away in one step) that an unsettled Coulomb step may
// leave as spurious separation at a pressed contact before the solver corrects its normal
// impulses (ccp::Settings::coulomb_max_separation): a part lifted at 0.01 |g| h rises
// (0.01 |g| h)^2 / (2 |g|) = 5e-5 |g| h^2, 5e-8 m at h = 0.01 s, and falls back within the step.
inline constexpr double kSpuriousSeparationShare = 0.01;

}  // namespace detail

using detail::Matrix3d;
using detail::Vector3d;

/// The state of a World (world.hpp): bodies, geoms, feeders, the solver and the last step's
/// contacts.
struct WorldState {
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
    int index;  // position among the pair's contacts
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
  StepObserver observer;
  ccp::Solver solver;
  ccp::NsgsSolver nsgs;
  ccp::IpmSolver ipm;
  Eigen::VectorXd trial_gamma;  // the impulses of a solve of Settings::ipm_rounds
  std::vector<RawContact> raw;
  std::vector<ContactImpulse> contacts;
  // Last step's contacts per geom pair (dCollide's order): point and impulse on g1's body, both
  // world frame (the warm start).
  struct WarmContact {
    Vector3d position;
    Vector3d impulse;
    int index;  // position among the pair's contacts (RawContact::index)
  };
  std::map<std::pair<dGeomID, dGeomID>, std::vector<WarmContact>> warm;
  std::vector<char> warm_claimed;  // scratch of warmStartStage
  std::vector<dContactGeom> scratch;
  rheofeed::MeshCollisionScratch mesh_scratch;  // collideSpanning's memory for pairs with a mesh
  ccp::Problem problem;                         // the last step's contact problem

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
    return detail::toEigen(bodies[b].state.orientation).normalized().toRotationMatrix();
  }

  // Velocity (m/s, world) of body b's material point at p (0 for the static environment).
  Vector3d pointVelocity(BodyId b, const Vector3d& p, const Eigen::VectorXd& v) const {
    if (b == kStatic) return Vector3d::Zero();
    const Body& body = bodies[b];
    const Vector3d x = detail::toEigen(body.state.position);
    if (body.kinematic) {
      return detail::toEigen(body.state.linear_velocity) +
             detail::toEigen(body.state.angular_velocity).cross(p - x);
    }
    return v.segment<3>(body.dof) + v.segment<3>(body.dof + 3).cross(p - x);
  }

  void placeGeoms() {
    for (const Attached& a : attached) {
      const dGeomID geom = a.geom;
      const Body& body = bodies[a.body];
      const Matrix3d rb = rotation(a.body);
      const Matrix3d r = rb * detail::rotationOf(a.offset);
      const Vector3d x =
          detail::toEigen(body.state.position) + rb * detail::toEigen(a.offset.position);
      setGeomPose(geom, detail::poseOf(x, r));
    }
  }

  // ODE calls this from dSpaceCollide (C code): nothing may unwind through it. The first
  // exception (a user friction callback, an allocation) is kept, the rest of the pass is skipped,
  // and step() rethrows it once dSpaceCollide has returned.
  static void nearCallback(void* data, dGeomID o1, dGeomID o2) noexcept {
    auto* self = static_cast<WorldState*>(data);
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
    // the reference world's geoms carry no ODE bodies: a fixture is a geom of no dynamic body
    // (set once: this state is created in place and never moved)
    if (!mesh_scratch.is_fixture) {
      mesh_scratch.is_fixture = [this](dGeomID g) { return !isDynamic(bodyOf(g)); };
    }
    const int n =
        rheofeed::collideSpanning(o1, o2, max, scratch.data(), sizeof(dContactGeom), mesh_scratch);
    if (n <= 0) return;
    const double mu = friction ? friction(o1, o2) : settings.default_mu;
    for (int i = 0; i < n; ++i) {
      const dContactGeom& c = scratch[static_cast<std::size_t>(i)];
      raw.push_back({c.g1, c.g2, bodyOf(c.g1), bodyOf(c.g2), detail::toEigen(detail::toVec3(c.pos)),
                     detail::toEigen(detail::toVec3(c.normal)), c.depth, mu, i});
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
    const Body* body = carried == kStatic ? nullptr : &bodies[static_cast<std::size_t>(carried)];
    return detail::toEigen(contactSurfaceVelocity(
        law, detail::toVec3(p), detail::toVec3(n_out), detail::toVec3(n_out), mu,
        body ? body->efficiency : 1.0, body ? &body->state.position : nullptr));
  }

  void freezeLaws(double h) {
    for (Feeder& f : feeders) {
      Pose pose;
      const Pose* body_pose = nullptr;
      const BodyId b = bodyOf(f.geom);
      if (b != kStatic) {
        pose = detail::poseOf(detail::toEigen(bodies[b].state.position), rotation(b));
        body_pose = &pose;
      }
      f.frozen = f.law.evaluate(time, body_pose, h);
      if (!f.frozen.finite()) detail::refuse("feeder law is not finite: " + f.frozen.problem());
    }
  }
};

/// What one step carries from stage to stage (World::step in world.cpp). Filled in stage
/// order; each stage's comment says which fields it reads and writes.
struct StepContext {
  StepContext(WorldState& world_state, double step, const Settings& settings)
      : s(world_state), h(step), cfg(settings) {}
  WorldState& s;
  const double h;       // time step (s)
  const Settings& cfg;  // the world's settings, checked
  StepReport report;
  // Kinematics: pose of every kinematic body at t + h (applied by the integration stage).
  std::vector<Pose> next_pose;
  // Free velocities: generalised velocities (6 per dynamic body: linear m/s, angular rad/s).
  int ndof = 0;
  Eigen::VectorXd v_free;  // after gravity, external forces and the gyroscopic rotation
  Eigen::VectorXd v_pre;   // at the step's start (restitution)
  Eigen::VectorXd v_next;  // after the contact impulses
  std::vector<Matrix3d> inv_inertia_world;
  // Contact rows (nc contacts found by the collision stage, in (n, t1, t2) order).
  int nc = 0;
  std::vector<Eigen::Triplet<double>> d_entries, m_entries;
  Eigen::VectorXd r, mu;
  std::vector<Matrix3d> frames;  // columns n, t1, t2
  ccp::SparseMatrix d, minv;
  Eigen::VectorXd gamma;            // contact impulses (N s)
  std::vector<ContactImpulse> out;  // the step's contact records
};

// Stages of World::step, in order.
void kinematicsStage(StepContext& c);
void freeVelocityStage(StepContext& c);
void collisionStage(StepContext& c);
void contactRowsStage(StepContext& c);
void problemStage(StepContext& c);
void warmStartStage(StepContext& c);
void solveStage(StepContext& c);
void recordStage(StepContext& c);
void integrationStage(StepContext& c);

}  // namespace rheofeed::reference

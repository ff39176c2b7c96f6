// SPDX-License-Identifier: MIT
// Stages of World::step that move bodies (world.hpp, "Time step"): the kinematic bodies'
// secant velocities, the free velocities (gravity, external forces, the implicit-midpoint
// gyroscopic rotation), collision detection, and the semi-implicit Euler integration. The
// contact stages between collision and integration are in world_contacts.cpp.
#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>
#include <utility>

#include "world_internal.hpp"

namespace rheofeed::reference {
namespace {

using detail::refuse;
using detail::toEigen;
using detail::toQuat;
using detail::toVec3;

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

// Kinematic bodies: secant velocity over [t, t + h], pose at t + h applied after the step
// (integrationStage). Writes c.next_pose and the kinematic bodies' states.
void kinematicsStage(StepContext& c) {
  WorldState& s = c.s;
  const double h = c.h;
  c.next_pose.assign(s.bodies.size(), Pose{});
  for (std::size_t k = 0; k < s.bodies.size(); ++k) {
    WorldState::Body& b = s.bodies[k];
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
    c.next_pose[k] = p1;
  }
}

// Free velocities of the dynamic bodies. Writes c.ndof, c.v_free, c.v_pre,
// c.inv_inertia_world; disables bodies whose free velocity is not finite.
void freeVelocityStage(StepContext& c) {
  WorldState& s = c.s;
  const double h = c.h;
  const Settings& cfg = c.cfg;
  int ndof = 0;
  for (const auto& b : s.bodies) ndof += b.kinematic ? 0 : 6;
  c.ndof = ndof;
  c.v_free.resize(ndof);
  c.v_pre = Eigen::VectorXd::Zero(ndof);  // pre-step velocities, for restitution
  c.inv_inertia_world.assign(s.bodies.size(), Matrix3d::Zero());
  Eigen::VectorXd& v_free = c.v_free;
  for (std::size_t k = 0; k < s.bodies.size(); ++k) {
    WorldState::Body& b = s.bodies[k];
    if (b.kinematic) continue;
    const Matrix3d r = s.rotation(static_cast<BodyId>(k));
    // A disabled body keeps its mass in M^-1 (it has no contacts) but does not move.
    c.inv_inertia_world[k] = r * b.inv_inertia_body * r.transpose();
    if (b.disabled) {
      v_free.segment<6>(b.dof).setZero();
      continue;
    }
    c.v_pre.segment<3>(b.dof) = toEigen(b.state.linear_velocity);
    c.v_pre.segment<3>(b.dof + 3) = toEigen(b.state.angular_velocity);
    // Solved in the world frame with I_world = R I R^T (Euler's equation reads the same there,
    // I_world dw/dt = -w x I_world w, with I_world frozen over the step). Mapping w to the body
    // and back instead would scale it by the rotation's round-off, twice per step, and that
    // bias accumulates (~3e-16 of the energy per step, measured).
    Matrix3d i_world = r * b.inertia_body * r.transpose();
    i_world = 0.5 * (i_world + i_world.transpose()).eval();
    bool converged = true;
    const Vector3d w = gyroscopicStep(i_world, toEigen(b.state.angular_velocity), h, converged);
    if (!converged) c.report.gyroscopic_fallbacks++;
    v_free.segment<3>(b.dof) =
        toEigen(b.state.linear_velocity) + h * (toEigen(cfg.gravity) + b.force / b.mass);
    v_free.segment<3>(b.dof + 3) = w + h * c.inv_inertia_world[k] * b.torque;
    if (!v_free.segment<6>(b.dof).allFinite()) {
      // E.g. forces or torques whose sum or effect overflows: the body stops where it is.
      v_free.segment<6>(b.dof).setZero();
      s.disable(static_cast<BodyId>(k));
      c.report.nonfinite_bodies.push_back(static_cast<BodyId>(k));
    }
  }
}

// Collision after the free velocities, so that bodies found non-finite there no longer
// collide. Places the geoms, freezes the feeders' laws over the step and fills c.s.raw.
void collisionStage(StepContext& c) {
  WorldState& s = c.s;
  s.placeGeoms();
  s.freezeLaws(c.h);
  s.raw.clear();
  s.collide_error = nullptr;
  dSpaceCollide(s.space, &s, &WorldState::nearCallback);
  if (s.collide_error) {
    s.raw.clear();
    std::rethrow_exception(std::exchange(s.collide_error, nullptr));
  }
  if (c.cfg.solver.coulomb_outer_iterations > 0 && c.cfg.coulomb_solver == CoulombSolver::Nsgs &&
      c.cfg.nsgs_top_down) {
    // Top first, against gravity: a Gauss-Seidel sweep then carries a heap's weight from the
    // top contact to the floor in one pass (as shock propagation orders its layers). Stable, so
    // that contacts at one height keep the collision order.
    const Vector3d up = -toEigen(c.cfg.gravity);
    std::stable_sort(s.raw.begin(), s.raw.end(),
                     [&up](const WorldState::RawContact& a, const WorldState::RawContact& b) {
                       return a.p.dot(up) > b.p.dot(up);
                     });
  }
}

// Integrate (semi-implicit Euler, as ODE's dxStepBody without finite rotation) with c.v_next;
// kinematic bodies take c.next_pose. A body whose new state is not finite is disabled at its
// last finite state.
void integrationStage(StepContext& c) {
  WorldState& s = c.s;
  const double h = c.h;
  for (std::size_t k = 0; k < s.bodies.size(); ++k) {
    WorldState::Body& b = s.bodies[k];
    if (b.kinematic) {
      b.state.position = c.next_pose[k].position;
      b.state.orientation = toQuat(c.next_pose[k]);
      continue;
    }
    if (b.disabled) continue;
    const BodyState before = b.state;
    const Vector3d v = c.v_next.segment<3>(b.dof), w = c.v_next.segment<3>(b.dof + 3);
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
      c.report.nonfinite_bodies.push_back(static_cast<BodyId>(k));
    }
  }
}

}  // namespace rheofeed::reference

// SPDX-License-Identifier: MIT
/// @file vec3.hpp
/// A minimal 3-vector for the motion laws. It depends on nothing, so the laws serve the ODE
/// plugin and the Eigen reference solver alike (neither library's types leak into the other).
#pragma once

#include <cmath>

namespace rheofeed {

/// pi, defined once for the whole project (C++17 has no std::numbers::pi).
inline constexpr double kPi = 3.14159265358979323846;

/// A 3-vector of doubles. Its unit and frame are those of the value it carries; every function
/// that takes or returns one says which.
struct Vec3 {
  double x = 0.0;
  double y = 0.0;
  double z = 0.0;
};

inline Vec3 operator+(const Vec3& a, const Vec3& b) {
  return {a.x + b.x, a.y + b.y, a.z + b.z};
}
inline Vec3 operator-(const Vec3& a, const Vec3& b) {
  return {a.x - b.x, a.y - b.y, a.z - b.z};
}
inline Vec3 operator-(const Vec3& a) {
  return {-a.x, -a.y, -a.z};
}
inline Vec3 operator*(double s, const Vec3& a) {
  return {s * a.x, s * a.y, s * a.z};
}
inline bool operator==(const Vec3& a, const Vec3& b) {
  return a.x == b.x && a.y == b.y && a.z == b.z;
}
inline bool operator!=(const Vec3& a, const Vec3& b) {
  return !(a == b);
}
inline double dot(const Vec3& a, const Vec3& b) {
  return a.x * b.x + a.y * b.y + a.z * b.z;
}
inline Vec3 cross(const Vec3& a, const Vec3& b) {
  return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}
inline double norm(const Vec3& a) {
  return std::sqrt(dot(a, a));
}
inline bool isFinite(const Vec3& a) {
  return std::isfinite(a.x) && std::isfinite(a.y) && std::isfinite(a.z);
}
inline bool isZero(const Vec3& a) {
  return a.x == 0.0 && a.y == 0.0 && a.z == 0.0;
}

/// The part of `a` orthogonal to the unit vector `n`: a - (a . n) n.
inline Vec3 tangentialPart(const Vec3& a, const Vec3& n) {
  return a - dot(a, n) * n;
}

/// A rigid pose: position (m, world frame) and rotation matrix R (row-major, body to world:
/// x_world = R x_body + position).
struct Pose {
  Vec3 position;
  double rotation[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1};

  /// R a: a direction from the body frame to the world frame.
  Vec3 rotate(const Vec3& a) const {
    const double* r = rotation;
    return {r[0] * a.x + r[1] * a.y + r[2] * a.z, r[3] * a.x + r[4] * a.y + r[5] * a.z,
            r[6] * a.x + r[7] * a.y + r[8] * a.z};
  }
  /// R a + position: a point from the body frame to the world frame (m).
  Vec3 transform(const Vec3& a) const { return rotate(a) + position; }
  /// R^T (w - position): a point from the world frame to the body frame (m).
  Vec3 inverseTransform(const Vec3& w) const {
    const double* r = rotation;
    const Vec3 d{w.x - position.x, w.y - position.y, w.z - position.z};
    return {r[0] * d.x + r[3] * d.y + r[6] * d.z, r[1] * d.x + r[4] * d.y + r[7] * d.z,
            r[2] * d.x + r[5] * d.y + r[8] * d.z};
  }

  /// The rotation by `angle` (rad, right hand) about the unit axis `k` (Rodrigues), placed at
  /// `position` (m).
  static Pose axisAngle(const Vec3& k, double angle, const Vec3& position = {}) {
    const double c = std::cos(angle), s = std::sin(angle), v = 1 - c;
    Pose p;
    const double r[9] = {c + k.x * k.x * v,       k.x * k.y * v - k.z * s, k.x * k.z * v + k.y * s,
                         k.y * k.x * v + k.z * s, c + k.y * k.y * v,       k.y * k.z * v - k.x * s,
                         k.z * k.x * v - k.y * s, k.z * k.y * v + k.x * s, c + k.z * k.z * v};
    for (int i = 0; i < 9; ++i) p.rotation[i] = r[i];
    p.position = position;
    return p;
  }
};

}  // namespace rheofeed

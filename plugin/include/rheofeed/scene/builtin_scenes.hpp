// SPDX-License-Identifier: MIT
/// @file builtin_scenes.hpp
/// Small scenes built in code, used to cross-check ODE + plugin against the reference solver
/// and as defaults of the demos. Gravity -z, SI units, world frame.
#pragma once

#include "rheofeed/scene/scene.hpp"

namespace rheofeed::scene {

/// A 2 m x 0.5 m belt (top at z = 0) moving at `speed` (m/s) along +x; one 5 cm box dropped
/// 5 mm above it at x = -0.5 m; mu = 0.5; 1 s at h = 0.01 s.
Scene beltScene(double speed = 0.3);

/// The same belt tilted by `angle` (rad) about y so that +x along the belt climbs; the belt
/// carries parts up the slope at `speed`; mu = 0.5 (so tan(angle) <= mu sticks).
Scene inclineBeltScene(double angle, double speed = 0.2);

/// A turntable (static box, top at z = 0) turning at `omega` (rad/s) about +z through the
/// origin; two boxes at radius 0.15 m and 0.3 m on the x axis; mu = 0.8; 0.5 s.
Scene turntableScene(double omega = 1.0);

/// A helical ramp around +z (radius 0.3 m, pitch 0.1 m per turn, right-handed: it rises
/// counter-clockwise seen from above) made of tilted box segments, turning at `omega` (rad/s)
/// about +z; one box on it. It climbs for omega > 0 and descends for omega < 0.
Scene helicalRampScene(double omega);

/// `count` boxes (4 cm, 10 % size spread) dropped in a pile on the belt of beltScene.
Scene pileOnBeltScene(int count = 50, double speed = 0.3);

}  // namespace rheofeed::scene

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

/// A straight horizontal track (static box, top at z = 0, along +x) vibrating at `frequency`
/// (Hz) with peak amplitude `amplitude` (m) at `angle` (rad) to the track, in the x-z plane;
/// `parts` flat boxes (20 x 20 x 5 mm, steel) spread along it, far enough apart not to touch;
/// mu = 0.4. Time step 1/(200 f); 2 s with 0.5 s warm-up; conveying direction +x.
Scene vibratingTrackScene(double amplitude = 0.2e-3, double frequency = 50, double angle = 0.349066,
                          int parts = 1);

/// A single flat part on the track of vibratingTrackScene (0.2 mm at 20 degrees, 50 Hz, mu 0.4:
/// throw number 0.69, sliding), with gravity turned so that the track climbs by `incline_deg`
/// along +x and falls sideways by `cross_deg` towards -y (a turned gravity is the same physics
/// as a turned track and keeps the part on the same box). 4 s with 1 s warm-up (`quick`: 1.5 s
/// with 0.5 s); drift measured along +x, or along +y (uphill across) with `sideways`. The
/// drift-model study's tracks and the friction cone's cross-slope test.
Scene tiltedTrackScene(double incline_deg, double cross_deg, bool sideways, bool quick);

/// A linear vibratory trough (base 0.7 m x 0.12 m with side walls, along +x, top of the base at
/// z = 0) fed by a hopper at its start: boxes with normally distributed sizes (mean 15 mm,
/// 15 % spread) spawned at `rate` parts/s up to `count`; the trough vibrates at `frequency`
/// (Hz), `amplitude` (m, peak) at `angle` (rad) to the track (defaults: 50 Hz, 0.25 mm, 30 deg:
/// throw number 1.26, mild hopping, as industrial feeders run); an exit plane at its end, x = 0.6
/// m; a catch floor below the end.
Scene linearTroughScene(int count = 60, double rate = 20, double amplitude = 0.25e-3,
                        double frequency = 50, double angle = 0.523599);

/// The trough of linearTroughScene without its hopper, vibrating at 50 Hz, 0.2 mm peak,
/// 20 degrees (throw number 0.69, sliding regime), 3 s with 0.5 s warm-up. `count` boxes of
/// normally distributed sizes are dropped at t = 0: with `heap`, turned at random into a heap
/// over its first 0.3 m (the drift then varies by tens of percent from seed to seed); without,
/// lying flat in one layer spread over its first 0.5 m, touching now and then.
Scene troughScene(int count = 40, bool heap = false);

/// A helical track about the world z axis, right-handed (it rises counter-clockwise seen from
/// above), made of tilted boxes (helicalTrack).
struct HelicalTrack {
  double radius = 0.3;         ///< centre line of the track (m)
  double width = 0.1;          ///< radial width of the boxes (m)
  double thickness = 0.02;     ///< box thickness below the top surface (m)
  double pitch = 0.1;          ///< rise per turn (m)
  double turns = 1.5;          ///< from azimuth 0 (on +x)
  int segments_per_turn = 48;  ///< boxes per turn
  double z_start = 0;          ///< height of the top surface at azimuth 0 (m)
  double outward_tilt = 0;     ///< roll of the top surface, falling outwards (rad)
};

/// The boxes of `track`: each one's top face a chord of the helix through the centre line,
/// 5 % longer than its share so that neighbours overlap.
std::vector<Fixture::Geom> helicalTrack(const HelicalTrack& track);

/// A vibratory bowl feeder built from ODE primitives (bowl_scene.cpp): inner radius 150 mm,
/// a box floor (top at z = 10 mm), a central cone of 36 box facets (25 degrees, 25 mm thick,
/// from r = 10 mm at z = 66 mm down to the floor at r = 130 mm, the ramp's inner edge), a wall of
/// 192 boxes (10 mm thick, 100 mm high), and a helical ramp of 128 boxes (20 mm wide, r =
/// 130..150 mm, 12 mm thick, pitch 30 mm, 2 turns counter-clockwise rising out of the floor at
/// azimuth 0, its top falling 3 degrees towards the wall). Screw vibration 50 Hz, 0.15 mm vertical,
/// 0.17 degrees torsion; rheonomic runs use the local vibration law at h = 0.01 s
/// (the calibrated drift 0.313 rad/s about +z, the mesh bowl's, is kept in the scene). `nuts` M6
/// nuts as cylinders (radius 5.25 mm, 5 mm thick, 2.3 g) dropped one by one at `rate` parts/s (> 0)
/// from at most 14 mm above the cone. With `outlet`: a wiper across the last turn (6.5 mm above the
/// track: nuts lying flat pass, nuts on edge or on another nut are pushed inwards off the track
/// onto a return chute that stays 7 mm above the turn below), a straight outlet track with rails
/// leaving tangentially at the top (azimuth 0, z = 69 mm, along +y) through a cut in the wall, and
/// an exit plane outside the bowl (tangent to r = 175 mm at azimuth 45 degrees). `duration` (s); mu
/// = 0.3. Named bowl_feeder_fill above 12 nuts, else bowl_feeder_primitives.
Scene bowlFeederScene(int nuts = 12, double rate = 4, bool outlet = true, double duration = 60);

/// The bowl feeder as a mesh with the tooling of bowlFeederScene: the bowl
/// (demos/meshes/vibratory_bowl_outlet.stl, millimetres scaled by 0.001; generate_meshes.cpp):
/// inner radius 150 mm, wall 5 mm thick and 100 mm high, cut down to 64 mm over azimuth
/// -0.5..40 degrees for the outlet, a floor falling 4 degrees towards the wall, a central cone of
/// revolution (25 degrees from the floor at r = 124 mm up to a flat top of radius 70 mm at z = 37
/// mm), and a helical ramp (20 mm wide, r = 130..150 mm, 4 mm thick, pitch 30 mm, 2 turns
/// counter-clockwise from the floor at azimuth 0, its top falling 3 degrees towards the wall); the
/// wiper, return chute, outlet track and rails of bowlFeederScene as boxes, fitted to this ramp
/// and cone; its screw vibration on the local law; the exit plane tangent to r = 175 mm at 45
/// degrees. `nuts` M6 nuts read from demos/meshes/hex_nut_m6.obj (2.3 g), colliding as their
/// convex hull, dropped one by one at `rate` parts/s (> 0) from at most 15 mm above the cone.
/// `duration` (s); mu = 0.3; h = 0.01 s for rheonomic runs. The mesh paths are relative to
/// demos/scenes/: the scene is meant to be written there (dump_builtin_scene) and loaded.
Scene meshBowlFeederScene(int nuts = 200, double rate = 5, double duration = 300);

/// A static ring of `count` upright boxes about the world z axis (a turntable's rim): box centres
/// on a circle of radius `centre_radius` (m) at height `z_centre` (m), each `thickness` (m)
/// radially and `height` (m) tall, and wide enough tangentially to close the ring at
/// `inner_radius` (m) with 5 mm of overlap between neighbours.
Fixture boxRing(const std::string& name, int count, double centre_radius, double inner_radius,
                double thickness, double height, double z_centre);

}  // namespace rheofeed::scene

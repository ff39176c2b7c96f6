// SPDX-License-Identifier: MIT
// The vibratory bowl feeder built from ODE primitives (bowlFeederScene, builtin_scenes.hpp).
//
// Why primitives: ODE collides two triangle meshes (a mesh nut on a mesh bowl) triangle by
// triangle with no notion of inside, so a nut that goes deeper than about half its thickness
// into a thin shell gets contacts from the far side and is pushed through (the mesh bowl of
// demos/meshes lost 5 of 12 nuts in 12 s, and all 12 in 60 s, at h = 0.01 s). A nut mesh on
// boxes did no better (it sank 1.8 mm into a box ramp and stuck). Cylinder nuts on boxes get
// ODE's full contact patch, and a box is a solid to it: the contact normal points out of the
// nearest face whatever the depth. What remained were falls of a few centimetres, each now
// caught (demos/results/bowl_feeder.md).
#include <cmath>

#include "common/builtin_scenes.hpp"

namespace rheofeed::scene {
namespace {

// Row-major product of two rotations (a then b applied as a * b).
Pose composed(const Pose& a, const Pose& b, const Vec3& position) {
  Pose p;
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) {
      double sum = 0;
      for (int k = 0; k < 3; ++k) sum += a.rotation[3 * r + k] * b.rotation[3 * k + c];
      p.rotation[3 * r + c] = sum;
    }
  }
  p.position = position;
  return p;
}

Fixture::Geom box(const Vec3& size, const Pose& pose) {
  Fixture::Geom g;
  g.shape.kind = Shape::Kind::Box;
  g.shape.size = size;
  g.pose = pose;
  return g;
}

// Bowl geometry (m). The bowl axis is +z through the origin.
constexpr double kDeg = kPi / 180;
constexpr double kInnerRadius = 0.150;     // inside of the wall
constexpr double kWall = 0.010;            // wall thickness
constexpr double kWallHeight = 0.100;      // wall top above z = 0
constexpr double kFloorTop = 0.010;        // floor surface
constexpr double kConeInner = 0.010;       // central cone: flat cap inside this radius
constexpr double kConeOuter = 0.130;       // the cone meets the floor here, at the ramp's inner
                                           // edge: no gutter where nuts circle past its start
constexpr double kConeSlope = 25 * kDeg;   // > atan(mu): nuts slide off it to the wall
constexpr double kTrackWidth = 0.020;      // ramp: r = 130..150 mm
constexpr double kTrackThickness = 0.012;  // a nut falling 30 mm from the turn above must not pass
constexpr double kPitch = 0.030;           // ramp rise per turn
constexpr double kTurns = 2;
constexpr double kTrackTilt = 3 * kDeg;       // the ramp's top falls towards the wall
constexpr int kTrackSegments = 64;            // per turn
constexpr double kWiperAzimuth = 300 * kDeg;  // on the last turn
constexpr double kWiperClearance = 0.0065;    // above the track, along the whole blade
constexpr double kWiperAngle = 35 * kDeg;     // to the track direction
constexpr double kOutletLength = 0.125;       // straight outlet track, tangent at azimuth 0
constexpr double kOutletWallTop = 0.064;      // the wall is cut down to this where it exits
constexpr double kExitRadius = 0.175;         // the exit plane: tangent to this circle at 45 deg

// What the tooling (wiper, return chute, outlet) needs of a bowl whose ramp follows the
// constants above (m): the ramp's top on its centre line at azimuth 0, its thickness there, the
// line of the central cone (it meets the floor at cone_foot_radius, height cone_foot_z, and rises
// inwards at kConeSlope), and the wall's top where the outlet leaves through it.
struct BowlLayout {
  double track_top_start;
  double track_thickness;
  double cone_foot_radius;
  double cone_foot_z;
  double outlet_wall_top;

  // Height of the ramp's top surface on its centre line at azimuth phi (rad, from +x, counted on
  // along the ramp: phi in [0, 2 pi kTurns]).
  double trackTop(double phi) const { return track_top_start + kPitch * phi / (2 * kPi); }
  // The cone's surface at radius r (inside the foot).
  double coneAt(double r) const {
    return cone_foot_z + (cone_foot_radius - r) * std::tan(kConeSlope);
  }
};

// The bowl of boxes: the ramp starts 1 mm below the floor's top, so that it rises out of the
// floor (over the first 12 degrees) instead of starting at a step a nut's rim can catch on.
constexpr BowlLayout kBoxBowl{kFloorTop - 0.001, kTrackThickness, kConeOuter, kFloorTop,
                              kOutletWallTop};

// The mesh bowl (demos/meshes/vibratory_bowl_outlet.stl, generate_meshes.cpp; mm there): the
// ramp's top rises from z = 10 mm at the wall (r = 150 mm) and falls 3 degrees towards it, so on
// the centre line it starts 10 mm x tan 3 degrees higher; 4 mm thick below the wall's edge; the
// cone meets the 4 degree floor at r = 124 mm.
const BowlLayout kMeshBowl{0.010 + 0.010 * std::tan(kTrackTilt),
                           0.004 + 0.010 * std::tan(kTrackTilt), 0.124,
                           0.010 + 0.026 * std::tan(4 * kDeg), kOutletWallTop};

double trackCentre() {
  return kInnerRadius - 0.5 * kTrackWidth;
}

// The central cone: a flat cylindrical cap and `count` tilted boxes whose top faces are facets
// of a cone falling at kConeSlope from kConeInner to the floor at kConeOuter.
void addCone(Fixture& bowl, int count) {
  const double thickness = 0.025;  // a falling nut (0.8 m/s: 8 mm per step) cannot cross it
  const double run = kConeOuter - kConeInner;
  const double extra = 0.005;  // the boxes reach 5 mm beyond the floor line (into the floor)
  const double length = (run + extra) / std::cos(kConeSlope);
  const double width = 2 * kConeOuter * std::tan(kPi / count) + 0.002;
  const double cap_top = kFloorTop + run * std::tan(kConeSlope);
  for (int k = 0; k < count; ++k) {
    const double phi = (k + 0.5) * 2 * kPi / count;
    const Vec3 radial{std::cos(phi), std::sin(phi), 0};
    const double r_mid = kConeInner + 0.5 * (run + extra);
    const Vec3 top_centre =
        r_mid * radial + Vec3{0, 0, cap_top - (r_mid - kConeInner) * std::tan(kConeSlope)};
    const Vec3 normal = std::sin(kConeSlope) * radial + Vec3{0, 0, std::cos(kConeSlope)};
    // Rz(phi) Ry(slope): local x runs down the slope, local z is the facet's normal.
    const Pose pose =
        composed(Pose::axisAngle({0, 0, 1}, phi), Pose::axisAngle({0, 1, 0}, kConeSlope),
                 top_centre - 0.5 * thickness * normal);
    bowl.geoms.push_back(box({length, width, thickness}, pose));
  }
  // The apex: a box over the cap (a cylinder would meet the cylinder nuts through ODE's
  // one-point convex test).
  const double cap = 2 * kConeInner + 0.004;
  bowl.geoms.push_back(
      box({cap, cap, thickness}, Pose::axisAngle({0, 0, 1}, 0, {0, 0, cap_top - 0.5 * thickness})));
}

// The tooling on the last turn and the outlet of a bowl laid out as `layout`: the wiper, the
// return chute under it, and the straight outlet track with its rails (all boxes).
void addTooling(Fixture& bowl, const BowlLayout& layout) {
  // Wiper: a blade across the last turn, kWiperClearance above the track, running from the
  // wall forwards and inwards at kWiperAngle. Nuts lying flat (5 mm) pass under it; nuts on
  // edge (9-11 mm) or riding on another nut hit it, slide along it and fall off the track's
  // inner edge back into the bowl. Its bottom follows the track's top (which rises along the
  // helix and falls towards the wall, a few mm over the blade's length): under a level blade a
  // 9 mm cube slid along it and passed where its top overlapped the blade by about 1 mm. Its
  // outer end lies in the wall: the end face (square to the blade) has one corner 1.6 mm into
  // the wall and the other beyond its outer face.
  const double blade_height = 0.020, blade_thickness = 0.012;
  const double phi0 = 2 * kPi + kWiperAzimuth;
  const double r0 = kInnerRadius + 0.001 + 0.5 * blade_thickness * std::cos(kWiperAngle),
               r1 = kInnerRadius - kTrackWidth - 0.004;
  const double along = (r0 - r1) / std::tan(kWiperAngle);
  const double phi1 = phi0 + along / trackCentre();
  // The track's top at radius r, azimuth phi (it falls outwards at kTrackTilt).
  const auto top_at = [&layout](double r, double phi) {
    return layout.trackTop(phi) - std::tan(kTrackTilt) * (r - trackCentre());
  };
  const Vec3 p0{r0 * std::cos(phi0), r0 * std::sin(phi0), top_at(r0, phi0) + kWiperClearance};
  const Vec3 p1{r1 * std::cos(phi1), r1 * std::sin(phi1), top_at(r1, phi1) + kWiperClearance};
  const Vec3 d = p1 - p0;  // along the blade's bottom edge
  const double level = std::hypot(d.x, d.y);
  const Pose yaw = Pose::axisAngle({0, 0, 1}, std::atan2(d.y, d.x));
  const Pose pitch = Pose::axisAngle({0, 1, 0}, -std::atan2(d.z, level));
  const Pose blade = composed(yaw, pitch, Vec3{});
  bowl.geoms.push_back(
      box({norm(d), blade_thickness, blade_height},
          composed(yaw, pitch, 0.5 * (p0 + p1) + blade.rotate({0, 0, 0.5 * blade_height}))));

  // Return chute: a plate under the wiper's drop zone, from just below the ramp's inner
  // edge down inwards at 35 degrees (> atan(mu), so nuts slide) to the cone. A wiped nut
  // falls about 10 mm onto it instead of 50 mm onto the cone's foot (1 m/s, 10 mm per step:
  // its centre crossed the cone's surface for a step). Its top edge stays 5 mm inside the
  // ramp's inner edge and it is 6 mm thick and 50 mm wide, so that no part of it hangs lower
  // than 7 mm over the turn below (a 12 mm plate 70 mm wide reached down to that track's top
  // and jammed the nuts climbing under it).
  const double chute_slope = 35 * kDeg, chute_thickness = 0.006;
  const double r_top = kInnerRadius - kTrackWidth - 0.005;
  const double z_top = layout.trackTop(phi0) - layout.track_thickness - 0.003;
  // Where the plate's top meets the cone: z_top - (r_top - r) tan(chute) = cone(r).
  const double r_meet = (layout.coneAt(0) - z_top + r_top * std::tan(chute_slope)) /
                        (std::tan(chute_slope) + std::tan(kConeSlope));
  const double run = r_top - r_meet + 0.004;  // 4 mm into the cone
  const double chute_az = phi0 + 0.5 * (phi1 - phi0) + 5 * kDeg;
  const Vec3 inward{-std::cos(chute_az), -std::sin(chute_az), 0};
  const Vec3 top_mid = (r_top - 0.5 * run) * Vec3{std::cos(chute_az), std::sin(chute_az), 0} +
                       Vec3{0, 0, z_top - 0.5 * run * std::tan(chute_slope)};
  const Vec3 up_normal = std::sin(chute_slope) * inward + Vec3{0, 0, std::cos(chute_slope)};
  // Rz(azimuth + pi) Ry(chute): local x runs down the plate, inwards; local z is its normal.
  bowl.geoms.push_back(box(
      {run / std::cos(chute_slope), 0.050, chute_thickness},
      composed(Pose::axisAngle({0, 0, 1}, chute_az + kPi), Pose::axisAngle({0, 1, 0}, chute_slope),
               top_mid - 0.5 * chute_thickness * up_normal)));

  // Outlet: a straight track leaving the ramp's top tangentially (+y at azimuth 0), through
  // the cut-down wall, with a rail on each side.
  const double top = layout.trackTop(2 * kPi * kTurns);
  const Pose roll = Pose::axisAngle({0, 1, 0}, kTrackTilt);  // top falls outwards (+x)
  const double x = trackCentre() + 0.0005;
  bowl.geoms.push_back(box(
      {kTrackWidth + 0.001, kOutletLength, kTrackThickness},
      composed(roll, Pose{},
               Vec3{x, 0.5 * kOutletLength, top} - roll.rotate({0, 0, 0.5 * kTrackThickness}))));
  // Rails 10 mm above the track and 6 mm into the cut wall below it (no seam for a nut). The
  // inner one runs the whole length too: the field w x r has an inward component along the
  // straight track, and a nut pushed off its inner edge would fall 60 mm into the bowl.
  const double rail_top = 0.010, rail_bottom = layout.outlet_wall_top - 0.006 - top,
               rail = 0.011;  // as thick as a falling nut needs (the scene check)
  for (double rail_x :
       {kInnerRadius + 0.001 + 0.5 * rail, kInnerRadius - kTrackWidth - 0.5 * rail}) {
    bowl.geoms.push_back(
        box({rail, kOutletLength, rail_top - rail_bottom},
            Pose::axisAngle({0, 0, 1}, 0,
                            {rail_x, 0.5 * kOutletLength, top + 0.5 * (rail_top + rail_bottom)})));
  }
}

// Screw vibration at 50 Hz: 0.15 mm vertical (A w^2 = 1.5 g: the nuts hop) and 0.17 degrees of
// torsion (0.13 m/s peak tangential speed at r = 140 mm), as demos/scenes/bowl_feeder.json; the
// rheonomic runs use the local vibration law (no calibration).
FeederLaw screwVibration() {
  FeederLaw law;
  law.kind = FeederLaw::Kind::Vibration;
  Vibration& v = law.vibration;
  v.amplitude = 0.00015;
  v.direction = {0, 0, 1};
  v.torsion_amplitude = 0.17 * kDeg;
  v.frequency = 50;
  law.drift_model = DriftModel::Local;
  return law;
}

// The bowls' run: mu = 0.3; full vibration at 100 steps per period, rheonomic runs at the paper's
// 0.01 s; seed 7; parts below z = -0.1 m leave; the angular drift about +z after 1 s; with the
// outlet, the exit plane tangent to r = kExitRadius at azimuth 45 degrees.
void setBowlRun(Scene& s, double duration, bool outlet) {
  s.material.mu = 0.3;
  s.solver.time_step = 0.0002;  // full vibration: 100 steps per period
  s.solver.rheonomic_time_step = 0.01;
  s.solver.iterations = 40;
  s.duration = duration;
  s.seed = 7;
  s.removal_height = -0.1;
  s.outputs.angular_drift = true;
  s.outputs.sample_interval = 0.05;
  s.outputs.warmup = 1;
  if (outlet) {
    s.outputs.exit_plane = true;
    const Vec3 n{std::cos(45 * kDeg), std::sin(45 * kDeg), 0};
    s.outputs.exit_normal = n;
    s.outputs.exit_point = kExitRadius * n;
  }
}

}  // namespace

std::vector<Fixture::Geom> helicalTrack(const HelicalTrack& t) {
  std::vector<Fixture::Geom> geoms;
  const double slope = std::atan(t.pitch / (2 * kPi * t.radius));
  const double seg_angle = 2 * kPi / t.segments_per_turn;
  const double seg_length = 2 * t.radius * std::tan(seg_angle / 2) / std::cos(slope) * 1.05;
  const int total = static_cast<int>(std::lround(t.turns * t.segments_per_turn));
  for (int i = 0; i < total; ++i) {
    const double phi = (i + 0.5) * seg_angle;  // angle of the segment centre
    // Segment frame: x along the tangent (rising), y radial-in, z up; roll by `outward_tilt`
    // about x (the top falls towards -y, outwards), tilt by `slope` about the outward radial
    // axis (r x t = +z lifts the tangent), then turn to phi.
    const Pose heading = Pose::axisAngle({0, 0, 1}, phi + kPi / 2);
    const Vec3 radial = heading.rotate({0, -1, 0});
    const Pose oriented = composed(composed(Pose::axisAngle(radial, slope), heading, {}),
                                   Pose::axisAngle({1, 0, 0}, t.outward_tilt), {});
    const Vec3 centre{t.radius * std::cos(phi), t.radius * std::sin(phi),
                      t.z_start + t.pitch * phi / (2 * kPi)};
    geoms.push_back(
        box({seg_length, t.width, t.thickness},
            composed(oriented, Pose{}, centre - oriented.rotate({0, 0, 0.5 * t.thickness}))));
  }
  return geoms;
}

Scene bowlFeederScene(int nuts, double rate, bool outlet, double duration) {
  Scene s;
  s.name = nuts > 12 ? "bowl_feeder_fill" : "bowl_feeder_primitives";
  Fixture bowl;
  bowl.name = "bowl";

  // Floor: one box under the whole bowl (its corners stick out beyond the wall; nothing reaches
  // them).
  const double floor_half = kInnerRadius + kWall;
  bowl.geoms.push_back(box({2 * floor_half, 2 * floor_half, 0.020},
                           Pose::axisAngle({0, 0, 1}, 0, {0, 0, kFloorTop - 0.010})));
  addCone(bowl, 36);

  // Wall: 192 upright boxes (facets 1.9 degrees apart, their joints 0.02 mm proud; with 48 the
  // joints stood 0.3 mm proud and stopped nuts in full vibration, demos/results/bowl_feeder.md);
  // with the outlet, the boxes it passes over are cut down.
  const Fixture wall = boxRing("wall", 192, kInnerRadius + 0.5 * kWall, kInnerRadius, kWall,
                               kWallHeight, 0.5 * kWallHeight);
  for (Fixture::Geom g : wall.geoms) {
    const double azimuth = std::atan2(g.pose.position.y, g.pose.position.x);
    if (outlet && azimuth > -0.5 * kDeg && azimuth < 40 * kDeg) {
      g.shape.size.z = kOutletWallTop;
      g.pose.position.z = 0.5 * kOutletWallTop;
    }
    bowl.geoms.push_back(g);
  }

  // The helical ramp on the wall (its outer edge 1 mm into the wall).
  HelicalTrack ramp;
  ramp.radius = trackCentre() + 0.0005;
  ramp.width = kTrackWidth + 0.001;
  ramp.thickness = kTrackThickness;
  ramp.pitch = kPitch;
  ramp.turns = kTurns;
  ramp.segments_per_turn = kTrackSegments;
  ramp.z_start = kBoxBowl.track_top_start;
  ramp.outward_tilt = kTrackTilt;
  for (const Fixture::Geom& g : helicalTrack(ramp)) bowl.geoms.push_back(g);

  if (outlet) addTooling(bowl, kBoxBowl);

  bowl.law = screwVibration();
  // The rheonomic runs: the local vibration law (no calibration). The former calibrated drift of
  // demos/scenes/bowl_feeder.json's ramp (same vibration, nuts and mu; measured while ODE kept 8
  // contacts per mesh pair, and since recalibrated there to 0.212 rad/s) stays in the scene for
  // `--drift-model calibrated_drift` and as the rotation the tooling tests' kinematics use.
  bowl.law.has_calibrated_drift = true;
  bowl.law.calibrated_drift.angular = {0, 0, 0.313};
  s.fixtures.push_back(bowl);

  // M6 nut blanks (10 mm across flats, 5 mm thick, 2.3 g) as ODE cylinders of the hexagon's
  // area (radius 5.25 mm) and the blank's mass: ODE's cylinder-box test gives a flat nut its
  // full contact patch. The nut mesh (demos/meshes/hex_nut_m6.obj) against these boxes sank
  // 1.8 mm into the ramp and stuck while lying flat (demos/results/bowl_feeder.md). 3 % spread, cut
  // at +-5 %.
  PartSpec p;
  p.name = "m6_nuts";
  p.shape = Shape::Kind::Cylinder;
  p.size[0] = {0.00525, 0.00016, 0.005, 0.0055};   // radius (m)
  p.size[1] = {0.005, 0.00015, 0.00475, 0.00525};  // thickness (m)
  p.density = 5290;  // 2.29 g at the mean size, the steel blank with its 6 mm hole
  p.random_orientation = true;
  p.count = nuts;
  p.rate = rate;
  // Dropped one by one onto the cone (at r = 90..102 mm, where its surface is 23..29 mm high)
  // from at most 14 mm above it: a nut falling further moves more than its thickness in a step
  // of 0.01 s and can pass into the cone's boxes before its first contact.
  p.spawn_min = {0.0, -0.100, 0.0348};
  p.spawn_max = {0.02, -0.090, 0.0368};
  s.parts.push_back(p);
  setBowlRun(s, duration, outlet);
  return s;
}

Scene meshBowlFeederScene(int nuts, double rate, double duration) {
  Scene s;
  s.name = "bowl_feeder_mesh_fill";
  Fixture bowl;
  bowl.name = "bowl";
  // The bowl, its central cone and its ramp: one mesh (mm), with the wall cut for the outlet.
  Fixture::Geom body;
  body.shape.kind = Shape::Kind::Mesh;
  body.shape.mesh = "../meshes/vibratory_bowl_outlet.stl";
  body.shape.mesh_scale = 0.001;
  bowl.geoms.push_back(body);
  addTooling(bowl, kMeshBowl);
  bowl.law = screwVibration();
  s.fixtures.push_back(bowl);

  // M6 nut blanks read from their mesh (mm), colliding as their convex hull (the plain hexagonal
  // prism: nothing in this bowl enters the 6 mm hole); mass and inertia from the mesh (2.3 g).
  // 3 % size spread, cut at +-10 %.
  PartSpec p;
  p.name = "m6_nuts";
  p.shape = Shape::Kind::Mesh;
  p.mesh = "../meshes/hex_nut_m6.obj";
  p.collision = PartSpec::Collision::ConvexHull;
  p.size[0] = {0.001, 0.00003, 0.0009, 0.0011};  // scale: mm to m
  p.density = 7850;
  p.random_orientation = true;
  p.count = nuts;
  p.rate = rate;
  // Dropped one by one onto the cone (at r = 90..102 mm, where its surface is 22..28 mm high)
  // from at most 15 mm above it. A nut's corners reach 6.9 mm from its centre at the largest
  // size, and the region's lowest inner corner is 6.6 mm from the cone: the largest nuts, turned
  // corner down there, start up to 0.3 mm inside it and are pushed out.
  p.spawn_min = {0.0, -0.100, 0.0350};
  p.spawn_max = {0.02, -0.090, 0.0370};
  s.parts.push_back(p);
  setBowlRun(s, duration, true);
  return s;
}

}  // namespace rheofeed::scene

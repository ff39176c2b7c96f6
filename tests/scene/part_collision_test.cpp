// SPDX-License-Identifier: MIT
// A mesh part colliding as its convex hull (PartSpec::Collision::ConvexHull) against the same
// part colliding as its mesh, in both engines. The expectations are the geometry's: the M6 nut
// blank (demos/meshes/hex_nut_m6.obj, 5 mm thick, a 6 mm hole) dropped level over three 1 mm
// square pins threads onto them and comes to rest on the floor, centre 2.5 mm up; its hull has no
// hole and stops on the pins' tops, centre 2.5 mm above them. Its mass is the nut's, without the
// hole's. Also the point the run's health checks follow in the nut (partAnchor: its centre of
// mass is in its hole, outside its material), checked against the nut's dimensions, and the
// counts that follow from it: a nut threaded on a pin on its axis is not inside the pin, one
// thrown through a thin sheet passed through it.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <limits>
#include <memory>
#include <vector>

#include "rheofeed/scene/mesh.hpp"
#include "rheofeed/scene/scene_io.hpp"
#include "rheofeed/simulation/simulation.hpp"
#include "scene_builders.hpp"

namespace rheofeed::scene {
namespace {

using test::boxFixture;

constexpr double kThickness = 0.005;  // m, the nut blank
constexpr double kPinTop = 0.010;     // m, above the floor's top (z = 0)
// At rest after 0.5 s: the centre within a contact's penetration (ODE's ERP/CFM leave a few
// 10 um; 0.2 mm is under a tenth of the 2.5 mm that tells the floor from the pins' tops), on the
// axis within 1 mm (a nut that tipped off the pins would be 5 mm off it), nearly still.
constexpr double kRestHeight = 2e-4;  // m
constexpr double kRestAxis = 1e-3;    // m
constexpr double kRestSpeed = 0.01;   // m/s

// The nut held level 2.5 mm above the pins' tops, on a floor with three 1 mm x 1 mm pins through
// its hole, 1.5 mm from its axis 120 degrees apart (their far corners 2.2 mm from the axis, inside
// the hole's 3 mm radius): a tripod the hull rests on level. (One pin on the axis:
// NutThreadedOnACentredPinIsNotCountedInsideTheFixture.)
Scene nutOverPins(PartSpec::Collision collision) {
  Scene s;
  s.name = "nut_over_pin";
  s.fixtures.push_back(boxFixture("floor", {0.1, 0.1, 0.01}));
  for (int k = 0; k < 3; ++k) {
    const double a = 2 * kPi * k / 3;
    s.fixtures.push_back(boxFixture("pin " + std::to_string(k), {0.001, 0.001, kPinTop},
                                    {0.0015 * std::cos(a), 0.0015 * std::sin(a), kPinTop}));
  }
  PartSpec nut;
  nut.name = "nut";
  nut.shape = Shape::Kind::Mesh;
  nut.mesh = "hex_nut_m6.obj";
  nut.size[0].mean = 0.001;  // millimetres to metres
  nut.density = 7850;
  nut.collision = collision;
  nut.spawn_min = nut.spawn_max = {0, 0, kPinTop + 0.5 * kThickness + 0.0025};
  s.parts.push_back(nut);
  s.material.mu = 0.3;
  s.solver.time_step = 0.001;
  s.solver.iterations = 50;
  s.duration = 0.5;
  loadSceneMeshes(s, std::filesystem::path(RHEOFEED_DEMO_DIR) / "meshes");
  return s;
}

TEST(PartCollision, ConvexHullNutStopsOnPinsThatThreadTheMeshNut) {
  const TriangleMesh nut_mesh =
      loadTriangleMesh(std::filesystem::path(RHEOFEED_DEMO_DIR) / "meshes" / "hex_nut_m6.obj");
  const double nut_mass = massProperties(nut_mesh, 7850).mass * 1e-9;  // mm^3 to m^3
  for (Method method : {Method::OdeRheonomic, Method::ReferenceRheonomic}) {
    for (auto collision : {PartSpec::Collision::Mesh, PartSpec::Collision::ConvexHull}) {
      const bool hull = collision == PartSpec::Collision::ConvexHull;
      SCOPED_TRACE(std::string(toString(method)) + (hull ? ", convex hull" : ", mesh"));
      const Scene s = nutOverPins(collision);
      std::unique_ptr<Simulation> sim = makeSimulation(s, method);
      const long steps = std::lround(s.duration / s.solver.time_step);
      for (long k = 0; k < steps; ++k) sim->step();
      const PartState p = sim->part(0);
      const double rest = (hull ? kPinTop : 0.0) + 0.5 * kThickness;
      EXPECT_NEAR(p.position.z, rest, kRestHeight);
      EXPECT_NEAR(std::hypot(p.position.x, p.position.y), 0.0, kRestAxis);
      EXPECT_LT(norm(p.velocity), kRestSpeed);
      EXPECT_NEAR(sim->partMass(0), nut_mass, 1e-9 * nut_mass);  // the hole's mass is not added
      EXPECT_EQ(sim->health().partsLost(), 0);
    }
  }
}

// ---- The point the health checks follow (partAnchor) ----------------------------------------
// The nut blank's geometry (demos/meshes/hex_nut_m6.obj, millimetres): a 24-gon hole of
// circumradius 3 mm (vertices every 15 degrees from +x, so its apothem is 3 cos 7.5 deg), outer
// flats 5 mm from the axis facing 30 + 60 k degrees (corners on +-x), faces at z = +-2.5 mm. Its
// centre of mass is on the axis, in the hole.
constexpr double kHoleRadius = 0.003, kFlatDistance = 0.005;
// Metres per millimetre of the mesh; the nut's parts are drawn at exactly this scale here.
constexpr double kNutScale = 0.001;
// Round-off of the mesh's 6-digit coordinates and of the distances (m).
constexpr double kGeometryTolerance = 1e-8;

// Distance (m) from a point in the nut's body frame to its outer flats (positive inside).
double flatDepth(const Vec3& x) {
  double depth = std::numeric_limits<double>::infinity();
  for (int k = 0; k < 6; ++k) {
    const double a = kPi / 6 + k * kPi / 3;
    depth = std::min(depth, kFlatDistance - (x.x * std::cos(a) + x.y * std::sin(a)));
  }
  return depth;
}

// The first part drawn from a scene of one nut (as the simulations draw it).
PartInstance drawnNut(PartSpec::Collision collision) {
  const std::vector<PartInstance> parts = drawParts(nutOverPins(collision));
  return parts.at(0);
}

TEST(PartAnchor, NutWithItsCentreInTheHoleIsFollowedByAPointDeepInItsRing) {
  const PartAnchor a = partAnchor(drawnNut(PartSpec::Collision::Mesh).shape);
  const Vec3& x = a.point;
  const double r = std::hypot(x.x, x.y);
  // Inside the material: beyond the hole, within the flats, between the faces.
  EXPECT_GT(r, kHoleRadius);
  EXPECT_GT(flatDepth(x), 0);
  EXPECT_LT(std::abs(x.z), 0.5 * kThickness);
  // Its clearance is its distance to the nearest surface: to the hole (between r - 3 mm and
  // r - 3 mm cos 7.5 deg), the flats or the faces.
  const double faces = 0.5 * kThickness - std::abs(x.z);
  const double hole_far = r - kHoleRadius, hole_near = r - kHoleRadius * std::cos(kPi / 24);
  EXPECT_GE(a.clearance, std::min({hole_far, flatDepth(x), faces}) - kGeometryTolerance);
  EXPECT_LE(a.clearance, std::min({hole_near, flatDepth(x), faces}) + kGeometryTolerance);
  // As deep as the ring allows, nearly: its ring is 2 mm wide across the flats (the midpoint
  // is 1 mm deep there) and deepest towards a corner, where r - 3 mm = 5 mm - r cos 30 deg:
  // r = 8 mm / (1 + cos 30 deg), 1.287 mm deep.
  const double deepest = 8 * kNutScale / (1 + std::cos(kPi / 6)) - kHoleRadius;
  EXPECT_GE(a.clearance, 1e-3 - kGeometryTolerance);
  EXPECT_LE(a.clearance, deepest + kGeometryTolerance);
}

// A flat ring (washer) of radii 4 and 8 mm, 1 mm thick, 24 sectors, its axis along the unit
// vector `axis` of its own frame (a part tilted in its CAD file), centred on the origin.
TriangleMesh tiltedRing(const Vec3& axis) {
  constexpr int kSectors = 24;
  constexpr double kInner = 0.004, kOuter = 0.008, kHalf = 0.0005;
  // An orthonormal frame (e1, e2, axis).
  const Vec3 e1 = (1 / norm(cross(axis, {1, 0, 0}))) * cross(axis, {1, 0, 0}), e2 = cross(axis, e1);
  TriangleMesh m;
  m.source = "tilted ring";
  // Cross-section corners counter-clockwise in the (r, z) half-plane.
  const double section[4][2] = {
      {kInner, -kHalf}, {kOuter, -kHalf}, {kOuter, kHalf}, {kInner, kHalf}};
  for (int k = 0; k < kSectors; ++k) {
    const double a = 2 * kPi * k / kSectors;
    for (const auto& [r, z] : section) {
      const Vec3 v = (r * std::cos(a)) * e1 + (r * std::sin(a)) * e2 + z * axis;
      m.vertices.insert(m.vertices.end(), {v.x, v.y, v.z});
    }
  }
  auto at = [](int k, int j) { return 4 * (k % kSectors) + j % 4; };
  for (int k = 0; k < kSectors; ++k) {
    for (int j = 0; j < 4; ++j) {  // outward: (around) x (across the section)
      m.triangles.insert(m.triangles.end(), {at(k, j), at(k + 1, j), at(k + 1, j + 1)});
      m.triangles.insert(m.triangles.end(), {at(k, j), at(k + 1, j + 1), at(k, j + 1)});
    }
  }
  return m;
}

// A washer whose axis is tilted in its file: none of the 26 cube directions from its centre
// (in its hole) crosses its 1 mm thick material. The anchor must still lie in the material, at
// most half its thickness deep, and not far less.
TEST(PartAnchor, WasherTiltedInItsFileIsFollowedByAPointInItsMaterial) {
  const Vec3 axis = (1 / norm(Vec3{0.17, 0.42, 0.89})) * Vec3{0.17, 0.42, 0.89};
  Shape ring;
  ring.kind = Shape::Kind::Mesh;
  ring.mesh_data = std::make_shared<const TriangleMesh>(tiltedRing(axis));
  ASSERT_GT(massProperties(*ring.mesh_data, 1.0).volume, 0);  // closed and outward
  const PartAnchor a = partAnchor(ring);
  const double along = dot(a.point, axis), across = norm(a.point - along * axis);
  EXPECT_LT(std::abs(along), 0.0005);
  EXPECT_GT(across, 0.004);
  EXPECT_LT(across, 0.008 * std::cos(kPi / 24));  // inside the 24-gon's flat sides
  EXPECT_LE(a.clearance, 0.0005 + kGeometryTolerance);
  EXPECT_GE(a.clearance, 0.00025);
}

TEST(PartAnchor, SolidPartsAreFollowedByTheirCentreAtTheirSmallestHalfSize) {
  Shape box;
  box.kind = Shape::Kind::Box;
  box.size = {0.01, 0.02, 0.03};
  const PartAnchor b = partAnchor(box);
  EXPECT_EQ(b.point, Vec3{});
  EXPECT_DOUBLE_EQ(b.clearance, 0.005);
  // The same box as a mesh (its corners' convex hull, centred on the origin).
  TriangleMesh corners;
  for (int c = 0; c < 8; ++c) {
    corners.vertices.insert(corners.vertices.end(),
                            {c & 1 ? 0.005 : -0.005, c & 2 ? 0.01 : -0.01, c & 4 ? 0.015 : -0.015});
  }
  Shape mesh_box;
  mesh_box.kind = Shape::Kind::Mesh;
  mesh_box.mesh_data = std::make_shared<const TriangleMesh>(convexHull(corners));
  const PartAnchor m = partAnchor(mesh_box);
  EXPECT_EQ(m.point, Vec3{});
  EXPECT_DOUBLE_EQ(m.clearance, 0.005);
  // The nut colliding as its hull (a solid prism holding its centre): its centre and its
  // smallest half-size, half its thickness.
  const PartAnchor hull = partAnchor(drawnNut(PartSpec::Collision::ConvexHull).shape);
  EXPECT_EQ(hull.point, Vec3{});
  EXPECT_NEAR(hull.clearance, 0.5 * kThickness, kGeometryTolerance);
}

// The nut dropped level over one 2 mm square pin on its axis (the pin's corners 1.41 mm from
// the axis, inside the 3 mm hole): it threads onto the pin and rests on the floor, its centre
// 2.5 mm up and inside the pin. Physically fine: nothing lost, sunk or inside a fixture.
TEST(PartCollision, NutThreadedOnACentredPinIsNotCountedInsideTheFixture) {
  for (Method method : {Method::OdeRheonomic, Method::ReferenceRheonomic}) {
    SCOPED_TRACE(toString(method));
    Scene s = nutOverPins(PartSpec::Collision::Mesh);
    s.fixtures.resize(1);  // the floor
    s.fixtures.push_back(boxFixture("pin", {0.002, 0.002, kPinTop}, {0, 0, kPinTop}));
    s.parts[0].spawn_min = s.parts[0].spawn_max = {0, 0, 0.015};
    std::unique_ptr<Simulation> sim = makeSimulation(s, method);
    const long steps = std::lround(s.duration / s.solver.time_step);
    for (long k = 0; k < steps; ++k) sim->step();
    const PartState p = sim->part(0);
    EXPECT_NEAR(p.position.z, 0.5 * kThickness, kRestHeight);
    EXPECT_NEAR(std::hypot(p.position.x, p.position.y), 0.0, kRestAxis);
    EXPECT_LT(norm(p.velocity), kRestSpeed);
    const RunHealth& h = sim->health();
    EXPECT_EQ(h.partsLost(), 0);
    EXPECT_EQ(h.parts_sunk, 0);
    EXPECT_EQ(h.parts_inside_fixture, 0);
    EXPECT_EQ(h.parts_through_fixture, 0);
  }
}

// The nut thrown down level at 2 m/s onto a 0.5 mm sheet at h = 0.01 s, without speculative
// contacts: semi-implicit Euler (v1 = v0 - g h, z1 = z0 + h v1) takes its centre from 3.5 mm to
// -17.5 mm in one step, and it overlaps the sheet only while -0.5 mm - 2.5 mm < z < 2.5 mm: it
// never touches the sheet, and its material passes through it.
TEST(PartCollision, NutThrownThroughAThinSheetIsCountedThroughTheFixture) {
  constexpr double kSheet = 0.0005, kStep = 0.01, kSpeed = 2.0, kStart = 0.0035;
  const double z1 = kStart - kStep * (kSpeed + 9.81 * kStep);
  ASSERT_GT(kStart, 0.5 * kThickness);
  ASSERT_LT(z1, -kSheet - 0.5 * kThickness);
  for (Method method : {Method::OdeRheonomic, Method::ReferenceRheonomic}) {
    SCOPED_TRACE(toString(method));
    Scene s = nutOverPins(PartSpec::Collision::Mesh);
    s.fixtures = {boxFixture("sheet", {0.1, 0.1, kSheet})};
    s.parts[0].spawn_min = s.parts[0].spawn_max = {0, 0, kStart};
    s.parts[0].initial_velocity = {0, 0, -kSpeed};
    s.solver.time_step = kStep;
    s.solver.speculative_contacts = false;
    s.removal_height = -2;
    std::unique_ptr<Simulation> sim = makeSimulation(s, method);
    sim->step();
    EXPECT_LT(sim->part(0).position.z, -kSheet - 0.5 * kThickness);
    EXPECT_EQ(sim->health().parts_through_fixture, 1);
    EXPECT_EQ(sim->health().partsLost(), 1);
  }
}

}  // namespace
}  // namespace rheofeed::scene

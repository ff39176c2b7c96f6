// SPDX-License-Identifier: MIT
// Scene files: a full round trip, and every kind of bad input refused with the JSON path of the
// bad value and the file name.
#include "rheofeed/scene/scene_io.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>

#include "rheofeed/scene/mesh.hpp"
#include "scene_builders.hpp"

namespace rheofeed::scene {
namespace {

namespace fs = std::filesystem;

const fs::path kData = RHEOFEED_IO_TEST_DATA;
constexpr double kPi = 3.14159265358979323846;
// Rotations go through axis-angle in the file: a few ulp per matrix entry.
constexpr double kRotationTolerance = 1e-14;

// A stand-in mesh loader: the test box (closed), with a call counter.
struct CountingLoader {
  int calls = 0;
  MeshLoader loader() {
    return [this](const fs::path& file, double scale) {
      ++calls;
      TriangleMesh m = loadTriangleMesh(kData / "box_20x30x40mm.obj", scale);
      m.source = file.string();
      return m;
    };
  }
};

void expectSame(const Vec3& a, const Vec3& b, const std::string& what) {
  EXPECT_EQ(a.x, b.x) << what;
  EXPECT_EQ(a.y, b.y) << what;
  EXPECT_EQ(a.z, b.z) << what;
}
void expectSame(const Twist& a, const Twist& b, const std::string& what) {
  expectSame(a.linear, b.linear, what + ".linear");
  expectSame(a.angular, b.angular, what + ".angular");
  expectSame(a.origin, b.origin, what + ".origin");
}
void expectSame(const Vibration& a, const Vibration& b, const std::string& what) {
  EXPECT_EQ(a.amplitude, b.amplitude) << what;
  EXPECT_EQ(a.frequency, b.frequency) << what;
  expectSame(a.direction, b.direction, what + ".direction");
  EXPECT_EQ(a.phase, b.phase) << what;
  EXPECT_EQ(a.torsion_amplitude, b.torsion_amplitude) << what;
  expectSame(a.axis_origin, b.axis_origin, what + ".axis_origin");
  expectSame(a.axis_direction, b.axis_direction, what + ".axis_direction");
}

void expectSame(const Distribution& a, const Distribution& b, const std::string& what) {
  EXPECT_EQ(a.mean, b.mean) << what;
  EXPECT_EQ(a.stddev, b.stddev) << what;
  EXPECT_EQ(a.min, b.min) << what;
  EXPECT_EQ(a.max, b.max) << what;
}

// Every field of scene.hpp that a file carries.
void expectSameScene(const Scene& a, const Scene& b) {
  EXPECT_EQ(a.name, b.name);
  expectSame(a.gravity, b.gravity, "gravity");
  EXPECT_EQ(a.duration, b.duration);
  EXPECT_EQ(a.seed, b.seed);
  ASSERT_EQ(a.fixtures.size(), b.fixtures.size());
  for (std::size_t i = 0; i < a.fixtures.size(); ++i) {
    const Fixture &fa = a.fixtures[i], &fb = b.fixtures[i];
    const std::string w = "fixtures[" + std::to_string(i) + "]";
    EXPECT_EQ(fa.name, fb.name) << w;
    ASSERT_EQ(fa.geoms.size(), fb.geoms.size()) << w;
    for (std::size_t g = 0; g < fa.geoms.size(); ++g) {
      const Shape &sa = fa.geoms[g].shape, &sb = fb.geoms[g].shape;
      const std::string wg = w + ".geoms[" + std::to_string(g) + "]";
      ASSERT_EQ(sa.kind, sb.kind) << wg;
      switch (sa.kind) {
        case Shape::Kind::Box:
          expectSame(sa.size, sb.size, wg + ".size");
          break;
        case Shape::Kind::Sphere:
          EXPECT_EQ(sa.radius, sb.radius) << wg;
          break;
        case Shape::Kind::Cylinder:
        case Shape::Kind::Capsule:
          EXPECT_EQ(sa.radius, sb.radius) << wg;
          EXPECT_EQ(sa.length, sb.length) << wg;
          break;
        case Shape::Kind::Plane:
          expectSame(sa.plane_normal, sb.plane_normal, wg + ".normal");
          EXPECT_EQ(sa.plane_offset, sb.plane_offset) << wg;
          break;
        case Shape::Kind::Mesh:
          EXPECT_EQ(sa.mesh, sb.mesh) << wg;
          EXPECT_EQ(sa.mesh_scale, sb.mesh_scale) << wg;
          break;
      }
      if (sa.kind == Shape::Kind::Plane) continue;
      expectSame(fa.geoms[g].pose.position, fb.geoms[g].pose.position, wg + ".position");
      for (int k = 0; k < 9; ++k) {
        EXPECT_NEAR(fa.geoms[g].pose.rotation[k], fb.geoms[g].pose.rotation[k], kRotationTolerance)
            << wg << ".rotation " << k;
      }
    }
    const FeederLaw &la = fa.law, &lb = fb.law;
    ASSERT_EQ(la.kind, lb.kind) << w;
    expectSame(la.drift, lb.drift, w + ".drift");
    expectSame(la.belt_direction, lb.belt_direction, w + ".belt_direction");
    EXPECT_EQ(la.belt_speed, lb.belt_speed) << w;
    expectSame(la.vibration, lb.vibration, w + ".vibration");
    ASSERT_EQ(la.calibrated_for.has_value(), lb.calibrated_for.has_value()) << w;
    if (la.calibrated_for) {
      expectSame(la.calibrated_for->vibration, lb.calibrated_for->vibration,
                 w + ".calibrated_for.vibration");
      expectSame(la.calibrated_for->gravity, lb.calibrated_for->gravity,
                 w + ".calibrated_for.gravity");
      EXPECT_EQ(la.calibrated_for->mu, lb.calibrated_for->mu) << w;
      EXPECT_EQ(la.calibrated_for->method, lb.calibrated_for->method) << w;
      const CalibrationBasis &ba = *la.calibrated_for, &bb = *lb.calibrated_for;
      ASSERT_EQ(ba.conveying_direction.has_value(), bb.conveying_direction.has_value()) << w;
      if (ba.conveying_direction) {
        expectSame(*ba.conveying_direction, *bb.conveying_direction,
                   w + ".calibrated_for.conveying_direction");
      }
      ASSERT_EQ(ba.track_point.has_value(), bb.track_point.has_value()) << w;
      if (ba.track_point) {
        expectSame(*ba.track_point, *bb.track_point, w + ".calibrated_for.track_point");
      }
      EXPECT_EQ(ba.restitution, bb.restitution) << w;
      EXPECT_EQ(ba.part_digests, bb.part_digests) << w;
      EXPECT_EQ(ba.fixture_digests, bb.fixture_digests) << w;
    }
    EXPECT_EQ(la.has_calibrated_drift, lb.has_calibrated_drift) << w;
    expectSame(la.calibrated_drift, lb.calibrated_drift, w + ".calibrated_drift");
    EXPECT_EQ(la.drift_model, lb.drift_model) << w;
    EXPECT_EQ(la.efficiency, lb.efficiency) << w;  // bit-identical doubles
  }
  ASSERT_EQ(a.parts.size(), b.parts.size());
  for (std::size_t i = 0; i < a.parts.size(); ++i) {
    const PartSpec &pa = a.parts[i], &pb = b.parts[i];
    const std::string w = "parts[" + std::to_string(i) + "]";
    EXPECT_EQ(pa.name, pb.name) << w;
    ASSERT_EQ(pa.shape, pb.shape) << w;
    const int n = pa.shape == Shape::Kind::Box                                            ? 3
                  : pa.shape == Shape::Kind::Cylinder || pa.shape == Shape::Kind::Capsule ? 2
                                                                                          : 1;
    for (int d = 0; d < n; ++d) expectSame(pa.size[d], pb.size[d], w + ".size");
    if (pa.shape == Shape::Kind::Mesh) {
      EXPECT_EQ(pa.mesh, pb.mesh) << w;
      EXPECT_EQ(pa.collision, pb.collision) << w;
    }
    EXPECT_EQ(pa.density, pb.density) << w;
    expectSame(pa.spawn_min, pb.spawn_min, w + ".spawn_min");
    expectSame(pa.spawn_max, pb.spawn_max, w + ".spawn_max");
    EXPECT_EQ(pa.random_orientation, pb.random_orientation) << w;
    EXPECT_EQ(pa.count, pb.count) << w;
    EXPECT_EQ(pa.rate, pb.rate) << w;
    expectSame(pa.initial_velocity, pb.initial_velocity, w + ".initial_velocity");
  }
  EXPECT_EQ(a.material.mu, b.material.mu);
  EXPECT_EQ(a.material.restitution, b.material.restitution);
  EXPECT_EQ(a.solver.time_step, b.solver.time_step);
  EXPECT_EQ(a.solver.iterations, b.solver.iterations);
  EXPECT_EQ(a.solver.ode_quickstep, b.solver.ode_quickstep);
  EXPECT_EQ(a.solver.friction, b.solver.friction);
  EXPECT_EQ(a.solver.broad_phase, b.solver.broad_phase);
  EXPECT_EQ(a.solver.erp, b.solver.erp);
  EXPECT_EQ(a.solver.cfm, b.solver.cfm);
  EXPECT_EQ(a.solver.tolerance, b.solver.tolerance);
  EXPECT_EQ(a.solver.apgd, b.solver.apgd);
  EXPECT_EQ(a.solver.coulomb_iterations, b.solver.coulomb_iterations);
  EXPECT_EQ(a.solver.max_correcting_velocity, b.solver.max_correcting_velocity);
  EXPECT_EQ(a.solver.surface_layer, b.solver.surface_layer);
  EXPECT_EQ(a.solver.rheonomic_time_step, b.solver.rheonomic_time_step);
  EXPECT_EQ(a.removal_height, b.removal_height);
  const Outputs &oa = a.outputs, &ob = b.outputs;
  expectSame(oa.conveying_direction, ob.conveying_direction, "conveying_direction");
  EXPECT_EQ(oa.angular_drift, ob.angular_drift);
  expectSame(oa.axis_origin, ob.axis_origin, "outputs.axis_origin");
  expectSame(oa.axis_direction, ob.axis_direction, "outputs.axis_direction");
  EXPECT_EQ(oa.exit_plane, ob.exit_plane);
  expectSame(oa.exit_point, ob.exit_point, "exit_point");
  expectSame(oa.exit_normal, ob.exit_normal, "exit_normal");
  EXPECT_EQ(oa.sample_interval, ob.sample_interval);
  EXPECT_EQ(oa.warmup, ob.warmup);
}

// A scene that sets every field away from its default.
Scene everyFieldScene() {
  Scene s;
  s.name = "every field";
  s.gravity = {0.1, -0.2, -9.7};
  s.removal_height = -0.75;
  s.solver.max_correcting_velocity = 0.25;
  s.solver.surface_layer = 2e-4;
  s.solver.rheonomic_time_step = 0.004;  // written only when given (> 0)
  s.solver.coulomb_iterations = 3;
  s.duration = 2.5;
  s.seed = 18446744073709551557ull;  // needs all 64 bits
  const double c = std::cos(0.3), sn = std::sin(0.3);

  Fixture belt;
  belt.name = "belt";
  Fixture::Geom g;
  g.shape.kind = Shape::Kind::Box;
  g.shape.size = {2, 0.5, 0.02};
  g.pose.position = {0.1, 0.2, -0.01};
  const double ry[9] = {c, 0, sn, 0, 1, 0, -sn, 0, c};  // 0.3 rad about y
  std::copy(ry, ry + 9, g.pose.rotation);
  belt.geoms.push_back(g);
  belt.law.kind = FeederLaw::Kind::Belt;
  belt.law.belt_direction = {c, sn, 0};
  belt.law.belt_speed = -0.25;
  s.fixtures.push_back(belt);

  Fixture table;
  table.name = "turntable";
  Fixture::Geom cyl;
  cyl.shape.kind = Shape::Kind::Cylinder;
  cyl.shape.radius = 0.4;
  cyl.shape.length = 0.05;
  cyl.pose.position = {3, 0, -0.025};
  table.geoms.push_back(cyl);
  Fixture::Geom cap;
  cap.shape.kind = Shape::Kind::Capsule;
  cap.shape.radius = 0.01;
  cap.shape.length = 0.3;
  cap.pose.position = {3, 0.5, 0.01};
  table.geoms.push_back(cap);
  table.law.kind = FeederLaw::Kind::Drift;
  table.law.drift = {{0.01, 0, 0.002}, {0, 0, 1.5}, {3, 0, 0}};
  s.fixtures.push_back(table);

  Fixture bowl;
  bowl.name = "bowl";
  Fixture::Geom mesh;
  mesh.shape.kind = Shape::Kind::Mesh;
  mesh.shape.mesh = "/meshes/bowl.stl";
  mesh.shape.mesh_scale = 0.001;
  mesh.pose.position = {-3, 0, 0};
  const double rz[9] = {c, -sn, 0, sn, c, 0, 0, 0, 1};
  std::copy(rz, rz + 9, mesh.pose.rotation);
  bowl.geoms.push_back(mesh);
  Fixture::Geom ball;
  ball.shape.kind = Shape::Kind::Sphere;
  ball.shape.radius = 0.02;
  ball.pose.position = {-3, 0, 0.5};
  bowl.geoms.push_back(ball);
  bowl.law.kind = FeederLaw::Kind::Vibration;
  Vibration& v = bowl.law.vibration;
  v.amplitude = 1.5e-4;
  v.frequency = 50;
  v.direction = {0, 0, 1};
  v.phase = 0.1;
  v.torsion_amplitude = 0.003;
  v.axis_origin = {-3, 0, 0};
  v.axis_direction = {0, 0, 1};
  bowl.law.has_calibrated_drift = true;
  bowl.law.calibrated_drift = {{0, 0, 0.0019}, {0, 0, 0.4}, {-3, 0, 0}};
  bowl.law.drift_model = DriftModel::LocalSampled;            // the calibrated drift kept beside it
  bowl.law.efficiency = {0.8123456789012345, 1, 1.0 / 3, 0};  // boxes, balls, pins, nuts
  CalibrationBasis& basis = bowl.law.calibrated_for.emplace();
  basis.vibration = v;
  basis.gravity = {0.1, 0, -9.7};
  basis.mu = 0.45;
  basis.method = "sampling";
  basis.conveying_direction = Vec3{0.6, 0.8, 0};
  basis.track_point = Vec3{-2.86, 0.125, 0.0421};
  basis.restitution = 0.15;
  basis.part_digests = {"0123456789abcdef", "", "00000000000000ff", "0123456789abcdef"};
  basis.fixture_digests = {"fedcba9876543210", "fedcba9876543210", "0000000000000001"};
  bowl.law.calibrated_for->vibration.amplitude = 2.5e-4;  // calibrated for another amplitude
  s.fixtures.push_back(bowl);

  s.fixtures.push_back(test::groundPlane("ground", -1));

  PartSpec boxes;
  boxes.name = "boxes";
  boxes.shape = Shape::Kind::Box;
  boxes.size[0] = {0.02, 0.002, 0.015, 0.025};
  boxes.size[1] = {0.03, 0, 0, 1e300};
  boxes.size[2] = {0.01, 0.001, 0.005, 1e300};
  boxes.density = 2700;
  boxes.spawn_min = {-0.9, -0.2, 0.05};
  boxes.spawn_max = {-0.5, 0.2, 0.3};
  boxes.random_orientation = true;
  boxes.count = 20;
  boxes.rate = 10;
  boxes.initial_velocity = {0.1, 0, -0.2};
  s.parts.push_back(boxes);
  PartSpec balls;
  balls.name = "balls";
  balls.shape = Shape::Kind::Sphere;
  balls.size[0] = {0.005, 0, 0, 1e300};
  balls.spawn_min = {0, 0, 1};
  balls.spawn_max = {0.3, 0.3, 1.3};
  balls.count = 3;
  s.parts.push_back(balls);
  PartSpec pins;
  pins.name = "pins";
  pins.shape = Shape::Kind::Capsule;
  pins.size[0] = {0.003, 0, 0, 1e300};
  pins.size[1] = {0.02, 0.001, 0.01, 0.03};
  pins.spawn_min = {0, 1, 1};
  pins.spawn_max = {0.3, 1.3, 1.3};
  s.parts.push_back(pins);
  PartSpec nuts;
  nuts.name = "nuts";
  nuts.shape = Shape::Kind::Mesh;
  nuts.mesh = "/meshes/nut.obj";
  nuts.size[0] = {0.5, 0.05, 0.4, 0.6};
  nuts.density = 7850;
  nuts.collision = PartSpec::Collision::ConvexHull;
  nuts.spawn_min = {-3, 0, 1};
  nuts.spawn_max = {-2.5, 0.5, 1.5};
  nuts.count = 4;
  s.parts.push_back(nuts);

  s.material = {0.35, 0.2};
  s.solver = SolverSettings{};
  s.solver.time_step = 0.002;
  s.solver.iterations = 77;
  s.solver.ode_quickstep = false;
  s.solver.erp = 0.3;
  s.solver.cfm = 1e-6;
  s.solver.tolerance = 1e-8;
  s.solver.apgd = false;
  s.solver.coulomb_iterations = 3;
  s.solver.friction = FrictionModel::Pyramid;  // a Dantzig scene may ask for the pyramid
  s.solver.broad_phase = BroadPhase::SweepAndPrune;
  s.outputs.conveying_direction = {0, 1, 0};
  s.outputs.angular_drift = true;
  s.outputs.axis_origin = {-3, 0, 0};
  s.outputs.axis_direction = {0, 0, -1};
  s.outputs.exit_plane = true;
  s.outputs.exit_point = {1.1, 0, 0};
  s.outputs.exit_normal = {1, 0, 0};
  s.outputs.sample_interval = 0.02;
  s.outputs.warmup = 0.5;
  return s;
}

TEST(SceneFile, RoundTripKeepsEveryField) {
  const Scene original = everyFieldScene();
  CountingLoader meshes;
  const std::string text = toJson(original);
  const Scene back = parseScene(text, "round_trip.json", meshes.loader());
  expectSameScene(original, back);
  EXPECT_EQ(toJson(back), text);  // and the text is stable
  EXPECT_EQ(meshes.calls, 2);     // bowl (scale 0.001) and nut (scale 1), each once
  ASSERT_TRUE(back.fixtures[2].geoms[0].shape.mesh_data);
  ASSERT_TRUE(back.parts[3].mesh_data);
  // What a sampling calibration records of the parts and fixtures (their digests, taken from
  // the loaded meshes and the rotations computed from angles) reads back the same.
  const Scene again = parseScene(toJson(back), "again.json", meshes.loader());
  for (std::size_t k = 0; k < back.parts.size(); ++k) {
    EXPECT_EQ(partDigest(again.parts[k]), partDigest(back.parts[k])) << k;
  }
  for (std::size_t i = 0; i < back.fixtures.size(); ++i) {
    EXPECT_EQ(fixtureDigest(again.fixtures[i]), fixtureDigest(back.fixtures[i])) << i;
  }
  EXPECT_EQ(partDigest(back.parts[3]).size(), 16u);  // the mesh nuts
}

TEST(SceneFile, PartMeshIsCentredOnItsCentreOfMass) {
  const Scene back = parseScene(toJson(everyFieldScene()), "x.json", CountingLoader{}.loader());
  const MassProperties p = massProperties(*back.parts[3].mesh_data, 1.0);
  EXPECT_NEAR(norm(p.centre_of_mass), 0.0, 1e-12);  // the test box sits at (0.1, -0.05, 0.2)
  // The fixture mesh keeps its own frame, scaled by 0.001.
  const MassProperties f = massProperties(*back.fixtures[2].geoms[0].shape.mesh_data, 1.0);
  EXPECT_NEAR(f.centre_of_mass.x, 0.1e-3, 1e-9);
}

// A part colliding as its convex hull keeps its own mesh for mass and drawing; the hull (of the
// test box: itself, 12 triangles) is built once in the same centred frame, and every drawn part
// collides with a copy scaled as its mesh.
TEST(SceneFile, ConvexHullPartsCollideWithTheHullScaledAsTheirMesh) {
  const Scene back = parseScene(toJson(everyFieldScene()), "x.json", CountingLoader{}.loader());
  const PartSpec& nuts = back.parts[3];
  ASSERT_EQ(nuts.collision, PartSpec::Collision::ConvexHull);
  ASSERT_TRUE(nuts.collision_mesh_data);
  EXPECT_EQ(nuts.collision_mesh_data->triangles.size(), 36u);
  const MassProperties mesh = massProperties(*nuts.mesh_data, 1.0);
  const MassProperties hull = massProperties(*nuts.collision_mesh_data, 1.0);
  EXPECT_NEAR(hull.volume, mesh.volume, 1e-12 * mesh.volume);  // a box is its own hull
  EXPECT_NEAR(norm(hull.centre_of_mass), 0.0, 1e-12);
  EXPECT_NE(nuts.collision_mesh_data->source.find("convex hull of"), std::string::npos);
  for (const PartInstance& p : drawParts(back)) {
    if (p.spec != 3) {
      EXPECT_FALSE(p.shape.collision_mesh_data);
      continue;
    }
    ASSERT_TRUE(p.shape.collision_mesh_data);
    EXPECT_NEAR(boundingRadius(*p.shape.collision_mesh_data), boundingRadius(*p.shape.mesh_data),
                1e-12);
    EXPECT_NEAR(p.mass, 7850 * mesh.volume * std::pow(p.shape.mesh_scale, 3), 1e-9 * p.mass);
  }
}

// Built in code: the hull is chosen by the part's setting, never by leftover data; a hull not
// built, or asked of a primitive part, is an error naming the part.
TEST(SceneFile, ConvexHullFollowsTheSettingAndIsRefusedWhereItCannotApply) {
  Scene hull = parseScene(toJson(everyFieldScene()), "x.json", CountingLoader{}.loader());
  Scene mesh = hull;
  mesh.parts[3].collision = PartSpec::Collision::Mesh;  // the hull data is still there
  for (const PartInstance& p : drawParts(mesh)) EXPECT_FALSE(p.shape.collision_mesh_data);
  Scene unbuilt = hull;
  unbuilt.parts[3].collision_mesh_data = nullptr;
  try {
    drawParts(unbuilt);
    ADD_FAILURE() << "drawn without its hull";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("parts[3].collision"), std::string::npos) << e.what();
  }
  Scene box = hull;
  box.parts[0].collision = PartSpec::Collision::ConvexHull;
  try {
    box.validate();
    ADD_FAILURE() << "a box part accepted as a convex hull";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("parts[0].collision: only mesh parts"), std::string::npos)
        << e.what();
  }
}

TEST(SceneFile, SceneWithoutMeshesNeverCallsTheMeshLoader) {
  Scene s = everyFieldScene();
  s.fixtures.erase(s.fixtures.begin() + 2);  // the bowl
  s.parts.pop_back();                        // the nuts
  int calls = 0;
  const MeshLoader counting = [&calls](const fs::path&, double) {
    ++calls;
    return TriangleMesh{};
  };
  const Scene back = parseScene(toJson(s), "no_meshes.json", counting);
  EXPECT_EQ(calls, 0);
  EXPECT_FALSE(back.hasMeshes());
}

TEST(SceneFile, RelativeMeshPathsResolveAgainstTheSceneFolder) {
  const std::string text = R"({
    "fixtures": [{"geoms": [{"shape": "mesh", "mesh": "../meshes/floor.obj", "scale": 2}]}],
    "parts": [{"shape": "sphere", "size": [0.01], "spawn_min": [0, 0, 1], "spawn_max": [0, 0, 1]}]
  })";
  fs::path asked;
  double asked_scale = 0;
  const MeshLoader loader = [&](const fs::path& file, double scale) {
    asked = file;
    asked_scale = scale;
    return loadTriangleMesh(kData / "floor_slab.obj", scale);
  };
  const Scene s = parseScene(text, "/work/scenes/demo.json", loader);
  EXPECT_EQ(asked, fs::path("/work/meshes/floor.obj"));
  EXPECT_EQ(asked_scale, 2.0);
  EXPECT_EQ(s.fixtures[0].geoms[0].shape.mesh, "/work/meshes/floor.obj");
}

TEST(SceneFile, ShorthandsAndAnglesWithUnitsInTheKey) {
  const std::string text = R"({
    "comment": "comments are allowed in every object",
    "fixtures": [{
      "geoms": [{"shape": "box", "size": [1, 0.1, 0.02],
                 "rotation": {"axis": [0, 0, 2], "angle_deg": 90}}],
      "law": {"vibration": {"amplitude": 2e-4, "frequency": 50, "angle_deg": 30,
                            "phase_deg": 180},
              "calibrated_drift": {"linear": [0.05, 0, 0]}}
    }, {
      "geoms": [{"shape": "cylinder", "radius": 0.15, "length": 0.01}],
      "law": {"screw": {"vertical_amplitude": 1e-4, "torsion_amplitude_deg": 0.2,
                        "frequency": 60, "axis_origin": [0, 0, 0]}}
    }],
    "parts": [{"shape": "box", "size": [0.02, {"mean": 0.02, "stddev": 0.002}, 0.005],
               "spawn_min": [0, 0, 0.01], "spawn_max": [0, 0, 0.01]}]
  })";
  const Scene s = parseScene(text, "short.json");
  const Pose& pose = s.fixtures[0].geoms[0].pose;
  EXPECT_NEAR(pose.rotation[1], -1, 1e-15);  // 90 degrees about +z: x -> y
  EXPECT_NEAR(pose.rotation[3], 1, 1e-15);
  const Vibration& v = s.fixtures[0].law.vibration;
  EXPECT_NEAR(v.direction.x, std::sqrt(3.0) / 2, 1e-15);
  EXPECT_NEAR(v.direction.z, 0.5, 1e-15);
  EXPECT_NEAR(v.phase, kPi, 1e-15);
  EXPECT_TRUE(s.fixtures[0].law.has_calibrated_drift);
  const Vibration& screw = s.fixtures[1].law.vibration;
  EXPECT_EQ(screw.amplitude, 1e-4);
  EXPECT_NEAR(screw.torsion_amplitude, 0.2 * kPi / 180, 1e-18);
  expectSame(screw.direction, {0, 0, 1}, "screw direction is the axis");
  EXPECT_EQ(s.parts[0].size[1].stddev, 0.002);
  EXPECT_EQ(s.parts[0].size[0].stddev, 0.0);
  // Defaults for everything omitted.
  EXPECT_EQ(s.solver.time_step, SolverSettings{}.time_step);
  EXPECT_EQ(s.duration, Scene{}.duration);
  EXPECT_EQ(s.parts[0].count, 1);
}

// ---- Refused input -----------------------------------------------------------------------------

// A valid scene; the tests break one value each.
TEST(SceneFile, DriftModelDefaultsToLocalUnlessTheLawCarriesACalibratedDrift) {
  const std::string law = R"("law": {"vibration": {"amplitude": 2e-4, "frequency": 50}})";
  const std::string base = R"({"fixtures": [{"geoms": [{"shape": "box", "size": [1, 0.1, 0.02]}],
                                LAW}],
    "parts": [{"shape": "box", "size": [0.02, 0.02, 0.005],
               "spawn_min": [0, 0, 0.02], "spawn_max": [0, 0, 0.02]}]})";
  auto with = [&](const std::string& text) {
    std::string s = base;
    return s.replace(s.find("LAW"), 3, text);
  };
  EXPECT_EQ(parseScene(with(law), "a.json").fixtures[0].law.drift_model, DriftModel::Local);
  // A file written before the local law (a calibrated drift, no drift_model) behaves as before.
  const std::string calibrated =
      R"("law": {"vibration": {"amplitude": 2e-4, "frequency": 50},
                 "calibrated_drift": {"linear": [0.02, 0, 0]}})";
  const Scene old = parseScene(with(calibrated), "b.json");
  EXPECT_EQ(old.fixtures[0].law.drift_model, DriftModel::CalibratedDrift);
  EXPECT_TRUE(old.fixtures[0].law.has_calibrated_drift);
  // An explicit model wins; the calibrated drift is kept as an alternative.
  std::string local = calibrated;
  local.insert(local.find("\"calibrated_drift\""), R"("drift_model": "local", )");
  const Scene chosen = parseScene(with(local), "c.json");
  EXPECT_EQ(chosen.fixtures[0].law.drift_model, DriftModel::Local);
  EXPECT_TRUE(chosen.fixtures[0].law.has_calibrated_drift);
  EXPECT_EQ(chosen.fixtures[0].law.calibrated_drift.linear.x, 0.02);
  // calibrated_drift and local_sampled without their values are valid (the demos calibrate).
  for (const char* model : {"calibrated_drift", "local_sampled"}) {
    std::string m = law;
    m.insert(m.size() - 1, std::string(R"(, "drift_model": ")") + model + "\"");
    const Scene s = parseScene(with(m), "d.json");
    EXPECT_EQ(toString(s.fixtures[0].law.drift_model), std::string(model));
    EXPECT_TRUE(s.fixtures[0].law.efficiency.empty());
  }
}

TEST(SceneFile, EfficiencyByPartFamilyNameOrAsAnArray) {
  const std::string base = R"({"fixtures": [{"geoms": [{"shape": "box", "size": [1, 0.1, 0.02]}],
      "law": {"vibration": {"amplitude": 2e-4, "frequency": 50}, "drift_model": "local_sampled",
              "efficiency": EFF}}],
    "parts": [{"name": "nuts", "shape": "box", "size": [0.02, 0.02, 0.005],
               "spawn_min": [0, 0, 0.02], "spawn_max": [0, 0, 0.02]},
              {"name": "pins", "shape": "sphere", "size": [0.004],
               "spawn_min": [0.2, 0, 0.02], "spawn_max": [0.2, 0, 0.02]}]})";
  auto with = [&](const std::string& text) {
    std::string s = base;
    return s.replace(s.find("EFF"), 3, text);
  };
  const Scene named = parseScene(with(R"({"pins": 0.75})"), "named.json");
  EXPECT_EQ(named.fixtures[0].law.drift_model, DriftModel::LocalSampled);
  EXPECT_EQ(named.fixtures[0].law.efficiency, (std::vector<double>{1.0, 0.75}));  // nuts: 1
  const Scene array = parseScene(with("[0.5, 2]"), "array.json");
  EXPECT_EQ(array.fixtures[0].law.efficiency, (std::vector<double>{0.5, 2.0}));
  // Written by family name (unique names), read back bit-identical.
  const std::string text = toJson(named);
  EXPECT_NE(text.find(R"("efficiency": {)"), std::string::npos) << text;
  const Scene back = parseScene(text, "back.json");
  EXPECT_EQ(back.fixtures[0].law.efficiency, named.fixtures[0].law.efficiency);
  EXPECT_EQ(toJson(back), text);
}

TEST(SceneFile, EfficiencyIsWrittenAsAnArrayWhenFamilyNamesRepeat) {
  Scene s = everyFieldScene();
  s.parts[1].name = s.parts[0].name;  // two families named "boxes"
  CountingLoader meshes;
  const std::string text = toJson(s);
  EXPECT_NE(text.find(R"("efficiency": [)"), std::string::npos);
  const Scene back = parseScene(text, "repeat.json", meshes.loader());
  expectSameScene(s, back);
  EXPECT_EQ(toJson(back), text);
}

const char* kGood = R"({
  "fixtures": [{"name": "track",
                "geoms": [{"shape": "box", "size": [1, 0.1, 0.02], "position": [0, 0, -0.01]}],
                "law": {"vibration": {"amplitude": 2e-4, "frequency": 50, "angle_deg": 20}}}],
  "parts": [{"shape": "box", "size": [0.02, 0.02, 0.005],
             "spawn_min": [0, 0, 0.003], "spawn_max": [0, 0, 0.003]},
            {"shape": "sphere", "size": [0.004],
             "spawn_min": [0.2, 0, 0.005], "spawn_max": [0.2, 0, 0.005]},
            {"shape": "cylinder", "size": [0.004, {"mean": 0.01}],
             "spawn_min": [0.4, 0, 0.01], "spawn_max": [0.4, 0, 0.01]}],
  "duration": 1
})";

std::string replaced(std::string text, const std::string& from, const std::string& to) {
  const std::size_t at = text.find(from);
  EXPECT_NE(at, std::string::npos) << from;
  return at == std::string::npos ? text : text.replace(at, from.size(), to);
}

// Parses `text` as "bad.json", expects a SceneFileError at `path` whose problem contains `what`.
SceneFileError refused(const std::string& text, const std::string& path, const std::string& what) {
  try {
    parseScene(text, "bad.json");
  } catch (const SceneFileError& e) {
    EXPECT_EQ(e.path(), path) << e.what();
    EXPECT_NE(e.problem().find(what), std::string::npos) << e.what();
    EXPECT_EQ(e.source(), "bad.json");
    EXPECT_EQ(std::string(e.what()).rfind("bad.json", 0), 0u) << e.what();
    return e;
  }
  ADD_FAILURE() << "accepted; expected " << path << ": " << what;
  return SceneFileError("", "", "");
}

TEST(SceneFileErrors, TheGoodSceneIsAccepted) {
  EXPECT_NO_THROW(parseScene(kGood, "good.json"));
}

TEST(SceneFileErrors, MissingRequiredKeyNamesIt) {
  refused(replaced(kGood, R"({"shape": "sphere", )", "{"), "parts[1].shape",
          "missing required key");
  refused(replaced(kGood, R"("parts")", R"("prts")"), "parts", "\"prts\" a typo");
  refused(replaced(kGood, R"("frequency": 50)", R"("frequncy": 50)"),
          "fixtures[0].law.vibration.frequency", "missing required key");
}

TEST(SceneFileErrors, WrongTypeNamesTheValue) {
  const SceneFileError e =
      refused(replaced(kGood, R"("frequency": 50)", R"("frequency": "fifty")"),
              "fixtures[0].law.vibration.frequency", "expected a number, got \"fifty\"");
  EXPECT_EQ(std::string(e.what()),
            "bad.json: fixtures[0].law.vibration.frequency: expected a number, got \"fifty\"");
  refused(replaced(kGood, R"("size": [0.004])", R"("size": [true])"), "parts[1].size[0]",
          "expected a number or {\"mean\": ..., \"stddev\": ...}, got true");
  refused(replaced(kGood, R"("position": [0, 0, -0.01])", R"("position": [0, -0.01])"),
          "fixtures[0].geoms[0].position", "expected [x, y, z]");
  refused(replaced(kGood, R"("duration": 1)", R"("duration": {"s": 1})"), "duration",
          "expected a number, got an object");
  refused(replaced(kGood, R"("name": "track")", R"("name": 7)"), "fixtures[0].name",
          "expected a string, got 7");
  refused(R"({"parts": {}})", "parts", "expected an array");
  refused("[1, 2]", "", "expected an object, got an array");
}

TEST(SceneFileErrors, OutOfRangeValuesNameThePath) {
  refused(
      replaced(kGood, R"("size": [0.004, {"mean": 0.01}])", R"("size": [0.004, {"mean": -0.01}])"),
      "parts[2].size[1].mean", "must be > 0");
  refused(replaced(kGood, R"("size": [0.02, 0.02, 0.005])", R"("size": [0.02, -0.02, 0.005])"),
          "parts[0].size[1]", "must be > 0");
  refused(replaced(kGood, R"("size": [1, 0.1, 0.02])", R"("size": [1, 0, 0.02])"),
          "fixtures[0].geoms[0].size[1]", "must be > 0");
  refused(replaced(kGood, R"("duration": 1)", R"("duration": 1, "material": {"restitution": 2})"),
          "material.restitution", "must be in [0, 1]");
  refused(replaced(kGood, R"("duration": 1)", R"("duration": 1, "solver": {"iterations": 2.5})"),
          "solver.iterations", "expected an integer");
  refused(replaced(kGood, R"("duration": 1)", R"("duration": 1, "solver": {"iterations": 0})"),
          "solver.iterations", "must be >= 1");
  refused(replaced(kGood, R"("size": [0.004, {"mean": 0.01}])",
                   R"("size": [0.004, {"mean": 0.01, "min": 0.02, "max": 0.01}])"),
          "parts[2].size[1].max", "must be >= min (0.02)");  // from Scene::validate()
  refused(replaced(kGood, R"("spawn_max": [0, 0, 0.003])", R"("spawn_max": [0, 0, 0.001])"),
          "parts[0].spawn_max.z", "must be >= spawn_min.z (0.003)");  // Scene::validate()
  refused(replaced(kGood, R"("angle_deg": 20)", R"("angle_deg": 20, "direction": [1, 0, 0])"),
          "fixtures[0].law.vibration.direction", "not both");
  refused(replaced(kGood, R"("angle_deg": 20)", R"("angle_deg": 20, "angle_rad": 0.3)"),
          "fixtures[0].law.vibration.angle_deg", "not both");
  refused(replaced(kGood, R"("position": [0, 0, -0.01])",
                   R"("rotation": {"axis": [0, 0, 0], "angle_deg": 5})"),
          "fixtures[0].geoms[0].rotation.axis", "zero vector");
  const std::string basis =
      R"("angle_deg": 20}, "calibrated_drift": {"linear": [0.02, 0, 0]},
         "calibrated_for": {"vibration": {"amplitude": 2e-4, "frequency": 50, "angle_deg": 20},
                            "gravity": [0, 0, -9.81], "mu": 0.5, )";
  refused(replaced(kGood, R"("angle_deg": 20})", basis + R"("part_digests": ["12ab"]})"),
          "fixtures[0].law.calibrated_for.part_digests[0]", "expected 16 lowercase hex digits");
  refused(replaced(kGood, R"("angle_deg": 20})", basis + R"("part_digests": "12ab"})"),
          "fixtures[0].law.calibrated_for.part_digests", "expected an array");
  refused(replaced(kGood, R"("angle_deg": 20})",
                   basis + R"("fixture_digests": ["", "0123456789ABCDEF"]})"),
          "fixtures[0].law.calibrated_for.fixture_digests[0]", "got \"\"");
  refused(replaced(kGood, R"("angle_deg": 20})", basis + R"("restitution": 1.5})"),
          "fixtures[0].law.calibrated_for.restitution", "must be in [0, 1]");
  refused(replaced(kGood, R"("angle_deg": 20})", basis + R"("conveying_direction": [0, 0, 0]})"),
          "fixtures[0].law.calibrated_for.conveying_direction", "zero vector");
}

TEST(SceneFileErrors, OverflowingNumberIsRefusedAsNotFinite) {
  const std::string text = replaced(kGood, R"("duration": 1)", R"("duration": 1e999)");
  const SceneFileError e = refused(text, "duration", "not finite");
  const std::string before = text.substr(0, text.find("1e999"));
  EXPECT_EQ(e.line(), 1 + std::count(before.begin(), before.end(), '\n'));
  refused(replaced(kGood, R"("size": [0.004])", R"("size": [-1e999])"), "parts[1].size[0]",
          "not finite");
}

TEST(SceneFileErrors, UnknownKeyIsRefusedWithASuggestion) {
  refused(replaced(kGood, R"("duration": 1)", R"("duration": 1, "material": {"restitusion": 0.1})"),
          "material.restitusion", "did you mean \"restitution\"");
  refused(replaced(kGood, R"("size": [0.004])", R"("size": [0.004], "radius": 0.004)"),
          "parts[1].radius", "unknown key");
  refused(replaced(kGood, R"("duration": 1)", R"("duration": 1, "durration": 2)"), "durration",
          "did you mean \"duration\"");
  // A key of another shape is unknown for this one.
  refused(replaced(kGood, R"("size": [1, 0.1, 0.02])", R"("size": [1, 0.1, 0.02], "radius": 1)"),
          "fixtures[0].geoms[0].radius", "unknown key");
}

TEST(SceneFileErrors, DuplicateKeyIsRefused) {
  refused(replaced(kGood, R"("duration": 1)", R"("duration": 1, "duration": 2)"), "duration",
          "duplicate key");
  refused(replaced(kGood, R"("frequency": 50)", R"("frequency": 50, "frequency": 60)"),
          "fixtures[0].law.vibration.frequency", "duplicate key");
}

TEST(SceneFileErrors, SyntaxErrorReportsLineAndColumn) {
  const std::string text =
      "{\n  \"parts\": [\n    {\"shape\": \"box\"}\n    {\"shape\": \"box\"}\n]}";
  const SceneFileError e = refused(text, "", "syntax error");
  EXPECT_EQ(e.line(), 4);
  EXPECT_GT(e.column(), 0);
  EXPECT_EQ(std::string(e.what()).rfind("bad.json:4:", 0), 0u) << e.what();
  refused("", "", "syntax error");
  refused("{\"parts\": [] ", "", "syntax error");
}

TEST(SceneFileErrors, BadLawAndShapeNamesAreExplained) {
  refused(replaced(kGood, R"("shape": "sphere")", R"("shape": "ball")"), "parts[1].shape",
          "expected box, sphere");
  refused(replaced(kGood, R"("shape": "sphere")", R"("shape": "plane")"), "parts[1].shape",
          "cannot be a plane");
  refused(replaced(kGood, R"("law": {)", R"("law": {"drift": {}, )"), "fixtures[0].law.vibration",
          "one kind");
  refused(replaced(kGood, R"("law": {"vibration")", R"("law": {"vibrations")"), "fixtures[0].law",
          "expected one of");
  refused(
      replaced(kGood,
               R"("law": {"vibration": {"amplitude": 2e-4, "frequency": 50, "angle_deg": 20}})",
               R"("law": {"belt": {"direction": [1, 0, 0], "speed": 1}, "calibrated_drift": {}})"),
      "fixtures[0].law.calibrated_drift", "only a vibration or screw");
  refused(replaced(kGood, R"("amplitude": 2e-4, )", ""), "fixtures[0].law.vibration.amplitude",
          "needs an amplitude");  // from Scene::validate()
  refused(replaced(kGood, R"("size": [0.004])", R"("size": [0.004, 0.01])"), "parts[1].size",
          "needs an array of 1");
  refused(replaced(kGood, R"("duration": 1)", R"("duration": 1, "format_version": 2)"),
          "format_version", "reads version 1");
  refused(replaced(kGood, R"("shape": "sphere")", R"("shape": "sphere", "collision": "mesh")"),
          "parts[1].collision", "only mesh parts choose what they collide as (a sphere part");
}

TEST(SceneFileErrors, BadCollisionNameIsExplained) {
  const std::string text = R"({"parts": [{"shape": "mesh", "mesh": "nut.obj", "collision": "hull",
                                 "spawn_min": [0, 0, 1], "spawn_max": [0, 0, 1]}]})";
  refused(text, "parts[0].collision", "must be \"mesh\" or \"convex_hull\", got \"hull\"");
}

TEST(SceneFileErrors, UnknownBroadPhaseIsExplained) {
  auto withSolver = [](const std::string& solver) {
    return replaced(kGood, R"("duration": 1)", R"("duration": 1, "solver": {)" + solver + "}");
  };
  refused(withSolver(R"("broad_phase": "sap")"), "solver.broad_phase",
          "unknown broad phase \"sap\"");
  refused(withSolver(R"("broad_phase": "sweep-and-prune")"), "solver.broad_phase",
          "did you mean \"sweep_and_prune\"");
  refused(withSolver(R"("broad_phase": 2)"), "solver.broad_phase", "expected a string");
  const Scene s = parseScene(withSolver(R"("broad_phase": "hash")"), "hash.json");
  EXPECT_EQ(s.solver.broad_phase, BroadPhase::Hash);
}

// A throw angle of more than a turn is never needed: "angle_rad": 20 was meant in degrees.
TEST(SceneFileErrors, AThrowAngleBeyondOneTurnIsRefusedAsAUnitSlip) {
  const std::string angle = R"("angle_deg": 20)";
  refused(replaced(kGood, angle, R"("angle_rad": 20)"), "fixtures[0].law.vibration.angle_rad",
          "a throw angle must be within one turn, [-360, 360] degrees or [-2 pi, 2 pi] rad, got "
          "20 rad (did you mean angle_deg?)");
  refused(replaced(kGood, angle, R"("angle_deg": 400)"), "fixtures[0].law.vibration.angle_deg",
          "got 400 degrees");
  const Scene s = parseScene(replaced(kGood, angle, R"("angle_rad": 0.35)"), "rad.json");
  EXPECT_NEAR(s.fixtures[0].law.vibration.direction.z, std::sin(0.35), 1e-15);
}

TEST(SceneFileErrors, BadDriftModelAndEfficiencyAreExplained) {
  const std::string law = R"("angle_deg": 20}})";
  auto withLaw = [&](const std::string& extra) {
    return replaced(kGood, law, R"("angle_deg": 20}, )" + extra + "}");
  };
  refused(withLaw(R"("drift_model": "locale")"), "fixtures[0].law.drift_model",
          "did you mean \"local\"");
  refused(withLaw(R"("drift_model": "constant")"), "fixtures[0].law.drift_model",
          "expected local, local_sampled or calibrated_drift");
  refused(withLaw(R"("drift_model": 1)"), "fixtures[0].law.drift_model", "expected a string");
  refused(withLaw(R"("efficiency": [1, 1, 1])"), "fixtures[0].law.efficiency",
          "local_sampled only; this law's drift_model is local (the default)");
  refused(withLaw(R"("drift_model": "calibrated_drift", "efficiency": [1, 1, 1])"),
          "fixtures[0].law.efficiency", "drift_model is calibrated_drift");
  const std::string sampled = R"("drift_model": "local_sampled", "efficiency": )";
  refused(withLaw(sampled + "[1, 1]"), "fixtures[0].law.efficiency",
          "one per part family (3, in the order of parts), got an array of 2");
  refused(withLaw(sampled + "[1, 200, 1]"), "fixtures[0].law.efficiency[1]", "must be in [0, 100]");
  refused(withLaw(sampled + "[1, -0.5, 1]"), "fixtures[0].law.efficiency[1]", "must be >= 0");
  refused(withLaw(sampled + "[1, \"x\", 1]"), "fixtures[0].law.efficiency[1]", "expected a number");
  refused(withLaw(sampled + "0.8"), "fixtures[0].law.efficiency",
          "expected {\"<part family name>\": factor, ...} or an array");
  // kGood's families are all named "parts" (the default): a name cannot pick one.
  refused(withLaw(sampled + R"({"parts": 0.8})"), "fixtures[0].law.efficiency.parts",
          "parts[0] and parts[1] are both named \"parts\"");
  const std::string named =
      replaced(kGood, R"({"shape": "sphere")", R"({"name": "balls", "shape": "sphere")");
  refused(replaced(named, law, R"("angle_deg": 20}, )" + sampled + R"({"ball": 0.8}})"),
          "fixtures[0].law.efficiency.ball", "no part family is named \"ball\" (did you mean");
  refused(replaced(named, law, R"("angle_deg": 20}, )" + sampled + R"({"balls": 1e3}})"),
          "fixtures[0].law.efficiency.balls", "must be in [0, 100]");
  EXPECT_NO_THROW(parseScene(
      replaced(named, law, R"("angle_deg": 20}, )" + sampled + R"({"balls": 0.8}})"), "good.json"));
  refused(
      replaced(kGood,
               R"("law": {"vibration": {"amplitude": 2e-4, "frequency": 50, "angle_deg": 20}})",
               R"("law": {"belt": {"direction": [1, 0, 0], "speed": 1}, "drift_model": "local"})"),
      "fixtures[0].law.drift_model", "only a vibration or screw law");
}

TEST(SceneFileErrors, PlaneTakesNoPose) {
  refused(replaced(kGood, R"({"shape": "box", "size": [1, 0.1, 0.02], "position": [0, 0, -0.01]})",
                   R"({"shape": "plane", "normal": [0, 0, 1], "position": [0, 0, 0]})"),
          "fixtures[0].geoms[0].position", "unknown key");
}

TEST(SceneFileErrors, MeshProblemsNameTheGeomAndTheFile) {
  const std::string text = R"({
    "fixtures": [{"geoms": [{"shape": "mesh", "mesh": "garbage.stl"}]}],
    "parts": [{"shape": "mesh", "mesh": "box_open.obj",
               "spawn_min": [0, 0, 1], "spawn_max": [0, 0, 1]}]
  })";
  const std::string source = (kData / "scene.json").string();
  try {
    parseScene(text, source);
    ADD_FAILURE() << "accepted";
  } catch (const SceneFileError& e) {
    EXPECT_EQ(e.path(), "fixtures[0].geoms[0].mesh");
    EXPECT_NE(e.problem().find("garbage.stl"), std::string::npos) << e.what();
  }
  try {
    parseScene(replaced(text, "garbage.stl", "box_20x30x40mm.stl"), source);
    ADD_FAILURE() << "accepted";
  } catch (const SceneFileError& e) {
    EXPECT_EQ(e.path(), "parts[0].mesh");
    EXPECT_NE(e.problem().find("not closed"), std::string::npos) << e.what();
  }
  try {
    parseScene(replaced(text, "garbage.stl", "missing.stl"), source);
    ADD_FAILURE() << "accepted";
  } catch (const SceneFileError& e) {
    EXPECT_NE(e.problem().find("file not found"), std::string::npos) << e.what();
  }
}

TEST(SceneFileErrors, UnreadableFileIsRefusedWithItsName) {
  try {
    loadScene(kData / "no_such_scene.json");
    ADD_FAILURE() << "accepted";
  } catch (const SceneFileError& e) {
    EXPECT_NE(std::string(e.what()).find("no_such_scene.json"), std::string::npos);
    EXPECT_NE(e.problem().find("file not found"), std::string::npos);
  }
}

TEST(SceneFile, LoadSceneReadsAFile) {
  const fs::path file = fs::path(testing::TempDir()) / "rheofeed_io_load_scene.json";
  std::ofstream(file) << kGood;
  const Scene s = loadScene(file);
  EXPECT_EQ(s.fixtures[0].name, "track");
  EXPECT_EQ(s.parts.size(), 3u);
  // The scene knows its file (a run's JSON names it as scene_source); from text it has none.
  EXPECT_EQ(s.source_file, fs::absolute(file).lexically_normal().string());
  EXPECT_EQ(parseScene(kGood, "text.json").source_file, "");
  fs::remove(file);
}

}  // namespace
}  // namespace rheofeed::scene

// SPDX-License-Identifier: MIT
// Mesh geoms in running simulations (geom_factory.cpp builds ODE trimeshes; drawParts takes mesh
// parts' mass from the mesh): parts rest at the analytic height on mesh floors and mesh parts
// rest on floors, in ODE and in the reference solver; a vibrating mesh fixture runs in all four
// methods; every demo scene file loads and runs.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <string>
#include <vector>

#include "rheofeed/scene/mesh.hpp"
#include "rheofeed/scene/scene_io.hpp"
#include "rheofeed/simulation/simulation.hpp"

namespace rheofeed::scene {
namespace {

namespace fs = std::filesystem;

const fs::path kData = RHEOFEED_IO_TEST_DATA;
const fs::path kDemoScenes = fs::path(RHEOFEED_DEMO_DIR) / "scenes";

// Resting height: the ERP/CFM softness (cfm 1e-5 with these sub-newton weights) and the float
// coordinates of the mesh files (~1e-8 m) leave ~1e-7 m in both engines; 1e-5 m would still
// catch a part resting on the wrong face, a wrong centre of mass or a mesh offset.
constexpr double kRestHeight = 1e-5;
// A resting part has essentially no velocity left (~1e-6 m/s observed).
constexpr double kRestSpeed = 1e-3;

// Parses `json` as if it were a file in tests/io/data (relative mesh paths resolve there).
Scene sceneOf(const std::string& json) {
  return parseScene(json, (kData / "test.json").string());
}

PartState runFor(const Scene& scene, Method method, double seconds) {
  const auto sim = makeSimulation(scene, method);
  const int steps = static_cast<int>(std::lround(seconds / scene.solver.time_step));
  for (int i = 0; i < steps; ++i) sim->step();
  EXPECT_EQ(sim->numParts(), 1);
  return sim->part(0);
}

const Method kRheonomic[] = {Method::OdeRheonomic, Method::ReferenceRheonomic};

TEST(MeshGeoms, SphereRestsOnAMeshFloorAtItsRadius) {
  const Scene scene = sceneOf(R"({
    "fixtures": [{"name": "floor", "geoms": [{"shape": "mesh", "mesh": "floor_slab.obj"}]}],
    "parts": [{"shape": "sphere", "size": [0.01],
               "spawn_min": [0.1, 0.05, 0.0102], "spawn_max": [0.1, 0.05, 0.0102]}],
    "solver": {"time_step": 0.002}
  })");
  for (Method m : kRheonomic) {
    const PartState s = runFor(scene, m, 0.5);
    EXPECT_NEAR(s.position.z, 0.01, kRestHeight) << toString(m);
    EXPECT_NEAR(s.position.x, 0.1, kRestHeight) << toString(m);
    EXPECT_LT(norm(s.velocity), kRestSpeed) << toString(m);
  }
}

// The 2 x 3 x 4 cm box mesh, re-centred on its centre of mass, stands on its 2 x 3 face: its
// centre rests 2 cm above the floor, on a box floor and on a mesh floor (trimesh-trimesh).
TEST(MeshGeoms, MeshPartRestsAtHalfItsHeight) {
  const std::string part = R"(
    "parts": [{"shape": "mesh", "mesh": "box_20x30x40mm.obj", "density": 2700,
               "spawn_min": [0, 0, 0.0202], "spawn_max": [0, 0, 0.0202]}],
    "solver": {"time_step": 0.002})";
  const Scene on_box = sceneOf(R"({"fixtures": [{"geoms": [{"shape": "box",
      "size": [1, 1, 0.05], "position": [0, 0, -0.025]}]}],)" +
                               part + "}");
  const Scene on_mesh = sceneOf(
      R"({"fixtures": [{"geoms": [{"shape": "mesh", "mesh": "floor_slab.obj"}]}],)" + part + "}");
  for (const Scene* scene : {&on_box, &on_mesh}) {
    for (Method m : kRheonomic) {
      const PartState s = runFor(*scene, m, 0.5);
      EXPECT_NEAR(s.position.z, 0.02, kRestHeight) << toString(m);
      EXPECT_NEAR(s.rotation[8], 1.0, 1e-6) << toString(m) << ": still upright";
      EXPECT_LT(norm(s.velocity), kRestSpeed) << toString(m);
    }
  }
}

// A drift law on a mesh fixture drives parts like on any geom (mu g = 4.9 m/s^2: the part
// reaches the 0.1 m/s surface speed within 0.03 s).
TEST(MeshGeoms, DriftOnAMeshFixtureCarriesThePart) {
  const Scene scene = sceneOf(R"({
    "fixtures": [{"geoms": [{"shape": "mesh", "mesh": "floor_slab.obj"}],
                  "law": {"drift": {"linear": [0.1, 0, 0]}}}],
    "parts": [{"shape": "mesh", "mesh": "box_20x30x40mm.obj", "density": 2700,
               "spawn_min": [0, 0, 0.0201], "spawn_max": [0, 0, 0.0201]}],
    "material": {"mu": 0.5},
    "solver": {"time_step": 0.002}
  })");
  for (Method m : kRheonomic) {
    const PartState s = runFor(scene, m, 0.3);
    EXPECT_NEAR(s.velocity.x, 0.1, 5e-3) << toString(m);
    EXPECT_GT(s.position.x, 0.02) << toString(m);
  }
}

// Mass from the mesh: density * volume * scale^3 and inertia * scale^5 (scale = size[0]).
TEST(MeshGeoms, MeshPartMassAndInertiaScaleWithTheDrawnSize) {
  const Scene scene = sceneOf(R"({
    "parts": [{"shape": "mesh", "mesh": "box_20x30x40mm.obj", "size": [0.5], "density": 1000,
               "spawn_min": [0, 0, 1], "spawn_max": [0, 0, 1]}]
  })");
  const std::vector<PartInstance> parts = drawParts(scene);
  ASSERT_EQ(parts.size(), 1u);
  const double a = 0.01, b = 0.015, c = 0.02, mass = 1000 * a * b * c;  // edges halved
  const double rel = 2e-5;  // float coordinates in the file (mesh_test.cpp)
  EXPECT_NEAR(parts[0].mass, mass, rel * mass);
  EXPECT_NEAR(parts[0].inertia[0], mass / 12 * (b * b + c * c), rel * mass * b * b);
  EXPECT_NEAR(parts[0].inertia[8], mass / 12 * (a * a + b * b), rel * mass * b * b);
  ASSERT_TRUE(parts[0].shape.mesh_data);
  EXPECT_NEAR(boundingRadius(*parts[0].shape.mesh_data), 0.5 * std::sqrt(a * a + b * b + c * c),
              1e-8);
}

TEST(MeshGeoms, VibratingMeshFixtureRunsInAllFourMethods) {
  const Scene scene = sceneOf(R"({
    "fixtures": [{"geoms": [{"shape": "mesh", "mesh": "floor_slab.obj"}],
                  "law": {"vibration": {"amplitude": 2e-4, "frequency": 50, "angle_deg": 20},
                          "calibrated_drift": {"linear": [0.05, 0, 0]}}}],
    "parts": [{"shape": "mesh", "mesh": "box_20x30x40mm.obj", "density": 2700,
               "spawn_min": [0, 0, 0.0201], "spawn_max": [0, 0, 0.0201]}],
    "solver": {"time_step": 0.0005}
  })");
  for (Method m : {Method::OdeRheonomic, Method::OdeFullVibration, Method::ReferenceRheonomic,
                   Method::ReferenceFullVibration}) {
    const PartState s = runFor(scene, m, 0.05);
    EXPECT_TRUE(isFinite(s.position)) << toString(m);
    EXPECT_NEAR(s.position.z, 0.02, 2e-3) << toString(m) << ": on the floor, not through it";
  }
}

TEST(DemoScenes, EveryDemoSceneLoadsAndRuns) {
  int files = 0;
  for (const fs::directory_entry& entry : fs::directory_iterator(kDemoScenes)) {
    if (entry.path().extension() != ".json") continue;
    ++files;
    SCOPED_TRACE(entry.path().filename().string());
    Scene scene;
    ASSERT_NO_THROW(scene = loadScene(entry.path()));
    for (Method m : kRheonomic) {
      const auto sim = makeSimulation(scene, m);
      for (int i = 0; i < 3; ++i) sim->step();
      EXPECT_GT(sim->numParts(), 0);
    }
    EXPECT_NO_THROW(parseScene(toJson(scene), entry.path().string()));  // round trip
  }
  EXPECT_GE(files, 3);
}

}  // namespace
}  // namespace rheofeed::scene

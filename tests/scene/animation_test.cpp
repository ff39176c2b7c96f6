// SPDX-License-Identifier: MIT
// The animation file (animation.hpp) read back with tinygltf, an independent glTF reader: its
// nodes are the fixtures and the parts, its animation lasts the simulated time, a part's animated
// pose is the one the simulation reported at each sample, the vibrating feeder moves by the
// analytic vibration law, and every accessor carries the bounds the glTF spec asks for.
#include <gtest/gtest.h>
#include <tiny_gltf.h>
#include <unistd.h>

#include <algorithm>
#include <cfloat>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "rheofeed/measure/metrics.hpp"
#include "rheofeed/output/animation.hpp"
#include "rheofeed/simulation/simulation.hpp"
#include "scene_builders.hpp"

namespace rheofeed::scene {
namespace {

namespace fs = std::filesystem;

// glTF stores 32-bit floats: a value x (m, s or a quaternion component) comes back within half
// an ulp, |x| 2^-24 <= |x| FLT_EPSILON / 2; we allow FLT_EPSILON times max(1, |x|).
double floatTolerance(double x) {
  return FLT_EPSILON * std::max(1.0, std::abs(x));
}
// A unit quaternion written as floats has |q| within 4 components x half an ulp of 1.
constexpr double kUnitQuaternionTolerance = 4 * FLT_EPSILON;

constexpr double kStep = 1e-3;       // s
constexpr double kSample = 0.01;     // s: ten steps per sample
constexpr double kDuration = 0.205;  // s: not a whole number of samples (the end is recorded too)
constexpr double kAmplitude = 0.5e-3, kFrequency = 50;  // m, Hz
const Vec3 kDirection{std::cos(kPi / 6), 0, std::sin(kPi / 6)};

// A vibrating plate (box and a cylinder rail and a capsule post) over a plane, two families of
// parts on it (cubes at t = 0, spheres at 20 per second) and a sphere that falls past the
// removal height beside the plate.
Scene testScene() {
  Scene s;
  s.name = "animation test";
  Fixture plate =
      test::vibratingBox("plate", {0.3, 0.1, 0.01}, {0, 0, 0}, kAmplitude, kFrequency, kDirection);
  Fixture::Geom g;
  g.shape.kind = Shape::Kind::Cylinder;
  g.shape.radius = 0.005;
  g.shape.length = 0.3;
  g.pose = Pose::axisAngle({0, 1, 0}, kPi / 2, {0, 0.055, 0.005});
  plate.geoms.push_back(g);
  g.shape.kind = Shape::Kind::Capsule;
  g.shape.length = 0.02;
  g.pose = Pose{};
  g.pose.position = {0.14, -0.055, 0.015};
  plate.geoms.push_back(g);
  s.fixtures.push_back(plate);
  Fixture ground;
  ground.name = "ground";
  g.shape.kind = Shape::Kind::Plane;
  g.shape.plane_normal = {0, 0, 1};
  g.shape.plane_offset = -0.3;
  ground.geoms.push_back(g);
  s.fixtures.push_back(ground);

  PartSpec cubes;
  cubes.name = "cubes";
  cubes.shape = Shape::Kind::Box;
  for (auto& d : cubes.size) d.mean = 0.01;
  cubes.density = 1000;
  cubes.count = 2;
  cubes.spawn_min = {-0.1, -0.03, 0.006};
  cubes.spawn_max = {0.1, 0.03, 0.006};
  cubes.random_orientation = false;
  s.parts.push_back(cubes);
  PartSpec balls;
  balls.name = "balls";
  balls.shape = Shape::Kind::Sphere;
  balls.size[0].mean = 0.006;
  balls.density = 1000;
  balls.count = 3;
  balls.rate = 20;  // spawns at 0, 0.05 and 0.1 s
  balls.spawn_min = {-0.05, 0, 0.02};
  balls.spawn_max = {-0.05, 0, 0.02};
  s.parts.push_back(balls);
  PartSpec dropped;
  dropped.name = "dropped";
  dropped.shape = Shape::Kind::Sphere;
  dropped.size[0].mean = 0.005;
  dropped.density = 1000;
  dropped.spawn_min = dropped.spawn_max = {0.3, 0.2, 0.05};
  s.parts.push_back(dropped);
  s.removal_height = -0.02;  // the dropped sphere passes it at sqrt(2 0.07 / g) = 0.12 s
  s.solver.time_step = kStep;
  s.duration = kDuration;
  s.outputs.sample_interval = kSample;
  return s;
}

// Floats of an accessor (tightly packed, as the writer lays them out).
std::vector<float> floats(const tinygltf::Model& m, int accessor) {
  const tinygltf::Accessor& a = m.accessors.at(static_cast<std::size_t>(accessor));
  EXPECT_EQ(a.componentType, TINYGLTF_COMPONENT_TYPE_FLOAT);
  const tinygltf::BufferView& v = m.bufferViews.at(static_cast<std::size_t>(a.bufferView));
  const std::size_t n =
      a.count * static_cast<std::size_t>(tinygltf::GetNumComponentsInType(a.type));
  std::vector<float> out(n);
  const unsigned char* p = m.buffers.at(0).data.data() + v.byteOffset + a.byteOffset;
  std::memcpy(out.data(), p, n * sizeof(float));
  return out;
}

// The sampler output accessor animating `path` of node `node`, or -1.
int channelOutput(const tinygltf::Model& m, int node, const std::string& path,
                  int* input = nullptr) {
  const tinygltf::Animation& a = m.animations.at(0);
  for (const tinygltf::AnimationChannel& c : a.channels) {
    if (c.target_node == node && c.target_path == path) {
      const tinygltf::AnimationSampler& s = a.samplers.at(static_cast<std::size_t>(c.sampler));
      if (input) *input = s.input;
      return s.output;
    }
  }
  return -1;
}

// A run recorded at every sample, with the states the simulation reported, written and read back.
struct RecordedRun {
  Scene scene = testScene();
  Method method = Method::OdeFullVibration;
  std::vector<double> times;                   // s
  std::vector<std::vector<PartState>> states;  // per sample, per spawned part
  double simulated = 0;                        // s
  AnimationRecorder recorder{scene, method};
  tinygltf::Model model;
  std::string error, warning;
  bool loaded = false;

  RecordedRun() {
    std::unique_ptr<Simulation> sim = makeSimulation(scene, method);
    auto take = [&] {
      recorder.record(*sim);
      times.push_back(sim->time());
      states.emplace_back();
      for (int i = 0; i < sim->numParts(); ++i) states.back().push_back(sim->part(i));
    };
    take();
    const long steps = std::lround(kDuration / kStep), every = std::lround(kSample / kStep);
    for (long k = 1; k <= steps; ++k) {
      sim->step();
      if (k % every == 0 || k == steps) take();
    }
    simulated = sim->time();
    const fs::path dir =
        fs::temp_directory_path() / ("rheofeed_animation_" + std::to_string(getpid()));
    const fs::path file = dir / "run.glb";
    recorder.write(file);
    tinygltf::TinyGLTF gltf;
    loaded = gltf.LoadBinaryFromFile(&model, &error, &warning, file.string());
    fs::remove_all(dir);
  }
};

const RecordedRun& run() {
  static const RecordedRun recorded;
  return recorded;
}

int nodeNamed(const tinygltf::Model& m, const std::string& name) {
  for (std::size_t n = 0; n < m.nodes.size(); ++n) {
    if (m.nodes[n].name == name) return static_cast<int>(n);
  }
  return -1;
}

TEST(Animation, FileLoadsInTinygltf) {
  const RecordedRun& r = run();
  ASSERT_TRUE(r.loaded) << r.error;
  EXPECT_EQ(r.model.asset.version, "2.0");
  ASSERT_EQ(r.model.animations.size(), 1u);
  ASSERT_EQ(r.model.scenes.size(), 1u);
}

TEST(Animation, OneNodePerFixtureAndPartUnderTheRoot) {
  const RecordedRun& r = run();
  ASSERT_TRUE(r.loaded) << r.error;
  const int parts = static_cast<int>(r.states.back().size());
  ASSERT_EQ(parts, 6);  // 2 cubes, 3 balls, 1 dropped: all spawned by 0.1 s
  EXPECT_EQ(r.model.nodes.size(), 1u + r.scene.fixtures.size() + parts);
  const tinygltf::Node& root = r.model.nodes.at(0);
  EXPECT_EQ(root.name, "rheofeed_world");
  EXPECT_EQ(root.children.size(), r.scene.fixtures.size() + parts);
  // Spawn order (drawParts: by spawn time, then family): the cubes, the first ball and the
  // dropped sphere at t = 0, the balls due at 0.05 and 0.1 s.
  const std::vector<std::string> expected = {"plate",        "ground",       "part_0_cubes",
                                             "part_1_cubes", "part_2_balls", "part_3_dropped",
                                             "part_4_balls", "part_5_balls"};
  std::vector<std::string> names;
  for (int child : root.children) names.push_back(r.model.nodes.at(child).name);
  EXPECT_EQ(names, expected);
  EXPECT_EQ(r.recorder.nodeNames(), expected);
}

TEST(Animation, RootTurnsZUpToGltfYUp) {
  const RecordedRun& r = run();
  ASSERT_TRUE(r.loaded) << r.error;
  // Rotation of -90 degrees about x: (sin(-pi/4), 0, 0, cos(pi/4)) maps +z onto +y.
  const std::vector<double>& q = r.model.nodes.at(0).rotation;
  ASSERT_EQ(q.size(), 4u);
  EXPECT_NEAR(q[0], -std::sqrt(0.5), 1e-12);
  EXPECT_NEAR(q[1], 0, 1e-12);
  EXPECT_NEAR(q[2], 0, 1e-12);
  EXPECT_NEAR(q[3], std::sqrt(0.5), 1e-12);
}

TEST(Animation, DurationIsTheSimulatedTime) {
  const RecordedRun& r = run();
  ASSERT_TRUE(r.loaded) << r.error;
  EXPECT_NEAR(r.simulated, kDuration, kStep / 2);  // the run's own duration, as a check
  double end = 0;
  for (const tinygltf::AnimationSampler& s : r.model.animations[0].samplers) {
    const std::vector<float> t = floats(r.model, s.input);
    ASSERT_FALSE(t.empty());
    for (std::size_t k = 1; k < t.size(); ++k) ASSERT_LT(t[k - 1], t[k]);  // strictly increasing
    end = std::max(end, double(t.back()));
  }
  EXPECT_NEAR(end, r.simulated, floatTolerance(r.simulated));
  EXPECT_DOUBLE_EQ(r.recorder.duration(), r.simulated);
  // 20 whole samples, t = 0 and the end at 0.205 s.
  EXPECT_EQ(r.recorder.samples(), 22);
}

TEST(Animation, PartPosesAreTheSimulatedOnesAtEverySample) {
  const RecordedRun& r = run();
  ASSERT_TRUE(r.loaded) << r.error;
  const std::size_t fixtures = r.scene.fixtures.size();
  for (std::size_t i = 0; i < r.states.back().size(); ++i) {
    const int node = r.model.nodes[0].children.at(fixtures + i);
    int input = -1;
    const int out_t = channelOutput(r.model, node, "translation", &input);
    const int out_r = channelOutput(r.model, node, "rotation");
    ASSERT_GE(out_t, 0);
    ASSERT_GE(out_r, 0);
    const std::vector<float> times = floats(r.model, input);
    const std::vector<float> x = floats(r.model, out_t), q = floats(r.model, out_r);
    ASSERT_EQ(times.size(), r.times.size());
    ASSERT_EQ(x.size(), 3 * times.size());
    ASSERT_EQ(q.size(), 4 * times.size());
    for (std::size_t k = 0; k < times.size(); ++k) {
      EXPECT_NEAR(times[k], r.times[k], floatTolerance(r.times[k]));
      if (i >= r.states[k].size()) continue;  // not spawned yet
      const PartState& s = r.states[k][i];
      const double want[3] = {s.position.x, s.position.y, s.position.z};
      for (int c = 0; c < 3; ++c) {
        EXPECT_NEAR(x[3 * k + c], want[c], floatTolerance(want[c]))
            << "part " << i << " t " << times[k];
      }
      // The rotation matrix of the quaternion (the textbook formula) is the simulated one.
      const double qx = q[4 * k], qy = q[4 * k + 1], qz = q[4 * k + 2], qw = q[4 * k + 3];
      const double m[9] = {
          1 - 2 * (qy * qy + qz * qz), 2 * (qx * qy - qz * qw),     2 * (qx * qz + qy * qw),
          2 * (qx * qy + qz * qw),     1 - 2 * (qx * qx + qz * qz), 2 * (qy * qz - qx * qw),
          2 * (qx * qz - qy * qw),     2 * (qy * qz + qx * qw),     1 - 2 * (qx * qx + qy * qy)};
      for (int c = 0; c < 9; ++c) {
        EXPECT_NEAR(m[c], s.rotation[c], 4 * kUnitQuaternionTolerance)
            << "part " << i << " entry " << c;
      }
    }
  }
}

TEST(Animation, QuaternionsAreUnit) {
  const RecordedRun& r = run();
  ASSERT_TRUE(r.loaded) << r.error;
  int checked = 0;
  for (const tinygltf::AnimationChannel& c : r.model.animations[0].channels) {
    if (c.target_path != "rotation") continue;
    const std::vector<float> q = floats(r.model, r.model.animations[0].samplers[c.sampler].output);
    for (std::size_t k = 0; k + 3 < q.size(); k += 4) {
      const double n = std::sqrt(double(q[k]) * q[k] + double(q[k + 1]) * q[k + 1] +
                                 double(q[k + 2]) * q[k + 2] + double(q[k + 3]) * q[k + 3]);
      EXPECT_NEAR(n, 1.0, kUnitQuaternionTolerance);
      ++checked;
    }
  }
  EXPECT_GT(checked, 0);
}

TEST(Animation, EveryAccessorHasMinAndMaxThatBoundItsValues) {
  const RecordedRun& r = run();
  ASSERT_TRUE(r.loaded) << r.error;
  for (std::size_t a = 0; a < r.model.accessors.size(); ++a) {
    const tinygltf::Accessor& acc = r.model.accessors[a];
    const std::size_t n = static_cast<std::size_t>(tinygltf::GetNumComponentsInType(acc.type));
    ASSERT_EQ(acc.minValues.size(), n) << "accessor " << a;
    ASSERT_EQ(acc.maxValues.size(), n) << "accessor " << a;
    if (acc.componentType != TINYGLTF_COMPONENT_TYPE_FLOAT) continue;
    const std::vector<float> v = floats(r.model, static_cast<int>(a));
    for (std::size_t k = 0; k < v.size(); ++k) {
      EXPECT_GE(v[k], acc.minValues[k % n]) << "accessor " << a;
      EXPECT_LE(v[k], acc.maxValues[k % n]) << "accessor " << a;
    }
  }
}

TEST(Animation, CubeMeshSpansItsEdgesAboutItsCentre) {
  const RecordedRun& r = run();
  ASSERT_TRUE(r.loaded) << r.error;
  const int node = nodeNamed(r.model, "part_0_cubes");
  ASSERT_GE(node, 0);
  const tinygltf::Primitive& p = r.model.meshes.at(r.model.nodes[node].mesh).primitives.at(0);
  const tinygltf::Accessor& pos = r.model.accessors.at(p.attributes.at("POSITION"));
  for (int c = 0; c < 3; ++c) {  // the scene's 10 mm cube about its centre of mass
    EXPECT_NEAR(pos.minValues[c], -0.005, floatTolerance(0.005));
    EXPECT_NEAR(pos.maxValues[c], 0.005, floatTolerance(0.005));
  }
}

// The plate moves by x(t) = A sin(2 pi f t) d, the law of the scene (scene.hpp).
TEST(Animation, VibratingFixtureFollowsTheVibrationLaw) {
  const RecordedRun& r = run();
  ASSERT_TRUE(r.loaded) << r.error;
  const int plate = nodeNamed(r.model, "plate");
  int input = -1;
  const int out = channelOutput(r.model, plate, "translation", &input);
  ASSERT_GE(out, 0);
  const std::vector<float> t = floats(r.model, input), x = floats(r.model, out);
  ASSERT_EQ(x.size(), 3 * t.size());
  for (std::size_t k = 0; k < t.size(); ++k) {
    const double s = kAmplitude * std::sin(2 * kPi * kFrequency * r.times[k]);
    EXPECT_NEAR(x[3 * k], s * kDirection.x, floatTolerance(0) * kAmplitude);
    EXPECT_NEAR(x[3 * k + 1], 0, floatTolerance(0) * kAmplitude);
    EXPECT_NEAR(x[3 * k + 2], s * kDirection.z, floatTolerance(0) * kAmplitude);
  }
  // The ground is not a feeder: not animated.
  EXPECT_LT(channelOutput(r.model, nodeNamed(r.model, "ground"), "translation"), 0);
}

// Scale 0 until the first sample at which a part exists, 1 while it is in, 0 once removed.
TEST(Animation, PartsShowFromTheirSpawnUntilTheirRemoval) {
  const RecordedRun& r = run();
  ASSERT_TRUE(r.loaded) << r.error;
  auto scaleKeys = [&](const std::string& name, std::vector<float>& keys) {
    int input = -1;
    const int out = channelOutput(r.model, nodeNamed(r.model, name), "scale", &input);
    EXPECT_GE(out, 0);
    keys = floats(r.model, input);
    std::vector<float> s = floats(r.model, out), first;
    for (std::size_t k = 0; k < s.size(); k += 3) first.push_back(s[k]);
    return first;
  };
  std::vector<float> keys;
  // A cube spawned at t = 0 and never removed: shown from the start.
  EXPECT_EQ(scaleKeys("part_0_cubes", keys), std::vector<float>({1}));
  EXPECT_EQ(keys, std::vector<float>({0}));
  // The third ball is due at 0.1 s: it shows from the first sample at which it exists, the
  // one at 0.1 s or the next (0.11 s), depending on whether the step ending at 0.1 s spawns it.
  EXPECT_EQ(scaleKeys("part_5_balls", keys), std::vector<float>({0, 1}));
  ASSERT_EQ(keys.size(), 2u);
  EXPECT_GE(keys[1], 0.1 - floatTolerance(0.1));
  EXPECT_LE(keys[1], 0.1 + kSample + floatTolerance(0.1));
  // The dropped sphere: shown, then hidden at the first sample after it passed the removal
  // height. Semi-implicit Euler from rest: z_n = z_0 - g h^2 n (n + 1) / 2 passes 0.07 m below
  // z_0 at step n = 119 (t = 0.119 s), so the sample at 0.12 s is the first without it.
  EXPECT_EQ(scaleKeys("part_3_dropped", keys), std::vector<float>({1, 0}));
  ASSERT_EQ(keys.size(), 2u);
  EXPECT_NEAR(keys[1], 0.12, floatTolerance(0.12));
}

TEST(Animation, MeasureRunRecordsEverySampleAndTheEnd) {
  Scene s = testScene();
  AnimationRecorder recorder(s, Method::OdeFullVibration);
  const RunMetrics m = measureRun(s, Method::OdeFullVibration, {}, {&recorder});
  EXPECT_EQ(recorder.samples(), static_cast<int>(m.series.size()) + 2);  // t = 0 and the end
  EXPECT_DOUBLE_EQ(recorder.duration(), m.simulated_seconds);
  EXPECT_EQ(static_cast<int>(recorder.nodeNames().size()), 2 + m.parts);
}

TEST(Animation, WriteBeforeRecordingIsRefused) {
  AnimationRecorder recorder(testScene(), Method::OdeRheonomic);
  EXPECT_THROW(recorder.write(fs::temp_directory_path() / "never.glb"), std::logic_error);
}

}  // namespace
}  // namespace rheofeed::scene

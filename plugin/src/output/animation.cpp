// SPDX-License-Identifier: MIT
// The glTF 2.0 binary writer of animation.hpp (tinygltf builds the JSON and the GLB container).
//
// Layout of the file: one buffer; per node mesh positions, normals (FLOAT VEC3, ARRAY_BUFFER)
// and indices (UNSIGNED_INT, ELEMENT_ARRAY_BUFFER); the animation's shared input (the recorded
// times, FLOAT SCALAR) and per node outputs (translation VEC3, rotation VEC4, scale VEC3). Every
// accessor carries min and max (the spec requires them for POSITION and sampler inputs).
#include "rheofeed/output/animation.hpp"

#include <tiny_gltf.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <sstream>
#include <stdexcept>

#include "rheofeed/output/output.hpp"

namespace rheofeed::scene {
namespace {

// Tessellation of round shapes: segments around the axis and rings from pole to pole. 24 x 12
// keeps a sphere's silhouette within 1 - cos(pi / 24) = 0.9 % of its radius.
constexpr int kSegments = 24;
constexpr int kRings = 12;

// Triangles of one node (its mesh's frame), with per-vertex normals.
struct Geometry {
  std::vector<float> positions, normals;  // x, y, z per vertex (m; unit)
  std::vector<std::uint32_t> indices;     // three per triangle, counter-clockwise outside

  std::uint32_t vertex(const Pose& pose, const Vec3& p, const Vec3& n) {
    const Vec3 x = pose.transform(p), m = pose.rotate(n);
    positions.insert(positions.end(), {float(x.x), float(x.y), float(x.z)});
    normals.insert(normals.end(), {float(m.x), float(m.y), float(m.z)});
    return static_cast<std::uint32_t>(positions.size() / 3 - 1);
  }
  void triangle(std::uint32_t a, std::uint32_t b, std::uint32_t c) {
    indices.insert(indices.end(), {a, b, c});
  }
  void quad(std::uint32_t a, std::uint32_t b, std::uint32_t c, std::uint32_t d) {
    triangle(a, b, c);
    triangle(a, c, d);
  }
};

Vec3 unit(const Vec3& v) {
  const double n = norm(v);
  return n > 0 ? (1.0 / n) * v : Vec3{0, 0, 1};
}

// Two unit vectors that complete the unit n to a right-handed frame (e1, e2, n).
void completeFrame(const Vec3& n, Vec3& e1, Vec3& e2) {
  e1 = unit(tangentialPart(std::abs(n.x) < 0.9 ? Vec3{1, 0, 0} : Vec3{0, 1, 0}, n));
  e2 = cross(n, e1);
}

void addBox(Geometry& g, const Pose& pose, const Vec3& size) {
  const Vec3 h = 0.5 * size;
  const Vec3 axes[3] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
  for (int a = 0; a < 3; ++a) {
    for (double sign : {-1.0, 1.0}) {
      const Vec3 n = sign * axes[a];
      const Vec3 u = axes[(a + 1) % 3], v = sign * axes[(a + 2) % 3];  // u x v = n
      const double hn = a == 0 ? h.x : a == 1 ? h.y : h.z;
      const double hu = a == 0 ? h.y : a == 1 ? h.z : h.x;
      const double hv = a == 0 ? h.z : a == 1 ? h.x : h.y;
      const Vec3 c = hn * n;
      const std::uint32_t i0 = g.vertex(pose, c - hu * u - hv * v, n);
      const std::uint32_t i1 = g.vertex(pose, c + hu * u - hv * v, n);
      const std::uint32_t i2 = g.vertex(pose, c + hu * u + hv * v, n);
      const std::uint32_t i3 = g.vertex(pose, c - hu * u + hv * v, n);
      g.quad(i0, i1, i2, i3);
    }
  }
}

// A sphere of radius r centred at z = z0 (body frame), or its upper (part = 1) or lower
// (part = -1) half for capsules.
void addSphere(Geometry& g, const Pose& pose, double r, double z0 = 0, int part = 0) {
  const int first_ring = part == 1 ? kRings / 2 : 0, last_ring = part == -1 ? kRings / 2 : kRings;
  std::vector<std::uint32_t> previous;
  for (int k = first_ring; k <= last_ring; ++k) {
    const double theta = kPi * k / kRings - kPi / 2;  // latitude, -pi/2 (bottom) to pi/2
    std::vector<std::uint32_t> ring;
    for (int s = 0; s <= kSegments; ++s) {
      const double phi = 2 * kPi * s / kSegments;
      const Vec3 n{std::cos(theta) * std::cos(phi), std::cos(theta) * std::sin(phi),
                   std::sin(theta)};
      ring.push_back(g.vertex(pose, r * n + Vec3{0, 0, z0}, n));
    }
    if (!previous.empty()) {
      for (int s = 0; s < kSegments; ++s)
        g.quad(previous[s], previous[s + 1], ring[s + 1], ring[s]);
    }
    previous = ring;
  }
}

// The side of a cylinder of radius r from z = -l/2 to l/2 (body frame), with flat caps if asked.
void addCylinder(Geometry& g, const Pose& pose, double r, double l, bool caps) {
  std::uint32_t bottom = 0, top = 0;
  for (int s = 0; s <= kSegments; ++s) {
    const double phi = 2 * kPi * s / kSegments;
    const Vec3 n{std::cos(phi), std::sin(phi), 0};
    const std::uint32_t b = g.vertex(pose, r * n + Vec3{0, 0, -l / 2}, n);
    const std::uint32_t t = g.vertex(pose, r * n + Vec3{0, 0, l / 2}, n);
    if (s > 0) g.quad(bottom, b, t, top);
    bottom = b;
    top = t;
  }
  if (!caps) return;
  for (double sign : {-1.0, 1.0}) {
    const Vec3 n{0, 0, sign};
    const std::uint32_t centre = g.vertex(pose, Vec3{0, 0, sign * l / 2}, n);
    std::uint32_t last = 0;
    for (int s = 0; s <= kSegments; ++s) {
      const double phi = 2 * kPi * s / kSegments;
      const std::uint32_t v =
          g.vertex(pose, Vec3{r * std::cos(phi), r * std::sin(phi), sign * l / 2}, n);
      if (s > 0) {
        if (sign > 0) {
          g.triangle(centre, last, v);
        } else {
          g.triangle(centre, v, last);
        }
      }
      last = v;
    }
  }
}

// A triangle mesh, flat shaded (each triangle its own three vertices and its face normal).
void addMesh(Geometry& g, const Pose& pose, const TriangleMesh& mesh) {
  const auto& v = mesh.vertices;
  for (std::size_t t = 0; t + 2 < mesh.triangles.size(); t += 3) {
    Vec3 p[3];
    for (int k = 0; k < 3; ++k) {
      const std::size_t i = 3 * static_cast<std::size_t>(mesh.triangles[t + k]);
      p[k] = {v[i], v[i + 1], v[i + 2]};
    }
    const Vec3 n = unit(cross(p[1] - p[0], p[2] - p[0]));
    const std::uint32_t a = g.vertex(pose, p[0], n), b = g.vertex(pose, p[1], n);
    g.triangle(a, b, g.vertex(pose, p[2], n));
  }
}

// A plane (normal . x = d) as a square around the projection of the scene's extent centre.
void addPlane(Geometry& g, const Shape& s, const Bounds& extent) {
  const Vec3 n = unit(s.plane_normal);
  Vec3 e1, e2;
  completeFrame(n, e1, e2);
  Vec3 centre = 0.5 * (extent.min + extent.max);
  if (!isFinite(centre)) centre = {};
  const double half = 0.5 * norm(extent.max - extent.min) + kPlaneMargin;
  const Vec3 c = tangentialPart(centre, n) + s.plane_offset * n;
  const Pose world;
  const std::uint32_t a = g.vertex(world, c - half * e1 - half * e2, n);
  const std::uint32_t b = g.vertex(world, c + half * e1 - half * e2, n);
  const std::uint32_t d = g.vertex(world, c + half * e1 + half * e2, n);
  const std::uint32_t f = g.vertex(world, c - half * e1 + half * e2, n);
  g.quad(a, b, d, f);
}

void addShape(Geometry& g, const Shape& s, const Pose& pose, const Bounds& extent) {
  switch (s.kind) {
    case Shape::Kind::Box:
      addBox(g, pose, s.size);
      return;
    case Shape::Kind::Sphere:
      addSphere(g, pose, s.radius);
      return;
    case Shape::Kind::Cylinder:
      addCylinder(g, pose, s.radius, s.length, true);
      return;
    case Shape::Kind::Capsule:
      addCylinder(g, pose, s.radius, s.length, false);
      addSphere(g, pose, s.radius, s.length / 2, 1);
      addSphere(g, pose, s.radius, -s.length / 2, -1);
      return;
    case Shape::Kind::Plane:
      addPlane(g, s, extent);
      return;
    case Shape::Kind::Mesh:
      if (!s.mesh_data) {
        throw std::invalid_argument("animation: mesh '" + s.mesh +
                                    "' has no triangles loaded (use loadScene or loadSceneMeshes)");
      }
      addMesh(g, pose, *s.mesh_data);
      return;
  }
}

// Unit quaternion (x, y, z, w) of a row-major rotation matrix (Shepperd's method: the largest
// of 4w^2, 4x^2, 4y^2, 4z^2 is divided by, so no step loses precision).
std::array<double, 4> quaternion(const double* r) {
  std::array<double, 4> q;
  const double trace = r[0] + r[4] + r[8];
  if (trace > 0) {
    const double s = 2 * std::sqrt(trace + 1);
    q = {(r[7] - r[5]) / s, (r[2] - r[6]) / s, (r[3] - r[1]) / s, s / 4};
  } else if (r[0] > r[4] && r[0] > r[8]) {
    const double s = 2 * std::sqrt(1 + r[0] - r[4] - r[8]);
    q = {s / 4, (r[1] + r[3]) / s, (r[2] + r[6]) / s, (r[7] - r[5]) / s};
  } else if (r[4] > r[8]) {
    const double s = 2 * std::sqrt(1 + r[4] - r[0] - r[8]);
    q = {(r[1] + r[3]) / s, s / 4, (r[5] + r[7]) / s, (r[2] - r[6]) / s};
  } else {
    const double s = 2 * std::sqrt(1 + r[8] - r[0] - r[4]);
    q = {(r[2] + r[6]) / s, (r[5] + r[7]) / s, s / 4, (r[3] - r[1]) / s};
  }
  const double n = std::sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
  for (double& c : q) c /= n;
  return q;
}

// Appends pose's translation (3 floats) and rotation (4 floats, on the same hemisphere as the
// previous quaternion, so that interpolation takes the short way).
void appendPose(const Pose& pose, std::vector<float>& translation, std::vector<float>& rotation) {
  translation.insert(translation.end(),
                     {float(pose.position.x), float(pose.position.y), float(pose.position.z)});
  std::array<double, 4> q = quaternion(pose.rotation);
  if (rotation.size() >= 4) {
    const float* p = &rotation[rotation.size() - 4];
    if (p[0] * q[0] + p[1] * q[1] + p[2] * q[2] + p[3] * q[3] < 0) {
      for (double& c : q) c = -c;
    }
  }
  rotation.insert(rotation.end(), {float(q[0]), float(q[1]), float(q[2]), float(q[3])});
}

// A node name of [A-Za-z0-9_-] (three.js's animation bindings drop other characters).
std::string sanitized(const std::string& name) {
  std::string out = name;
  for (char& c : out) {
    const bool ok = (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') ||
                    c == '_' || c == '-';
    if (!ok) c = '_';
  }
  return out;
}

std::vector<std::string> fixtureNames(const Scene& scene) {
  std::vector<std::string> names;
  for (std::size_t f = 0; f < scene.fixtures.size(); ++f) {
    std::string name = sanitized(scene.fixtures[f].name);
    if (name.empty() || name.rfind("part_", 0) == 0 || name == "rheofeed_world" ||
        std::find(names.begin(), names.end(), name) != names.end()) {
      name = "fixture_" + std::to_string(f) + (name.empty() ? "" : "_" + name);
    }
    names.push_back(name);
  }
  return names;
}

std::string partName(int index, const std::string& family) {
  return "part_" + std::to_string(index) + "_" + sanitized(family);
}

bool vibrates(const Fixture& fixture, Method method) {
  return isFullVibration(method) && fixture.law.kind == FeederLaw::Kind::Vibration;
}

// Colours of the part families (linear RGB), repeated past the last; fixtures are grey.
constexpr double kFamilyColours[][3] = {{0.90, 0.35, 0.05}, {0.05, 0.40, 0.85}, {0.10, 0.65, 0.20},
                                        {0.80, 0.10, 0.45}, {0.85, 0.70, 0.05}, {0.40, 0.15, 0.75},
                                        {0.05, 0.65, 0.65}, {0.55, 0.30, 0.10}};
constexpr double kFixtureGrey = 0.55;

// Builds the model's buffer, views and accessors.
class ModelWriter {
 public:
  explicit ModelWriter(tinygltf::Model& model) : model_(model) { model_.buffers.emplace_back(); }

  // An accessor over `values` (count elements of `components` floats) with min and max.
  int floats(const std::vector<float>& values, int components, int type, int target = 0) {
    const std::size_t count = values.size() / static_cast<std::size_t>(components);
    std::vector<double> lo(components, std::numeric_limits<double>::infinity());
    std::vector<double> hi(components, -std::numeric_limits<double>::infinity());
    for (std::size_t i = 0; i < values.size(); ++i) {
      const std::size_t c = i % static_cast<std::size_t>(components);
      lo[c] = std::min(lo[c], double(values[i]));
      hi[c] = std::max(hi[c], double(values[i]));
    }
    return accessor(view(values.data(), values.size() * sizeof(float), target),
                    TINYGLTF_COMPONENT_TYPE_FLOAT, count, type, lo, hi);
  }
  int indices(const std::vector<std::uint32_t>& values) {
    std::uint32_t lo = std::numeric_limits<std::uint32_t>::max(), hi = 0;
    for (std::uint32_t v : values) {
      lo = std::min(lo, v);
      hi = std::max(hi, v);
    }
    return accessor(view(values.data(), values.size() * sizeof(std::uint32_t),
                         TINYGLTF_TARGET_ELEMENT_ARRAY_BUFFER),
                    TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT, values.size(), TINYGLTF_TYPE_SCALAR,
                    {double(lo)}, {double(hi)});
  }

 private:
  int view(const void* data, std::size_t bytes, int target) {
    std::vector<unsigned char>& buffer = model_.buffers[0].data;
    buffer.resize((buffer.size() + 3) / 4 * 4, 0);  // 4-byte alignment of every view
    tinygltf::BufferView v;
    v.buffer = 0;
    v.byteOffset = buffer.size();
    v.byteLength = bytes;
    v.target = target;
    const auto* p = static_cast<const unsigned char*>(data);
    buffer.insert(buffer.end(), p, p + bytes);
    model_.bufferViews.push_back(v);
    return static_cast<int>(model_.bufferViews.size() - 1);
  }
  int accessor(int view_index, int component_type, std::size_t count, int type,
               std::vector<double> lo, std::vector<double> hi) {
    tinygltf::Accessor a;
    a.bufferView = view_index;
    a.componentType = component_type;
    a.count = count;
    a.type = type;
    a.minValues = std::move(lo);
    a.maxValues = std::move(hi);
    model_.accessors.push_back(a);
    return static_cast<int>(model_.accessors.size() - 1);
  }
  tinygltf::Model& model_;
};

int addMaterial(tinygltf::Model& model, const std::string& name, const double* rgb) {
  tinygltf::Material m;
  m.name = name;
  m.pbrMetallicRoughness.baseColorFactor = {rgb[0], rgb[1], rgb[2], 1.0};
  m.pbrMetallicRoughness.metallicFactor = 0.0;
  m.pbrMetallicRoughness.roughnessFactor = 0.6;
  m.doubleSided = true;  // planes and open meshes (a bowl) are seen from both sides
  model.materials.push_back(m);
  return static_cast<int>(model.materials.size() - 1);
}

int addMeshNode(tinygltf::Model& model, ModelWriter& writer, const std::string& name,
                const Geometry& g, int material) {
  tinygltf::Primitive p;
  p.attributes["POSITION"] =
      writer.floats(g.positions, 3, TINYGLTF_TYPE_VEC3, TINYGLTF_TARGET_ARRAY_BUFFER);
  p.attributes["NORMAL"] =
      writer.floats(g.normals, 3, TINYGLTF_TYPE_VEC3, TINYGLTF_TARGET_ARRAY_BUFFER);
  p.indices = writer.indices(g.indices);
  p.material = material;
  p.mode = TINYGLTF_MODE_TRIANGLES;
  tinygltf::Mesh mesh;
  mesh.name = name;
  mesh.primitives.push_back(p);
  model.meshes.push_back(mesh);
  tinygltf::Node node;
  node.name = name;
  node.mesh = static_cast<int>(model.meshes.size() - 1);
  model.nodes.push_back(node);
  return static_cast<int>(model.nodes.size() - 1);
}

void addChannel(tinygltf::Animation& animation, int node, const char* path, int input, int output,
                const char* interpolation) {
  tinygltf::AnimationSampler s;
  s.input = input;
  s.output = output;
  s.interpolation = interpolation;
  animation.samplers.push_back(s);
  tinygltf::AnimationChannel c;
  c.sampler = static_cast<int>(animation.samplers.size() - 1);
  c.target_node = node;
  c.target_path = path;
  animation.channels.push_back(c);
}

// The root node: turns the scene's up (-gravity) onto glTF's +y (q = (u x y, 1 + u . y),
// normalised), and carries the scene's extent (m, scene frame) and the run's facts as extras
// for viewers (view.html frames the scene with them).
tinygltf::Node worldRoot(const Scene& scene, const Bounds& extent, double duration, Method method) {
  tinygltf::Node root;
  root.name = "rheofeed_world";
  const Vec3 up = isZero(scene.gravity) ? Vec3{0, 0, 1} : unit(-scene.gravity);
  const Vec3 y{0, 1, 0};
  std::array<double, 4> q{};
  if (dot(up, y) < -1 + 1e-12) {
    q = {1, 0, 0, 0};  // upside down: half a turn about x
  } else {
    const Vec3 axis = cross(up, y);
    const double w = 1 + dot(up, y);
    const double n = std::sqrt(dot(axis, axis) + w * w);
    q = {axis.x / n, axis.y / n, axis.z / n, w / n};
  }
  root.rotation = {q[0], q[1], q[2], q[3]};
  auto triple = [](const Vec3& v) {
    return tinygltf::Value(
        tinygltf::Value::Array{tinygltf::Value(v.x), tinygltf::Value(v.y), tinygltf::Value(v.z)});
  };
  tinygltf::Value::Object extras;
  extras["extent_min"] = triple(extent.min);
  extras["extent_max"] = triple(extent.max);
  extras["duration_s"] = tinygltf::Value(duration);
  extras["method"] = tinygltf::Value(std::string(toString(method)));
  extras["scene"] = tinygltf::Value(scene.name);
  root.extras = tinygltf::Value(extras);
  return root;
}

}  // namespace

AnimationRecorder::AnimationRecorder(const Scene& scene, Method method)
    : scene_(scene), method_(method), drawn_(drawParts(scene)) {
  for (const Fixture& f : scene_.fixtures) {
    if (vibrates(f, method_)) {
      for (const Fixture::Geom& g : f.geoms) {
        if (g.shape.kind == Shape::Kind::Mesh && !g.shape.mesh_data) {
          throw std::invalid_argument("animation: fixture '" + f.name + "' mesh '" + g.shape.mesh +
                                      "' has no triangles loaded");
        }
      }
    }
  }
  fixture_translation_.resize(scene_.fixtures.size());
  fixture_rotation_.resize(scene_.fixtures.size());
}

void AnimationRecorder::record(const Simulation& sim) {
  const double t = sim.time();
  if (sim.method() != method_) {
    throw std::invalid_argument(std::string("AnimationRecorder::record: simulation method ") +
                                toString(sim.method()) + " differs from the recorder's " +
                                toString(method_));
  }
  if (!std::isfinite(t) || (!times_.empty() && t < times_.back())) {
    throw std::invalid_argument("AnimationRecorder::record: time " + std::to_string(t) +
                                " s must be finite and >= the last recorded time " +
                                std::to_string(duration()) + " s");
  }
  if (!times_.empty() && t == times_.back()) return;
  const int n = sim.numParts();
  if (n > static_cast<int>(drawn_.size())) {
    throw std::invalid_argument("AnimationRecorder::record: the simulation has " +
                                std::to_string(n) + " parts, the scene draws " +
                                std::to_string(drawn_.size()));
  }
  const int sample = static_cast<int>(times_.size());
  times_.push_back(t);
  parts_.resize(static_cast<std::size_t>(std::max(n, static_cast<int>(parts_.size()))));
  for (int i = 0; i < n; ++i) {
    PartTrack& track = parts_[static_cast<std::size_t>(i)];
    const PartState state = sim.part(i);
    if (track.first_sample < 0) track.first_sample = sample;
    if (!state.active && track.removed_sample < 0) track.removed_sample = sample;
    Pose pose;
    pose.position = state.position;
    std::copy(state.rotation, state.rotation + 9, pose.rotation);
    appendPose(pose, track.translation, track.rotation);
  }
  for (std::size_t f = 0; f < scene_.fixtures.size(); ++f) {
    if (!vibrates(scene_.fixtures[f], method_)) continue;
    appendPose(scene_.fixtures[f].law.vibration.displacement(t), fixture_translation_[f],
               fixture_rotation_[f]);
  }
}

std::vector<std::string> AnimationRecorder::nodeNames() const {
  std::vector<std::string> names = fixtureNames(scene_);
  for (std::size_t i = 0; i < parts_.size(); ++i) {
    names.push_back(partName(static_cast<int>(i), scene_.parts[drawn_[i].spec].name));
  }
  return names;
}

void AnimationRecorder::write(const std::filesystem::path& path) const {
  if (times_.empty()) {
    throw std::logic_error("AnimationRecorder::write(" + path.string() +
                           "): nothing recorded (call record at t = 0 and at every sample)");
  }
  tinygltf::Model model;
  model.asset.version = "2.0";
  model.asset.generator = "rheofeed";
  ModelWriter writer(model);
  const Bounds extent = sceneLimits(scene_).extent;

  model.nodes.push_back(worldRoot(scene_, extent, duration(), method_));

  const double grey[3] = {kFixtureGrey, kFixtureGrey, kFixtureGrey};
  const int fixture_material = addMaterial(model, "fixture", grey);
  std::vector<int> family_material;
  for (std::size_t s = 0; s < scene_.parts.size(); ++s) {
    const std::size_t c = s % (sizeof kFamilyColours / sizeof kFamilyColours[0]);
    family_material.push_back(
        addMaterial(model, sanitized(scene_.parts[s].name), kFamilyColours[c]));
  }

  // Shared input: the recorded times (s).
  const std::vector<float> times(times_.begin(), times_.end());
  const int time_input = writer.floats(times, 1, TINYGLTF_TYPE_SCALAR);
  tinygltf::Animation animation;
  animation.name = "run";

  const std::vector<std::string> names = nodeNames();
  for (std::size_t f = 0; f < scene_.fixtures.size(); ++f) {
    Geometry g;
    for (const Fixture::Geom& geom : scene_.fixtures[f].geoms) {
      addShape(g, geom.shape, geom.pose, extent);
    }
    const int node = addMeshNode(model, writer, names[f], g, fixture_material);
    model.nodes[0].children.push_back(node);
    if (!fixture_translation_[f].empty()) {
      addChannel(animation, node, "translation", time_input,
                 writer.floats(fixture_translation_[f], 3, TINYGLTF_TYPE_VEC3), "LINEAR");
      addChannel(animation, node, "rotation", time_input,
                 writer.floats(fixture_rotation_[f], 4, TINYGLTF_TYPE_VEC4), "LINEAR");
    }
  }

  const std::size_t samples = times_.size();
  for (std::size_t i = 0; i < parts_.size(); ++i) {
    const PartTrack& track = parts_[i];
    const PartInstance& part = drawn_[i];
    Geometry g;
    addShape(g, part.shape, Pose{}, extent);
    const int node = addMeshNode(model, writer, names[scene_.fixtures.size() + i], g,
                                 family_material[static_cast<std::size_t>(part.spec)]);
    model.nodes[0].children.push_back(node);
    // Before it was first seen the part waits, hidden, at its first recorded pose.
    const std::size_t before = static_cast<std::size_t>(track.first_sample);
    std::vector<float> translation, rotation;
    translation.reserve(3 * samples);
    rotation.reserve(4 * samples);
    for (std::size_t k = 0; k < before; ++k) {
      translation.insert(translation.end(), track.translation.begin(),
                         track.translation.begin() + 3);
      rotation.insert(rotation.end(), track.rotation.begin(), track.rotation.begin() + 4);
    }
    translation.insert(translation.end(), track.translation.begin(), track.translation.end());
    rotation.insert(rotation.end(), track.rotation.begin(), track.rotation.end());
    addChannel(animation, node, "translation", time_input,
               writer.floats(translation, 3, TINYGLTF_TYPE_VEC3), "LINEAR");
    addChannel(animation, node, "rotation", time_input,
               writer.floats(rotation, 4, TINYGLTF_TYPE_VEC4), "LINEAR");
    // Visibility as a stepped scale: 0 before the spawn, 1 while active, 0 once removed.
    // Keys must increase strictly: a part first seen already removed never shows.
    std::vector<float> keys, scales;
    auto key = [&](std::size_t sample, float scale) {
      if (!keys.empty() && keys.back() == times[sample]) {
        scales.resize(scales.size() - 3);
        keys.pop_back();
      }
      keys.push_back(times[sample]);
      scales.insert(scales.end(), {scale, scale, scale});
    };
    if (before > 0) key(0, 0);
    key(before, 1);
    if (track.removed_sample >= 0) key(static_cast<std::size_t>(track.removed_sample), 0);
    addChannel(animation, node, "scale", writer.floats(keys, 1, TINYGLTF_TYPE_SCALAR),
               writer.floats(scales, 3, TINYGLTF_TYPE_VEC3), "STEP");
  }
  model.animations.push_back(animation);

  tinygltf::Scene gltf_scene;
  gltf_scene.name = sanitized(scene_.name);
  gltf_scene.nodes = {0};
  model.scenes.push_back(gltf_scene);
  model.defaultScene = 0;

  tinygltf::TinyGLTF gltf;
  std::ostringstream out(std::ios::binary);
  if (!gltf.WriteGltfSceneToStream(&model, out, false, true)) {
    throw std::runtime_error("animation: tinygltf could not serialise " + path.string());
  }
  writeFileAtomically(path, out.str());
}

}  // namespace rheofeed::scene

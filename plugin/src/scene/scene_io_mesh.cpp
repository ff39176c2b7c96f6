// SPDX-License-Identifier: MIT
// Scene files, the meshes they name (scene_io.hpp, loadSceneMeshes): loaded once per file and
// scale, fixture meshes checked against the size and coordinate limits, part meshes centred
// on their centre of mass (and their convex hulls built for parts that collide as one).
#include <algorithm>
#include <cmath>
#include <map>
#include <sstream>

#include "rheofeed/scene/mesh.hpp"
#include "scene_io_internal.hpp"
#include "scene_limits.hpp"

namespace rheofeed::scene {
namespace {

namespace fs = std::filesystem;
using io::fail;
using io::show;

// A fixture mesh, scaled by `scale` (the geom's "scale", named in the messages): its bounding
// box diagonal within the size limits and, placed at `position`, every vertex within the
// coordinate limits (scene.hpp).
void checkFixtureMesh(const TriangleMesh& mesh, double scale, const Vec3& position,
                      const std::string& path) {
  double lo[3] = {HUGE_VAL, HUGE_VAL, HUGE_VAL}, hi[3] = {-HUGE_VAL, -HUGE_VAL, -HUGE_VAL};
  for (std::size_t v = 0; v + 2 < mesh.vertices.size(); v += 3) {
    for (int k = 0; k < 3; ++k) {
      lo[k] = std::min(lo[k], mesh.vertices[v + k]);
      hi[k] = std::max(hi[k], mesh.vertices[v + k]);
    }
  }
  const double diagonal = std::hypot(hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]);
  const std::string name = "mesh '" + mesh.source + "' at scale " + show(scale);
  auto range = [](double low, double high) {  // as Scene::validate writes its ranges
    std::ostringstream out;
    out << "[" << low << ", " << high << "] m";
    return out.str();
  };
  if (!(diagonal >= limits::kMinSize && diagonal <= limits::kMaxSize)) {
    fail(path, name + ": scaled bounding box diagonal " + show(diagonal) + " m must be in " +
                   range(limits::kMinSize, limits::kMaxSize));
  }
  // The geom may be rotated: bound every vertex by the farthest one from the mesh origin.
  const double reach = boundingRadius(mesh);
  const double p[3] = {position.x, position.y, position.z};
  for (int k = 0; k < 3; ++k) {
    if (!(std::abs(p[k]) + reach <= limits::kMaxCoordinate)) {
      fail(path, name + ": vertices reach " + show(std::abs(p[k]) + reach) +
                     " m from the origin along " + std::string(1, "xyz"[k]) +
                     "; coordinates must be in " +
                     range(-limits::kMaxCoordinate, limits::kMaxCoordinate));
    }
  }
}

}  // namespace

void loadSceneMeshes(Scene& scene, const fs::path& base_dir, const MeshLoader& mesh_loader) {
  const MeshLoader load = mesh_loader ? mesh_loader : MeshLoader(loadTriangleMesh);
  std::map<std::pair<std::string, double>, std::shared_ptr<const TriangleMesh>> cache;
  auto get = [&](std::string& file, double scale, const std::string& path) {
    fs::path p(file);
    if (p.is_relative()) p = base_dir / p;
    file = fs::absolute(p).lexically_normal().string();
    std::shared_ptr<const TriangleMesh>& mesh = cache[{file, scale}];
    if (!mesh) {
      try {
        TriangleMesh m = load(file, scale);
        if (m.source.empty()) m.source = file;
        mesh = std::make_shared<const TriangleMesh>(std::move(m));
      } catch (const std::exception& e) {
        fail(path, e.what());
      }
    }
    return mesh;
  };
  for (std::size_t i = 0; i < scene.fixtures.size(); ++i) {
    for (std::size_t g = 0; g < scene.fixtures[i].geoms.size(); ++g) {
      Shape& s = scene.fixtures[i].geoms[g].shape;
      if (s.kind != Shape::Kind::Mesh) continue;
      const std::string path =
          "fixtures[" + std::to_string(i) + "].geoms[" + std::to_string(g) + "].mesh";
      s.mesh_data = get(s.mesh, s.mesh_scale, path);
      checkFixtureMesh(*s.mesh_data, s.mesh_scale, scene.fixtures[i].geoms[g].pose.position, path);
    }
  }
  for (std::size_t i = 0; i < scene.parts.size(); ++i) {
    PartSpec& p = scene.parts[i];
    if (p.shape != Shape::Kind::Mesh) continue;
    const std::string path = "parts[" + std::to_string(i) + "].mesh";
    const std::shared_ptr<const TriangleMesh> mesh = get(p.mesh, 1.0, path);
    try {  // a part must be a closed, outward-oriented solid; centre it on its centre of mass
      const MassProperties mp = massProperties(*mesh, 1.0);
      p.mesh_data = std::make_shared<const TriangleMesh>(translateMesh(*mesh, -mp.centre_of_mass));
      p.collision_mesh_data = p.collision == PartSpec::Collision::ConvexHull
                                  ? std::make_shared<const TriangleMesh>(convexHull(*p.mesh_data))
                                  : nullptr;
    } catch (const std::exception& e) {
      fail(path, e.what());
    }
  }
}

}  // namespace rheofeed::scene

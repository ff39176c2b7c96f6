// SPDX-License-Identifier: MIT
#include "geom_factory.hpp"

#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

namespace rheofeed::scene {

TriMeshStore::~TriMeshStore() {
  for (auto& [key, entry] : entries_) dGeomTriMeshDataDestroy(entry->id);
}

dTriMeshDataID TriMeshStore::data(const std::shared_ptr<const TriangleMesh>& mesh) {
  auto found = entries_.find(mesh.get());
  if (found != entries_.end()) return found->second->id;

  const std::string name = "mesh '" + mesh->source + "'";
  const std::size_t nv = mesh->vertices.size() / 3, nt = mesh->triangles.size() / 3;
  if (nt == 0 || mesh->vertices.size() % 3 != 0 || mesh->triangles.size() % 3 != 0) {
    throw std::invalid_argument(name + ": no triangles (or arrays not in threes)");
  }
  if (nv > static_cast<std::size_t>(std::numeric_limits<int>::max() / 3) ||
      mesh->triangles.size() > static_cast<std::size_t>(std::numeric_limits<int>::max())) {
    throw std::invalid_argument(name + ": too large for ODE");
  }
  for (double v : mesh->vertices) {
    if (!std::isfinite(v)) throw std::invalid_argument(name + ": non-finite vertex coordinate");
  }
  // OPCODE's trimesh colliders are set up by dInitODE2; the reference world alone never calls it.
  static const bool initialised = (dInitODE2(0), true);
  (void)initialised;
  auto entry = std::make_unique<Entry>();
  entry->mesh = mesh;
  entry->indices.reserve(mesh->triangles.size());
  for (int i : mesh->triangles) {
    if (i < 0 || static_cast<std::size_t>(i) >= nv) {
      throw std::invalid_argument(name + ": vertex index " + std::to_string(i) + " out of range");
    }
    entry->indices.push_back(static_cast<dTriIndex>(i));
  }
  entry->id = dGeomTriMeshDataCreate();
  dGeomTriMeshDataBuildDouble(entry->id, mesh->vertices.data(), 3 * sizeof(double),
                              static_cast<int>(nv), entry->indices.data(),
                              static_cast<int>(entry->indices.size()), 3 * sizeof(dTriIndex));
  // Concave-edge flags and face angles: OPCODE then skips spurious contacts on inner edges.
  dGeomTriMeshDataPreprocess2(
      entry->id,
      (1U << dTRIDATAPREPROCESS_BUILD_CONCAVE_EDGES) | (1U << dTRIDATAPREPROCESS_BUILD_FACE_ANGLES),
      nullptr);
  const dTriMeshDataID id = entry->id;
  entries_.emplace(mesh.get(), std::move(entry));
  return id;
}

dGeomID createGeom(dSpaceID space, const Shape& s, TriMeshStore& meshes) {
  switch (s.kind) {
    case Shape::Kind::Box:
      return dCreateBox(space, s.size.x, s.size.y, s.size.z);
    case Shape::Kind::Sphere:
      return dCreateSphere(space, s.radius);
    case Shape::Kind::Cylinder:
      return dCreateCylinder(space, s.radius, s.length);
    case Shape::Kind::Capsule:
      return dCreateCapsule(space, s.radius, s.length);
    case Shape::Kind::Plane:
      return dCreatePlane(space, s.plane_normal.x, s.plane_normal.y, s.plane_normal.z,
                          s.plane_offset);
    case Shape::Kind::Mesh:
      if (!s.mesh_data) {
        throw std::invalid_argument("mesh '" + s.mesh +
                                    "' is not loaded (load the scene with loadScene, or call "
                                    "loadSceneMeshes; scene_io.hpp)");
      }
      return dCreateTriMesh(
          space, meshes.data(s.collision_mesh_data ? s.collision_mesh_data : s.mesh_data), nullptr,
          nullptr, nullptr);
  }
  throw std::invalid_argument("unknown shape kind");
}

}  // namespace rheofeed::scene

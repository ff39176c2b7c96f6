// SPDX-License-Identifier: MIT
// Internal: ODE geoms from scene shapes, shared by the ODE and the reference simulations (both
// use ODE's collision module, so both must build the very same geoms).
#pragma once

#include <ode/ode.h>

#include <memory>
#include <unordered_map>
#include <vector>

#include "ode_vec.hpp"  // setGeomPose and the other ODE <-> rheofeed conversions
#include "rheofeed/scene/scene.hpp"

namespace rheofeed::scene {

/// Owns the ODE triangle-mesh data (dTriMeshDataID) of the mesh geoms built with it. ODE keeps
/// pointers into that data and into the vertex and index arrays it was built from, so the store
/// keeps the TriangleMesh alive and must outlive every geom made with it: a simulation destroys
/// its space (and with it the geoms) before the store. One data object per TriangleMesh, shared
/// by every geom of that mesh (all parts drawn at the same scale share one).
class TriMeshStore {
 public:
  TriMeshStore() = default;
  ~TriMeshStore();
  TriMeshStore(const TriMeshStore&) = delete;
  TriMeshStore& operator=(const TriMeshStore&) = delete;

  /// The ODE data of `mesh` (built on first use). Throws std::invalid_argument for a mesh with
  /// no triangles, bad indices or non-finite coordinates.
  dTriMeshDataID data(const std::shared_ptr<const TriangleMesh>& mesh);

 private:
  struct Entry {
    std::shared_ptr<const TriangleMesh> mesh;  // vertices are read in place by ODE
    std::vector<dTriIndex> indices;
    dTriMeshDataID id = nullptr;
  };
  std::unordered_map<const TriangleMesh*, std::unique_ptr<Entry>> entries_;
};

/// Creates the geom of `shape` in `space` (no body, identity pose). Planes use their world
/// equation. Meshes are built from shape.collision_mesh_data when set (a part colliding as its
/// convex hull), else from shape.mesh_data (already scaled; filled by the scene loader), with
/// their ODE data owned by `meshes`; a mesh shape without mesh_data throws
/// std::invalid_argument.
dGeomID createGeom(dSpaceID space, const Shape& shape, TriMeshStore& meshes);

}  // namespace rheofeed::scene

// SPDX-License-Identifier: MIT
/// @file mesh.hpp
/// Triangle meshes read from files (any format assimp reads: STL, OBJ, PLY, glTF, ...) and the
/// mass properties of the homogeneous solid a closed mesh bounds.
///
/// This is the only part of rheofeed that uses assimp (target rheofeed::mesh). The scene loader
/// (scene_io.hpp) calls loadTriangleMesh only for the meshes a scene names, so a scene without
/// meshes never touches assimp.
///
/// ## Mass properties (divergence theorem)
/// Each triangle (a, b, c), counter-clockwise seen from outside, closes a signed tetrahedron with
/// a reference point r0 (here the vertex mean, to keep the sums well conditioned). With
/// A = [a b c] relative to r0 and det = a . (b x c) = 6 V_tet:
///   V    = sum det / 6
///   m c  = rho sum det (a + b + c) / 24                          (first moment)
///   C    = rho sum det (a a^T + b b^T + c c^T + s s^T) / 120,     s = a + b + c
/// (the second moment of the unit tetrahedron is (I + 1 1^T) / 120, mapped by A). Then
///   C_c = C - m c c^T,   I = trace(C_c) Id - C_c                 (about the centre of mass)
/// A closed surface has sum of area vectors (b - a) x (c - a) / 2 equal to zero; an open one
/// does not, and an inside-out one has V < 0: both are refused.
#pragma once

#include <filesystem>

#include "rheofeed/scene/scene.hpp"
#include "rheofeed/vec3.hpp"

namespace rheofeed::scene {

/// Mass properties of a homogeneous solid bounded by a closed triangle mesh.
struct MassProperties {
  double volume = 0;       ///< (m^3)
  double mass = 0;         ///< density * volume (kg)
  Vec3 centre_of_mass;     ///< (m, mesh frame)
  double inertia[9] = {};  ///< about the centre of mass, mesh axes, row-major (kg m^2)
};

/// Reads every mesh of `file` (triangulated, identical vertices joined, node transforms applied,
/// all meshes merged into one; points and lines dropped) and multiplies its coordinates by
/// `scale` (dimensionless, > 0; the file's units times scale must give metres).
///
/// Throws std::runtime_error naming the file and the problem when the file is missing, empty,
/// unreadable or corrupt, or holds no triangles; std::invalid_argument for a bad `scale` or a
/// non-finite coordinate.
TriangleMesh loadTriangleMesh(const std::filesystem::path& file, double scale = 1.0);

/// Volume, mass, centre of mass and inertia about the centre of mass of the solid bounded by
/// `mesh` with uniform `density` (kg/m^3, > 0). Throws std::invalid_argument naming
/// `mesh.source` when the mesh has no triangles or a bad index, is not closed, or is inside out
/// (signed volume <= 0: triangles must be counter-clockwise seen from outside).
MassProperties massProperties(const TriangleMesh& mesh, double density);

/// The mass properties of the same solid scaled uniformly by `scale` (> 0) about the mesh
/// origin: volume and mass times scale^3, centre of mass times scale, inertia times scale^5.
MassProperties scaleMassProperties(const MassProperties& properties, double scale);

/// A copy of `mesh` with every coordinate multiplied by `scale` (about the mesh origin).
TriangleMesh scaleMesh(const TriangleMesh& mesh, double scale);

/// A copy of `mesh` moved by `offset` (m): every vertex v becomes v + offset.
TriangleMesh translateMesh(const TriangleMesh& mesh, const Vec3& offset);

/// The convex hull of `mesh`'s vertices (qhull) as a closed triangle mesh, outward
/// (counter-clockwise seen from outside), in the same frame and units; `source` is
/// "convex hull of <mesh.source>". Coplanar faces are merged before they are triangulated, so a
/// hexagonal prism gives 20 triangles however finely its sides were cut, and vertices that are
/// not hull corners (a nut's hole, points along an edge) are dropped. Used to collide a part as
/// its hull (PartSpec::collision) while its mass comes from the mesh itself.
///
/// Throws std::invalid_argument naming `mesh.source` when the mesh has fewer than 4 vertices,
/// a non-finite coordinate, or no volume (all vertices on one plane or line: qhull's message
/// is quoted).
TriangleMesh convexHull(const TriangleMesh& mesh);

/// The largest distance of a vertex from the mesh origin (m); 0 for an empty mesh.
double boundingRadius(const TriangleMesh& mesh);

}  // namespace rheofeed::scene

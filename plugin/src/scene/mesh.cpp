// SPDX-License-Identifier: MIT
// Triangle meshes from files (assimp) and the mass properties of the solids they bound; the
// derivation is in mesh.hpp.
#include "rheofeed/scene/mesh.hpp"
#include "scene_limits.hpp"

#include <assimp/postprocess.h>
#include <assimp/scene.h>

#include <algorithm>
#include <assimp/Importer.hpp>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <system_error>

#include "rheofeed/number_format.hpp"

// Last: qhull's headers define macros (True, False, FORALLfacets, ...).
#include <libqhull_r/qhull_ra.h>

namespace rheofeed::scene {
namespace {

namespace fs = std::filesystem;

// A closed surface has zero total area vector. Merged vertices close it to rounding error
// (~1e-7 relative with the single-precision coordinates of STL files); a CAD export whose
// seams are a hair apart stays far below this, while a missing face gives a residual of the
// order of its own area.
constexpr double kClosureTolerance = 1e-4;

std::string quoted(const std::string& s) {
  return "'" + s + "'";
}

std::string nameOf(const TriangleMesh& mesh) {
  return mesh.source.empty() ? std::string("mesh") : "mesh " + quoted(mesh.source);
}

void checkIndices(const TriangleMesh& mesh) {
  const std::string name = nameOf(mesh);
  if (mesh.vertices.size() % 3 != 0) {
    throw std::invalid_argument(name + ": the vertex array length is not a multiple of 3");
  }
  if (mesh.triangles.size() % 3 != 0) {
    throw std::invalid_argument(name + ": the triangle index array length is not a multiple of 3");
  }
  if (mesh.triangles.empty()) throw std::invalid_argument(name + ": no triangles");
  for (std::size_t i = 0; i < mesh.vertices.size(); ++i) {
    if (!std::isfinite(mesh.vertices[i])) {
      throw std::invalid_argument(name + ": vertex " + std::to_string(i / 3) +
                                  " has a non-finite coordinate");
    }
  }
  const long n = static_cast<long>(mesh.vertices.size() / 3);
  for (std::size_t i = 0; i < mesh.triangles.size(); ++i) {
    if (mesh.triangles[i] < 0 || mesh.triangles[i] >= n) {
      throw std::invalid_argument(name + ": triangle " + std::to_string(i / 3) +
                                  " has vertex index " + std::to_string(mesh.triangles[i]) +
                                  " outside 0.." + std::to_string(n - 1));
    }
  }
}

Vec3 vertex(const TriangleMesh& mesh, int index) {
  const double* v = &mesh.vertices[3 * static_cast<std::size_t>(index)];
  return {v[0], v[1], v[2]};
}

}  // namespace

TriangleMesh loadTriangleMesh(const fs::path& file, double scale) {
  const std::string name = "mesh " + quoted(file.string());
  if (!(std::isfinite(scale) && scale > 0)) {
    throw std::invalid_argument(name + ": scale = " + formatNumber(scale) +
                                " must be a finite number > 0");
  }
  // Kind and size from stat first: a FIFO, a device or a directory is never opened.
  const std::string problem = limits::regularFileProblem(file, limits::kMaxMeshFileBytes);
  if (!problem.empty()) throw std::runtime_error(name + ": " + problem);
  if (!std::ifstream(file, std::ios::binary)) {
    throw std::runtime_error(name + ": cannot open the file for reading");
  }

  Assimp::Importer importer;
  const aiScene* ai = importer.ReadFile(file.string(), aiProcess_ValidateDataStructure);
  if (ai == nullptr) {
    throw std::runtime_error(
        name + ": cannot read it (corrupt or unknown format): " + importer.GetErrorString());
  }
  // Non-finite coordinates are refused before the vertices are joined: joining compares
  // coordinates, and a NaN one could be merged into a finite vertex and vanish. Named by the
  // face that uses the vertex, in the file's order of faces.
  for (unsigned m = 0; m < ai->mNumMeshes; ++m) {
    const aiMesh* part = ai->mMeshes[m];
    for (unsigned f = 0; f < part->mNumFaces; ++f) {
      for (unsigned k = 0; k < part->mFaces[f].mNumIndices; ++k) {
        const aiVector3D& p = part->mVertices[part->mFaces[f].mIndices[k]];
        const double xyz[3] = {p.x, p.y, p.z};
        for (int c = 0; c < 3; ++c) {
          if (!std::isfinite(xyz[c])) {
            throw std::invalid_argument(
                name + ": face " + std::to_string(f + 1) + " of mesh " + std::to_string(m + 1) +
                " in the file has a vertex with a non-finite coordinate (" +
                std::string(1, "xyz"[c]) + " = " + formatNumber(xyz[c]) + ")");
          }
        }
      }
    }
  }
  ai = importer.ApplyPostProcessing(aiProcess_Triangulate | aiProcess_JoinIdenticalVertices |
                                    aiProcess_PreTransformVertices | aiProcess_SortByPType |
                                    aiProcess_ValidateDataStructure);
  if (ai == nullptr) {
    throw std::runtime_error(
        name + ": cannot read it (corrupt or unknown format): " + importer.GetErrorString());
  }

  // Count before copying anything: ODE's trimesh collider must stay bounded (scene_limits.hpp).
  long faces = 0;
  for (unsigned m = 0; m < ai->mNumMeshes; ++m) {
    if (ai->mMeshes[m]->mPrimitiveTypes & aiPrimitiveType_TRIANGLE)
      faces += ai->mMeshes[m]->mNumFaces;
  }
  if (faces > limits::kMaxTriangles) {
    throw std::runtime_error(name + ": " + std::to_string(faces) + " triangles; at most " +
                             std::to_string(limits::kMaxTriangles) + " are allowed per mesh");
  }
  TriangleMesh mesh;
  mesh.source = file.string();
  for (unsigned m = 0; m < ai->mNumMeshes; ++m) {
    const aiMesh* part = ai->mMeshes[m];
    if (!(part->mPrimitiveTypes & aiPrimitiveType_TRIANGLE)) continue;
    const int offset = static_cast<int>(mesh.vertices.size() / 3);
    for (unsigned v = 0; v < part->mNumVertices; ++v) {
      const aiVector3D& p = part->mVertices[v];
      const double xyz[3] = {scale * p.x, scale * p.y, scale * p.z};
      for (int k = 0; k < 3; ++k) {
        if (!std::isfinite(xyz[k])) {
          throw std::invalid_argument(
              name + ": vertex " + std::to_string(offset + v) + " has a non-finite coordinate (" +
              std::string(1, "xyz"[k]) + " = " + formatNumber(xyz[k]) +
              ", the file's value times scale " + formatNumber(scale) + ")");
        }
      }
      mesh.vertices.insert(mesh.vertices.end(), xyz, xyz + 3);
    }
    for (unsigned f = 0; f < part->mNumFaces; ++f) {
      const aiFace& face = part->mFaces[f];
      if (face.mNumIndices != 3) continue;
      for (int k = 0; k < 3; ++k)
        mesh.triangles.push_back(offset + static_cast<int>(face.mIndices[k]));
    }
  }
  if (mesh.triangles.empty()) throw std::runtime_error(name + ": the file holds no triangles");
  return mesh;
}

MassProperties massProperties(const TriangleMesh& mesh, double density) {
  const std::string name = nameOf(mesh);
  if (!(std::isfinite(density) && density > 0)) {
    throw std::invalid_argument(name + ": density = " + formatNumber(density) +
                                " must be a finite number > 0");
  }
  checkIndices(mesh);

  Vec3 r0;  // reference point: the vertex mean
  const std::size_t nv = mesh.vertices.size() / 3;
  for (std::size_t i = 0; i < nv; ++i) r0 = r0 + vertex(mesh, static_cast<int>(i));
  r0 = (1.0 / static_cast<double>(nv)) * r0;

  double six_volume = 0, area = 0;
  Vec3 first, area_vector;  // sum det (a + b + c); sum (b - a) x (c - a)
  double second[9] = {};    // sum det (a a^T + b b^T + c c^T + s s^T)
  for (std::size_t t = 0; t < mesh.triangles.size(); t += 3) {
    const Vec3 a = vertex(mesh, mesh.triangles[t]) - r0;
    const Vec3 b = vertex(mesh, mesh.triangles[t + 1]) - r0;
    const Vec3 c = vertex(mesh, mesh.triangles[t + 2]) - r0;
    const double det = dot(a, cross(b, c));
    const Vec3 s = a + b + c;
    const Vec3 n = cross(b - a, c - a);
    six_volume += det;
    first = first + det * s;
    area_vector = area_vector + n;
    area += 0.5 * norm(n);
    const double pa[3] = {a.x, a.y, a.z}, pb[3] = {b.x, b.y, b.z}, pc[3] = {c.x, c.y, c.z},
                 ps[3] = {s.x, s.y, s.z};
    for (int i = 0; i < 3; ++i) {
      for (int j = 0; j < 3; ++j) {
        second[3 * i + j] += det * (pa[i] * pa[j] + pb[i] * pb[j] + pc[i] * pc[j] + ps[i] * ps[j]);
      }
    }
  }
  const double residual = 0.5 * norm(area_vector);
  if (!(residual <= kClosureTolerance * area)) {
    throw std::invalid_argument(name + ": the surface is not closed (its area vectors sum to " +
                                formatNumber(residual / area * 100) +
                                " % of its area); a solid needs a watertight mesh");
  }
  const double volume = six_volume / 6;
  if (!(volume > 0)) {
    throw std::invalid_argument(name + ": signed volume " + formatNumber(volume) +
                                " (the mesh's length unit cubed) <= 0: the mesh encloses no volume "
                                "(flat, or two-sided), or is inside out (triangles must be "
                                "counter-clockwise seen from outside)");
  }
  // A flat or sliver solid: its volume against the sphere about r0 through the farthest vertex.
  double r2 = 0;
  for (std::size_t i = 0; i < nv; ++i) {
    const Vec3 d = vertex(mesh, static_cast<int>(i)) - r0;
    r2 = std::max(r2, dot(d, d));
  }
  const double sphere = 4.0 / 3.0 * kPi * r2 * std::sqrt(r2);
  if (!(volume >= limits::kMinVolumeFraction * sphere)) {
    throw std::invalid_argument(name + ": degenerate solid: volume " + formatNumber(volume) +
                                " (the mesh's length unit cubed) is " +
                                formatNumber(volume / sphere) +
                                " of its bounding sphere's; at least " +
                                formatNumber(limits::kMinVolumeFraction) + " is needed for a part");
  }

  MassProperties out;
  out.volume = volume;
  out.mass = density * volume;
  const Vec3 c = (1.0 / (24 * volume)) * first;  // centre of mass relative to r0
  out.centre_of_mass = r0 + c;
  const double pc[3] = {c.x, c.y, c.z};
  double cc[9];  // covariance about the centre of mass (kg m^2)
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) {
      cc[3 * i + j] = density * second[3 * i + j] / 120 - out.mass * pc[i] * pc[j];
    }
  }
  const double trace = cc[0] + cc[4] + cc[8];
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) out.inertia[3 * i + j] = (i == j ? trace : 0.0) - cc[3 * i + j];
  }
  // Symmetric by construction; make it exactly so.
  for (int i = 0; i < 3; ++i) {
    for (int j = i + 1; j < 3; ++j) {
      const double m = 0.5 * (out.inertia[3 * i + j] + out.inertia[3 * j + i]);
      out.inertia[3 * i + j] = out.inertia[3 * j + i] = m;
    }
  }
  return out;
}

MassProperties scaleMassProperties(const MassProperties& p, double scale) {
  const double s3 = scale * scale * scale, s5 = s3 * scale * scale;
  MassProperties out = p;
  out.volume *= s3;
  out.mass *= s3;
  out.centre_of_mass = scale * p.centre_of_mass;
  for (double& i : out.inertia) i *= s5;
  return out;
}

TriangleMesh scaleMesh(const TriangleMesh& mesh, double scale) {
  TriangleMesh out = mesh;
  for (double& v : out.vertices) v *= scale;
  return out;
}

TriangleMesh translateMesh(const TriangleMesh& mesh, const Vec3& offset) {
  TriangleMesh out = mesh;
  for (std::size_t i = 0; i + 2 < out.vertices.size(); i += 3) {
    out.vertices[i] += offset.x;
    out.vertices[i + 1] += offset.y;
    out.vertices[i + 2] += offset.z;
  }
  return out;
}

TriangleMesh convexHull(const TriangleMesh& mesh) {
  const std::string name = nameOf(mesh);
  if (mesh.vertices.size() % 3 != 0 || mesh.vertices.size() < 12) {
    throw std::invalid_argument(name + ": a convex hull needs at least 4 vertices, the mesh has " +
                                std::to_string(mesh.vertices.size() / 3));
  }
  for (std::size_t i = 0; i < mesh.vertices.size(); ++i) {
    if (!std::isfinite(mesh.vertices[i])) {
      throw std::invalid_argument(name + ": vertex " + std::to_string(i / 3) +
                                  " has a non-finite coordinate");
    }
  }
  std::vector<coordT> points(mesh.vertices.begin(), mesh.vertices.end());
  // Facets within a millionth of the mesh's size of coplanar are merged ('C-n'): a flat face
  // is one polygon even where the file rounded the points along its edges (an OBJ's 6 decimals).
  double lo[3] = {HUGE_VAL, HUGE_VAL, HUGE_VAL}, hi[3] = {-HUGE_VAL, -HUGE_VAL, -HUGE_VAL};
  for (std::size_t i = 0; i < points.size(); ++i) {
    lo[i % 3] = std::min(lo[i % 3], points[i]);
    hi[i % 3] = std::max(hi[i % 3], points[i]);
  }
  char command[64];
  std::snprintf(command, sizeof command, "qhull C-%.3g",
                1e-6 * std::hypot(hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]));

  // qhull's state and its message stream (quoted in the exception; nothing reaches stderr),
  // released on every path, exceptions included.
  struct Qhull {
    qhT qh;
    char* message = nullptr;
    std::size_t message_size = 0;
    FILE* err = nullptr;
    bool built = false;
    Qhull() : err(open_memstream(&message, &message_size)) {}
    Qhull(const Qhull&) = delete;
    Qhull& operator=(const Qhull&) = delete;
    ~Qhull() {
      if (built) {
        int still_long = 0, still_total = 0;
        qh_freeqhull(&qh, !qh_ALL);
        qh_memfreeshort(&qh, &still_long, &still_total);
      }
      if (err) std::fclose(err);
      std::free(message);
    }
    std::string text() {
      if (err) std::fflush(err);
      return std::string(message ? message : "", message ? message_size : 0);
    }
  } run;
  if (!run.err) throw std::runtime_error(name + ": convex hull: cannot open a message stream");
  qhT* qh = &run.qh;
  QHULL_LIB_CHECK
  qh_zero(qh, run.err);
  run.built = true;
  const int exit_code = qh_new_qhull(qh, 3, static_cast<int>(points.size() / 3), points.data(),
                                     False, command, nullptr, run.err);
  TriangleMesh hull;
  hull.source = "convex hull of " + (mesh.source.empty() ? std::string("a mesh") : mesh.source);
  if (exit_code == 0) {
    const int count = static_cast<int>(points.size() / 3);
    std::vector<int> index(points.size() / 3, -1);  // qhull point id -> hull vertex
    auto at = [&hull](int k) { return vertex(hull, k); };
    facetT* facet;
    FORALLfacets {
      // The facet's vertices in order round it (qh_facet3vertex: its only qhull call that could
      // raise an error, on an inconsistent hull, after which qhull ends the process), fanned
      // into triangles turned to face along its outward normal.
      setT* ring = qh_facet3vertex(qh, facet);
      std::vector<int> polygon;
      vertexT *vertex, **vertexp;
      FOREACHvertex_(ring) {
        const int id = qh_pointid(qh, vertex->point);
        if (id < 0 || id >= count) continue;  // not an input point (qhull adds none here)
        int& k = index[static_cast<std::size_t>(id)];
        if (k < 0) {
          k = static_cast<int>(hull.vertices.size() / 3);
          hull.vertices.insert(hull.vertices.end(), vertex->point, vertex->point + 3);
        }
        polygon.push_back(k);
      }
      qh_settempfree(qh, &ring);
      if (polygon.size() < 3) continue;
      const Vec3 n{facet->normal[0], facet->normal[1], facet->normal[2]};
      const bool outward =
          dot(cross(at(polygon[1]) - at(polygon[0]), at(polygon[2]) - at(polygon[0])), n) > 0;
      for (std::size_t k = 1; k + 1 < polygon.size(); ++k) {
        const int b = polygon[outward ? k : k + 1], c = polygon[outward ? k + 1 : k];
        hull.triangles.insert(hull.triangles.end(), {polygon[0], b, c});
      }
    }
  }
  if (exit_code != 0 || hull.triangles.empty()) {
    const std::string text = run.text();
    const std::size_t end = text.find('\n', text.find_first_not_of(" \n"));
    throw std::invalid_argument(name + ": no convex hull (the vertices span no volume?): qhull: " +
                                text.substr(0, std::min(end, std::size_t{300})));
  }
  return hull;
}

double boundingRadius(const TriangleMesh& mesh) {
  double r2 = 0;
  for (std::size_t i = 0; i + 2 < mesh.vertices.size(); i += 3) {
    const double* v = &mesh.vertices[i];
    r2 = std::max(r2, v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
  }
  return std::sqrt(r2);
}

}  // namespace rheofeed::scene

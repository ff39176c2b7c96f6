// SPDX-License-Identifier: MIT
// Mesh files (assimp) and mass properties from closed surfaces, against analytic solids.
#include "rheofeed/scene/mesh.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <stdexcept>
#include <string>

namespace rheofeed::scene {
namespace {

namespace fs = std::filesystem;

const fs::path kData = RHEOFEED_IO_TEST_DATA;
const fs::path kDemoMeshes = fs::path(RHEOFEED_DEMO_DIR) / "meshes";

// assimp stores coordinates as float: ~6e-9 m on the 0.2 m offsets of the test box, i.e. a few
// 1e-7 of its 2 cm edges, so volume and inertia agree to a few 1e-6 relative.
constexpr double kFloatFile = 2e-5;
// Meshes built in double precision: only rounding in the sums.
constexpr double kExact = 1e-12;

// The test box: edges a x b x c (m) centred at (0.1, -0.05, 0.2) m.
constexpr double kA = 0.02, kB = 0.03, kC = 0.04;
const Vec3 kCentre{0.1, -0.05, 0.2};

void expectBox(const MassProperties& p, double density, double scale, double rel) {
  const double a = scale * kA, b = scale * kB, c = scale * kC;
  const double volume = a * b * c, mass = density * volume;
  EXPECT_NEAR(p.volume, volume, rel * volume);
  EXPECT_NEAR(p.mass, mass, rel * mass);
  const Vec3 centre = scale * kCentre;
  EXPECT_NEAR(p.centre_of_mass.x, centre.x, rel * a);
  EXPECT_NEAR(p.centre_of_mass.y, centre.y, rel * a);
  EXPECT_NEAR(p.centre_of_mass.z, centre.z, rel * a);
  const double ixx = mass / 12 * (b * b + c * c), iyy = mass / 12 * (a * a + c * c),
               izz = mass / 12 * (a * a + b * b);
  EXPECT_NEAR(p.inertia[0], ixx, rel * ixx);
  EXPECT_NEAR(p.inertia[4], iyy, rel * ixx);
  EXPECT_NEAR(p.inertia[8], izz, rel * ixx);
  for (int i : {1, 2, 3, 5, 6, 7}) EXPECT_NEAR(p.inertia[i], 0.0, rel * ixx) << "entry " << i;
}

// Expects `call` to throw E whose message contains every one of `parts`.
template <class E, class F>
void expectThrowWith(F call, std::initializer_list<std::string> parts) {
  try {
    call();
    ADD_FAILURE() << "no exception";
  } catch (const E& e) {
    for (const std::string& part : parts) {
      EXPECT_NE(std::string(e.what()).find(part), std::string::npos)
          << "message: " << e.what() << "\nmissing: " << part;
    }
  }
}

TEST(MeshFile, ObjBoxHasAnalyticVolumeCentreAndInertia) {
  const TriangleMesh mesh = loadTriangleMesh(kData / "box_20x30x40mm.obj");
  EXPECT_EQ(mesh.vertices.size(), 8u * 3);  // identical vertices joined
  EXPECT_EQ(mesh.triangles.size(), 12u * 3);
  EXPECT_EQ(mesh.source, (kData / "box_20x30x40mm.obj").string());
  expectBox(massProperties(mesh, 1000), 1000, 1, kFloatFile);
}

TEST(MeshFile, BinaryStlBoxHasAnalyticVolumeCentreAndInertia) {
  const TriangleMesh mesh = loadTriangleMesh(kData / "box_20x30x40mm.stl");
  EXPECT_EQ(mesh.vertices.size(), 8u * 3);  // STL repeats vertices per facet; joined
  expectBox(massProperties(mesh, 7800), 7800, 1, kFloatFile);
}

TEST(MeshFile, ScaleMultipliesCoordinatesSoMassGoesAsCubeAndInertiaAsFifthPower) {
  const double scale = 10;
  const TriangleMesh mesh = loadTriangleMesh(kData / "box_20x30x40mm.obj", scale);
  expectBox(massProperties(mesh, 1000), 1000, scale, kFloatFile);
  const MassProperties unit = massProperties(loadTriangleMesh(kData / "box_20x30x40mm.obj"), 1000);
  expectBox(scaleMassProperties(unit, scale), 1000, scale, kFloatFile);
}

TEST(MeshFile, MissingFileIsRefusedWithItsName) {
  expectThrowWith<std::runtime_error>([] { loadTriangleMesh(kData / "no_such_mesh.stl"); },
                                      {"no_such_mesh.stl", "file not found"});
}

TEST(MeshFile, GarbageBytesAreRefusedAsUnreadable) {
  expectThrowWith<std::runtime_error>([] { loadTriangleMesh(kData / "garbage.stl"); },
                                      {"garbage.stl", "cannot read"});
}

TEST(MeshFile, EmptyFileIsRefused) {
  expectThrowWith<std::runtime_error>([] { loadTriangleMesh(kData / "empty.obj"); },
                                      {"empty.obj", "empty"});
}

TEST(MeshFile, FileWithoutTrianglesIsRefused) {
  expectThrowWith<std::runtime_error>([] { loadTriangleMesh(kData / "lines_only.obj"); },
                                      {"lines_only.obj", "no triangles"});
}

TEST(MeshFile, NonFiniteCoordinateIsRefused) {
  // assimp reads the 1e999 of the file as infinity.
  expectThrowWith<std::invalid_argument>(
      [] { loadTriangleMesh(kData / "infinite_vertex.obj"); },
      {"infinite_vertex.obj", "face 1 of mesh 1", "non-finite coordinate (x = inf"});
  // A NaN in the box's last vertex: refused naming the first face that uses it, not merged away
  // with the identical-vertex join (it was: the box then loaded with 7 corners).
  expectThrowWith<std::invalid_argument>([] { loadTriangleMesh(kData / "box_nan_vertex.obj"); },
                                         {"box_nan_vertex.obj", "face 3 of mesh 1", "y = nan"});
}

TEST(MeshFile, BadScaleIsRefused) {
  expectThrowWith<std::invalid_argument>(
      [] { loadTriangleMesh(kData / "box_20x30x40mm.obj", 0.0); }, {"scale", "> 0"});
  expectThrowWith<std::invalid_argument>(
      [] { loadTriangleMesh(kData / "box_20x30x40mm.obj", INFINITY); }, {"scale"});
}

TEST(MassProperties, InsideOutMeshIsRefused) {
  const TriangleMesh mesh = loadTriangleMesh(kData / "box_inside_out.obj");
  expectThrowWith<std::invalid_argument>([&] { massProperties(mesh, 1000); },
                                         {"box_inside_out.obj", "inside out", "<= 0"});
}

TEST(MassProperties, OpenMeshIsRefused) {
  const TriangleMesh mesh = loadTriangleMesh(kData / "box_open.obj");
  expectThrowWith<std::invalid_argument>([&] { massProperties(mesh, 1000); },
                                         {"box_open.obj", "not closed"});
}

TEST(MassProperties, BadDensityAndIndicesAreRefused) {
  TriangleMesh mesh = loadTriangleMesh(kData / "box_20x30x40mm.obj");
  expectThrowWith<std::invalid_argument>([&] { massProperties(mesh, -1); }, {"density"});
  mesh.triangles[5] = 99;
  expectThrowWith<std::invalid_argument>([&] { massProperties(mesh, 1); }, {"vertex index 99"});
}

// A box rotated by 30 degrees about z has I = R diag(Ixx, Iyy, Izz) R^T: off-diagonal xy terms.
TEST(MassProperties, RotatedBoxHasRotatedInertiaTensor) {
  const TriangleMesh box = loadTriangleMesh(kData / "box_20x30x40mm.obj");
  const MassProperties straight = massProperties(box, 1000);
  TriangleMesh turned = translateMesh(box, -straight.centre_of_mass);
  const double t = kPi / 6, c = std::cos(t), s = std::sin(t);
  for (std::size_t i = 0; i < turned.vertices.size(); i += 3) {
    const double x = turned.vertices[i], y = turned.vertices[i + 1];
    turned.vertices[i] = c * x - s * y;
    turned.vertices[i + 1] = s * x + c * y;
  }
  const MassProperties p = massProperties(turned, 1000);
  const double ixx = straight.inertia[0], iyy = straight.inertia[4];
  const double tol = 1e-9 * ixx;
  EXPECT_NEAR(p.inertia[0], c * c * ixx + s * s * iyy, tol);
  EXPECT_NEAR(p.inertia[4], s * s * ixx + c * c * iyy, tol);
  EXPECT_NEAR(p.inertia[1], c * s * (ixx - iyy), tol);
  EXPECT_NEAR(p.inertia[3], p.inertia[1], 0.0);  // exactly symmetric
  EXPECT_NEAR(p.inertia[8], straight.inertia[8], tol);
  EXPECT_NEAR(norm(p.centre_of_mass), 0.0, 1e-12);
}

TEST(MassProperties, TranslationMovesOnlyTheCentreOfMass) {
  const TriangleMesh box = loadTriangleMesh(kData / "box_20x30x40mm.obj");
  const MassProperties p0 = massProperties(box, 1000);
  const MassProperties p1 = massProperties(translateMesh(box, {1, 2, 3}), 1000);
  EXPECT_NEAR(p1.centre_of_mass.x - p0.centre_of_mass.x, 1, kExact);
  EXPECT_NEAR(p1.centre_of_mass.z - p0.centre_of_mass.z, 3, kExact);
  EXPECT_NEAR(p1.volume, p0.volume, kExact * p0.volume * 1e3);
  for (int i = 0; i < 9; ++i) EXPECT_NEAR(p1.inertia[i], p0.inertia[i], 1e-9 * p0.inertia[0]);
}

// The generated demo part: a hexagonal prism (10 mm across flats) minus a 24-gon hole of
// circumradius 3 mm, 5 mm thick, in millimetres.
TEST(DemoMeshes, HexNutIsClosedWithPrismMinusHoleVolume) {
  const TriangleMesh nut = loadTriangleMesh(kDemoMeshes / "hex_nut_m6.obj");
  const double flats = 10, thickness = 5, r = 3;
  const double hexagon = 3 * std::sqrt(3.0) / 2 * std::pow(flats / std::sqrt(3.0), 2);
  const double hole = 24.0 / 2 * r * r * std::sin(2 * kPi / 24);
  const double volume = (hexagon - hole) * thickness;
  const MassProperties p = massProperties(nut, 1.0);
  EXPECT_NEAR(p.volume, volume, 1e-6 * volume);  // OBJ written with 6 decimals of a mm
  EXPECT_NEAR(norm(p.centre_of_mass), 0.0, 1e-6);
  // Symmetric about z: Ixx = Iyy (a hexagon's in-plane inertia is isotropic).
  EXPECT_NEAR(p.inertia[0], p.inertia[4], 1e-6 * p.inertia[0]);
  EXPECT_GT(p.inertia[8], p.inertia[0]);  // flat: the axis has the largest moment
}

// The nut's convex hull is the plain hexagonal prism: its hole and the points that cut its
// sides are dropped, its coplanar faces merged (6 sides of 2 triangles, 2 hexagons of 4), and
// it is a closed outward solid of the prism's volume with every nut vertex inside or on it.
TEST(DemoMeshes, HexNutsConvexHullIsThePlainPrism) {
  const TriangleMesh nut = loadTriangleMesh(kDemoMeshes / "hex_nut_m6.obj");
  const TriangleMesh hull = convexHull(nut);
  const double flats = 10, thickness = 5;
  const double volume = 3 * std::sqrt(3.0) / 2 * std::pow(flats / std::sqrt(3.0), 2) * thickness;
  EXPECT_EQ(hull.vertices.size() / 3, 12u);
  EXPECT_EQ(hull.triangles.size() / 3, 20u);
  const MassProperties p = massProperties(hull, 1.0);  // throws if open or inside out
  EXPECT_NEAR(p.volume, volume, 1e-6 * volume);
  EXPECT_NEAR(norm(p.centre_of_mass), 0.0, 1e-6);
  EXPECT_NE(hull.source.find("hex_nut_m6.obj"), std::string::npos) << hull.source;
  // Every nut vertex lies on the inner side of every hull face's plane.
  for (std::size_t t = 0; t < hull.triangles.size(); t += 3) {
    auto at = [&](int k) {
      const double* v = &hull.vertices[3 * static_cast<std::size_t>(hull.triangles[t + k])];
      return Vec3{v[0], v[1], v[2]};
    };
    const Vec3 n = cross(at(1) - at(0), at(2) - at(0));
    for (std::size_t v = 0; v < nut.vertices.size(); v += 3) {
      const Vec3 x{nut.vertices[v], nut.vertices[v + 1], nut.vertices[v + 2]};
      EXPECT_LE(dot(x - at(0), n) / norm(n), 1e-6) << "nut vertex " << v / 3 << ", face " << t / 3;
    }
  }
}

// A hull of points on one plane has no volume: refused, naming the mesh and quoting qhull.
TEST(MeshHull, FlatOrTooFewVerticesAreRefusedByName) {
  TriangleMesh flat;
  flat.source = "flat.stl";
  flat.vertices = {0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0, 0.5, 0.5, 0};
  flat.triangles = {0, 1, 2, 0, 2, 3};
  expectThrowWith<std::invalid_argument>([&] { convexHull(flat); },
                                         {"flat.stl", "no convex hull", "qhull"});
  flat.vertices.resize(9);
  expectThrowWith<std::invalid_argument>([&] { convexHull(flat); },
                                         {"flat.stl", "at least 4 vertices", "has 3"});
  TriangleMesh bad = flat;
  bad.vertices = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, NAN};
  expectThrowWith<std::invalid_argument>([&] { convexHull(bad); }, {"vertex 3", "non-finite"});
}

TEST(DemoMeshes, BowlLoadsAsClosedShellsWithinTheCommitBudget) {
  const fs::path file = kDemoMeshes / "vibratory_bowl.stl";
  const TriangleMesh bowl = loadTriangleMesh(file, 0.001);
  const MassProperties p = massProperties(bowl, 1.0);  // both shells closed and outward
  // Body alone: the wall ring plus the floor, bounded by the 155 mm x 100 mm cylinder.
  const double wall = kPi * (0.155 * 0.155 - 0.15 * 0.15) * 0.1;
  EXPECT_GT(p.volume, wall);
  EXPECT_LT(p.volume, kPi * 0.155 * 0.155 * 0.1);
  EXPECT_NEAR(boundingRadius(translateMesh(bowl, {0, 0, -0.1})), std::hypot(0.155, 0.1), 1e-6);
  EXPECT_LT(fs::file_size(file) + fs::file_size(kDemoMeshes / "hex_nut_m6.obj"), 1u << 20);
}

}  // namespace
}  // namespace rheofeed::scene

// SPDX-License-Identifier: MIT
// The narrow phase against triangle meshes (narrow_phase.hpp): a part touching more triangles
// than the contacts kept per pair must still be held over its whole footprint and on every
// face it touches. The numbers are the geometry's own: a cylinder of radius 5 mm lying on a
// floor tessellated in 1 mm triangles has its contacts on a disc 10 mm across, and at rest its
// centre is half its length above the floor.
#include <gtest/gtest.h>

#include <ode/ode.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <functional>
#include <vector>

#include "rheofeed/contact_collider.hpp"
#include "rheofeed/feeder_set.hpp"
#include "rheofeed/narrow_phase.hpp"

namespace rheofeed::test {
namespace {

constexpr double kRadius = 0.005;  // m
constexpr double kLength = 0.005;  // m, along the cylinder's axis (+z: lying flat)

// A square floor (top z = 0, side `side` m, centred on the origin) in cells of `cell` m, two
// triangles each, counter-clockwise from +z; and, when `wall`, a vertical wall in the plane
// x = wall_x facing -x, in the same cells. The arrays must outlive the geom.
struct MeshData {
  std::vector<dReal> vertices;
  std::vector<dTriIndex> indices;
  dTriMeshDataID data = nullptr;
  ~MeshData() {
    if (data) dGeomTriMeshDataDestroy(data);
  }
  int vertex(double x, double y, double z) {
    vertices.insert(vertices.end(), {x, y, z});
    return static_cast<int>(vertices.size() / 3) - 1;
  }
  void quad(int a, int b, int c, int d) {  // counter-clockwise seen from outside
    indices.insert(indices.end(), {static_cast<dTriIndex>(a), static_cast<dTriIndex>(b),
                                   static_cast<dTriIndex>(c), static_cast<dTriIndex>(a),
                                   static_cast<dTriIndex>(c), static_cast<dTriIndex>(d)});
  }
  dGeomID build(dSpaceID space) {
    data = dGeomTriMeshDataCreate();
    dGeomTriMeshDataBuildDouble(data, vertices.data(), 3 * sizeof(dReal),
                                static_cast<int>(vertices.size() / 3), indices.data(),
                                static_cast<int>(indices.size()), 3 * sizeof(dTriIndex));
    return dCreateTriMesh(space, data, nullptr, nullptr, nullptr);
  }
};

void addFloor(MeshData& mesh, double side, double cell) {
  const int n = static_cast<int>(std::lround(side / cell));
  for (int i = 0; i < n; ++i) {
    for (int j = 0; j < n; ++j) {
      const double x = -0.5 * side + i * cell, y = -0.5 * side + j * cell;
      mesh.quad(mesh.vertex(x, y, 0), mesh.vertex(x + cell, y, 0),
                mesh.vertex(x + cell, y + cell, 0), mesh.vertex(x, y + cell, 0));
    }
  }
}

void addWall(MeshData& mesh, double wall_x, double side, double cell) {
  const int n = static_cast<int>(std::lround(side / cell));
  for (int i = 0; i < n; ++i) {
    for (int k = 0; k < n / 2; ++k) {
      const double y = -0.5 * side + i * cell, z = -0.25 * side + k * cell;
      mesh.quad(mesh.vertex(wall_x, y, z), mesh.vertex(wall_x, y, z + cell),
                mesh.vertex(wall_x, y + cell, z + cell), mesh.vertex(wall_x, y + cell, z));
    }
  }
}

// A steel cylinder (radius kRadius, length kLength, axis +z) on a new body in `world`.
dBodyID addSteelCylinder(dWorldID world, dSpaceID space) {
  dBodyID body = dBodyCreate(world);
  dMass mass;
  dMassSetCylinder(&mass, 7850, 3, kRadius, kLength);
  dBodySetMass(body, &mass);
  dGeomSetBody(dCreateCylinder(space, kRadius, kLength), body);
  return body;
}

// Steps `world` `steps` times at h through a ContactCollider over `space` driving `feeders`;
// `each_step(step)`, when given, runs before each step.
void runCollider(dWorldID world, dSpaceID space, FeederSet& feeders,
                 const ContactCollider::Settings& settings, int steps, double h,
                 const std::function<void(int)>& each_step = {}) {
  ContactCollider collider(world, feeders, settings);
  for (int step = 0; step < steps; ++step) {
    if (each_step) each_step(step);
    collider.collide(space, step * h, h);
    dWorldQuickStep(world, h);
  }
}

// A world (gravity 9.81 m/s^2 along -z) whose simple space holds a floor of 1 mm triangles,
// `side` m square, and a steel cylinder lying on it at (x, y); run() steps it through a
// ContactCollider at h.
struct CylinderOnMeshFloor {
  dWorldID world = dWorldCreate();
  dSpaceID space = dSimpleSpaceCreate(nullptr);
  MeshData mesh;
  dBodyID body = nullptr;
  CylinderOnMeshFloor(double side, double x, double y) {
    dWorldSetGravity(world, 0, 0, -9.81);
    addFloor(mesh, side, 0.001);
    mesh.build(space);
    body = addSteelCylinder(world, space);
    dBodySetPosition(body, x, y, 0.5 * kLength);
  }
  ~CylinderOnMeshFloor() {  // geoms before the mesh data (a member, destroyed after this)
    dSpaceDestroy(space);
    dWorldDestroy(world);
  }
  void run(const ContactCollider::Settings& settings, int steps, double h) {
    FeederSet feeders;
    runCollider(world, space, feeders, settings, steps, h);
  }
};

struct Extent {
  double x = 0, y = 0;
};
// The widths in x and in y of the contacts' positions.
Extent extentOf(const dContactGeom* c, int n) {
  if (n == 0) return {};
  double x0 = c[0].pos[0], x1 = x0, y0 = c[0].pos[1], y1 = y0;
  for (int i = 1; i < n; ++i) {
    x0 = std::min(x0, c[i].pos[0]);
    x1 = std::max(x1, c[i].pos[0]);
    y0 = std::min(y0, c[i].pos[1]);
    y1 = std::max(y1, c[i].pos[1]);
  }
  return {x1 - x0, y1 - y0};
}

TEST(NarrowPhase, CylinderOnAFinelyTessellatedFloorKeepsContactsAcrossItsFootprint) {
  dInitODE2(0);
  dSpaceID space = dSimpleSpaceCreate(nullptr);
  MeshData mesh;
  addFloor(mesh, 0.04, 0.001);
  dGeomID floor = mesh.build(space);
  dGeomID cylinder = dCreateCylinder(space, kRadius, kLength);
  dGeomSetPosition(cylinder, 0.0003, 0.0002, 0.5 * kLength - 1e-4);  // 0.1 mm into the floor

  MeshCollisionScratch scratch;
  std::array<dContactGeom, 8> kept{};
  const int n = collideSpanning(cylinder, floor, 8, kept.data(), sizeof(dContactGeom), scratch);
  ASSERT_EQ(n, 8);
  // ODE adds shallow contacts with horizontal normals at the edges of coplanar triangles; the
  // floor's own (normal +-z, 0.1 mm deep) hold the part: at least 4 of them, reaching across
  // at least 80 % of the 10 mm disc both ways.
  std::vector<dContactGeom> on_floor;
  for (int i = 0; i < n; ++i) {
    const dContactGeom& c = kept[static_cast<std::size_t>(i)];
    if (std::fabs(c.normal[2]) > 0.999) on_floor.push_back(c);
  }
  ASSERT_GE(on_floor.size(), 4u);
  const Extent e = extentOf(on_floor.data(), static_cast<int>(on_floor.size()));
  EXPECT_GT(e.x, 0.8 * 2 * kRadius);
  EXPECT_GT(e.y, 0.8 * 2 * kRadius);
  for (const dContactGeom& c : on_floor) EXPECT_NEAR(c.depth, 1e-4, 1e-6);

  // Why: ODE's own first 8 cover only a corner of the footprint (the premise of the fix).
  std::array<dContactGeom, 8> first{};
  const int m = dCollide(cylinder, floor, 8, first.data(), sizeof(dContactGeom));
  const Extent f = extentOf(first.data(), m);
  EXPECT_LT(std::min(f.x, f.y), 0.5 * 2 * kRadius)
      << "ODE's cylinder-trimesh collider no longer stops at the first contacts: "
         "narrow_phase.hpp's comment is out of date";
  dSpaceDestroy(space);
}

TEST(NarrowPhase, CylinderInACornerKeepsAContactOnTheFloorAndOnTheWall) {
  dInitODE2(0);
  dSpaceID space = dSimpleSpaceCreate(nullptr);
  MeshData mesh;
  addFloor(mesh, 0.04, 0.001);
  addWall(mesh, kRadius - 1e-4, 0.04, 0.001);  // the rim 0.1 mm into a wall at x = 4.9 mm
  dGeomID corner = mesh.build(space);
  dGeomID cylinder = dCreateCylinder(space, kRadius, kLength);
  dGeomSetPosition(cylinder, 0, 0, 0.5 * kLength - 1e-4);

  MeshCollisionScratch scratch;
  std::array<dContactGeom, 8> kept{};
  const int n = collideSpanning(cylinder, corner, 8, kept.data(), sizeof(dContactGeom), scratch);
  int on_floor = 0, on_wall = 0;
  for (int i = 0; i < n; ++i) {
    const dContactGeom& c = kept[static_cast<std::size_t>(i)];
    if (std::fabs(c.normal[2]) > 0.99) ++on_floor;
    if (std::fabs(c.normal[0]) > 0.99) ++on_wall;
  }
  EXPECT_GE(on_floor, 3);  // three points at least hold a flat part up
  EXPECT_GE(on_wall, 1);
  dSpaceDestroy(space);
}

// The whole chain at the method's step: a cylinder lying on the fine floor, through
// ContactCollider at h = 0.01 s for 2 s, stays on it. ODE's cylinder-trimesh contacts rock a
// 3 g cylinder by 2-8 degrees at this step even on a floor of two triangles, and it may lose its
// contacts for a step, falling g h^2 = 1 mm: its centre never goes lower than that below half its
// length above the floor (with 8 contacts cut by ODE it fell through).
TEST(NarrowPhase, CylinderStaysOnAFinelyTessellatedFloorAtTheRheonomicStep) {
  dInitODE2(0);
  CylinderOnMeshFloor scene(0.04, 0.0003, 0.0002);
  dBodySetPosition(scene.body, 0.0003, 0.0002, 0.5 * kLength - 5e-5);  // touching from the start
  FeederSet feeders;
  ContactCollider collider(scene.world, feeders, ContactCollider::Settings{});
  const double h = 0.01, g = 9.81;
  double lowest = 1;  // m
  for (int step = 0; step < 200; ++step) {
    collider.collide(scene.space, step * h, h);
    dWorldQuickStep(scene.world, h);
    lowest = std::min(lowest, static_cast<double>(dBodyGetPosition(scene.body)[2]));
  }
  EXPECT_GT(lowest, 0.5 * kLength - g * h * h);
}

// Speculative contacts against a mesh the part already touches: a cylinder sliding down a mesh
// wall at 1 m/s, h = 0.01 s (10 mm per step), onto a 4 mm shelf of the same mesh. The wall's
// contacts must not stop the sweep that catches the shelf: the cylinder lands on the shelf's top
// (centre half its length above z = 0) instead of passing through.
TEST(NarrowPhase, SpeculativeSweepCatchesAShelfOfTheMeshThePartSlidesDown) {
  dInitODE2(0);
  dWorldID world = dWorldCreate();
  dWorldSetGravity(world, 0, 0, -9.81);
  dSpaceID space = dSimpleSpaceCreate(nullptr);
  MeshData mesh;
  const double wall_x = kRadius - 1e-4, lo = -0.02, top = 0.06, shelf = 0.004;
  // the wall, facing -x, from z = -shelf to top
  mesh.quad(mesh.vertex(wall_x, lo, -shelf), mesh.vertex(wall_x, lo, top),
            mesh.vertex(wall_x, -lo, top), mesh.vertex(wall_x, -lo, -shelf));
  // the shelf: top face (z = 0, facing +z) and bottom face (z = -shelf, facing -z)
  mesh.quad(mesh.vertex(lo, lo, 0), mesh.vertex(wall_x, lo, 0), mesh.vertex(wall_x, -lo, 0),
            mesh.vertex(lo, -lo, 0));
  mesh.quad(mesh.vertex(lo, lo, -shelf), mesh.vertex(lo, -lo, -shelf),
            mesh.vertex(wall_x, -lo, -shelf), mesh.vertex(wall_x, lo, -shelf));
  mesh.build(space);
  dBodyID body = addSteelCylinder(world, space);
  dBodySetPosition(body, 0, 0, 0.5 * kLength + 0.025);
  dBodySetLinearVel(body, 0.02, 0, -1.0);  // pressed on the wall, falling
  {
    FeederSet feeders;
    ContactCollider::Settings settings;
    settings.speculative = true;
    settings.default_surface.mu = 0;
    runCollider(world, space, feeders, settings, 50, 0.01);
  }
  const dReal* p = dBodyGetPosition(body);
  EXPECT_NEAR(p[2], 0.5 * kLength, 5e-4);  // m: on the shelf, not through it
  dSpaceDestroy(space);
  dWorldDestroy(world);
}

// The other side of that sweep: a part sliding on a mesh floor at h = 0.01 s is swept every step
// (gravity alone moves it 1 mm per step), and the rays must not hold it on the floor it touches:
// a cylinder launched at 0.3 m/s with mu = 0.3 stops after v^2 / (2 mu g) = 15.3 mm, as Coulomb
// friction alone would stop it (0.5 s later; after it, ODE's cylinder-trimesh contacts rock it
// by a few degrees, a few mm/s at its centre, so its speed is not checked).
TEST(NarrowPhase, PartSlidingOnAMeshFloorStopsWhereCoulombFrictionStopsIt) {
  dInitODE2(0);
  CylinderOnMeshFloor scene(0.08, -0.02, 0.0002);
  const double v0 = 0.3, mu = 0.3, g = 9.81;
  dBodySetLinearVel(scene.body, v0, 0, 0);
  ContactCollider::Settings settings;
  settings.speculative = true;
  settings.default_surface.mu = mu;
  scene.run(settings, 50, 0.01);
  const double expected = v0 * v0 / (2 * mu * g);  // m
  EXPECT_NEAR(dBodyGetPosition(scene.body)[0] + 0.02, expected, 0.1 * expected);
}

// A hexagonal prism as a triangle mesh, the blank of an M6 nut without its hole: 10 mm across
// flats, 5 mm thick, centred on the origin, axis +z; every triangle has its own three vertices
// (as in an STL file), side faces as two triangles, the ends as fans of four.
void addHexPrism(MeshData& mesh) {
  const double r = 0.005 / std::cos(M_PI / 6), h = 0.0025;
  double x[6], y[6];
  for (int k = 0; k < 6; ++k) {
    x[k] = r * std::cos(M_PI / 3 * k);
    y[k] = r * std::sin(M_PI / 3 * k);
  }
  for (int k = 0; k < 6; ++k) {
    const int j = (k + 1) % 6;
    mesh.quad(mesh.vertex(x[k], y[k], -h), mesh.vertex(x[j], y[j], -h), mesh.vertex(x[j], y[j], h),
              mesh.vertex(x[k], y[k], h));
  }
  for (int k = 1; k < 5; ++k) {
    const auto tri = [&](int a, int b, int c) {
      mesh.indices.insert(mesh.indices.end(), {static_cast<dTriIndex>(a), static_cast<dTriIndex>(b),
                                               static_cast<dTriIndex>(c)});
    };
    tri(mesh.vertex(x[0], y[0], h), mesh.vertex(x[k], y[k], h), mesh.vertex(x[k + 1], y[k + 1], h));
    tri(mesh.vertex(x[0], y[0], -h), mesh.vertex(x[k + 1], y[k + 1], -h),
        mesh.vertex(x[k], y[k], -h));
  }
}

// An M6 nut blank with its 6 mm hole, as demos/meshes/hex_nut_m6.obj (generate_meshes.cpp): a
// profile (hole and hexagon, 5 mm thick) swept through 24 polar angles, the hexagon's corners at
// multiples of 60 degrees; shared vertices, 192 triangles, counter-clockwise from outside. Each
// flat face is a fan of 48 thin triangles round the hole.
void addHoledNut(MeshData& mesh) {
  constexpr int kAngles = 24;
  const double h = 0.0025, hole = 0.003;
  std::array<std::array<int, 4>, kAngles> ring{};
  for (int j = 0; j < kAngles; ++j) {
    const double phi = 2 * M_PI * j / kAngles;
    const double r = 0.005 / std::cos(std::fmod(phi, M_PI / 3) - M_PI / 6);
    const double c = std::cos(phi), s = std::sin(phi);
    ring[j] = {mesh.vertex(hole * c, hole * s, -h), mesh.vertex(r * c, r * s, -h),
               mesh.vertex(r * c, r * s, h), mesh.vertex(hole * c, hole * s, h)};
  }
  for (int j = 0; j < kAngles; ++j) {
    const int k = (j + 1) % kAngles;
    for (int p = 0; p < 4; ++p) {
      const int q = (p + 1) % 4;
      mesh.quad(ring[j][p], ring[k][p], ring[k][q], ring[j][q]);
    }
  }
}

// A body for a mesh nut blank (`nut`, addHexPrism) in `world`: steel, its mass and inertia
// those of a cylinder of the hexagon's area, lying flat on a floor at z = 0 at (x, y).
dBodyID addNutBody(dWorldID world, dGeomID nut, double x, double y) {
  dBodyID body = dBodyCreate(world);
  dMass mass;
  dMassSetCylinder(&mass, 7850, 3, 0.00525, 0.005);
  dBodySetMass(body, &mass);
  dGeomSetBody(nut, body);
  dBodySetPosition(body, x, y, 0.0025);
  return body;
}

// The edge tables of a floor of 1 mm cells (two triangles each, every triangle with its own
// vertices) and of a hexagonal prism: the floor's inner edges are smooth (coplanar triangles),
// its border is not (one triangle); the prism's edges are smooth inside its flat faces and
// sharp at its 60 and 90 degree edges. Checked edge by edge against the geometry.
TEST(NarrowPhase, MeshEdgesTellTheFloorsSeamsFromItsBorderAndCorners) {
  dInitODE2(0);
  dSpaceID space = dSimpleSpaceCreate(nullptr);
  MeshData mesh;
  addFloor(mesh, 0.004, 0.001);  // 4 x 4 cells, 32 triangles
  MeshData prism;
  addHexPrism(prism);
  const dGeomID floor = mesh.build(space);
  const dGeomID nut = prism.build(space);
  const MeshEdges floor_edges(floor), nut_edges(nut);
  ASSERT_EQ(floor_edges.triangles(), 32);
  // Triangle 2i is (a, b, c) of cell i = (ix, iy), 2i + 1 is (a, c, d): edge 0 of 2i is the
  // cell's bottom (y = y0), edge 1 its right side, edge 2 the diagonal; edge 0 of 2i + 1 the
  // diagonal, 1 the top, 2 the left side.
  for (int ix = 0; ix < 4; ++ix) {
    for (int iy = 0; iy < 4; ++iy) {
      const int t = 2 * (4 * ix + iy);
      EXPECT_EQ(floor_edges.smooth(t, 0), iy > 0) << ix << " " << iy;
      EXPECT_EQ(floor_edges.smooth(t, 1), ix < 3) << ix << " " << iy;
      EXPECT_TRUE(floor_edges.smooth(t, 2));
      EXPECT_TRUE(floor_edges.smooth(t + 1, 0));
      EXPECT_EQ(floor_edges.smooth(t + 1, 1), iy < 3) << ix << " " << iy;
      EXPECT_EQ(floor_edges.smooth(t + 1, 2), ix > 0) << ix << " " << iy;
    }
  }
  // The prism: 12 side triangles (each side's diagonal smooth, its 90 degree rims and the 60
  // degree edges between sides sharp), 8 end triangles (the fans' inner edges smooth).
  ASSERT_EQ(nut_edges.triangles(), 20);
  int smooth = 0;
  for (int t = 0; t < 20; ++t) {
    for (int k = 0; k < 3; ++k) smooth += nut_edges.smooth(t, k) ? 1 : 0;
  }
  EXPECT_EQ(smooth, 2 * (6 + 2 * 3));  // 6 side diagonals, 3 inner edges per fan, 2 sides each
  EXPECT_FALSE(floor_edges.smooth(32, 0));
  EXPECT_FALSE(floor_edges.smooth(-1, 0));
  dSpaceDestroy(space);
}

// collideSpanning takes dCollide's flags: the low 16 bits are the room in `out`, the high bits
// options (CONTACTS_UNIMPORTANT). A 1 cm box resting on 1 mm triangles touches dozens of them;
// it must get at most the count asked for, with CONTACTS_UNIMPORTANT or a high bit set too, and
// nothing at all (and nothing written) for a count of 0. The records past the count are checked
// untouched.
TEST(NarrowPhase, CollideSpanningWritesNoMoreThanTheCountInDCollidesFlags) {
  dInitODE2(0);
  dSpaceID space = dSimpleSpaceCreate(nullptr);
  MeshData mesh;
  addFloor(mesh, 0.04, 0.001);
  const dGeomID floor = mesh.build(space);
  dWorldID world = dWorldCreate();
  dBodyID body = dBodyCreate(world);
  const dGeomID box = dCreateBox(space, 0.01, 0.01, 0.01);
  dGeomSetBody(box, body);
  dBodySetPosition(body, 0, 0, 0.0049);  // 0.1 mm into the floor
  MeshCollisionScratch scratch;
  constexpr double kUntouched = -12345;
  for (const unsigned flags :
       {4u, 4u | static_cast<unsigned>(CONTACTS_UNIMPORTANT), 0x10004u, 0u}) {
    std::vector<dContactGeom> out(64);
    for (dContactGeom& c : out) c.depth = kUntouched;
    const int n = collideSpanning(box, floor, static_cast<int>(flags), out.data(),
                                  sizeof(dContactGeom), scratch);
    const int room = static_cast<int>(flags & 0xffffu);
    EXPECT_EQ(n, room) << std::hex << flags;  // the box touches more than 4 triangles
    for (int i = room; i < 64; ++i) ASSERT_EQ(out[i].depth, kUntouched) << std::hex << flags;
  }
  dSpaceDestroy(space);
  dWorldDestroy(world);
}

// The edge tables are cached by mesh data (MeshCollisionScratch), whose address ODE may give to
// another mesh once one is destroyed. A floor with a ridge across its middle, with the same
// triangle count and the same first and last triangles as a flat one, must not be taken for it;
// forget() drops a table.
TEST(NarrowPhase, EdgeTablesTellAnotherMeshOfTheSameSizeAndAreForgotten) {
  dInitODE2(0);
  dSpaceID space = dSimpleSpaceCreate(nullptr);
  MeshData flat, ridged;
  addFloor(flat, 0.01, 0.001);
  addFloor(ridged, 0.01, 0.001);
  for (std::size_t v = 0; v < ridged.vertices.size(); v += 3) {
    if (std::abs(ridged.vertices[v]) < 1e-9) ridged.vertices[v + 2] = 0.002;  // x = 0: 2 mm up
  }
  const dGeomID flat_geom = flat.build(space), ridged_geom = ridged.build(space);
  const MeshEdges flat_edges(flat_geom), ridged_edges(ridged_geom);
  ASSERT_EQ(flat_edges.triangles(), ridged_edges.triangles());
  EXPECT_TRUE(flat_edges.describes(flat_geom));
  EXPECT_FALSE(flat_edges.describes(ridged_geom));
  int sharp_flat = 0, sharp_ridged = 0;
  for (int t = 0; t < flat_edges.triangles(); ++t) {
    for (int k = 0; k < 3; ++k) {
      sharp_flat += flat_edges.smooth(t, k) ? 0 : 1;
      sharp_ridged += ridged_edges.smooth(t, k) ? 0 : 1;
    }
  }
  EXPECT_GT(sharp_ridged, sharp_flat);  // the ridge's edges turn by 63 degrees
  MeshCollisionScratch scratch;
  scratch.edgesOf(flat_geom);
  ASSERT_EQ(scratch.edges.size(), 1u);
  scratch.forget(dGeomTriMeshGetTriMeshDataID(flat_geom));
  EXPECT_TRUE(scratch.edges.empty());
  dSpaceDestroy(space);
}

// A world (gravity 9.81 m/s^2 along -z) whose hash space holds a floor of 1 mm triangles, `side` m
// square, and a mesh nut blank (built by `add_nut`) lying flat on it at (x, 0.3 mm) on a new body.
struct NutOnMeshFloor {
  dWorldID world = dWorldCreate();
  dSpaceID space = dHashSpaceCreate(nullptr);
  MeshData floor_mesh, nut_mesh;
  dGeomID floor = nullptr;
  dBodyID body = nullptr;
  NutOnMeshFloor(double side, void (*add_nut)(MeshData&), double x) {
    dInitODE2(0);
    dWorldSetGravity(world, 0, 0, -9.81);
    addFloor(floor_mesh, side, 0.001);
    floor = floor_mesh.build(space);
    add_nut(nut_mesh);
    body = addNutBody(world, nut_mesh.build(space), x, 0.0003);
  }
  ~NutOnMeshFloor() {  // geoms before the mesh data (members, destroyed after this)
    dSpaceDestroy(space);
    dWorldDestroy(world);
  }
};

// A mesh part on a mesh floor at the rheonomic step: at h = 0.01 s gravity alone sinks a resting
// part 1 mm per step before the contacts push it back, and ODE's trimesh-trimesh test then
// finds the floor triangles' edges poking past the part's side faces, and gives those contacts
// the side faces' horizontal normals: the part snags on seams of a flat floor. A hexagonal nut
// blank (mesh) on a belt of 1 mm triangles moving at 0.1 m/s must be carried at the belt's
// speed once it has caught up (from rest it reaches it in v / (mu g) = 34 ms); it is measured
// over the last 1.5 s of 2 s. With ODE's normals it was carried at 65 % of the belt's speed.
TEST(NarrowPhase, MeshNutOnATessellatedBeltIsCarriedAtTheBeltSpeed) {
  NutOnMeshFloor scene(0.6, addHexPrism, -0.2);
  const double speed = 0.1, mu = 0.3, h = 0.01;
  FeederSet feeders;
  feeders.add(scene.floor, MotionLaw::belt({1, 0, 0}, speed));
  ContactCollider::Settings settings;
  settings.default_surface.mu = mu;
  double x_start = 0;
  runCollider(scene.world, scene.space, feeders, settings, 200, h, [&](int step) {
    if (step == 50) x_start = dBodyGetPosition(scene.body)[0];
  });
  // the nut's mean velocity over simulated steps 50-200 (m/s of simulated time)
  const double carried_velocity = (dBodyGetPosition(scene.body)[0] - x_start) / (150 * h);
  EXPECT_NEAR(carried_velocity, speed, 0.03 * speed);
  EXPECT_NEAR(dBodyGetPosition(scene.body)[2], 0.0025, 0.001);  // still on the belt
}

// A mesh nut blank lying on `floor` (top at z = 0) slides without friction (mu = 0) at
// (0.1, 0.03) m/s for 1 s at h = 0.01 s; returns its velocity at the end. Newton's first law:
// nothing horizontal acts on it, so it must keep that velocity.
std::array<double, 3> slideFrictionless(dWorldID world, dSpaceID space, dGeomID nut) {
  dBodyID body = addNutBody(world, nut, -0.1, 0.0003);
  dBodySetLinearVel(body, 0.1, 0.03, 0);
  FeederSet feeders;
  ContactCollider::Settings settings;
  settings.default_surface.mu = 0;
  runCollider(world, space, feeders, settings, 100, 0.01);
  const dReal* v = dBodyGetLinearVel(body);
  return {v[0], v[1], v[2]};
}

// On a floor of 1 mm triangles, ODE's seam contacts (side-face normals) stopped the nut within
// 0.1 s; on an ODE box, which the correction must leave alone (the nut's own mesh is not a
// fixture), it slides straight on. Both keep the velocity to 1 %.
TEST(NarrowPhase, FrictionlessMeshNutKeepsItsVelocityOnAMeshFloorAndOnABox) {
  dInitODE2(0);
  for (const bool mesh_floor : {true, false}) {
    dWorldID world = dWorldCreate();
    dWorldSetGravity(world, 0, 0, -9.81);
    dSpaceID space = dHashSpaceCreate(nullptr);
    MeshData floor_mesh, nut_mesh;
    if (mesh_floor) {
      addFloor(floor_mesh, 0.4, 0.001);
      floor_mesh.build(space);
    } else {
      dGeomSetPosition(dCreateBox(space, 0.4, 0.4, 0.02), 0, 0, -0.01);
    }
    addHexPrism(nut_mesh);
    const std::array<double, 3> v = slideFrictionless(world, space, nut_mesh.build(space));
    EXPECT_NEAR(v[0], 0.1, 1e-3) << (mesh_floor ? "mesh floor" : "box floor");
    EXPECT_NEAR(v[1], 0.03, 1e-3) << (mesh_floor ? "mesh floor" : "box floor");
    dSpaceDestroy(space);
    dWorldDestroy(world);
  }
}

// A nut lying flat on a flat floor of 1 mm triangles: its bottom face and the floor are coplanar.
// Sliding without friction, nothing can tip it: the floor pushes straight up, on a footprint round
// its centre of mass. But ODE's trimesh-trimesh test finds contacts only where triangles cross:
// when rounding lifts one side of the face a nanometre, that side has none, gravity swings the
// free side down by g h in the step, and the nut spun at 13-18 rad/s (8 of 100 steps), landing
// up to 1 mm deep. Resting contacts (ContactCollider, Settings::speculative) keep the previous
// step's points over the floor as contacts across their gap. Checked each step of 1 s at
// h = 0.01 s: no spin above 0.5 rad/s (an edge of the nut then moves 2.5 mm/s); from 0.2 s on
// the nut flat on the floor, its centre within 0.05 mm of its half thickness (the first step has
// no history: the nut, placed touching, sinks g h^2 = 1 mm and ERP lifts it back by a fifth of
// the rest each step); and its velocity kept to 1e-3 m/s.
TEST(NarrowPhase, FrictionlessMeshNutSlidesFlatOverTheSeamsWithoutSpinning) {
  NutOnMeshFloor scene(0.4, addHoledNut, -0.1);
  const dBodyID body = scene.body;
  dBodySetLinearVel(body, 0.1, 0.03, 0);
  FeederSet feeders;
  ContactCollider::Settings settings;
  settings.default_surface.mu = 0;
  settings.speculative = true;
  double max_spin = 0, max_height_error = 0;
  int spinning_steps = 0;
  runCollider(scene.world, scene.space, feeders, settings, 101, 0.01, [&](int step) {
    if (step == 0) return;  // the state after step - 1
    const dReal* w = dBodyGetAngularVel(body);
    const double spin = std::sqrt(w[0] * w[0] + w[1] * w[1] + w[2] * w[2]);  // rad/s
    max_spin = std::max(max_spin, spin);
    spinning_steps += spin > 0.5 ? 1 : 0;
    if (step > 20) {
      max_height_error = std::max(max_height_error, std::abs(dBodyGetPosition(body)[2] - 0.0025));
    }
  });
  EXPECT_LT(max_spin, 0.5) << spinning_steps << " of 100 steps above 0.5 rad/s";
  EXPECT_LT(max_height_error, 5e-5);
  const dReal* v = dBodyGetLinearVel(body);
  EXPECT_NEAR(v[0], 0.1, 1e-3);
  EXPECT_NEAR(v[1], 0.03, 1e-3);
}

}  // namespace
}  // namespace rheofeed::test

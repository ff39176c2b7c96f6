// SPDX-License-Identifier: MIT
// Writes a built-in scene (common/builtin_scenes.hpp) as a scene file on stdout, with the
// comments that say what its objects are, the way the files of demos/scenes/ that come from code
// are made:
//   dump_builtin_scene bowl_feeder_fill > demos/scenes/bowl_feeder_fill.json
#include <CLI/CLI.hpp>
#include <cstdio>
#include <iostream>
#include <stdexcept>
#include <string>

#include "common/builtin_scenes.hpp"
#include "rheofeed/output/output.hpp"
#include "rheofeed/scene/scene_io.hpp"

namespace {

using rheofeed::scene::Scene;

// The local law's point-mass results of the shipped scenes, relative to demos/scenes/.
constexpr const char* kDriftTable = "tables/drift_table.json";
// The end of both scenes' comments: what kDriftTable is, and where the numbers are.
const std::string kDriftTableNote =
    "drift_table: the local law's point-mass results of the shipped scenes "
    "(tables/drift_table.json, written by `rheofeed run SCENE --drift-table "
    "demos/scenes/tables/drift_table.json`), so that a first run skips those model runs. Numbers "
    "and commands: demos/results/bowl_feeder.md.";

// Inserts `"comment": text,` as the first member of the object that `anchor` opens (anchor ends
// with '{') or, when it does not end with '{', on the line after `anchor` (a member line), at
// that line's indentation.
void insertComment(std::string& json, const std::string& anchor, const std::string& text) {
  const std::size_t at = json.find(anchor);
  if (at == std::string::npos) {
    throw std::logic_error("dump_builtin_scene: no '" + anchor + "' in the scene's JSON");
  }
  const std::size_t line_start = json.rfind('\n', at) + 1;
  std::size_t indent = at - line_start;
  if (anchor.back() == '{') indent += 2;
  const std::size_t line_end = json.find('\n', at);
  json.insert(line_end + 1, std::string(indent, ' ') +
                                "\"comment\": " + rheofeed::scene::jsonQuoted(text) + ",\n");
}

std::string range(int first, int count) {
  return count == 1 ? std::to_string(first)
                    : std::to_string(first) + "-" + std::to_string(first + count - 1);
}

// The bowl of primitives (bowlFeederScene, demos/common/bowl_scene.cpp): its geoms are, in
// order, the floor, 36 cone facets and the apex, the wall's boxes, 2 x 64 ramp boxes, and with the
// outlet the wiper, the return chute, the outlet track and its two rails.
void commentBowl(std::string& json, const Scene& scene, bool fill) {
  const auto& g = scene.fixtures.at(0).geoms;
  const int geoms = static_cast<int>(g.size());
  const int wall = geoms - 1 - 37 - 128 - 5;
  const int ramp_first = 38 + wall, tooling = ramp_first + 128;
  // The comment's index map must be the builder's: the 128 ramp boxes are one size, unlike the
  // wall box before them and the wiper after them.
  const auto size = [&g](int i) { return g[static_cast<std::size_t>(i)].shape.size; };
  bool layout =
      wall > 0 && size(ramp_first - 1) != size(ramp_first) && size(tooling) != size(tooling - 1);
  for (int i = ramp_first + 1; layout && i < tooling; ++i) layout = size(i) == size(ramp_first);
  if (!layout) {
    throw std::logic_error(
        "dump_builtin_scene: the bowl's geoms are no longer floor, 37 cone boxes, the wall, 128 "
        "ramp boxes and 5 tooling boxes: update commentBowl");
  }
  if (fill) {
    insertComment(
        json, "{",
        "The bowl feeder built from ODE primitives (`rheofeed run bowl_feeder_fill`; written by "
        "dump_builtin_scene from builtin_scenes.hpp bowlFeederScene(240, 6, true, 300)). 240 M6 "
        "nuts are poured onto the central cone at 6 parts/s (40 s); they slide to the wall, are "
        "carried round and up a 2-turn helical ramp by the bowl's screw vibration, meet a wiper on "
        "the last turn that pushes nuts not lying flat (on edge, or riding on another nut) back "
        "into the bowl over a return chute, and leave lying flat through a tangential outlet. The "
        "rheonomic runs use the local vibration law (no calibration). Outputs: output rate and "
        "cumulative count at the exit plane, first part out, exit "
        "orientation, mean height against time, angular drift. " +
            kDriftTableNote);
  } else {
    insertComment(
        json, "{",
        "The bowl feeder built from ODE primitives with 12 M6 nuts (`rheofeed run "
        "bowl_feeder_primitives`; written by dump_builtin_scene from builtin_scenes.hpp "
        "bowlFeederScene()): the same bowl, tooling and outlet as bowl_feeder_fill. Rheonomic at "
        "h = 0.01 s (the paper's step) on the local vibration law, with no nut lost or sunk in 60 "
        "s (the mesh bowl of bowl_feeder.json lost 5 of 12 in 12 s at that step until its mesh "
        "contacts were fixed; demos/results/bowl_feeder.md, sections 1 and 8). " +
            kDriftTableNote);
  }
  insertComment(
      json, "\"name\": \"bowl\",",
      "geoms, in order (all boxes): 0 the floor (top z = 10 mm); 1-36 the central cone, box "
      "facets falling 25 degrees (> atan(mu) = 16.7, so nuts slide off) from z = 66 mm at r = 10 "
      "mm to the floor at r = 130 mm (the ramp's inner edge), 25 mm thick; 37 the apex; " +
          range(38, wall) + " the wall, " + std::to_string(wall) +
          " boxes (inner radius 150 mm, 10 mm thick, 100 mm high; cut down to 64 mm over the "
          "outlet, azimuth 0-40 degrees); " +
          range(ramp_first, 128) +
          " the helical ramp, 64 boxes per turn (20 mm wide, r = 130..150 mm, 12 mm thick, pitch "
          "30 mm, 2 turns counter-clockwise rising out of the floor at azimuth 0 from 1 mm below "
          "its top, the top falling 3 degrees towards the wall); " +
          std::to_string(tooling) +
          " the wiper across the last turn at azimuth 300 degrees, 6.5 mm above the track, 35 "
          "degrees to it; " +
          std::to_string(tooling + 1) +
          " the return chute under it (6 mm thick, 50 mm wide, its top edge 5 mm inside the "
          "ramp's inner edge so that it stays 7 mm above the turn below), falling 35 degrees "
          "inwards to the cone (a wiped nut drops 10 mm instead of 50); " +
          std::to_string(tooling + 2) +
          " the outlet track, straight along +y from the ramp's top (z = 69 mm) at azimuth 0; " +
          range(tooling + 3, 2) +
          " its rails. Why boxes: ODE collides two triangle meshes without a notion of inside, "
          "and the nut mesh sank into and stuck on box ramps; boxes and cylinders are solids to "
          "ODE's box tests. The geometry's history: demos/results/bowl_feeder.md, section 4.");
  insertComment(
      json, "\"law\": {",
      "Screw vibration at 50 Hz: 0.15 mm vertical (1.5 g: the nuts hop) and 0.17 degrees torsion "
      "(0.13 m/s peak at r = 140 mm), as bowl_feeder.json. drift_model local: the rheonomic runs "
      "use the local vibration law, no calibration; against this bowl's own full vibration (ODE, "
      "friction cone) at 2000 steps per cycle it is within 3 % on the floor and 9 % on the ramp "
      "(demos/results/bowl_local_law.md, last section). calibrated_drift: 0.313 rad/s about +z, "
      "the mesh bowl's former calibration on its ramp (measured while ODE kept 8 contacts per "
      "mesh pair, since void there; bowl_feeder.json now runs on the local law), kept here for "
      "`--drift-model calibrated_drift` and as the rotation the tooling tests' kinematics use; it "
      "is not this bowl's (its runs are 13 % fast on the floor and 2-3x on the ramp).");
  insertComment(json, "\"name\": \"m6_nuts\",",
                "M6 nut blanks (10 mm across flats, 5 mm thick, 2.3 g with the 6 mm hole) as ODE "
                "cylinders of the hexagon's area (radius 5.25 mm), thickness 5 mm, density 5290 "
                "kg/m^3 for the blank's mass; 3 % spread cut at +-5 %. Dropped one by one at "
                "`rate` from at most 14 mm above the cone (r = 90..102 mm, azimuth about 275 "
                "degrees): a nut falling further moves more than its thickness per step of 0.01 "
                "s. Orientation: +z or -z up is lying flat.");
  insertComment(json, "\"solver\": {",
                "time_step 0.2 ms: 100 steps per vibration period, for full-vibration runs; the "
                "ramp's drift converges only at 1000-2000 steps per cycle (0.01-0.02 ms; "
                "demos/results/bowl_local_law.md). "
                "rheonomic_time_step 0.01 s, the paper's bowl step.");
  insertComment(json, "\"outputs\": {",
                "angular drift about +z (rad/s) after 1 s; the exit plane is tangent to r = 175 "
                "mm at azimuth 45 degrees, outside the wall (r <= 161 mm), crossed only by nuts "
                "on the outlet track; parts past it fall below removal_height (-0.1 m) and leave "
                "the simulation.");
}

// The mesh bowl with its outlet (meshBowlFeederScene, demos/common/bowl_scene.cpp): its geoms are
// the bowl's mesh, then the wiper, the return chute, the outlet track and its two rails.
void commentMeshBowl(std::string& json, const Scene& scene) {
  const auto& g = scene.fixtures.at(0).geoms;
  if (g.size() != 6 || g[0].shape.kind != rheofeed::scene::Shape::Kind::Mesh) {
    throw std::logic_error(
        "dump_builtin_scene: the mesh bowl's geoms are no longer its mesh and 5 tooling boxes: "
        "update commentMeshBowl");
  }
  insertComment(
      json, "{",
      "The vibratory bowl feeder as a mesh, with tooling and an outlet (`rheofeed run "
      "bowl_feeder_mesh_fill`; written by dump_builtin_scene from builtin_scenes.hpp "
      "meshBowlFeederScene()). 200 M6 nuts, read from their mesh, are poured onto the bowl's "
      "central cone at 5 parts/s (40 s); they slide to the wall, are carried round and up the "
      "2-turn helical ramp by the bowl's screw vibration, meet a wiper on the last turn that "
      "pushes "
      "nuts not lying flat (on edge, or riding on another nut) back into the bowl over a return "
      "chute, and leave lying flat through a tangential outlet. The rheonomic runs use the local "
      "vibration law (no calibration) at h = 0.01 s. Outputs: output rate and cumulative count at "
      "the exit plane, first part out, exit orientation, mean height against time, angular drift. "
      "The bowl of boxes with the same tooling is bowl_feeder_fill; the 12-nut mesh bowl with its "
      "cone of boxes and no outlet, bowl_feeder. " +
          kDriftTableNote);
  insertComment(
      json, "\"name\": \"bowl\",",
      "geoms, in order: 0 the bowl, one mesh (demos/meshes/vibratory_bowl_outlet.stl, millimetres "
      "scaled by 0.001; generate_meshes.cpp): inner radius 150 mm, wall 5 mm thick and 100 mm "
      "high, cut down to 64 mm over azimuth -0.5..40 degrees for the outlet; a floor falling 4 "
      "degrees towards the wall; a central cone of revolution falling 25 degrees (> atan(mu) = "
      "16.7, so nuts slide off) from a flat top of radius 70 mm at z = 37 mm to the floor at r = "
      "124 "
      "mm; the helical ramp (20 mm wide, r = 130..150 mm, 4 mm thick, pitch 30 mm, 2 turns "
      "counter-clockwise rising from the floor at azimuth 0, its top falling 3 degrees towards the "
      "wall); 1 the wiper across the last turn at azimuth 300 degrees, 6.5 mm above the track, 35 "
      "degrees to it; 2 the return chute under it, falling 35 degrees inwards to the cone; 3 the "
      "outlet track, straight along +y from the ramp's top (z = 70.5 mm on its centre line) at "
      "azimuth 0, through the cut; 4-5 its rails. The tooling is bowl_feeder_fill's, fitted to "
      "this ramp and cone; boxes, which ODE collides as solids.");
  insertComment(json, "\"law\": {",
                "Screw vibration at 50 Hz: 0.15 mm vertical (1.5 g: the nuts hop) and 0.17 "
                "degrees torsion (0.13 m/s peak at r = 140 mm), as bowl_feeder.json. drift_model "
                "local: the rheonomic runs use the local vibration law, no calibration.");
  insertComment(json, "\"name\": \"m6_nuts\",",
                "M6 nut blanks (10 mm across flats, 5 mm thick, a 6 mm hole; 2.3 g) read from "
                "demos/meshes/hex_nut_m6.obj: size[0] is the mesh's scale, millimetres to metres "
                "with a 3 % spread. collision convex_hull: the engines collide each nut as its "
                "convex hull, the plain hexagonal prism (nothing in this bowl enters the hole); "
                "mass, inertia and drawing keep the hole. Dropped one by one at `rate` from at "
                "most 15 mm above the cone (r = 90..102 mm, azimuth about 275 degrees). "
                "Orientation: +z or -z up is lying flat.");
  insertComment(json, "\"solver\": {",
                "time_step 0.2 ms: 100 steps per vibration period, for a quick full-vibration "
                "look; the bowl's ramp drift converges only at 1000 steps per cycle or finer "
                "(demos/results/bowl_feeder.md, section 10). rheonomic_time_step 0.01 s, the "
                "paper's bowl step.");
  insertComment(json, "\"outputs\": {",
                "angular drift about +z (rad/s) after 1 s; the exit plane is tangent to r = 175 "
                "mm at azimuth 45 degrees, outside the wall (r <= 155 mm), crossed only by nuts "
                "on the outlet track; parts past it fall below removal_height (-0.1 m) and leave "
                "the simulation.");
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"write a built-in scene as JSON on stdout"};
  std::string name;
  app.add_option("SCENE", name,
                 "bowl_feeder_primitives (12 nuts), bowl_feeder_fill (240 nuts poured in) or "
                 "bowl_feeder_mesh_fill (the mesh bowl with its outlet, 200 mesh nuts poured in)")
      ->required()
      ->check(
          CLI::IsMember({"bowl_feeder_primitives", "bowl_feeder_fill", "bowl_feeder_mesh_fill"}));
  CLI11_PARSE(app, argc, argv);
  using namespace rheofeed::scene;
  try {
    const bool fill = name == "bowl_feeder_fill", mesh = name == "bowl_feeder_mesh_fill";
    Scene scene = mesh   ? meshBowlFeederScene()
                  : fill ? bowlFeederScene(240, 6, true, 300)
                         : bowlFeederScene();
    // The shipped scenes' drift table (demos/scenes/tables/): a first run skips its model runs.
    scene.drift_table = kDriftTable;
    std::string json = toJson(scene);
    if (mesh) {
      commentMeshBowl(json, scene);
    } else {
      commentBowl(json, scene, fill);
    }
    std::cout << json;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "dump_builtin_scene: %s\n", e.what());
    return 1;
  }
  return 0;
}

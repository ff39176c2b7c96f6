// SPDX-License-Identifier: MIT
/// @file scene_io.hpp
/// Scene files: a Scene (scene.hpp) as JSON, read and written. The format is documented in
/// demos/scenes/README.md; in short: SI units everywhere, vectors as [x, y, z] in the world
/// frame, angles only in keys that name their unit ("angle_deg" or "angle_rad"), rotations as
/// {"axis": [x, y, z], "angle_deg": a} (right-hand rule, body to world), omitted optional keys
/// take the defaults of scene.hpp, unknown keys are errors.
///
/// Loading is all-or-nothing: the file is parsed, every value checked (type, range, unknown
/// and duplicate keys), Scene::validate() run, the meshes it names loaded (mesh.hpp) and the
/// parts drawn once (drawParts) before the Scene is returned; nothing is half-built when one
/// of these fails. A scene without meshes never calls the mesh loader, so never assimp.
#pragma once

#include <filesystem>
#include <functional>
#include <stdexcept>
#include <string>

#include "rheofeed/scene/scene.hpp"

namespace rheofeed::scene {

/// A refused scene file: names the file, the JSON path of the bad value (e.g.
/// "parts[2].size[0].mean") and the problem. what() is "<source>: <path>: <problem>",
/// "<source>:<line>:<column>: <path>: <problem>" when the position in the text is known, and
/// leaves out the parts that are empty (loadSceneMeshes has no source).
class SceneFileError : public std::invalid_argument {
 public:
  SceneFileError(std::string source, std::string path, std::string problem, int line = 0,
                 int column = 0);
  /// The file name (or the source name given to parseScene).
  const std::string& source() const { return source_; }
  /// JSON path of the bad value ("" for a syntax error or a problem with the whole file).
  const std::string& path() const { return path_; }
  /// What is wrong, without source and path.
  const std::string& problem() const { return problem_; }
  /// 1-based line and column of the error in the text; 0 when not known.
  int line() const { return line_; }
  int column() const { return column_; }

 private:
  std::string source_, path_, problem_;
  int line_ = 0, column_ = 0;
};

/// Reads a mesh file scaled by `scale` (see loadTriangleMesh in mesh.hpp, the default). Tests
/// and applications with their own mesh sources may pass another one.
using MeshLoader = std::function<TriangleMesh(const std::filesystem::path& file, double scale)>;

/// Reads, checks and returns the scene in `file`. Relative mesh paths are resolved against the
/// folder of `file` and stored as absolute paths. `mesh_loader` empty means loadTriangleMesh.
/// Only a regular file (symbolic links followed) of 1 byte to 16 MiB is read: a missing file,
/// a directory, a FIFO, a socket or a device (checked with stat, never opened), an empty file
/// and a larger one are refused before anything is read (scene files are hand-written
/// parameters, 12 KB for the largest demo; the cap bounds the JSON DOM). Throws
/// SceneFileError naming the file (and the JSON path of a bad value) for all of these, for a
/// file that cannot be read, for bad values (limits: scene.hpp) and for bad meshes. The scene's
/// source_file is the file's absolute path.
Scene loadScene(const std::filesystem::path& file, const MeshLoader& mesh_loader = {});

/// As loadScene, from the text `json_text`; `source_name` names it in messages and its parent
/// folder (if any; else the current directory) resolves relative mesh paths.
Scene parseScene(const std::string& json_text, const std::string& source_name,
                 const MeshLoader& mesh_loader = {});

/// The scene as JSON text (2-space indent) that parseScene reads back to an equal Scene (loaded
/// mesh data aside, which is reloaded from the mesh paths). Every field is written, except keys
/// whose section is unused (e.g. "exit_point" without an exit plane) and are at their defaults.
std::string toJson(const Scene& scene);

/// Loads the meshes of a scene built in code: Shape::mesh_data of every mesh geom (scaled by
/// its mesh_scale) and PartSpec::mesh_data of every mesh part (scale 1, centred on its centre
/// of mass; checked to be a closed, outward-oriented solid). Relative paths are resolved
/// against `base_dir` and replaced by absolute ones. Throws SceneFileError (no source) naming the
/// path of the bad mesh (e.g. "fixtures[0].geoms[1].mesh: mesh '/x/bowl.stl': file not found").
void loadSceneMeshes(Scene& scene, const std::filesystem::path& base_dir,
                     const MeshLoader& mesh_loader = {});

}  // namespace rheofeed::scene

// SPDX-License-Identifier: MIT
// libFuzzer target: a mesh file from bytes through loadTriangleMesh (mesh.hpp, assimp) and, for
// a mesh it returns, massProperties, scaleMesh and boundingRadius. Built once per file format:
// RHEOFEED_FUZZ_MESH_EXT (".obj", ".stl") is the extension of the temporary file the bytes are
// written to, which is how assimp picks its importer. loadTriangleMesh reads files only, so each
// input is written to one file in a private temporary folder (removed at exit).
//
// Documented refusals: std::runtime_error (unreadable, corrupt, no triangles) and
// std::invalid_argument (non-finite coordinates; massProperties: open, inside-out or degenerate
// meshes). Anything else is a finding, including a crash inside assimp.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <stdexcept>
#include <string>
#include <system_error>

#include <unistd.h>

#include "rheofeed/scene/mesh.hpp"

#ifndef RHEOFEED_FUZZ_MESH_EXT
#error "define RHEOFEED_FUZZ_MESH_EXT, e.g. \".obj\""
#endif

namespace {

namespace fs = std::filesystem;

// A folder of this process's own, removed by a static destructor when libFuzzer exits normally.
struct TempFolder {
  fs::path path;
  TempFolder() {
    std::string tmpl = (fs::temp_directory_path() / "rheofeed_fuzz_mesh_XXXXXX").string();
    if (mkdtemp(tmpl.data()) == nullptr) {
      std::perror("fuzz_mesh: mkdtemp");
      std::abort();
    }
    path = tmpl;
  }
  ~TempFolder() {
    std::error_code ec;
    fs::remove_all(path, ec);
  }
};

const fs::path& inputFile() {
  static TempFolder folder;
  static const fs::path file = folder.path / (std::string("input") + RHEOFEED_FUZZ_MESH_EXT);
  return file;
}

[[noreturn]] void finding(const char* what) {
  std::fprintf(stderr, "fuzz_mesh finding: %s\n", what);
  std::abort();
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const fs::path& file = inputFile();
  {
    std::ofstream out(file, std::ios::binary | std::ios::trunc);
    out.write(reinterpret_cast<const char*>(data), static_cast<std::streamsize>(size));
    if (!out) finding("cannot write the temporary mesh file");
  }
  using namespace rheofeed::scene;
  TriangleMesh mesh;
  try {
    mesh = loadTriangleMesh(file, 1e-3);  // millimetre files, as the demo meshes
  } catch (const std::runtime_error&) {
    return 0;
  } catch (const std::invalid_argument&) {
    return 0;
  }
  if (mesh.triangles.empty() || mesh.triangles.size() % 3 != 0 || mesh.vertices.size() % 3 != 0) {
    finding("accepted mesh without a whole number of triangles");
  }
  for (double v : mesh.vertices) {
    if (!std::isfinite(v)) finding("accepted mesh with a non-finite coordinate");
  }
  const long n = static_cast<long>(mesh.vertices.size() / 3);
  for (int t : mesh.triangles) {
    if (t < 0 || t >= n) finding("accepted mesh with a vertex index out of range");
  }
  const double radius = boundingRadius(mesh);
  if (!std::isfinite(radius)) finding("bounding radius of a finite mesh is not finite");
  try {
    const MassProperties mp = massProperties(mesh, 7800);
    if (!(mp.volume > 0)) finding("massProperties accepted a non-positive volume");
    (void)scaleMassProperties(mp, 2.0);
    (void)massProperties(scaleMesh(mesh, 2.0), 7800);
  } catch (const std::invalid_argument&) {
    return 0;  // open, inside-out or degenerate: documented refusal
  }
  return 0;
}

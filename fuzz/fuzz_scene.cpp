// SPDX-License-Identifier: MIT
// libFuzzer target: a scene file from bytes through parseScene (scene_io.hpp), i.e. JSON parse,
// value checks, Scene::validate(), mesh loading and the placement of the parts (drawParts).
//
// Documented refusals (SceneFileError, an std::invalid_argument, and std::runtime_error) are
// the expected outcome for most inputs. Anything else is a finding: a crash or sanitizer report,
// an abort inside ODE (dMass checks in drawParts), another exception type escaping (libFuzzer
// reports the std::terminate), a timeout, or a broken round trip: a scene that parseScene accepts
// must be written by toJson as text that parseScene accepts again and writes back equal: every
// value identical except rotations, which toJson writes as axis-angle from the rotation matrix
// and may come back a few ulps apart; those are compared as matrices (kRotationTolerance).
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <stdexcept>
#include <string>

#include <nlohmann/json.hpp>

#include "rheofeed/scene/scene_io.hpp"

namespace {

using rheofeed::scene::TriangleMesh;

// Mesh files are not read here (the mesh fuzzers cover assimp): every mesh name resolves to a
// closed, outward-oriented regular tetrahedron of circumradius sqrt(3) * scale, except names
// containing "missing", which fail like an absent file. So mesh geoms and mesh parts (mass
// properties, scaling, placement) are exercised without touching the file system.
TriangleMesh fakeMesh(const std::filesystem::path& file, double scale) {
  if (file.string().find("missing") != std::string::npos) {
    throw std::runtime_error("mesh '" + file.string() + "': file not found");
  }
  if (!(scale > 0)) throw std::invalid_argument("fake mesh: bad scale");
  TriangleMesh mesh;
  mesh.source = file.string();
  const double v[12] = {1, 1, 1, 1, -1, -1, -1, 1, -1, -1, -1, 1};
  for (double c : v) mesh.vertices.push_back(scale * c);
  // Counter-clockwise seen from outside.
  mesh.triangles = {0, 1, 2, 0, 3, 1, 0, 2, 3, 1, 3, 2};
  return mesh;
}

using Json = nlohmann::json;

// Rotation matrix entries are in [-1, 1]; a matrix -> axis-angle -> matrix round trip in double
// costs some 1e-16 per entry (Eigen's AngleAxis goes through a quaternion, well conditioned at
// every angle). 1e-12 leaves four orders of margin and still catches a wrong axis or angle.
constexpr double kRotationTolerance = 1e-12;

// Rodrigues' formula: the matrix of {"axis": [x, y, z], "angle_rad": a} (body to world).
bool rotationMatrix(const Json& r, double m[9]) {
  if (!r.is_object() || !r.contains("axis") || !r.contains("angle_rad")) return false;
  const Json& a = r["axis"];
  if (!a.is_array() || a.size() != 3 || !r["angle_rad"].is_number()) return false;
  double x = a[0].get<double>(), y = a[1].get<double>(), z = a[2].get<double>();
  const double n = std::sqrt(x * x + y * y + z * z);
  if (!(n > 0)) return false;
  x /= n, y /= n, z /= n;
  const double angle = r["angle_rad"].get<double>();
  const double c = std::cos(angle), s = std::sin(angle), t = 1 - c;
  const double out[9] = {t * x * x + c,     t * x * y - s * z, t * x * z + s * y,
                         t * x * y + s * z, t * y * y + c,     t * y * z - s * x,
                         t * x * z - s * y, t * y * z + s * x, t * z * z + c};
  for (int i = 0; i < 9; ++i) m[i] = out[i];
  return true;
}

// "" when equal as described at the top; else the JSON path of the first difference.
std::string difference(const Json& a, const Json& b, const std::string& path) {
  if (a.type() != b.type() && !(a.is_number() && b.is_number())) return path;
  if (a.is_object()) {
    if (a.size() != b.size()) return path;
    for (auto it = a.begin(); it != a.end(); ++it) {
      if (!b.contains(it.key())) return path + "." + it.key();
      if (it.key() == "rotation") {
        double ma[9], mb[9];
        if (rotationMatrix(it.value(), ma) && rotationMatrix(b[it.key()], mb)) {
          for (int i = 0; i < 9; ++i) {
            if (!(std::abs(ma[i] - mb[i]) <= kRotationTolerance)) return path + ".rotation";
          }
          continue;
        }
      }
      const std::string d = difference(it.value(), b[it.key()], path + "." + it.key());
      if (!d.empty()) return d;
    }
    return "";
  }
  if (a.is_array()) {
    if (a.size() != b.size()) return path;
    for (std::size_t i = 0; i < a.size(); ++i) {
      const std::string d = difference(a[i], b[i], path + "[" + std::to_string(i) + "]");
      if (!d.empty()) return d;
    }
    return "";
  }
  return a == b ? "" : path;
}

[[noreturn]] void finding(const char* what, const std::string& detail) {
  std::fprintf(stderr, "fuzz_scene finding: %s\n%s\n", what, detail.c_str());
  std::abort();
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  const rheofeed::scene::MeshLoader loader = fakeMesh;
  rheofeed::scene::Scene scene;
  try {
    scene = rheofeed::scene::parseScene(text, "/fuzz/scene.json", loader);
  } catch (const std::invalid_argument&) {
    return 0;  // documented refusal (SceneFileError)
  } catch (const std::runtime_error&) {
    return 0;  // documented refusal (e.g. a mesh that cannot be read)
  }
  // Accepted: the written form must be read back and written back equal.
  const std::string written = rheofeed::scene::toJson(scene);
  std::string rewritten;
  try {
    rewritten =
        rheofeed::scene::toJson(rheofeed::scene::parseScene(written, "/fuzz/scene.json", loader));
  } catch (const std::exception& e) {
    finding("toJson of an accepted scene is refused by parseScene",
            std::string(e.what()) + "\n--- written:\n" + written);
  }
  const std::string where = difference(Json::parse(written), Json::parse(rewritten), "");
  if (!where.empty()) {
    finding("toJson(parseScene(toJson(scene))) differs from toJson(scene)",
            "first difference at '" + where + "'\n--- first:\n" + written + "\n--- second:\n" +
                rewritten);
  }
  return 0;
}

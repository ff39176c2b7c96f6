// SPDX-License-Identifier: MIT
// Inputs found by the fuzz targets of fuzz/ (see fuzz/README.md), kept as regression tests: each
// test names the target that found it and what went wrong.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <string>

#include "rheofeed/scene/scene_io.hpp"

namespace rheofeed::scene {
namespace {

// Directions in the file that are not of unit length: the reader normalises them.
const char* kDirections = R"({
  "fixtures": [
    {"name": "belt", "geoms": [{"shape": "box", "size": [1, 0.1, 0.02], "position": [0, 0, -0.01]}],
     "law": {"belt": {"direction": [1, 1, 0], "speed": 0.3}}}
  ],
  "parts": [{"shape": "box", "size": [0.02, 0.02, 0.005], "spawn_min": [0, 0, 0.003],
             "spawn_max": [0.1, 0.05, 0.003], "count": 2}],
  "outputs": {"conveying_direction": [1, 2, 2], "exit_plane": true, "exit_point": [0.5, 0, 0],
              "exit_normal": [1, 1, 0], "sample_interval": 0.01},
  "duration": 1
})";

// A normalised direction is the exact quotient rounded per component, plus the rounding of
// the norm: a few ulps of 1.
constexpr double kNormalisedTolerance = 4 * std::numeric_limits<double>::epsilon();

void expectBitIdentical(const Vec3& a, const Vec3& b, const char* what) {
  EXPECT_EQ(a.x, b.x) << what;
  EXPECT_EQ(a.y, b.y) << what;
  EXPECT_EQ(a.z, b.z) << what;
}

// fuzz_scene: the linear trough demo with "exit_normal": [1, 1, 0] read as
// 0.7071067811865475 per component, written so, and read back as 0.7071067811865476 (normalised
// a second time): toJson(parseScene(toJson(scene))) differed from toJson(scene), against the
// round-trip contract of scene_io.hpp.
TEST(FuzzRegression, DirectionsNormalisedOnReadReadBackBitIdenticalAfterWriting) {
  const Scene first = parseScene(kDirections, "directions.json");
  const double h = 1 / std::sqrt(2.0);
  EXPECT_NEAR(first.outputs.exit_normal.x, h, kNormalisedTolerance);
  EXPECT_NEAR(first.outputs.exit_normal.y, h, kNormalisedTolerance);
  EXPECT_EQ(first.outputs.exit_normal.z, 0.0);
  EXPECT_NEAR(first.outputs.conveying_direction.x, 1.0 / 3, kNormalisedTolerance);
  EXPECT_NEAR(first.outputs.conveying_direction.y, 2.0 / 3, kNormalisedTolerance);
  EXPECT_NEAR(first.outputs.conveying_direction.z, 2.0 / 3, kNormalisedTolerance);
  EXPECT_NEAR(first.fixtures[0].law.belt_direction.x, h, kNormalisedTolerance);

  const std::string written = toJson(first);
  const Scene second = parseScene(written, "directions.json");
  expectBitIdentical(first.outputs.exit_normal, second.outputs.exit_normal, "exit_normal");
  expectBitIdentical(first.outputs.conveying_direction, second.outputs.conveying_direction,
                     "conveying_direction");
  expectBitIdentical(first.fixtures[0].law.belt_direction, second.fixtures[0].law.belt_direction,
                     "belt direction");
  EXPECT_EQ(toJson(second), written);
}

}  // namespace
}  // namespace rheofeed::scene

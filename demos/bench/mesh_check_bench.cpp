// SPDX-License-Identifier: MIT
// How long the scene check's mesh wall-thickness test takes on closed meshes of 1e4, 1e5 and
// 1e6 triangles (issue 20: the all-pairs test took 0.9 s at 1e4 and was extrapolated to 2.5 h
// at 1e6). The meshes are spherical shells (tests/scene/mesh_shell.hpp), 10 cm outer, 9 cm inner
// radius. One run on one machine; read the ratios, not the seconds. Usage:
//   mesh_check_bench [max_triangles]   (default 1000000)
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>

#include "../../tests/scene/mesh_shell.hpp"
#include "rheofeed/simulation/check.hpp"

int main(int argc, char** argv) {
  using namespace rheofeed::scene;
  const double max_triangles = argc > 1 ? std::atof(argv[1]) : 1e6;
  std::printf("| triangles | wall thickness (mm) | ray tests | tests per triangle | seconds |\n");
  std::printf("|---|---|---|---|---|\n");
  for (double n = 1e4; n <= max_triangles * 1.001; n *= 10) {
    // 2 spheres of 2 s (s - 1) triangles each with s slices and s stacks: s ~ sqrt(n / 4).
    const int s = static_cast<int>(std::lround(std::sqrt(n / 4)));
    const TriangleMesh mesh = testing::sphericalShell(0.1, 0.09, s, s);
    const auto start = std::chrono::steady_clock::now();
    const MeshWallThickness wall = meshWallThickness(mesh, 1.0);
    const double seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    const double triangles = static_cast<double>(mesh.triangles.size() / 3);
    std::printf("| %.0f | %.4f%s | %lld | %.0f | %.2f |\n", triangles, 1000 * wall.thickness,
                wall.measured ? "" : " (skipped)", wall.ray_tests, wall.ray_tests / triangles,
                seconds);
  }
  return 0;
}

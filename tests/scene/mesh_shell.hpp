// SPDX-License-Identifier: MIT
// A closed spherical shell as a triangle mesh, for the mesh wall-thickness test and its
// benchmark: an outer sphere of radius `outer` (outward normals) and an inner one of radius
// `inner` (normals towards the centre, the solid's outside there), `slices` x `stacks` each;
// 2 slices (stacks - 1) triangles per sphere. Its wall is outer - inner thick, less the
// faceting (the inner sphere's flat triangles sit up to inner (1 - cos(pi / stacks)) inside it).
#pragma once

#include <cmath>

#include "rheofeed/scene/scene.hpp"

namespace rheofeed::scene::testing {

inline TriangleMesh sphericalShell(double outer, double inner, int slices, int stacks) {
  TriangleMesh m;
  m.source = "spherical shell";
  const double pi = std::acos(-1.0);
  for (int sphere = 0; sphere < 2; ++sphere) {
    const double r = sphere == 0 ? outer : inner;
    const int first = static_cast<int>(m.vertices.size() / 3);
    auto add = [&](double x, double y, double z) {
      m.vertices.insert(m.vertices.end(), {x, y, z});
    };
    add(0, 0, r);  // north pole
    for (int i = 1; i < stacks; ++i) {
      const double theta = pi * i / stacks;
      for (int j = 0; j < slices; ++j) {
        const double phi = 2 * pi * j / slices;
        add(r * std::sin(theta) * std::cos(phi), r * std::sin(theta) * std::sin(phi),
            r * std::cos(theta));
      }
    }
    add(0, 0, -r);  // south pole
    const int south = first + 1 + (stacks - 1) * slices;
    auto ring = [&](int i, int j) { return first + 1 + (i - 1) * slices + (j % slices); };
    auto tri = [&](int a, int b, int c) {
      if (sphere == 0) {
        m.triangles.insert(m.triangles.end(), {a, b, c});
      } else {
        m.triangles.insert(m.triangles.end(), {a, c, b});  // inner sphere: flipped
      }
    };
    for (int j = 0; j < slices; ++j) tri(first, ring(1, j), ring(1, j + 1));
    for (int i = 1; i + 1 < stacks; ++i) {
      for (int j = 0; j < slices; ++j) {
        tri(ring(i, j), ring(i + 1, j), ring(i + 1, j + 1));
        tri(ring(i, j), ring(i + 1, j + 1), ring(i, j + 1));
      }
    }
    for (int j = 0; j < slices; ++j) tri(south, ring(stacks - 1, j + 1), ring(stacks - 1, j));
  }
  return m;
}

}  // namespace rheofeed::scene::testing

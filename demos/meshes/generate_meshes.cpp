// SPDX-License-Identifier: MIT
// Writes the CAD-like meshes of the bowl-feeder demo (committed beside this file; the build does
// not run this program). Run it as
//   generate_meshes [output folder, default .]
// Files, in millimetres like most CAD exports (the scenes scale them by 0.001):
//   vibratory_bowl.stl  binary STL: a bowl (inner radius 150 mm, wall 5 mm, height 100 mm) whose
//                       floor is a flat cone rising 4 degrees towards the centre (parts slide
//                       outwards), with a helical ramp on the inner wall: 20 mm wide, 4 mm
//                       thick, pitch 30 mm per turn, 2 turns, right-handed (it rises
//                       counter-clockwise seen from +z), its top tilted 3 degrees down towards
//                       the wall. Two closed shells: the bowl body and the ramp, which overlaps
//                       the wall by 1 mm. (bowl_feeder.json; its central cone is boxes.)
//   vibratory_bowl_outlet.stl  the same bowl with its central cone in the body (a cone of
//                       revolution falling 25 degrees from a flat top of radius 70 mm at z = 37 mm
//                       to the floor at r = 124 mm) and the wall cut down to 64 mm over azimuth
//                       -0.5..40 degrees, where the outlet track of bowl_feeder_mesh_fill.json
//                       leaves the ramp's top. Two closed shells, as above.
//   hex_nut_m6.obj      an M6 hex nut blank: 10 mm across flats, 5 mm thick, a 6 mm hole (a
//                       24-gon), centred on the origin, axis +z. One closed shell.
// Every shell is closed and its triangles are counter-clockwise seen from outside (outward
// normals), so the part's volume and inertia follow from its surface (mesh.hpp).
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <iostream>
#include <stdexcept>
#include <string>
#include <vector>

#include "rheofeed/vec3.hpp"

namespace {

using rheofeed::kPi;

struct Mesh {
  std::vector<std::array<double, 3>> vertices;
  std::vector<std::array<int, 3>> triangles;

  int add(double x, double y, double z) {
    vertices.push_back({x, y, z});
    return static_cast<int>(vertices.size()) - 1;
  }
  void triangle(int a, int b, int c) {
    if (a != b && b != c && c != a) triangles.push_back({a, b, c});
  }
};

// A point of a swept cross-section: radius r (mm) and height z (mm) at sweep angle phi.
struct ProfilePoint {
  double r, z;
};

// Sweeps a closed cross-section polygon, counter-clockwise in the (r, z) half-plane (r to the
// right, z up), about the z axis: section j sits at angle phi_j and is given by section(j).
// Points with r = 0 become one vertex on the axis. With `closed` the sweep wraps around (a
// solid of revolution); otherwise the two end sections are capped. Outward normals follow:
// for a profile edge a -> b the quad (a_j, a_j+1, b_j+1, b_j) faces outwards.
template <class Section>
void sweep(Mesh& mesh, int sections, bool closed, Section section, int profile_size) {
  std::vector<std::vector<int>> ids(sections);
  for (int j = 0; j < sections; ++j) {
    double phi = 0;
    const std::vector<ProfilePoint> points = section(j, phi);
    for (int k = 0; k < profile_size; ++k) {
      const ProfilePoint& p = points[k];
      if (closed && p.r == 0 && j > 0) {
        ids[j].push_back(ids[0][k]);  // one vertex on the axis, shared by every section
      } else {
        ids[j].push_back(mesh.add(p.r * std::cos(phi), p.r * std::sin(phi), p.z));
      }
    }
  }
  const int last = closed ? sections : sections - 1;
  for (int j = 0; j < last; ++j) {
    const std::vector<int>& s0 = ids[j];
    const std::vector<int>& s1 = ids[(j + 1) % sections];
    for (int k = 0; k < profile_size; ++k) {
      const int k1 = (k + 1) % profile_size;
      mesh.triangle(s0[k], s1[k], s1[k1]);
      mesh.triangle(s0[k], s1[k1], s0[k1]);
    }
  }
  if (!closed) {  // caps: a fan; the start faces -phi, the end +phi
    const std::vector<int>& a = ids.front();
    const std::vector<int>& b = ids.back();
    for (int k = 1; k + 1 < profile_size; ++k) {
      mesh.triangle(a[0], a[k], a[k + 1]);
      mesh.triangle(b[0], b[k + 1], b[k]);
    }
  }
}

// The bowl's common dimensions (mm).
constexpr double kRadius = 150, kWall = 5, kHeight = 100, kBottom = 10;
constexpr double kFloorSlope = 4 * kPi / 180;  // the floor rises towards the centre
constexpr int kSegments = 128;                 // facets of the solids of revolution

// The helical ramp on the inner wall: a trapezoid section swept from the floor at azimuth 0, 2
// turns up (right-handed), its outer edge 1 mm into the wall, its top falling 3 degrees towards
// the wall; the top's outer edge at r = 150 mm rises from z = 10 mm by 30 mm per turn.
void addRamp(Mesh& mesh) {
  const double width = 20, thickness = 4, pitch = 30, turns = 2, overlap = 1;
  const double tilt = 3 * kPi / 180;
  const int ramp_sections = static_cast<int>(kSegments * turns) + 1;
  sweep(
      mesh, ramp_sections, false,
      [&](int j, double& phi) {
        phi = 2 * kPi * turns * j / (ramp_sections - 1);
        const double top = kBottom + pitch * phi / (2 * kPi);
        const double r_in = kRadius - width, r_out = kRadius + overlap;
        return std::vector<ProfilePoint>{{r_in, top - thickness},
                                         {r_out, top - thickness},
                                         {r_out, top - overlap * std::tan(tilt)},
                                         {r_in, top + width * std::tan(tilt)}};
      },
      4);
}

// The bowl of bowl_feeder.json: the wall and a floor rising 4 degrees to the axis (the scene
// adds its central cone as boxes), and the ramp.
Mesh bowl() {
  const double centre = kBottom + kRadius * std::tan(kFloorSlope);  // floor height on the axis
  Mesh mesh;
  const std::vector<ProfilePoint> body = {{0, 0},
                                          {kRadius + kWall, 0},
                                          {kRadius + kWall, kHeight},
                                          {kRadius, kHeight},
                                          {kRadius, kBottom},
                                          {0, centre}};
  sweep(
      mesh, kSegments, true,
      [&](int j, double& phi) {
        phi = 2 * kPi * j / kSegments;
        return body;
      },
      static_cast<int>(body.size()));
  addRamp(mesh);
  return mesh;
}

// The bowl of bowl_feeder_mesh_fill.json: as bowl(), with the central cone turned into the body
// (25 degrees, steeper than the friction angle, from the floor at r = 124 mm, z = 11.8 mm, up to a
// flat top of radius 70 mm at z = 37.0 mm) and the wall cut down to 64 mm over azimuth -0.5..40
// degrees, where the scene's outlet track leaves the ramp's top through it (the cut's sides slope
// over 1 degree).
Mesh bowlWithOutlet() {
  const double cone_outer = 124, cone_inner = 70, cone_slope = 25 * kPi / 180;
  const double cut_from = -0.5, cut_to = 40, cut_top = 64, ramp_deg = 1;  // degrees, mm
  const double foot = kBottom + (kRadius - cone_outer) * std::tan(kFloorSlope);
  const double plateau = foot + (cone_outer - cone_inner) * std::tan(cone_slope);
  // Section angles (degrees): the uniform ones, with the cut's four corners put in and the
  // uniform angles within 0.3 degrees of them left out.
  const std::vector<double> corners = {cut_from - ramp_deg, cut_from, cut_to, cut_to + ramp_deg};
  std::vector<double> angles;
  for (int j = 0; j < kSegments; ++j) {
    double a = 360.0 * j / kSegments;
    if (a > 180) a -= 360;
    bool near = false;
    for (double c : corners) near = near || std::abs(a - c) < 0.3;
    if (!near) angles.push_back(a);
  }
  angles.insert(angles.end(), corners.begin(), corners.end());
  std::sort(angles.begin(), angles.end());
  Mesh mesh;
  sweep(
      mesh, static_cast<int>(angles.size()), true,
      [&](int j, double& phi) {
        const double a = angles[static_cast<std::size_t>(j)];
        phi = a * kPi / 180;
        const double top = a >= cut_from && a <= cut_to ? cut_top : kHeight;
        return std::vector<ProfilePoint>{{0, 0},
                                         {kRadius + kWall, 0},
                                         {kRadius + kWall, top},
                                         {kRadius, top},
                                         {kRadius, kBottom},
                                         {cone_outer, foot},
                                         {cone_inner, plateau},
                                         {0, plateau}};
      },
      8);
  addRamp(mesh);
  return mesh;
}

Mesh hexNut() {
  const double across_flats = 10, thickness = 5, hole_radius = 3;
  const int per_side = 4, n = 6 * per_side;  // hole polygon and hexagon share polar angles
  Mesh mesh;
  sweep(
      mesh, n, true,
      [&](int j, double& phi) {
        phi = 2 * kPi * j / n;  // corners at multiples of 60 degrees, flats at 30 + 60 k
        const double to_flat = std::fmod(phi, kPi / 3) - kPi / 6;
        const double r_hex = 0.5 * across_flats / std::cos(to_flat);
        const double h = 0.5 * thickness;
        return std::vector<ProfilePoint>{
            {hole_radius, -h}, {r_hex, -h}, {r_hex, h}, {hole_radius, h}};
      },
      4);
  return mesh;
}

void writeBinaryStl(const std::string& file, const Mesh& mesh, const std::string& header) {
  std::ofstream out(file, std::ios::binary);
  char head[80] = {};
  std::strncpy(head, header.c_str(), sizeof head - 1);  // must not start with "solid"
  out.write(head, sizeof head);
  const std::uint32_t count = static_cast<std::uint32_t>(mesh.triangles.size());
  out.write(reinterpret_cast<const char*>(&count), 4);
  for (const auto& t : mesh.triangles) {
    const auto& a = mesh.vertices[t[0]];
    const auto& b = mesh.vertices[t[1]];
    const auto& c = mesh.vertices[t[2]];
    const double u[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]};
    const double v[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]};
    double n[3] = {u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0]};
    const double len = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
    float record[12];
    for (int i = 0; i < 3; ++i) {
      record[i] = static_cast<float>(len > 0 ? n[i] / len : 0);
      record[3 + i] = static_cast<float>(a[i]);
      record[6 + i] = static_cast<float>(b[i]);
      record[9 + i] = static_cast<float>(c[i]);
    }
    out.write(reinterpret_cast<const char*>(record), sizeof record);
    const std::uint16_t attributes = 0;
    out.write(reinterpret_cast<const char*>(&attributes), 2);
  }
  if (!out) throw std::runtime_error("cannot write " + file);
}

void writeObj(const std::string& file, const Mesh& mesh, const std::string& comment) {
  std::ofstream out(file);
  out << "# " << comment << "\n";
  char line[128];
  for (const auto& v : mesh.vertices) {
    std::snprintf(line, sizeof line, "v %.6f %.6f %.6f\n", v[0], v[1], v[2]);
    out << line;
  }
  for (const auto& t : mesh.triangles) {
    out << "f " << t[0] + 1 << " " << t[1] + 1 << " " << t[2] + 1 << "\n";
  }
  if (!out) throw std::runtime_error("cannot write " + file);
}

}  // namespace

int main(int argc, char** argv) {
  const std::string dir = argc > 1 ? argv[1] : ".";
  try {
    const Mesh b = bowl();
    writeBinaryStl(dir + "/vibratory_bowl.stl", b,
                   "rheofeed vibratory bowl, mm, generate_meshes.cpp");
    std::cout << dir << "/vibratory_bowl.stl: " << b.triangles.size() << " triangles\n";
    const Mesh o = bowlWithOutlet();
    writeBinaryStl(dir + "/vibratory_bowl_outlet.stl", o,
                   "rheofeed vibratory bowl with cone and outlet cut, mm, generate_meshes.cpp");
    std::cout << dir << "/vibratory_bowl_outlet.stl: " << o.triangles.size() << " triangles\n";
    const Mesh n = hexNut();
    writeObj(dir + "/hex_nut_m6.obj", n,
             "rheofeed M6 hex nut blank, mm, 10 across flats, 5 thick, 6 hole (24-gon); "
             "generate_meshes.cpp");
    std::cout << dir << "/hex_nut_m6.obj: " << n.triangles.size() << " triangles\n";
  } catch (const std::exception& e) {
    std::cerr << "generate_meshes: " << e.what() << "\n";
    return 1;
  }
  return 0;
}

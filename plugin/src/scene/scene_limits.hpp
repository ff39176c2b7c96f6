// SPDX-License-Identifier: MIT
// The limits a scene (scene.hpp), its meshes (mesh.hpp) and its files (scene_io.hpp) are checked
// against where they enter: what ODE 0.16 (double) and the reference solver can represent, with
// margin. Each limit carries the reason for its value; scene.hpp states the ranges per field.
// Internal: used by scene.cpp, scene_io.cpp and mesh.cpp.
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>
#include <system_error>

namespace rheofeed::scene::limits {

// |coordinate| of every position (geoms, plane offsets, spawn bounds, axis origins, exit point,
// removal height), m. ODE's hash space turns AABB bounds into int cell indices and asserts
// beyond about 2.2e9 m (issue 9); 1e6 m keeps three orders of margin, and at 1e6 m a double
// still resolves 1.2e-10 m, 1e5 times finer than the smallest size below.
constexpr double kMaxCoordinate = 1e6;

// Sizes (box edges, radii, lengths, mesh extents) of parts and fixtures, m. With the density
// range below, mass m ~ rho s^3 and inertia I ~ m s^2 stay normal doubles far from both ends:
//   smallest: rho 1e-3 kg/m^3, s 1e-5 m -> m = 1e-18 kg, I = 1e-28 kg m^2 (DBL_MIN = 2.2e-308;
//             dMassCheck failed at s = 1e-300, where s^3 underflows to 0);
//   largest:  rho 1e6 kg/m^3,  s 1e3 m  -> m = 1e15 kg, I = 1e21 kg m^2, and with the speed
//             bounds below I w = 1e25, w x I w = 1e29 (DBL_MAX = 1.8e308; density 1e300 or
//             size 1e300 overflowed the inertia and broke ODE's quaternion normalisation).
// 10 um to 1 km also brackets every part and fixture a feeder is made of by orders.
constexpr double kMinSize = 1e-5;
constexpr double kMaxSize = 1e3;

// Density, kg/m^3: below silica aerogel (~1) by three orders, above osmium (22 590) by 44x
// (room for the effective density of a loaded or hollow part modelled as solid).
constexpr double kMinDensity = 1e-3;
constexpr double kMaxDensity = 1e6;

// Speeds: belt speed, drift and calibrated drift (linear), initial velocities, peak vibration
// speed 2 pi f A, max_correcting_velocity, m/s. Feeders run below 10 m/s; the plugin's contact
// gets motion1 = |v| and fdir1 = v / |v|, which overflowed at |v| ~ 1e154 (|v|^2 = inf) without
// a word; 1e3 m/s keeps |v|^2 <= 1e6 and two orders above any feeder.
constexpr double kMaxSpeed = 1e3;
// Angular speeds (drift, peak torsion speed 2 pi f theta), rad/s: the linear bound at a 0.1 m
// radius (a small turntable or bowl), 95 000 rpm.
constexpr double kMaxAngularSpeed = 1e4;
// |gravity|, m/s^2: 100 g, so that g h stays within kMaxSpeed up to the largest time step.
constexpr double kMaxGravity = 1e3;
// Vibration frequency, Hz: piezo feeders run at a few hundred Hz; 1e5 Hz is ultrasound.
constexpr double kMaxFrequency = 1e5;
// Peak torsion angle, rad: a half turn (sin is monotonic over the amplitude only up to pi/2, a
// larger amplitude is almost certainly degrees given as radians).
constexpr double kMaxTorsion = 3.14159265358979323846;

// Angles given in scene files (rotations, throw angles, phases), degrees: |angle| <= 1e6
// degrees (2778 turns). A double resolves 1e6 degrees to 1.1e-10 degree; an angle of 1e300
// (issue 20) is a multiple of 360 degrees to the last bit and means nothing. In radians:
constexpr double kMaxAngleDegrees = 1e6;
constexpr double kMaxAngle = kMaxAngleDegrees * 3.14159265358979323846 / 180;

// Time step, s: 1 us (a 1e-12 s step "hung" a run: 1e12 steps per simulated second) to 1 s
// (20x the largest step the stability matrix of issue 7 tries, 0.05 s).
constexpr double kMinTimeStep = 1e-6;
constexpr double kMaxTimeStep = 1.0;
// duration / time_step, steps: an ODE step of one part costs about 1 us, so 1e9 steps are
// at least a quarter of an hour of CPU; more is a typo (a duration in ms, a step in us), not a
// plan (a duration of 1e300 s "ran" as 1e302 steps and exited 0 having simulated nothing).
constexpr double kMaxSteps = 1e9;
// Solver iteration budgets (iterations, coulomb_iterations): a million sweeps per step is
// beyond any use (ODE's quickstep default is 20) and keeps the count an int with margin
// (2e9 iterations hung a run).
constexpr int kMaxIterations = 1000000;
// Friction coefficient: 10 is past any measured dry pair (rubber on rubber ~ 1-2); larger is
// a typo, and mu^2 terms of the cone stay tame.
constexpr double kMaxMu = 10;

// Parts (sum of all counts) plus fixture geoms: the geoms of ODE's hash space. Its collide
// puts on the stack (alloca) an n x n bit matrix (n^2 / 8 bytes), a table of > 8 n pointers
// and up to 8 cell nodes of ~48 bytes per geom: 2 MiB + 0.25 MiB + 1.5 MiB at n = 4096,
// under half the 8 MiB default stack of a Linux main thread (140 000 fixture geoms needed
// 2.3 GiB and aborted ODE).
constexpr long kMaxGeoms = 4096;

// Scene files, bytes: scenes are hand-written parameters (the largest demo scene is 12 KB);
// 16 MiB is 1000x that and bounds the JSON DOM (~10-20 bytes per byte of text) to ~300 MiB.
constexpr std::uintmax_t kMaxSceneFileBytes = 16u << 20;
// Mesh files, bytes: the demo bowl (binary STL) is 150 KB; 256 MiB holds a 5-million-triangle
// binary STL, beyond kMaxTriangles below.
constexpr std::uintmax_t kMaxMeshFileBytes = 256u << 20;
// Triangles per mesh: ODE's trimesh (OPCODE) builds an AABB tree of ~ 2 nodes per triangle and
// tests contacts triangle by triangle; 1e6 triangles (the demo bowl has 3 000) keeps a mesh
// collider within ~100 MB and a step's mesh tests bounded.
constexpr long kMaxTriangles = 1000000;
// A part mesh whose volume is below this fraction of its bounding sphere's is refused as
// degenerate (flat or a sliver): a 0.5 mm x 10 cm x 10 cm plate is 3e-3, a 10 um x 1 m x 1 m foil
// 7e-6; below 1e-6 the inertia is dominated by rounding.
constexpr double kMinVolumeFraction = 1e-6;

// "" when `file` is a regular file (symbolic links followed) of 1 to max_bytes bytes, else what
// it is: missing, a directory, a FIFO, a socket, a device, empty or too large. Uses stat only,
// never opens the file, so that a FIFO or a device is refused without blocking or reading.
inline std::string regularFileProblem(const std::filesystem::path& file, std::uintmax_t max_bytes) {
  namespace fs = std::filesystem;
  std::error_code ec;
  const fs::file_status status = fs::status(file, ec);
  if (status.type() == fs::file_type::not_found) return "file not found";
  if (ec) return "cannot access the file: " + ec.message();
  switch (status.type()) {
    case fs::file_type::regular:
      break;
    case fs::file_type::directory:
      return "is a directory, not a regular file";
    case fs::file_type::fifo:
      return "is a FIFO (named pipe), not a regular file";
    case fs::file_type::socket:
      return "is a socket, not a regular file";
    case fs::file_type::character:
      return "is a character device, not a regular file";
    case fs::file_type::block:
      return "is a block device, not a regular file";
    default:
      return "is not a regular file";
  }
  const std::uintmax_t bytes = fs::file_size(file, ec);
  if (ec) return "cannot read the file size: " + ec.message();
  if (bytes == 0) return "the file is empty";
  if (bytes > max_bytes) {
    return "the file is " + std::to_string(bytes) + " bytes; at most " + std::to_string(max_bytes) +
           " bytes (" + std::to_string(max_bytes >> 20) + " MiB) are read";
  }
  return "";
}

}  // namespace rheofeed::scene::limits

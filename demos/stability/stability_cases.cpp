// SPDX-License-Identifier: MIT
// The cases of the stability matrix (issue 7). Every case is built in code with the floor (belt,
// table, track) top at z = 0, gravity -9.81 m/s^2 along z, and lists the surfaces whose
// penetration is measured. Parts spawned at t = 0 may not overlap (drawParts refuses it, with
// bounding spheres), so stacked parts are spawned just clear of each other and fall a little.
#include "stability/stability_cases.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include "common/builtin_scenes.hpp"
#include "rheofeed/measure/calibration.hpp"
#include "rheofeed/measure/classical_model.hpp"
#include "rheofeed/number_format.hpp"

namespace rheofeed::stability {
namespace {

using namespace rheofeed::scene;

constexpr double kG = 9.81;
constexpr double kInf = std::numeric_limits<double>::infinity();
/// Vertical gap (m) between a spawned part and what is under it.
constexpr double kGap = 1e-3;
/// Vibration angle beta of the vibrating tracks (rad): 30 degrees, a usual linear feeder.
constexpr double kBeta = kPi / 6;

/// Builds one case step by step.
class Builder {
 public:
  Builder(const std::string& name, const std::string& covers) {
    c_.name = name;
    c_.covers = covers;
    Scene& s = c_.scene;
    s.name = name;
    s.solver.time_step = 0.01;
    s.solver.iterations = 50;
    s.material.mu = 0.5;
    s.duration = 1.0;
    s.removal_height = -0.3;  // parts off an edge leave the simulation after a 0.3 m fall
  }
  Scene& scene() { return c_.scene; }
  StabilityCase& kase() { return c_; }

  /// A box fixture of `size` (m) centred at `centre`; returns the fixture index.
  int boxFixture(const std::string& name, const Vec3& size, const Vec3& centre) {
    Fixture f;
    f.name = name;
    Fixture::Geom g;
    g.shape.kind = Shape::Kind::Box;
    g.shape.size = size;
    g.pose.position = centre;
    f.geoms.push_back(g);
    c_.scene.fixtures.push_back(f);
    return static_cast<int>(c_.scene.fixtures.size()) - 1;
  }
  /// A floor lx x ly (m), `thickness` thick, top at z = 0 centred on the origin; its top face
  /// is a measured surface.
  int floor(double lx, double ly, double thickness = 0.05, const std::string& name = "floor") {
    const int f = boxFixture(name, {lx, ly, thickness}, {0, 0, -0.5 * thickness});
    Surface top;
    top.name = name;
    top.region_min = {-0.5 * lx, -0.5 * ly, -kInf};
    top.region_max = {0.5 * lx, 0.5 * ly, kInf};
    top.fixture = f;
    c_.surfaces.push_back(top);
    return f;
  }
  /// A belt along +x at `speed` (m/s).
  int belt(double speed, double lx, double ly, double thickness = 0.05) {
    const int f = floor(lx, ly, thickness, "belt");
    FeederLaw& law = c_.scene.fixtures[f].law;
    law.kind = FeederLaw::Kind::Belt;
    law.belt_speed = speed;
    return f;
  }
  /// A turntable: a disc of `radius` (m), 5 cm thick, top at z = 0, turning at `omega` (rad/s)
  /// about +z through the origin.
  int turntable(double omega, double radius) {
    Fixture f;
    f.name = "table";
    Fixture::Geom g;
    g.shape.kind = Shape::Kind::Cylinder;
    g.shape.radius = radius;
    g.shape.length = 0.05;
    g.pose.position = {0, 0, -0.025};
    f.geoms.push_back(g);
    f.law.kind = FeederLaw::Kind::Drift;
    f.law.drift.angular = {0, 0, omega};
    c_.scene.fixtures.push_back(f);
    const int index = static_cast<int>(c_.scene.fixtures.size()) - 1;
    Surface top;
    top.name = "table";
    top.disc_radius = radius;
    top.fixture = index;
    c_.surfaces.push_back(top);
    return index;
  }
  /// A static rim of 36 boxes (2 cm thick, 6 cm tall, bottom 1 cm under the table top) around
  /// a table of `radius` (m).
  void rim(double radius) {
    c_.scene.fixtures.push_back(boxRing("rim", 36, radius + 0.01, radius + 0.01, 0.02, 0.06, 0.02));
  }
  /// A vibrating track along +x: floor lx x ly, 5 cm thick, vibrating at `frequency` (Hz) along
  /// (cos beta, 0, sin beta) with the amplitude of throw number `gamma`; an end wall at
  /// x = lx / 2 (part of the track, 1 cm thick, 5 cm tall, bottom at z = wall_bottom).
  int vibratingTrack(double frequency, double gamma, double lx = 1.0, double ly = 0.2,
                     double wall_bottom = -0.05) {
    const int f = floor(lx, ly, 0.05, "track");
    Fixture& track = c_.scene.fixtures[f];
    const double w = 2 * kPi * frequency;
    Vibration& v = track.law.vibration;
    track.law.kind = FeederLaw::Kind::Vibration;
    v.frequency = frequency;
    v.amplitude = gamma * kG / (w * w * std::sin(kBeta));
    v.direction = {std::cos(kBeta), 0, std::sin(kBeta)};
    endWall(f, 0.5 * lx, ly, wall_bottom, 0.05);
    Scene& s = c_.scene;
    s.solver.surface_layer = 1e-5;  // a tenth of builtin_scenes' value: thin plates stay measured
    return f;
  }
  /// A wall across x at x = x0 (its face towards -x), `height` (m) above z = 0, bottom at z =
  /// bottom (0: flush with the floor top), 1 cm thick, as a geom of fixture `fixture` (or its
  /// own static fixture when fixture < 0). Its face is a measured surface.
  void endWall(int fixture, double x0, double ly, double bottom, double height) {
    Fixture::Geom g;
    g.shape.kind = Shape::Kind::Box;
    g.shape.size = {0.01, ly, height - bottom};
    g.pose.position = {x0 + 0.005, 0, 0.5 * (height + bottom)};
    if (fixture < 0) {
      Fixture f;
      f.name = "wall";
      f.geoms.push_back(g);
      c_.scene.fixtures.push_back(f);
      fixture = static_cast<int>(c_.scene.fixtures.size()) - 1;
    } else {
      c_.scene.fixtures[fixture].geoms.push_back(g);
    }
    Surface face;
    face.name = "wall";
    face.normal = {-1, 0, 0};
    face.offset = -x0;
    face.region_min = {-kInf, -0.5 * ly, bottom};
    face.region_max = {kInf, 0.5 * ly, height};
    face.fixture = fixture;
    c_.surfaces.push_back(face);
  }
  /// A static square bin: four walls of height `height` around [-half, half]^2.
  void bin(double half, double height) {
    Fixture f;
    f.name = "bin";
    for (int k = 0; k < 4; ++k) {
      Fixture::Geom g;
      g.shape.kind = Shape::Kind::Box;
      const bool along_y = k < 2;
      const double sign = k % 2 == 0 ? 1 : -1;
      g.shape.size = along_y ? Vec3{0.01, 2 * half + 0.02, height + 0.05}
                             : Vec3{2 * half + 0.02, 0.01, height + 0.05};
      g.pose.position = along_y ? Vec3{sign * (half + 0.005), 0, 0.5 * (height - 0.05)}
                                : Vec3{0, sign * (half + 0.005), 0.5 * (height - 0.05)};
      f.geoms.push_back(g);
    }
    c_.scene.fixtures.push_back(f);
  }

  /// Adds a part family; returns it for further settings.
  PartSpec& parts(Shape::Kind shape, const Vec3& size, double density, int count,
                  const Vec3& spawn_min, const Vec3& spawn_max, bool random_orientation = false) {
    PartSpec p;
    p.name = "parts" + std::to_string(c_.scene.parts.size());
    p.shape = shape;
    p.size[0].mean = size.x;
    p.size[1].mean = size.y;
    p.size[2].mean = size.z;
    p.density = density;
    p.count = count;
    p.spawn_min = spawn_min;
    p.spawn_max = spawn_max;
    p.random_orientation = random_orientation;
    c_.scene.parts.push_back(p);
    return c_.scene.parts.back();
  }
  /// One box of `size` (m) and `mass` (kg) whose centre is at (x, y) and whose bottom is at
  /// least `bottom` (m) high and clear (by bounding spheres) of the single parts placed before.
  PartSpec& boxAt(const Vec3& size, double mass, double x, double y, double bottom) {
    const double bound = 0.5 * norm(size);
    double z = bottom + 0.5 * size.z;
    for (const auto& [c, r] : placed_) {
      const double dxy = std::hypot(c.x - x, c.y - y);
      const double reach = r + bound + 1e-4;
      if (dxy < reach) z = std::max(z, c.z + std::sqrt(reach * reach - dxy * dxy));
    }
    placed_.push_back({{x, y, z}, bound});
    return parts(Shape::Kind::Box, size, mass / (size.x * size.y * size.z), 1, {x, y, z},
                 {x, y, z});
  }

  /// Vibrating scenes: the rheonomic runs use the classical model's drift (calibrateClassical;
  /// it needs mu > 0, otherwise the drift is 0 and the note says so). Then the bounds box.
  StabilityCase finish() {
    Scene& s = c_.scene;
    // A run samples at most once per step (Scene::validate refuses a shorter sample interval):
    // the coarse-step cases sample once per step.
    s.outputs.sample_interval = std::max(s.outputs.sample_interval, s.solver.time_step);
    for (std::size_t f = 0; f < s.fixtures.size(); ++f) {
      if (s.fixtures[f].law.kind != FeederLaw::Kind::Vibration) continue;
      try {
        s = withCalibration(s, calibrateClassical(s, static_cast<int>(f)));
      } catch (const std::exception& e) {
        s.fixtures[f].law.drift_model = DriftModel::CalibratedDrift;
        s.fixtures[f].law.has_calibrated_drift = true;
        s.fixtures[f].law.calibrated_drift = {};
        c_.note += (c_.note.empty() ? "" : "; ") + std::string("classical calibration refused (") +
                   e.what() + "): rheonomic drift 0";
      }
    }
    bounds();
    c_.surface_speed = surfaceSpeed();
    return c_;
  }

 private:
  /// The fixtures' bounding box grown by 0.3 m sideways and 0.5 m up (beyond: lost).
  void bounds() {
    Vec3 lo{kInf, kInf, kInf}, hi{-kInf, -kInf, -kInf};
    auto grow = [&](const Vec3& p) {
      lo = {std::min(lo.x, p.x), std::min(lo.y, p.y), std::min(lo.z, p.z)};
      hi = {std::max(hi.x, p.x), std::max(hi.y, p.y), std::max(hi.z, p.z)};
    };
    for (const Fixture& f : c_.scene.fixtures) {
      for (const Fixture::Geom& g : f.geoms) {
        const Shape& sh = g.shape;
        const double r =
            sh.kind == Shape::Kind::Box ? 0.5 * norm(sh.size) : sh.radius + 0.5 * sh.length;
        grow(g.pose.position + Vec3{r, r, r});
        grow(g.pose.position - Vec3{r, r, r});
      }
    }
    for (const PartSpec& p : c_.scene.parts) grow(p.spawn_max);
    c_.bounds_min = lo - Vec3{0.3, 0.3, 1.0};
    c_.bounds_max = hi + Vec3{0.3, 0.3, 0.5};
  }
  /// Fastest surface speed (m/s): belt speed, drift |v| + |w| r_max, vibration peak velocity.
  double surfaceSpeed() const {
    double v = 0;
    for (const Fixture& f : c_.scene.fixtures) {
      double reach = 0;  // farthest geom point from the law's origin (m)
      const Vec3 origin =
          f.law.kind == FeederLaw::Kind::Drift ? f.law.drift.origin : f.law.vibration.axis_origin;
      for (const Fixture::Geom& g : f.geoms) {
        const Shape& sh = g.shape;
        const double r =
            sh.kind == Shape::Kind::Box ? 0.5 * norm(sh.size) : sh.radius + 0.5 * sh.length;
        reach = std::max(reach, norm(g.pose.position - origin) + r);
      }
      switch (f.law.kind) {
        case FeederLaw::Kind::Belt:
          v = std::max(v, std::abs(f.law.belt_speed));
          break;
        case FeederLaw::Kind::Drift:
          v = std::max(v, norm(f.law.drift.linear) + norm(f.law.drift.angular) * reach);
          break;
        case FeederLaw::Kind::Vibration: {
          const Vibration& vib = f.law.vibration;
          const double w = 2 * kPi * vib.frequency;
          v = std::max(v, w * (vib.amplitude + vib.torsion_amplitude * reach));
          v = std::max(v, norm(f.law.calibrated_drift.linear) +
                              norm(f.law.calibrated_drift.angular) * reach);
          break;
        }
        case FeederLaw::Kind::None:
          break;
      }
    }
    return v;
  }

  StabilityCase c_;
  std::vector<std::pair<Vec3, double>> placed_;
};

// --- Mass ratios -------------------------------------------------------------------------------

/// Four 1 cm cubes (1 g) under a 10 x 10 x 5 cm box of mass 1 g x ratio.
StabilityCase lightUnderHeavy(double ratio, double h, bool dantzig) {
  std::string name = "light_under_heavy_r" + formatNumber(ratio);
  if (h != 0.01) name += "_h" + formatNumber(h);
  if (dantzig) name += "_dantzig";
  Builder b(name, "mass ratio " + formatNumber(ratio) + " in contact: 1 g cubes under a heavy box");
  b.floor(1, 1);
  for (double x : {-0.035, 0.035}) {
    for (double y : {-0.035, 0.035}) b.boxAt({0.01, 0.01, 0.01}, 1e-3, x, y, kGap);
  }
  b.boxAt({0.1, 0.1, 0.05}, 1e-3 * ratio, 0, 0, 0.01 + kGap);
  b.scene().solver.time_step = h;
  b.scene().solver.ode_quickstep = !dantzig;
  b.kase().note = "the box falls ~4 cm onto the cubes (spawned clear of them)";
  return b.finish();
}

/// A 1 g cube on a box of mass 1 g x ratio.
StabilityCase heavyUnderLight(double ratio) {
  Builder b("heavy_under_light_r" + formatNumber(ratio),
            "mass ratio " + formatNumber(ratio) + " in contact: a 1 g cube on a heavy box");
  b.floor(1, 1);
  b.boxAt({0.1, 0.1, 0.05}, 1e-3 * ratio, 0, 0, kGap);
  b.boxAt({0.01, 0.01, 0.01}, 1e-3, 0.02, 0.01, 0.05 + kGap);
  return b.finish();
}

/// A belt at 0.5 m/s pushes a heavy box (1 g x ratio) against a 1 g cube held by a wall.
StabilityCase squeezedAgainstWall(double ratio) {
  Builder b(
      "squeezed_wall_r" + formatNumber(ratio),
      "mass ratio " + formatNumber(ratio) + ": 1 g cube squeezed between a wall and a heavy box");
  b.belt(0.5, 1.0, 0.4);
  b.endWall(-1, 0.2, 0.3, 0.0, 0.1);
  b.boxAt({0.01, 0.01, 0.01}, 1e-3, 0.2 - 0.0055, 0, kGap);
  b.boxAt({0.1, 0.1, 0.05}, 1e-3 * ratio, 0.2 - 0.0115 - 0.05 - 0.001, 0, kGap);
  return b.finish();
}

// --- Sizes -------------------------------------------------------------------------------------

std::vector<StabilityCase> sizeCases() {
  std::vector<StabilityCase> out;
  for (double h : {0.01, 0.001}) {
    Builder b("cube_1mm_h" + formatNumber(h),
              "1 mm steel cubes dropped 2 mm, h = " + formatNumber(h) + " s");
    b.floor(0.2, 0.2);
    b.parts(Shape::Kind::Box, {1e-3, 1e-3, 1e-3}, 7800, 10, {-0.02, -0.02, 0.002},
            {0.02, 0.02, 0.004}, true);
    b.scene().solver.time_step = h;
    b.kase().note =
        "h v at landing = " + formatNumber(h * std::sqrt(2 * kG * 0.004)) + " m vs 1 mm part";
    out.push_back(b.finish());
  }
  {
    Builder b("cube_1mm_belt", "1 mm cubes on a 0.2 m/s belt");
    b.belt(0.2, 1.0, 0.2);
    b.parts(Shape::Kind::Box, {1e-3, 1e-3, 1e-3}, 7800, 10, {-0.3, -0.02, 0.0015},
            {-0.25, 0.02, 0.0015});
    out.push_back(b.finish());
  }
  {
    Builder b("sphere_1mm_belt", "1 mm spheres (r 0.5 mm) on a 0.2 m/s belt");
    b.belt(0.2, 1.0, 0.2);
    b.parts(Shape::Kind::Sphere, {5e-4, 0, 0}, 7800, 10, {-0.3, -0.02, 0.001},
            {-0.25, 0.02, 0.001});
    out.push_back(b.finish());
  }
  {
    Builder b("cube_10cm_drop", "10 cm boxes dropped 5 cm at random orientations");
    b.floor(1, 1);
    b.parts(Shape::Kind::Box, {0.1, 0.1, 0.1}, 1000, 4, {-0.3, -0.3, 0.15}, {0.3, 0.3, 0.2}, true);
    out.push_back(b.finish());
  }
  {
    Builder b("capsule_10cm_turntable", "10 cm capsules on a 2 rad/s turntable");
    b.turntable(2, 0.4);
    b.rim(0.4);
    b.parts(Shape::Kind::Capsule, {0.01, 0.08, 0}, 7800, 4, {-0.25, -0.25, 0.06},
            {0.25, 0.25, 0.08}, true);
    out.push_back(b.finish());
  }
  {
    Builder b("cylinder_2mm_pile", "2 mm cylinders (r 1 mm) dropped in a heap");
    b.floor(0.2, 0.2);
    b.parts(Shape::Kind::Cylinder, {1e-3, 2e-3, 0}, 7800, 30, {-0.01, -0.01, 0.003},
            {0.01, 0.01, 0.02}, true);
    out.push_back(b.finish());
  }
  {
    Builder b("plate_0p5mm_floor", "0.5 mm plates (20 x 20 mm) laid on the floor");
    b.floor(0.4, 0.4);
    b.parts(Shape::Kind::Box, {0.02, 0.02, 5e-4}, 7800, 20, {-0.15, -0.15, 5e-4},
            {0.15, 0.15, 5e-4});
    out.push_back(b.finish());
  }
  {
    Builder b("plate_0p5mm_stack", "ten 0.5 mm plates stacked");
    b.floor(0.4, 0.4);
    for (int i = 0; i < 10; ++i) b.boxAt({0.02, 0.02, 5e-4}, 1.56e-3, 0, 0, 1e-4);
    b.kase().note = "spawned clear by bounding spheres: the stack falls ~1.4 cm per plate";
    out.push_back(b.finish());
  }
  {
    Builder b("plate_0p5mm_wall_flush", "0.5 mm plates driven by a belt against a flush wall");
    b.belt(0.3, 1.0, 0.2);
    b.endWall(-1, 0.2, 0.2, 0.0, 0.05);
    b.parts(Shape::Kind::Box, {0.02, 0.02, 5e-4}, 7800, 20, {-0.3, -0.08, 5e-4}, {0.0, 0.08, 5e-4});
    b.kase().note = "the wall's bottom is flush with the belt top: nothing closes the seam";
    out.push_back(b.finish());
  }
  {
    Builder b("plate_0p5mm_vibrating", "0.5 mm plates on a 50 Hz track against a flush end wall");
    b.vibratingTrack(50, 1.5, 0.6, 0.2, 0.0);
    b.parts(Shape::Kind::Box, {0.02, 0.02, 5e-4}, 7800, 10, {-0.2, -0.08, 5e-4},
            {0.15, 0.08, 5e-4});
    b.scene().duration = 3;
    b.kase().fv_duration = 1.0;
    out.push_back(b.finish());
  }
  return out;
}

// --- Time steps --------------------------------------------------------------------------------

StabilityCase beltStep(double h) {
  Builder b("belt_h" + formatNumber(h),
            "rheonomic h = " + formatNumber(h) + " s: boxes dropped on a 0.5 m/s belt");
  b.belt(0.5, 2.0, 0.4);
  b.parts(Shape::Kind::Box, {0.02, 0.02, 0.02}, 1000, 10, {-0.8, -0.15, 0.02}, {-0.5, 0.15, 0.05},
          true);
  b.scene().solver.time_step = h;
  b.scene().duration = h < 1e-3 ? 0.3 : 2.0;
  return b.finish();
}

StabilityCase tunnelDrop(double h) {
  Builder b("drop_0p5m_h" + formatNumber(h),
            "2 cm boxes dropped 0.5 m on a 1 cm floor, h = " + formatNumber(h));
  b.floor(1, 1, 0.01);
  b.parts(Shape::Kind::Box, {0.02, 0.02, 0.02}, 1000, 20, {-0.3, -0.3, 0.45}, {0.3, 0.3, 0.5},
          true);
  b.scene().solver.time_step = h;
  const double v = std::sqrt(2 * kG * 0.5);
  b.kase().note = "h v at landing = " + formatNumber(h * v) + " m vs floor 0.01 m + part 0.02 m";
  return b.finish();
}

// --- Vibrating tracks --------------------------------------------------------------------------

/// Ten 10 x 10 x 5 mm steel boxes in a row across a vibrating track.
StabilityCase track(const std::string& name, const std::string& covers, double frequency,
                    double gamma, int steps_per_cycle, double mu = 0.4) {
  Builder b(name, covers);
  b.vibratingTrack(frequency, gamma);
  b.parts(Shape::Kind::Box, {0.01, 0.01, 0.005}, 7800, 10, {-0.35, -0.09, 0.0025 + kGap},
          {-0.2, 0.09, 0.0025 + kGap});
  b.scene().material.mu = mu;
  b.scene().duration = 2.0;
  b.kase().fv_steps_per_cycle = steps_per_cycle;
  // Full vibration: 1 s, or 50000 steps when fewer (1000 steps per cycle at 50 Hz: 1 s).
  b.kase().fv_duration = std::min(1.0, 50000.0 / (frequency * steps_per_cycle));
  return b.finish();
}

// --- Belts, turntables -------------------------------------------------------------------------

StabilityCase beltSpeed(double speed, double h, bool lone, double mu = 0.5) {
  std::string name = (lone ? "belt_lone_box_" : "belt_") + formatNumber(speed) + "mps";
  if (h != 0.01) name += "_h" + formatNumber(h);
  if (mu != 0.5) name += "_mu" + formatNumber(mu);
  Builder b(name, "belt " + formatNumber(speed) + " m/s, mu " + formatNumber(mu) + ", h " +
                      formatNumber(h));
  b.belt(speed, 6.0, 0.4);
  if (lone) {
    b.parts(Shape::Kind::Box, {0.05, 0.05, 0.05}, 1000, 1, {-2.5, 0, 0.025 + kGap},
            {-2.5, 0, 0.025 + kGap});
  } else {
    b.parts(Shape::Kind::Box, {0.02, 0.02, 0.02}, 1000, 10, {-2.7, -0.15, 0.02}, {-2.4, 0.15, 0.05},
            true);
  }
  b.scene().material.mu = mu;
  b.scene().solver.time_step = h;
  if (!lone && speed >= 3) {
    // Measured over seeds 1-8 at 3 m/s: 6 of 80 boxes lost at h = 0.01 s, 3 at 0.002 s and 4 at
    // 0.001 s (and 1 of 60 over seeds 1-6 at 10 m/s, h = 0.01 s): the step does not make it.
    b.kase().note =
        "boxes dropped onto a belt at >= 3 m/s tumble as it catches them; a few leave over its "
        "open sides (lost, must be reported)";
    b.kase().expect_losses = true;
  }
  return b.finish();
}

StabilityCase turntableCase(double omega, bool rim, double duration) {
  std::string name = "turntable_" + formatNumber(omega) + "rads";
  if (rim) name += "_rim";
  if (duration != 1) name += "_" + formatNumber(duration) + "s";
  Builder b(name, "turntable " + formatNumber(omega) + " rad/s (rim speed " +
                      formatNumber(omega * 0.3) + " m/s)" + (rim ? " with a rim" : "") + ", " +
                      formatNumber(duration) + " s");
  b.turntable(omega, 0.3);
  if (rim) b.rim(0.3);
  if (duration > 10) {
    b.parts(Shape::Kind::Box, {0.02, 0.02, 0.02}, 1000, 1, {0.2, 0, 0.01 + kGap},
            {0.2, 0, 0.01 + kGap});
  } else {
    b.parts(Shape::Kind::Box, {0.02, 0.02, 0.02}, 1000, 8, {-0.2, -0.2, 0.01 + kGap},
            {0.2, 0.2, 0.01 + kGap});
  }
  b.scene().material.mu = 0.8;
  b.scene().duration = duration;
  if (!rim && omega * omega * 0.05 > 0.8 * kG) {
    b.kase().note = "w^2 r > mu g beyond r = " + formatNumber(0.8 * kG / (omega * omega)) +
                    " m: parts fly off the table (lost, must be reported)";
    b.kase().expect_losses = true;
  }
  if (rim && omega * omega * 0.29 > 50 * kG) {
    b.kase().note = "w^2 r = " + formatNumber(omega * omega * 0.29 / kG) +
                    " g at the rim: the boxes tumble against the 6 cm rim and some are thrown "
                    "over it (lost, must be reported; the reference engine loses one the same way)";
    b.kase().expect_losses = true;
  }
  return b.finish();
}

}  // namespace

std::vector<StabilityCase> stabilityCases() {
  std::vector<StabilityCase> out;
  auto add = [&](StabilityCase c) { out.push_back(std::move(c)); };

  // Mass ratios to 1e4: light under heavy, heavy under light, squeezed against a wall.
  for (double r : {1e2, 1e3, 1e4}) add(lightUnderHeavy(r, 0.01, false));
  add(lightUnderHeavy(1e4, 0.001, false));
  add(lightUnderHeavy(1e4, 0.01, true));
  for (double r : {1e2, 1e4}) add(heavyUnderLight(r));
  for (double r : {1e2, 1e4}) add(squeezedAgainstWall(r));

  // Sizes 1 mm to 10 cm, 0.5 mm plates.
  for (StabilityCase& c : sizeCases()) add(std::move(c));

  // Rheonomic time steps 1e-4 to 0.05 s; tunnelling drops.
  for (double h : {1e-4, 1e-3, 0.01, 0.02, 0.05}) add(beltStep(h));
  for (double h : {0.01, 0.05}) add(tunnelDrop(h));

  // Full vibration: 10 to 1000 steps per cycle at 50 Hz, throw number 1.5.
  for (int n : {10, 20, 50, 100, 200, 1000}) {
    add(track("track_spc" + std::to_string(n),
              "full vibration, " + std::to_string(n) + " steps per cycle (50 Hz, throw 1.5)", 50,
              1.5, n));
  }
  // Frequencies 50 to 500 Hz.
  for (double f : {100.0, 200.0, 500.0}) {
    add(track("track_" + formatNumber(f) + "hz",
              formatNumber(f) + " Hz, throw 1.5, 100 steps per cycle", f, 1.5, 100));
  }
  add(track("track_500hz_spc20", "500 Hz, throw 1.5, 20 steps per cycle", 500, 1.5, 20));
  // Throw numbers to 6.
  for (double g : {0.5, 1.0, 3.0, 6.0}) {
    add(track("track_throw" + formatNumber(g), "throw number " + formatNumber(g) + " at 50 Hz", 50,
              g, 100));
  }
  add(track("track_throw6_500hz", "throw number 6 at 500 Hz", 500, 6, 50));
  // Friction on the track.
  for (double mu : {0.0, 0.01, 1.0, 2.0}) {
    add(track("track_mu" + formatNumber(mu),
              "mu " + formatNumber(mu) + " on a 50 Hz track (throw 1.5)", 50, 1.5, 100, mu));
  }

  // Friction and speed on belts.
  for (double mu : {0.0, 0.01, 1.0, 2.0}) add(beltSpeed(1.0, 0.01, false, mu));
  for (double v : {0.1, 3.0, 10.0}) add(beltSpeed(v, 0.01, false));
  add(beltSpeed(10.0, 0.05, false));
  add(beltSpeed(10.0, 0.01, true));
  add(beltSpeed(10.0, 0.05, true));

  // Restitution 0 to 1.
  for (double e : {0.0, 0.5, 1.0}) {
    Builder b("restitution_" + formatNumber(e),
              "1 cm steel spheres dropped 0.2 m, restitution " + formatNumber(e));
    b.floor(1, 1);
    b.parts(Shape::Kind::Sphere, {0.01, 0, 0}, 7800, 5, {-0.2, -0.2, 0.2}, {0.2, 0.2, 0.2});
    b.scene().material.restitution = e;
    b.scene().duration = 2;
    add(b.finish());
  }
  {
    Builder b("restitution_1_bin", "30 boxes dropped in a bin, restitution 1");
    b.floor(1, 1);
    b.bin(0.1, 0.2);
    b.parts(Shape::Kind::Box, {0.02, 0.02, 0.02}, 1000, 30, {-0.08, -0.08, 0.02},
            {0.08, 0.08, 0.15}, true);
    b.scene().material.restitution = 1;
    b.scene().duration = 2;
    add(b.finish());
  }
  {
    StabilityCase c = track("track_restitution_1", "restitution 1 on a 50 Hz track", 50, 1.5, 100);
    c.scene.material.restitution = 1;
    add(c);
  }

  // Turntables to 50 rad/s, and 60 s on one.
  for (double w : {1.0, 5.0, 20.0, 50.0}) add(turntableCase(w, false, 1));
  add(turntableCase(50, true, 1));
  add(turntableCase(1, false, 60));

  // Piles.
  {
    Builder b("pile_1000_bin", "1000 1 cm boxes dropped in a 20 cm bin, h = 0.01 s");
    b.floor(1, 1);
    b.bin(0.1, 0.5);
    b.parts(Shape::Kind::Box, {0.01, 0.01, 0.01}, 2700, 1000, {-0.09, -0.09, 0.01},
            {0.09, 0.09, 0.45}, true);
    b.scene().solver.iterations = 30;
    b.scene().duration = 1;
    add(b.finish());
  }
  {
    Builder b("pile_1000_belt_h0.05", "1000 2 cm boxes dropped on a 10 cm belt, h = 0.05 s");
    b.belt(0.3, 2.0, 0.5, 0.1);
    b.parts(Shape::Kind::Box, {0.02, 0.02, 0.02}, 1000, 1000, {-0.9, -0.2, 0.02}, {0.9, 0.2, 0.3},
            true);
    b.scene().solver.time_step = 0.05;
    b.scene().solver.iterations = 30;
    b.scene().duration = 2;
    b.kase().note = "h v at landing from 0.3 m = " + formatNumber(0.05 * std::sqrt(2 * kG * 0.3)) +
                    " m vs belt 0.1 m + part 0.02 m";
    add(b.finish());
  }
  {
    Builder b("pile_100_track", "100 boxes heaped on a 50 Hz track (throw 1.5)");
    b.vibratingTrack(50, 1.5);
    b.parts(Shape::Kind::Box, {0.01, 0.01, 0.005}, 7800, 100, {-0.45, -0.09, 0.005},
            {-0.2, 0.09, 0.04}, true);
    b.scene().duration = 2;
    b.kase().fv_steps_per_cycle = 50;
    b.kase().fv_duration = 0.5;
    add(b.finish());
  }

  // Spawned overlapping or inside fixtures.
  {
    Builder b("spawn_overlapping_t0", "20 boxes spawned at t = 0 in a region smaller than one");
    b.floor(1, 1);
    b.parts(Shape::Kind::Box, {0.02, 0.02, 0.02}, 1000, 20, {0, 0, 0.011}, {0.01, 0.01, 0.02});
    b.kase().note = "expected refusal: drawParts refuses overlapping parts at t = 0";
    b.kase().expect_refusal = true;
    add(b.finish());
  }
  {
    Builder b("spawn_overlapping_stream", "10 boxes spawned at one point, 20 ms apart");
    b.floor(1, 1);
    PartSpec& p =
        b.parts(Shape::Kind::Box, {0.02, 0.02, 0.02}, 1000, 10, {0, 0, 0.011}, {0, 0, 0.011});
    p.rate = 50;
    b.kase().note =
        "each part spawns inside the previous one (fully overlapping); the speed and energy "
        "budgets allow one push-out at the correcting-velocity cap per part, a chain of pushes "
        "can add up";
    add(b.finish());
  }
  {
    Builder b("spawn_inside_floor_3mm", "1 cm cubes spawned 3 mm into the floor");
    b.floor(1, 1);
    b.parts(Shape::Kind::Box, {0.01, 0.01, 0.01}, 1000, 5, {-0.2, -0.2, 0.002}, {0.2, 0.2, 0.002});
    add(b.finish());
  }
  {
    Builder b("spawn_inside_floor_deep", "1 cm cubes spawned wholly inside a 5 cm floor");
    b.floor(1, 1);
    b.parts(Shape::Kind::Box, {0.01, 0.01, 0.01}, 1000, 5, {-0.2, -0.2, -0.02}, {0.2, 0.2, -0.02});
    b.kase().note = "parts inside a fixture from the start (lost from t = 0, must be reported)";
    add(b.finish());
  }
  {
    Builder b("spawn_inside_wall", "1 cm cubes spawned half inside a wall on a belt");
    b.belt(0.2, 1.0, 0.4);
    b.endWall(-1, 0.2, 0.3, -0.01, 0.1);
    b.parts(Shape::Kind::Box, {0.01, 0.01, 0.01}, 1000, 5, {0.2, -0.1, 0.005 + kGap},
            {0.2, 0.1, 0.005 + kGap});
    add(b.finish());
  }

  // 60 s runs.
  {
    Builder b("belt_wall_60s", "a box held against a wall by a 0.3 m/s belt for 60 s");
    b.belt(0.3, 1.0, 0.4);
    b.endWall(-1, 0.2, 0.3, -0.01, 0.1);
    b.parts(Shape::Kind::Box, {0.03, 0.03, 0.03}, 1000, 1, {0.1, 0, 0.015 + kGap},
            {0.1, 0, 0.015 + kGap});
    b.scene().duration = 60;
    add(b.finish());
  }
  {
    StabilityCase c =
        track("track_60s", "50 Hz track, 60 s rheonomic (2 s full vibration)", 50, 1.5, 50);
    c.scene.duration = 60;
    c.fv_duration = 2;
    add(c);
  }

  // The quick set: a few parts and few steps in every method (the ctest reduced matrix).
  for (StabilityCase& c : out) {
    long steps = std::lround(c.scene.duration / c.scene.solver.time_step);
    int parts = 0;
    for (const PartSpec& p : c.scene.parts) parts += p.count;
    if (c.scene.hasVibration()) {
      const double f = c.scene.fixtures[0].law.vibration.frequency;
      steps = std::max(steps, std::lround(c.fv_duration * f * c.fv_steps_per_cycle));
    }
    c.quick = parts <= 20 && steps * parts <= 20000;
  }
  return out;
}

std::vector<Method> methodsFor(const StabilityCase& c) {
  std::vector<Method> m{Method::OdeRheonomic, Method::ReferenceRheonomic};
  if (c.scene.hasVibration()) {
    m.push_back(Method::OdeFullVibration);
    m.push_back(Method::ReferenceFullVibration);
  }
  return m;
}

Scene sceneFor(const StabilityCase& c, Method method) {
  Scene s = c.scene;
  if (isFullVibration(method)) {
    double f = 0;
    for (const Fixture& x : s.fixtures) {
      if (x.law.kind == FeederLaw::Kind::Vibration) f = std::max(f, x.law.vibration.frequency);
    }
    if (f > 0) s.solver.time_step = 1.0 / (f * c.fv_steps_per_cycle);
    s.duration = c.fv_duration;
  }
  return s;
}

}  // namespace rheofeed::stability

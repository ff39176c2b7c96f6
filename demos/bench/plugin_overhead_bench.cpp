// SPDX-License-Identifier: MIT
// Cost of the rheofeed plugin, measured with Google Benchmark.
//
// 1. Per-step cost of a pile of boxes on a static ground (dWorldQuickStep, hash space) with
//    (a) plain ODE's near callback, (b) the same callback with FeederSet::driveContacts wrapped
//    around it while no contact touches a feeder (a feeder geom exists elsewhere), (c) the ground
//    itself registered as a feeder, so every ground contact is driven.
//    Goal: (b) / (a) within 2 %.
// 2. Cost of driveContacts per contact for a non-feeder contact and per driven feeder contact
//    with each kind of law; a twist with the step given (the secant: a 3 x 3 matrix times a
//    vector per contact) against the static environment and against a part on a body (the
//    secant of the body's centre of mass plus w x (p - x_c)), and the instantaneous twist
//    against a part on a body for comparison; the local vibration law (issue 8) of a translation
//    on a flat feeder (every contact has the previous contact's inputs) and of a screw vibration
//    (contacts spread over radius: the table's interpolation), with the table filled before
//    timing (filling costs milliseconds per cell, once per run).
//
// Each pile repetition builds a fresh, identical scene and times the same fixed number of steps,
// so (a), (b) and (c) see identical work; repetitions are randomly interleaved. The program ends
// with a table of ratios of medians (one run, one machine).
//
//   plugin_overhead_bench [--boxes N] [google benchmark flags]
#include <benchmark/benchmark.h>
#include <ode/ode.h>

#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "bench/box_pile.hpp"
#include "rheofeed/feeder_set.hpp"

namespace {

using rheofeed::FeederSet;
using rheofeed::MotionLaw;

constexpr double kStep = 0.005;    // s
constexpr int kSettleSteps = 100;  // untimed steps before timing: the pile is in contact
constexpr int kTimedSteps = 200;   // steps per repetition
constexpr int kRepetitions = 15;
int g_boxes = 400;

enum class Variant { Plain, PluginNoFeederContacts, PluginGroundIsFeeder };

struct Pile {
  rheofeed::demo::BoxPile pile;
  std::unique_ptr<FeederSet> feeders;

  explicit Pile(Variant v) : pile(g_boxes, dContactApprox1) {
    dGeomID far_feeder = dCreateBox(pile.space(), 1, 1, 0.1);
    dGeomSetPosition(far_feeder, 100, 100, 0);
    if (v != Variant::Plain) {
      feeders = std::make_unique<FeederSet>();
      feeders->add(far_feeder, MotionLaw::belt({1, 0, 0}, 0.2));
      if (v == Variant::PluginGroundIsFeeder) {
        feeders->add(pile.ground(), MotionLaw::belt({1, 0, 0}, 0.2));
      }
      pile.setFeeders(feeders.get());
    }
    for (int i = 0; i < kSettleSteps; ++i) step();
  }
  void step() { pile.step(kStep); }
};

void BM_PileStep(benchmark::State& state) {
  Pile pile(static_cast<Variant>(state.range(0)));
  for (auto _ : state) pile.step();
  state.counters["bodies"] = g_boxes;
}
BENCHMARK(BM_PileStep)
    ->ArgName("variant")
    ->Arg(static_cast<int>(Variant::Plain))
    ->Arg(static_cast<int>(Variant::PluginNoFeederContacts))
    ->Arg(static_cast<int>(Variant::PluginGroundIsFeeder))
    ->Iterations(kTimedSteps)
    ->Repetitions(kRepetitions)
    ->ReportAggregatesOnly(true)
    ->Unit(benchmark::kMicrosecond);

// driveContacts on 64 contacts of one pair, per law kind. Arg: 0 copy only, 1 no feeder,
// 2 belt, 3 translation, 4 twist, 5 field.
void BM_DriveContacts(benchmark::State& state) {
  const int kind = static_cast<int>(state.range(0));
  dGeomID feeder = dCreateBox(nullptr, 1, 1, 1);
  dGeomID part = dCreateBox(nullptr, 1, 1, 1);
  FeederSet set;
  switch (kind) {
    case 1:
      set.add(feeder, MotionLaw::belt({1, 0, 0}, 0.3));
      break;  // contacts use `part` only
    case 2:
      set.add(feeder, MotionLaw::belt({1, 0, 0}, 0.3));
      break;
    case 3:
      set.add(feeder, MotionLaw::translation({0.3, 0, 0}));
      break;
    case 4:
      set.add(feeder, MotionLaw::rotation({0, 0, 1}, {0, 0, 0}));
      break;
    case 5:
      set.add(feeder, MotionLaw::field([](const rheofeed::Vec3& p, const rheofeed::Vec3&, double) {
                return rheofeed::Vec3{-p.y, p.x, 0};
              }));
      break;
    case 6:
    case 7:
    case 8:
      set.add(feeder, MotionLaw::rotation({0, 0, 1}, {0, 0, 0}));
      break;
    case 9: {  // the main demo's trough: 50 Hz, 0.25 mm at 30 degrees
      rheofeed::LocalVibration v;
      v.amplitude = {2.5e-4 * 0.8660254037844387, 0, 2.5e-4 * 0.5};
      set.add(feeder, MotionLaw::localVibration(v));
      break;
    }
    case 10: {  // the bowl's screw: 0.15 mm vertical and 0.17 degrees torsion about +z
      rheofeed::LocalVibration v;
      v.amplitude = {0, 0, 1.5e-4};
      v.torsion_amplitude = 0.17 * 3.14159265358979323846 / 180;
      set.add(feeder, MotionLaw::localVibration(v));
      break;
    }
    default:
      break;
  }
  // Laws 6 and 7 freeze with the step (the secant), 8 without; 7 and 8 carry a part on a body.
  const double step = kind == 6 || kind == 7 ? 1e-3 : 0.0;
  dWorldID world = nullptr;
  if (kind == 7 || kind == 8) {
    world = dWorldCreate();
    dBodyID body = dBodyCreate(world);
    dBodySetPosition(body, 0.3, 0.5, 0.02);
    dGeomSetBody(part, body);
  }
  constexpr int kCount = 64;
  std::vector<dContact> tmpl(kCount), work(kCount);
  for (int i = 0; i < kCount; ++i) {
    std::memset(&tmpl[i], 0, sizeof(dContact));
    tmpl[i].geom.pos[0] = kind == 10 ? 0.13 + 3e-4 * i : 0.01 * i;  // the bowl: r = 130..149 mm
    tmpl[i].geom.pos[1] = kind == 10 ? 0.0 : 0.5;
    tmpl[i].geom.normal[2] = 1;
    tmpl[i].geom.depth = 1e-3;
    tmpl[i].geom.g1 = part;
    tmpl[i].geom.g2 = kind >= 2 ? feeder : dGeomID(nullptr);
    tmpl[i].surface.mode = dContactApprox1;
    tmpl[i].surface.mu = 0.5;
  }
  double t = 0;
  if (kind >= 9) {  // fill the local law's table before timing
    std::memcpy(work.data(), tmpl.data(), sizeof(dContact) * kCount);
    set.beginStep(t += 1e-3, step);
    set.driveContacts(work.data(), kCount);
  }
  for (auto _ : state) {
    std::memcpy(work.data(), tmpl.data(), sizeof(dContact) * kCount);
    if (kind > 0) {
      set.beginStep(t += 1e-3, step);
      benchmark::DoNotOptimize(set.driveContacts(work.data(), kCount));
    }
    benchmark::ClobberMemory();
  }
  state.SetItemsProcessed(state.iterations() * kCount);
  dGeomDestroy(feeder);
  dGeomDestroy(part);
  if (world) dWorldDestroy(world);
}
BENCHMARK(BM_DriveContacts)
    ->ArgName("law")
    ->DenseRange(0, 10)
    ->Repetitions(5)
    ->ReportAggregatesOnly(true);

// Collects medians to print the ratios at the end.
class RatioReporter : public benchmark::ConsoleReporter {
 public:
  void ReportRuns(const std::vector<Run>& runs) override {
    ConsoleReporter::ReportRuns(runs);
    for (const Run& r : runs) {
      if (r.run_type == Run::RT_Aggregate && r.aggregate_name == "median") {
        medians[r.run_name.function_name + "/" + r.run_name.args] =
            r.GetAdjustedCPUTime() / 1.0;  // in the benchmark's time unit
      }
    }
  }
  std::map<std::string, double> medians;
};

}  // namespace

int main(int argc, char** argv) {
  for (int i = 1; i + 1 < argc; ++i) {
    if (std::strcmp(argv[i], "--boxes") == 0) {
      g_boxes = std::atoi(argv[i + 1]);
      if (g_boxes < 1) {
        std::fprintf(stderr, "plugin_overhead_bench: --boxes %s must be a positive integer\n",
                     argv[i + 1]);
        return 2;
      }
      for (int k = i; k + 2 < argc + 1; ++k) argv[k] = argv[k + 2];
      argc -= 2;
      break;
    }
  }
  dInitODE2(0);
  benchmark::Initialize(&argc, argv);
  RatioReporter reporter;
  benchmark::RunSpecifiedBenchmarks(&reporter);
  benchmark::Shutdown();

  auto get = [&](const std::string& key) {
    auto it = reporter.medians.find(key);
    return it == reporter.medians.end() ? -1.0 : it->second;
  };
  const double plain = get("BM_PileStep/variant:0");
  const double wrapped = get("BM_PileStep/variant:1");
  const double ground = get("BM_PileStep/variant:2");
  std::printf("\n## Plugin overhead (medians of %d repetitions x %d steps, %d boxes)\n\n",
              kRepetitions, kTimedSteps, g_boxes);
  std::printf("| quantity | value |\n|---|---|\n");
  if (plain > 0 && wrapped > 0) {
    std::printf("| pile step, plugin wrapped, no feeder contact / plain ODE | %.4f |\n",
                wrapped / plain);
  }
  if (plain > 0 && ground > 0) {
    std::printf(
        "| pile step, ground is a feeder (all ground contacts driven) / plain ODE | %.4f |\n",
        ground / plain);
  }
  const double copy = get("BM_DriveContacts/law:0");
  const char* names[] = {"",
                         "no-feeder contact",
                         "belt",
                         "translation",
                         "twist",
                         "field",
                         "twist secant (step given)",
                         "twist secant carrying a body",
                         "twist without step, part on a body",
                         "local vibration, translation on a flat feeder",
                         "local vibration, screw (bowl, r = 130..149 mm)"};
  for (int k = 1; k <= 10; ++k) {
    const double t = get("BM_DriveContacts/law:" + std::to_string(k));
    if (t > 0 && copy >= 0) {
      std::printf("| driveContacts per %s contact (ns) | %.2f |\n", names[k], (t - copy) / 64.0);
    }
  }
  if (plain > 0) std::printf("| plain pile step (us) | %.1f |\n", plain);
  dCloseODE();
  return 0;
}

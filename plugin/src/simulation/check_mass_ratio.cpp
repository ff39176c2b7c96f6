// SPDX-License-Identifier: MIT
// The measured mass-ratio limits of the scene check (check.hpp): how heavy a part may rest on a
// light one before the solver's iteration count lets it crush the light one into the floor.
#include <algorithm>
#include <cstddef>
#include <limits>

#include "rheofeed/simulation/check.hpp"

namespace rheofeed::scene {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

// ---------------------------------------------------------------------------------------------
// Mass-ratio limits, measured. A light cube on a floor box (top z = 0), a heavy cube of the same
// edge e dropped on it from 0.8 e above, densities 1000 and 1000 R kg/m^3, mu 0.5, the scene
// layer's defaults (ERP 0.2, CFM 1e-5, max correcting velocity 0.5 m/s, no surface layer), run
// 2 s; the stack holds if the larger of (light into floor, heavy into light) stays below e / 4
// during the second second (it either stays below 1.5 mm or the heavy part passes the light
// one completely). The step h is chosen to give X = e / (g h^2), the light part's thickness in
// units of the distance gravity moves it in one step; X, not e or h alone, sets the boundary
// (within a factor of 2 for e = 2, 10 and 50 mm). Entries: the largest ratio R on the grid
// 1, 1.5, 2, 3, 5, 7, 10, 15, 20, 30, 50, ... that held; the minimum over the edges measured
// (2, 10, 50 mm for X = 5, 20, 100, 500; 10 mm elsewhere). Below X = 20 the probe's drop
// itself moves the heavy part by 0.5-0.8 thicknesses in its landing step, so the X = 5 and 10
// rows are lower bounds: the heavy cube lands on speculative contacts with the speed that
// closes the gap, and the next step's box-box contacts of the two exactly aligned faces (3 of
// the 4 corners, by rounding) turn it by 10-30 rad/s; it then rocks and topples off at a few
// times the light one's mass. Equal cubes toppled at X = 5 (k = 10), so below X = 10 the check
// warns for any stack. Below X = 5 (not measured) it warns for any ratio above 1.
// Re-measured after the speculative contacts' leading points moved inside the box
// (contact_collider.cpp, kLeadingPointInset): the X = 10 row fell from 3-70 to 2-7 (the landing
// is now square, see above); the other rows moved within the probe's scatter.
// Measured with the throwaway probe of check_test.cpp's comment (MassRatioProbe), ODE 0.16:
//   rheofeed_scene_tests --gtest_also_run_disabled_tests --gtest_filter='*MassRatioProbe*'
// Quickstep shuffles its constraint rows with ODE's global random generator, so the boundary
// moves from run to run: a repeat of X = 20, k = 20 crushed a stack at R = 7, the table's entry.
// The limit used is the table's times this margin.
constexpr double kRandomOrderMargin = 0.5;
constexpr double kRatioX[] = {5, 10, 20, 50, 100, 200, 500, 2000, 8000};
constexpr int kOdeIterations[] = {10, 20, 50, 100, 200};
constexpr double kOdeHolds[9][5] = {
    {0, 1.5, 1, 1, 2},            // X = 5 (drop-affected; 0: equal cubes toppled)
    {2, 3, 5, 3, 7},              // X = 10 (10 mm only; drop-affected)
    {5, 7, 20, 30, 50},           // X = 20
    {10, 20, 30, 100, 100},       // X = 50 (10 mm only)
    {15, 15, 50, 70, 200},        // X = 100
    {50, 30, 100, 200, 300},      // X = 200 (10 mm only)
    {50, 50, 100, 200, 500},      // X = 500
    {150, 200, 500, 700, 3000},   // X = 2000 (10 mm only)
    {500, 500, 1500, 2000, 7000}  // X = 8000 (10 mm only)
};
// The same probe with contact warm starts (solver.warm_start; RHEOFEED_PROBE=ode_warm), the
// minimum over the same edges as above (all three at X = 5, 20, 100, 500; 10 mm elsewhere),
// after warm starts stopped passing on a contact's first (impact) force, and again after the
// speculative contacts' inset (X = 200 and above, where the drop needs none, came out the same).
// Against the table above it holds as little below X = 20 and 2-15 times less at some points
// above (X = 8000, k = 20: 30 against 500); single runs with one seed, scattered like the table
// above. A run with warm starts takes the smaller of the two tables at each point.
constexpr double kOdeWarmHolds[9][5] = {
    {0, 1.5, 0, 0, 1.5},      // X = 5
    {2, 5, 7, 15, 7},         // X = 10 (10 mm only)
    {5, 15, 15, 100, 70},     // X = 20
    {15, 30, 30, 150, 200},   // X = 50 (10 mm only)
    {20, 30, 150, 150, 200},  // X = 100
    {20, 50, 100, 150, 150},  // X = 200 (10 mm only)
    {20, 50, 150, 100, 200},  // X = 500
    {30, 70, 70, 300, 2000},  // X = 2000 (10 mm only)
    {50, 30, 100, 200, 1500}  // X = 8000 (10 mm only)
};
// The reference solver (APGD, tolerance 1e-6 on the scale-invariant residual of solver.hpp, 10
// Coulomb iterations with the fallback that re-solves the normal impulses), 10 mm cubes, X = 20,
// 100, 500 only, re-measured after those changes (the earlier table, with an absolute
// tolerance, held up to 10 times more at some points). It holds 3-10 times the ratio of ODE
// quickstep at the same iteration count; the X = 500, k = 20 entry is below X = 100's (not
// monotone; tableLimit takes the minimum over the points at or above).
constexpr double kRefX[] = {20, 100, 500};
constexpr int kRefIterations[] = {20, 50, 100};
constexpr double kRefHolds[3][3] = {
    {50, 200, 700},    // X = 20
    {200, 300, 1000},  // X = 100
    {150, 700, 1500},  // X = 500
};

// The measured limit at the grid point at or below (X, k), taken as the minimum over every grid
// point at or above it, so that a non-monotone measurement never raises the limit.
template <std::size_t NX, std::size_t NK>
double tableLimit(const double (&xs)[NX], const int (&ks)[NK], const double (&holds)[NX][NK],
                  double x, int k) {
  if (!(x >= xs[0]) || k < ks[0]) return 1;  // below the grid: any ratio above 1 warns
  std::size_t i0 = 0, j0 = 0;
  while (i0 + 1 < NX && xs[i0 + 1] <= x) ++i0;
  while (j0 + 1 < NK && ks[j0 + 1] <= k) ++j0;
  double limit = kInf;
  for (std::size_t i = i0; i < NX; ++i) {
    for (std::size_t j = j0; j < NK; ++j) limit = std::min(limit, holds[i][j]);
  }
  return limit;
}

}  // namespace

double odeQuickstepMassRatioLimit(int iterations, double thickness, double time_step, double g,
                                  bool warm_start) {
  const double x = thickness / (g * time_step * time_step);
  double limit = tableLimit(kRatioX, kOdeIterations, kOdeHolds, x, iterations);
  if (warm_start) {
    limit = std::min(limit, tableLimit(kRatioX, kOdeIterations, kOdeWarmHolds, x, iterations));
  }
  return kRandomOrderMargin * limit;
}

double referenceMassRatioLimit(int iterations, double thickness, double time_step, double g) {
  return tableLimit(kRefX, kRefIterations, kRefHolds, thickness / (g * time_step * time_step),
                    iterations);
}

}  // namespace rheofeed::scene

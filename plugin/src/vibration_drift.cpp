// SPDX-License-Identifier: MIT
#include "rheofeed/vibration_drift.hpp"

#include <time.h>
#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <cstring>
#include <exception>
#include <mutex>
#include <sstream>
#include <stdexcept>
#include <thread>
#include <unordered_map>
#include <vector>

namespace rheofeed {
namespace {

// Grid steps of LocalDriftTable (header).
constexpr double kThrowStep = LocalDriftTable::kNormalThrowStep;
constexpr double kTangentialThrowStep = LocalDriftTable::kTangentialThrowStep;
constexpr double kSlopeStep = LocalDriftTable::kSlopeStep;

// The relative state of the mass at the start of a cycle (units: velocities |g_n| / w, gap
// |g_n| / w^2).
struct CycleState {
  double u1 = 0, u2 = 0, vn = 0, gap = 0;
};

struct CycleResult {
  double d1 = 0, d2 = 0;         // in-plane displacement over the cycle (units |g_n| / w^2)
  double flight = 0, stick = 0;  // fractions of the cycle
};

// One resolution of the model: Moreau steps of h = 2 pi / n in w t.
class MoreauPointMass {
 public:
  MoreauPointMass(const PointMassParams& p, int steps) : p_(p), steps_(steps) {
    h_ = 2 * kPi / steps;
    sin_mid_.resize(static_cast<std::size_t>(steps));
    // The mean of sin over each step: the free velocity change over the step is then exact.
    for (int k = 0; k < steps; ++k) {
      sin_mid_[static_cast<std::size_t>(k)] = (std::cos(k * h_) - std::cos((k + 1) * h_)) / h_;
    }
  }

  // Advances one cycle from `s` (updated in place).
  CycleResult cycle(CycleState& s) const {
    CycleResult r;
    const double h = h_, mu = p_.mu;
    int flying = 0, sticking = 0;
    for (int k = 0; k < steps_; ++k) {
      const double sn = sin_mid_[static_cast<std::size_t>(k)];
      // Free velocities after the step (relative acceleration g + a w^2 sin(w t), per |g_n|).
      double u1 = s.u1 + h * (p_.slope_along + p_.tangential_throw * sn);
      double u2 = s.u2 + h * p_.slope_across;
      double vn = s.vn + h * (-1.0 + p_.normal_throw * sn);
      const bool closed = s.gap + 0.5 * h * s.vn <= 0;  // the gap at mid-step (Moreau)
      if (closed && vn <= 0) {
        const double impulse = -vn;  // plastic: the normal velocity is killed
        vn = 0;
        s.gap = 0;
        const double slip = std::sqrt(u1 * u1 + u2 * u2);
        const double limit = mu * impulse;
        if (slip <= limit) {  // the Coulomb disc holds it
          u1 = 0;
          u2 = 0;
          ++sticking;
        } else {
          const double keep = 1.0 - limit / slip;
          u1 *= keep;
          u2 *= keep;
        }
      } else {
        s.gap += h * vn;
        ++flying;
      }
      s.u1 = u1;
      s.u2 = u2;
      s.vn = vn;
      r.d1 += h * u1;
      r.d2 += h * u2;
    }
    r.flight = double(flying) / steps_;
    r.stick = double(sticking) / steps_;
    return r;
  }

 private:
  PointMassParams p_;
  int steps_;
  double h_;
  std::vector<double> sin_mid_;
};

bool sameState(const CycleState& a, const CycleState& b, double tol) {
  return std::fabs(a.u1 - b.u1) <= tol && std::fabs(a.u2 - b.u2) <= tol &&
         std::fabs(a.vn - b.vn) <= tol && std::fabs(a.gap - b.gap) <= tol;
}

// The steady state at one resolution.
// The steady state at one resolution, from the cycle-start state `s` (updated to the last
// cycle's end state).
PointMassDrift steadyState(const PointMassParams& p, const PointMassSettings& settings, int steps,
                           CycleState& s) {
  const MoreauPointMass model(p, steps);
  std::vector<CycleState> starts;
  std::vector<CycleResult> cycles;
  starts.reserve(static_cast<std::size_t>(settings.max_cycles) + 1);
  cycles.reserve(static_cast<std::size_t>(settings.max_cycles));
  starts.push_back(s);
  int period = 0;
  for (int c = 0; c < settings.max_cycles && period == 0; ++c) {
    cycles.push_back(model.cycle(s));
    starts.push_back(s);
    const int n = static_cast<int>(starts.size()) - 1;  // index of the newest start
    for (int q = 1; q <= settings.max_period && q <= n - 1; ++q) {
      // Steady once the newest start equals the one q cycles before, and that one the one
      // before it (two repetitions, so a transient passing near an old state is not taken).
      if (sameState(starts[static_cast<std::size_t>(n)], starts[static_cast<std::size_t>(n - q)],
                    settings.periodic_tolerance) &&
          (n - 2 * q < 0 ||
           sameState(starts[static_cast<std::size_t>(n - q)],
                     starts[static_cast<std::size_t>(n - 2 * q)], settings.periodic_tolerance))) {
        period = q;
        break;
      }
    }
  }
  const int count =
      period > 0 ? period : std::min(settings.average_cycles, static_cast<int>(cycles.size()));
  PointMassDrift d;
  d.period = period;
  double d1 = 0, d2 = 0, flight = 0, stick = 0;
  for (std::size_t i = cycles.size() - static_cast<std::size_t>(count); i < cycles.size(); ++i) {
    d1 += cycles[i].d1;
    d2 += cycles[i].d2;
    flight += cycles[i].flight;
    stick += cycles[i].stick;
  }
  d.along = d1 / (2 * kPi * count);
  d.across = d2 / (2 * kPi * count);
  d.flight_fraction = flight / count;
  d.stick_fraction = stick / count;
  d.valid = true;
  return d;
}

std::string paramsProblem(const PointMassParams& p, const PointMassSettings& settings) {
  std::ostringstream out;
  const double slope = std::hypot(p.slope_along, p.slope_across);
  if (!std::isfinite(p.normal_throw) || p.normal_throw < 0) {
    out << "normal throw number = " << p.normal_throw << ": must be finite and >= 0";
  } else if (!std::isfinite(p.tangential_throw) || p.tangential_throw < 0) {
    out << "tangential throw number = " << p.tangential_throw << ": must be finite and >= 0";
  } else if (!std::isfinite(p.slope_along) || !std::isfinite(p.slope_across)) {
    out << "slope (" << p.slope_along << ", " << p.slope_across << ") is not finite";
  } else if (!std::isfinite(p.mu) || p.mu < 0) {
    out << "mu = " << p.mu << ": must be finite and >= 0";
  } else if (slope > 0 && !(slope < p.mu)) {
    out << "slope tangent " << slope << " >= mu = " << p.mu
        << ": the mass slides away with or without vibration, no steady drift";
  } else if (settings.steps_per_cycle < 16 || settings.steps_per_cycle % 2 != 0 ||
             settings.max_cycles < 8 || settings.average_cycles < 1 ||
             settings.average_cycles > settings.max_cycles || settings.max_period < 1 ||
             !(settings.periodic_tolerance > 0)) {
    out << "point-mass settings out of range: steps_per_cycle >= 16 and even, max_cycles >= 8, "
           "1 <= average_cycles <= max_cycles, max_period >= 1, periodic_tolerance > 0";
  }
  return out.str();
}

}  // namespace

PointMassDrift pointMassDrift(const PointMassParams& params, const PointMassSettings& settings) {
  PointMassDrift result;
  result.problem = paramsProblem(params, settings);
  if (!result.problem.empty()) return result;
  // Frictionless (and so level: paramsProblem): nothing in the plane couples the mass to the
  // plane's in-plane motion, whose mean relative velocity is zero; only the normal motion (the
  // flight and stick fractions) is simulated, without the in-plane forcing, and the drift is 0.
  PointMassParams q = params;
  if (q.mu == 0) q.tangential_throw = 0;
  // The transient from rest is run at 1/16 of the resolution, then the fine steps start from
  // its steady state and converge in a few cycles (the two steady states are within the
  // coarse step's error): about 8x less work than the fine transient, same result (the fine
  // steady state is found by the same periodicity test).
  CycleState state;
  const int coarse = std::max(16, settings.steps_per_cycle / 16 / 2 * 2);
  if (coarse < settings.steps_per_cycle) steadyState(q, settings, coarse, state);
  return steadyState(q, settings, settings.steps_per_cycle, state);
}

void LocalVibration::validate(const std::string& where) const {
  auto fail = [&](const std::string& what) { throw std::invalid_argument(where + ": " + what); };
  std::ostringstream out;
  if (!(frequency > 0 && frequency <= 1e5)) {
    out << "vibration frequency = " << frequency << " Hz: must be in (0, 1e+05] Hz";
    fail(out.str());
  }
  if (!isFinite(amplitude) || !(norm(amplitude) <= 1e3)) {
    out << "vibration |amplitude| = " << norm(amplitude) << " m: must be finite, in [0, 1e+03] m";
    fail(out.str());
  }
  if (!(torsion_amplitude >= 0 && torsion_amplitude <= kPi)) {
    out << "torsion amplitude = " << torsion_amplitude << " rad: must be in [0, pi] rad";
    fail(out.str());
  }
  if (!isFinite(axis_origin) || !isFinite(axis_direction) ||
      !(std::fabs(norm(axis_direction) - 1) <= 1e-6)) {
    out << "torsion axis (origin (" << axis_origin.x << ", " << axis_origin.y << ", "
        << axis_origin.z << ") m, direction |k| = " << norm(axis_direction)
        << "): must be finite with a unit direction";
    fail(out.str());
  }
  if (!isFinite(gravity) || !(norm(gravity) > 0)) {
    out << "gravity |g| = " << norm(gravity) << " m/s^2: must be finite and > 0";
    fail(out.str());
  }
  if (!(mu >= 0 && mu <= 1e3)) {
    out << "mu = " << mu << ": must be in [0, 1e+03]";
    fail(out.str());
  }
  if (!(efficiency >= 0 && efficiency <= kMaxEfficiency)) {
    out << "efficiency = " << efficiency << ": must be in [0, " << kMaxEfficiency << "]";
    fail(out.str());
  }
}

// ---------------------------------------------------------------------------------------------
// The table.

namespace {

struct CornerKey {
  std::int64_t i[4];
  std::uint64_t mu;
  bool operator==(const CornerKey& o) const {
    return i[0] == o.i[0] && i[1] == o.i[1] && i[2] == o.i[2] && i[3] == o.i[3] && mu == o.mu;
  }
};

struct CornerKeyHash {
  std::size_t operator()(const CornerKey& k) const {
    std::uint64_t h = k.mu * 0x9E3779B97F4A7C15ull;
    for (std::int64_t v : k.i) h = (h ^ static_cast<std::uint64_t>(v)) * 0x100000001B3ull;
    return static_cast<std::size_t>(h ^ (h >> 29));
  }
};

std::uint64_t bitsOf(double x) {
  std::uint64_t b;
  std::memcpy(&b, &x, sizeof b);
  return b;
}

struct Corner {
  double v1 = 0, v2 = 0;
  bool valid = false;
};

// A cell's corners are filled as lookups need them: a corner whose interpolation weight is 0
// (an input exactly on a grid line, e.g. s1 = s2 = 0 on a level floor) is not run.
struct Cell {
  std::array<Corner, 16> corners;
  std::uint32_t filled = 0;  // bit c: corners[c] computed
};

// CPU time of the calling thread (s): the model runs' cost, counted by the threads that run them.
double threadCpuSeconds() {
  timespec t{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
  return static_cast<double>(t.tv_sec) + 1e-9 * static_cast<double>(t.tv_nsec);
}

}  // namespace

struct LocalDriftTable::Impl {
  PointMassSettings settings;
  std::mutex mutex;
  std::unordered_map<CornerKey, Corner, CornerKeyHash> corners;
  std::unordered_map<CornerKey, Cell, CornerKeyHash> cells;
  LocalDriftStats stats;  // cells and model runs (under the mutex)
  std::atomic<std::int64_t> contacts{0}, wall_contacts{0};
  bool has_last = false;
  PointMassParams last_params;
  PointMassDrift last_result;

  int threads = defaultThreads();  // model runs of one cell at a time (setThreads)

  static int defaultThreads() {
    const unsigned n = std::thread::hardware_concurrency();
    return n == 0 ? 1 : static_cast<int>(std::min(n, 16u));
  }

  static PointMassParams cornerParams(const CornerKey& key, double mu) {
    PointMassParams p;
    p.normal_throw = key.i[0] * kThrowStep;
    p.tangential_throw = key.i[1] * kTangentialThrowStep;
    p.slope_along = key.i[2] * kSlopeStep;
    p.slope_across = key.i[3] * kSlopeStep;
    p.mu = mu;
    return p;
  }

  // Runs the model at the corners of `keys` the table lacks, on up to `threads` threads (the
  // caller's among them), and adds them. The model is a pure function of its inputs, so the
  // values do not depend on the number of threads.
  void fill(const std::vector<CornerKey>& keys, double mu) {
    std::vector<CornerKey> missing;
    for (const CornerKey& key : keys) {
      if (corners.find(key) == corners.end()) missing.push_back(key);
    }
    if (missing.empty()) return;
    std::vector<PointMassDrift> results(missing.size());
    std::atomic<std::size_t> next{0};
    std::exception_ptr failure;
    std::mutex failure_mutex;
    double cpu = 0;  // summed over the threads (under failure_mutex)
    auto work = [&] {
      const double cpu_start = threadCpuSeconds();
      for (std::size_t k = next++; k < missing.size(); k = next++) {
        try {
          results[k] = pointMassDrift(cornerParams(missing[k], mu), settings);
        } catch (...) {  // only std::bad_alloc: pointMassDrift refuses inputs by `valid`
          const std::lock_guard<std::mutex> lock(failure_mutex);
          if (!failure) failure = std::current_exception();
        }
      }
      const std::lock_guard<std::mutex> lock(failure_mutex);
      cpu += threadCpuSeconds() - cpu_start;
    };
    const std::size_t helpers =
        std::min(missing.size(), static_cast<std::size_t>(std::max(threads, 1))) - 1;
    std::vector<std::thread> pool;
    pool.reserve(helpers);
    for (std::size_t t = 0; t < helpers; ++t) pool.emplace_back(work);
    work();
    for (std::thread& t : pool) t.join();
    if (failure) std::rethrow_exception(failure);
    for (std::size_t k = 0; k < missing.size(); ++k) {
      corners.emplace(missing[k], Corner{results[k].along, results[k].across, results[k].valid});
    }
    stats.model_runs += static_cast<std::int64_t>(missing.size());
    stats.model_cpu_seconds += cpu;
  }
};

LocalDriftTable::LocalDriftTable(PointMassSettings settings) : impl_(std::make_unique<Impl>()) {
  impl_->settings = settings;
}
LocalDriftTable::~LocalDriftTable() = default;

std::shared_ptr<LocalDriftTable> LocalDriftTable::shared(const PointMassSettings& settings) {
  static std::mutex mutex;
  static std::vector<std::shared_ptr<LocalDriftTable>> tables;
  std::lock_guard<std::mutex> lock(mutex);
  for (const auto& table : tables) {
    const PointMassSettings& t = table->settings();
    if (t.steps_per_cycle == settings.steps_per_cycle && t.max_cycles == settings.max_cycles &&
        t.average_cycles == settings.average_cycles && t.max_period == settings.max_period &&
        bitsOf(t.periodic_tolerance) == bitsOf(settings.periodic_tolerance)) {
      return table;
    }
  }
  tables.push_back(std::make_shared<LocalDriftTable>(settings));
  return tables.back();
}

const PointMassSettings& LocalDriftTable::settings() const {
  return impl_->settings;
}

void LocalDriftTable::setThreads(int threads) {
  if (threads < 1) {
    throw std::invalid_argument("LocalDriftTable::setThreads: " + std::to_string(threads) +
                                " threads: must be >= 1");
  }
  std::lock_guard<std::mutex> lock(impl_->mutex);
  impl_->threads = threads;
}

int LocalDriftTable::threads() const {
  std::lock_guard<std::mutex> lock(impl_->mutex);
  return impl_->threads;
}

std::size_t LocalDriftTable::numCorners() const {
  std::lock_guard<std::mutex> lock(impl_->mutex);
  return impl_->corners.size();
}

std::vector<DriftTableCorner> LocalDriftTable::corners() const {
  std::vector<DriftTableCorner> out;
  {
    std::lock_guard<std::mutex> lock(impl_->mutex);
    out.reserve(impl_->corners.size());
    for (const auto& [key, corner] : impl_->corners) {
      DriftTableCorner c;
      std::copy(std::begin(key.i), std::end(key.i), std::begin(c.grid));
      std::memcpy(&c.mu, &key.mu, sizeof c.mu);
      c.along = corner.v1;
      c.across = corner.v2;
      c.valid = corner.valid;
      out.push_back(c);
    }
  }
  std::sort(out.begin(), out.end(), [](const DriftTableCorner& a, const DriftTableCorner& b) {
    if (a.mu != b.mu) return a.mu < b.mu;
    return std::lexicographical_compare(std::begin(a.grid), std::end(a.grid), std::begin(b.grid),
                                        std::end(b.grid));
  });
  return out;
}

std::size_t LocalDriftTable::addCorners(const std::vector<DriftTableCorner>& corners) {
  constexpr std::int64_t kMaxIndex = 1000000000;
  for (std::size_t k = 0; k < corners.size(); ++k) {
    const DriftTableCorner& c = corners[k];
    std::ostringstream out;
    out << "drift table corner " << k << ": ";
    if (!std::isfinite(c.along) || !std::isfinite(c.across)) {
      out << "drift (" << c.along << ", " << c.across << ") is not finite";
      throw std::invalid_argument(out.str());
    }
    if (!(std::isfinite(c.mu) && c.mu >= 0)) {
      out << "mu = " << c.mu << ": must be finite and >= 0";
      throw std::invalid_argument(out.str());
    }
    for (int d = 0; d < 4; ++d) {
      if (c.grid[d] < -kMaxIndex || c.grid[d] > kMaxIndex) {
        out << "grid index " << d << " = " << c.grid[d] << ": must be in [-1e9, 1e9]";
        throw std::invalid_argument(out.str());
      }
    }
  }
  std::lock_guard<std::mutex> lock(impl_->mutex);
  std::size_t added = 0;
  for (const DriftTableCorner& c : corners) {
    CornerKey key;
    std::copy(std::begin(c.grid), std::end(c.grid), std::begin(key.i));
    key.mu = bitsOf(c.mu);
    if (impl_->corners.emplace(key, Corner{c.along, c.across, c.valid}).second) ++added;
  }
  impl_->stats.corners_added += static_cast<std::int64_t>(added);
  return added;
}

LocalDriftStats LocalDriftTable::stats() const {
  std::lock_guard<std::mutex> lock(impl_->mutex);
  LocalDriftStats out = impl_->stats;
  out.contacts = impl_->contacts.load(std::memory_order_relaxed);
  out.wall_contacts = impl_->wall_contacts.load(std::memory_order_relaxed);
  return out;
}

void LocalDriftTable::countContacts(std::int64_t contacts, std::int64_t walls) {
  impl_->contacts.fetch_add(contacts, std::memory_order_relaxed);
  if (walls != 0) impl_->wall_contacts.fetch_add(walls, std::memory_order_relaxed);
}

PointMassDrift LocalDriftTable::drift(const PointMassParams& p) {
  Impl& s = *impl_;
  std::lock_guard<std::mutex> lock(s.mutex);
  if (s.has_last && p.normal_throw == s.last_params.normal_throw &&
      p.tangential_throw == s.last_params.tangential_throw &&
      p.slope_along == s.last_params.slope_along && p.slope_across == s.last_params.slope_across &&
      p.mu == s.last_params.mu) {
    return s.last_result;
  }
  PointMassDrift result;
  const double x[4] = {p.normal_throw / kThrowStep, p.tangential_throw / kTangentialThrowStep,
                       p.slope_along / kSlopeStep, p.slope_across / kSlopeStep};
  bool inside = std::isfinite(p.mu) && p.mu >= 0;
  for (double v : x) inside = inside && std::isfinite(v) && std::fabs(v) < 1e15;
  if (!inside) {
    result = pointMassDrift(p, s.settings);  // names the bad input
  } else {
    CornerKey key;
    double frac[4];
    for (int d = 0; d < 4; ++d) {
      const double f = std::floor(x[d]);
      key.i[d] = static_cast<std::int64_t>(f);
      frac[d] = x[d] - f;
    }
    key.mu = bitsOf(p.mu);
    auto it = s.cells.find(key);
    if (it == s.cells.end()) {
      ++s.stats.cells_computed;
      it = s.cells.emplace(key, Cell{}).first;
    }
    Cell& cell = it->second;
    auto cornerKey = [&key](int c) {  // corner c of the cell: bit d steps along input d
      CornerKey ck = key;
      for (int d = 0; d < 4; ++d) ck.i[d] += (c >> d) & 1;
      return ck;
    };
    double weight[16];
    std::vector<CornerKey> needed;  // weighted corners the cell lacks, run together
    for (int c = 0; c < 16; ++c) {
      double w = 1;
      for (int d = 0; d < 4; ++d) w *= ((c >> d) & 1) ? frac[d] : 1 - frac[d];
      weight[c] = w;
      if (w != 0 && !((cell.filled >> c) & 1u)) needed.push_back(cornerKey(c));
    }
    s.fill(needed, p.mu);
    bool valid = true;
    double v1 = 0, v2 = 0;
    for (int c = 0; c < 16 && valid; ++c) {
      const double w = weight[c];
      if (w == 0) continue;
      const auto k = static_cast<std::size_t>(c);
      if (!((cell.filled >> c) & 1u)) {
        cell.corners[k] = s.corners.at(cornerKey(c));
        cell.filled |= 1u << c;
      }
      valid = cell.corners[k].valid;
      v1 += w * cell.corners[k].v1;
      v2 += w * cell.corners[k].v2;
    }
    if (valid) {
      result.along = v1;
      result.across = v2;
      result.valid = true;
    } else {  // a corner beyond the friction angle: the point itself may still be inside
      const double cpu_start = threadCpuSeconds();
      result = pointMassDrift(p, s.settings);
      ++s.stats.model_runs;
      s.stats.model_cpu_seconds += threadCpuSeconds() - cpu_start;
    }
  }
  s.has_last = true;
  s.last_params = p;
  s.last_result = result;
  return result;
}

// ---------------------------------------------------------------------------------------------
// The law at a contact.

namespace {

// A unit vector orthogonal to the unit vector n.
Vec3 anyPerpendicular(const Vec3& n) {
  const Vec3 t = std::fabs(n.x) < 0.9 ? Vec3{1, 0, 0} : Vec3{0, 1, 0};
  const Vec3 e = tangentialPart(t, n);
  return (1.0 / norm(e)) * e;
}

// The point-mass drift on a gravity-loaded plane (g . n < 0, |g_t| < mu |g_n|). `ok` false when
// the model refused the inputs.
Vec3 planeDrift(const LocalVibration& v, const Vec3& p, const Vec3& n, double mu,
                LocalDriftTable* table, bool* ok) {
  const double w = 2 * kPi * v.frequency;
  Vec3 a = v.amplitude;
  if (v.torsion_amplitude != 0) {
    a = a + v.torsion_amplitude * cross(v.axis_direction, p - v.axis_origin);
  }
  double an = dot(a, n);
  if (an < 0) {  // half a period of phase
    a = -a;
    an = -an;
  }
  const Vec3 at = a - an * n;
  const double gn = -dot(v.gravity, n);  // > 0
  const Vec3 gt = v.gravity + gn * n;
  const double at_len = norm(at), gt_len = norm(gt);
  Vec3 e1;
  if (at_len > 1e-12 * norm(a) && at_len > 0) {
    e1 = (1.0 / at_len) * at;
  } else if (gt_len > 0) {
    e1 = (1.0 / gt_len) * gt;
  } else {
    e1 = anyPerpendicular(n);
  }
  Vec3 e2 = cross(n, e1);
  PointMassParams q;
  q.normal_throw = an * w * w / gn;
  q.tangential_throw = at_len * w * w / gn;
  q.slope_along = dot(gt, e1) / gn;
  q.slope_across = dot(gt, e2) / gn;
  if (q.slope_across < 0) {  // mirror: only s2 >= 0 is computed
    q.slope_across = -q.slope_across;
    e2 = -e2;
  }
  q.mu = mu;
  const PointMassDrift d = table ? table->drift(q) : pointMassDrift(q);
  *ok = d.valid;
  if (!d.valid) return {};
  return (v.efficiency * gn / w) * (d.along * e1 + d.across * e2);
}

}  // namespace

Vec3 localDrift(const LocalVibration& vibration, const Vec3& p, const Vec3& n_out, double mu,
                LocalDriftTable* table, bool* wall) {
  // An infinite mu (ODE's dInfinity) is a surface without slip: 1e3 behaves the same.
  mu = std::min(mu, 1e3);
  const double g = norm(vibration.gravity);
  const double gn = -dot(vibration.gravity, n_out);
  bool use_wall = !(gn > g * std::cos(kWallAngle));
  if (!use_wall) {
    const double gt = norm(tangentialPart(vibration.gravity, n_out));
    use_wall = !(gt < mu * gn);
  }
  Vec3 drift;
  bool ok = false;
  if (!use_wall) drift = planeDrift(vibration, p, n_out, mu, table, &ok);
  if (!ok) {  // walls, overhangs, slopes beyond the friction angle
    use_wall = true;
    const Vec3 up = (-1.0 / g) * vibration.gravity;
    drift = tangentialPart(planeDrift(vibration, p, up, mu, table, &ok), n_out);
  }
  if (table) table->countContacts(1, use_wall ? 1 : 0);
  if (wall) *wall = use_wall;
  return drift;
}

}  // namespace rheofeed

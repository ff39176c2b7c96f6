// SPDX-License-Identifier: MIT
// Solver::solve must not allocate once warmed up on problems of the same size. This executable
// interposes malloc and friends (glibc) to count heap allocations made during a solve; it is a
// separate executable because the interposition is process wide.

#include "rheofeed/ccp/solver.hpp"

#include "test_support.hpp"

#include <gtest/gtest.h>

#include <atomic>
#include <cstddef>
#include <random>

#if defined(__GLIBC__) && !defined(__SANITIZE_ADDRESS__)
#define RHEOFEED_COUNT_ALLOCATIONS 1

namespace {
std::atomic<bool> g_counting{false};
std::atomic<long> g_allocations{0};
}  // namespace

extern "C" {
void* __libc_malloc(std::size_t size);
void* __libc_calloc(std::size_t count, std::size_t size);
void* __libc_realloc(void* pointer, std::size_t size);
void* __libc_memalign(std::size_t alignment, std::size_t size);

void* malloc(std::size_t size) {
  if (g_counting.load(std::memory_order_relaxed)) g_allocations.fetch_add(1);
  return __libc_malloc(size);
}
void* calloc(std::size_t count, std::size_t size) {
  if (g_counting.load(std::memory_order_relaxed)) g_allocations.fetch_add(1);
  return __libc_calloc(count, size);
}
void* realloc(void* pointer, std::size_t size) {
  if (g_counting.load(std::memory_order_relaxed)) g_allocations.fetch_add(1);
  return __libc_realloc(pointer, size);
}
void* aligned_alloc(std::size_t alignment, std::size_t size) {
  if (g_counting.load(std::memory_order_relaxed)) g_allocations.fetch_add(1);
  return __libc_memalign(alignment, size);
}
int posix_memalign(void** pointer, std::size_t alignment, std::size_t size) {
  if (g_counting.load(std::memory_order_relaxed)) g_allocations.fetch_add(1);
  *pointer = __libc_memalign(alignment, size);
  return *pointer == nullptr ? 12 /* ENOMEM */ : 0;
}
}
#endif

namespace rheofeed::ccp {
namespace {

// Heap allocations made by `solve` on an already warmed-up solver.
long allocationsOfSolve(Solver& solver, const Problem& problem, Eigen::VectorXd& gamma,
                        Result& result) {
#if defined(RHEOFEED_COUNT_ALLOCATIONS)
  g_allocations = 0;
  g_counting = true;
  result = solver.solve(problem, gamma);
  g_counting = false;
  return g_allocations.load();
#else
  result = solver.solve(problem, gamma);
  return 0;
#endif
}

// Large enough (n = 1200, N of 11 MB) that any Eigen temporary in the dense products would
// exceed Eigen's stack-allocation limit (128 kB) and show up on the heap.
Problem denseProblem(unsigned seed) {
  std::mt19937 rng(seed);
  const Eigen::Index nc = 400, n = 3 * nc;
  // Symmetric, diagonally dominant (off-diagonal row sums < 2 < 3): positive definite.
  const Eigen::MatrixXd b = test::randomMatrix(n, n, rng).cwiseMax(-3.0).cwiseMin(3.0) / (3.0 * n);
  const Eigen::MatrixXd delassus = 3.0 * Eigen::MatrixXd::Identity(n, n) + b + b.transpose();
  return Problem::makeDense(delassus, test::randomVector(n, 1.0, rng),
                            Eigen::VectorXd::Constant(nc, 0.4));
}

Problem matrixFreeProblem(unsigned seed) {
  std::mt19937 rng(seed);
  const Eigen::Index bodies = 4, nc = 6, ndof = 6 * bodies;
  Eigen::MatrixXd d = Eigen::MatrixXd::Zero(ndof, 3 * nc);
  for (Eigen::Index i = 0; i < nc; ++i) {
    d.block(6 * (i % bodies), 3 * i, 6, 3) = test::randomMatrix(6, 3, rng);
    d.block(6 * ((i + 1) % bodies), 3 * i, 6, 3) = test::randomMatrix(6, 3, rng);
  }
  Eigen::MatrixXd minv = Eigen::MatrixXd::Zero(ndof, ndof);
  for (Eigen::Index b = 0; b < bodies; ++b) {
    minv.block(6 * b, 6 * b, 6, 6) = test::randomSpd(6, 0.3, 2.0, rng);
  }
  return Problem::makeMatrixFree(SparseMatrix(d.sparseView()), SparseMatrix(minv.sparseView()),
                                 test::randomVector(3 * nc, 1.0, rng),
                                 Eigen::VectorXd::Constant(nc, 0.4));
}

class SolverAllocation : public testing::TestWithParam<std::tuple<Method, bool, int>> {};

TEST_P(SolverAllocation, SecondSolveOfSameSizeDoesNotAllocate) {
#if !defined(RHEOFEED_COUNT_ALLOCATIONS)
  GTEST_SKIP() << "malloc interposition needs glibc without AddressSanitizer";
#endif
  const auto [method, matrix_free, coulomb_outer_iterations] = GetParam();
  Settings settings;
  settings.method = method;
  settings.tolerance = 1e-10;
  settings.coulomb_outer_iterations = coulomb_outer_iterations;
  settings.coulomb_tolerance = 1e-10;
  const Problem first = matrix_free ? matrixFreeProblem(1) : denseProblem(1);
  const Problem second = matrix_free ? matrixFreeProblem(2) : denseProblem(2);
  Solver solver(settings);
  Eigen::VectorXd gamma;
  ASSERT_EQ(solver.solve(first, gamma).status, Status::Converged);
  Result result;
  // A different problem of the same size, warm-started from the first solution.
  EXPECT_EQ(allocationsOfSolve(solver, second, gamma, result), 0);
  EXPECT_EQ(result.status, Status::Converged) << result.message;
  EXPECT_GT(result.iterations, 0);
  // And cold.
  gamma.setZero();
  EXPECT_EQ(allocationsOfSolve(solver, first, gamma, result), 0);
  EXPECT_EQ(result.status, Status::Converged) << result.message;
}

INSTANTIATE_TEST_SUITE_P(MethodsFormsAndModes, SolverAllocation,
                         testing::Combine(testing::Values(Method::Pgs, Method::Apgd),
                                          testing::Bool(), testing::Values(0, 30)),
                         [](const testing::TestParamInfo<SolverAllocation::ParamType>& param_info) {
                           return std::string(toString(std::get<0>(param_info.param))) +
                                  (std::get<1>(param_info.param) ? "MatrixFree" : "Dense") +
                                  (std::get<2>(param_info.param) > 0 ? "Coulomb" : "Relaxed");
                         });

TEST(AllocationCounter, SeesAllocations) {
#if !defined(RHEOFEED_COUNT_ALLOCATIONS)
  GTEST_SKIP() << "malloc interposition needs glibc without AddressSanitizer";
#else
  // The counter itself works: a fresh solver allocates its workspace.
  Solver solver;
  Eigen::VectorXd gamma;
  Result result;
  EXPECT_GT(allocationsOfSolve(solver, denseProblem(3), gamma, result), 0);
#endif
}

}  // namespace
}  // namespace rheofeed::ccp

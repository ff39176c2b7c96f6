// SPDX-License-Identifier: MIT
// libFuzzer target: Siconos fc3d problem text from bytes through parseFc3d (fc3d_reader.hpp),
// then Problem::validate() and the per-contact diagonal blocks of an accepted problem.
//
// std::runtime_error is the reader's documented refusal. Anything else is a finding: a crash
// or sanitizer report, another exception type escaping (e.g. std::bad_alloc from a header that
// claims more than the file holds), a timeout, or an accepted problem that breaks the reader's
// contract (sizes 3 nc x 3 nc / 3 nc / nc with 1 <= nc <= 5461, finite values, mu >= 0).
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <sstream>
#include <stdexcept>
#include <string>

#include "rheofeed/ccp/fc3d_reader.hpp"

namespace {

constexpr long kMaxContacts = 5461;  // fc3d_reader.hpp: the dense W of 3 nc x 3 nc within 2 GiB

[[noreturn]] void finding(const char* what) {
  std::fprintf(stderr, "fuzz_fc3d finding: %s\n", what);
  std::abort();
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  std::istringstream in(std::string(reinterpret_cast<const char*>(data), size));
  rheofeed::ccp::Problem problem;
  try {
    problem = rheofeed::ccp::parseFc3d(in, "fuzz.dat");
  } catch (const std::runtime_error&) {
    return 0;  // documented refusal
  }
  const Eigen::Index nc = problem.numContacts();
  if (nc < 1 || nc > kMaxContacts) finding("accepted a contact count outside [1, 5461]");
  if (problem.form != rheofeed::ccp::DelassusForm::Dense) finding("accepted problem is not dense");
  if (problem.delassus.rows() != 3 * nc || problem.delassus.cols() != 3 * nc ||
      problem.r.size() != 3 * nc) {
    finding("accepted problem has inconsistent sizes");
  }
  if (!problem.delassus.allFinite() || !problem.r.allFinite() || !problem.mu.allFinite()) {
    finding("accepted problem has a non-finite value");
  }
  if ((problem.mu.array() < 0).any()) finding("accepted problem has a negative mu");
  // validate() reports, it does not throw; the diagonal blocks need only consistent sizes.
  (void)problem.validate();
  double trace = 0;
  for (Eigen::Index i = 0; i < nc; ++i) trace += problem.diagonalBlock(i).trace();
  if (std::isnan(trace) && problem.delassus.allFinite()) finding("NaN from finite diagonal blocks");
  return 0;
}

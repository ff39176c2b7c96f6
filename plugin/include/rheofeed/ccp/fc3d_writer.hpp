// SPDX-License-Identifier: MIT
#pragma once

/// @file
/// Writer of the Siconos fc3d text format read by fc3d_reader.hpp, so that problems built by
/// our own scenes (reference::lastContactProblem) can be kept, shared and compared with other
/// solvers. W is written in sparse block storage (only the nonzero 3 x 3 blocks of
/// N = D^T M^-1 D, row by block row), q = r and mu as they are; every value with 17 significant
/// digits, so that reading the file back gives the same doubles.

#include "rheofeed/ccp/problem.hpp"

#include <ostream>
#include <string>

namespace rheofeed::ccp {

/// Writes `problem` (dense or matrix-free, valid) to `out` in fc3d sparse block storage. A dense
/// problem's blocks are kept when any of their entries is nonzero. Returns an empty string on
/// success, else a message (an empty problem, a stream error).
std::string writeFc3d(const Problem& problem, std::ostream& out);

/// Writes `problem` to the file `path` atomically (a temporary file beside it, then renamed).
/// Returns an empty string on success, else a message naming the path.
std::string writeFc3dFile(const Problem& problem, const std::string& path);

}  // namespace rheofeed::ccp

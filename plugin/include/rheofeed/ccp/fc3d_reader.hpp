// SPDX-License-Identifier: MIT
#pragma once

/// @file
/// Reader for the Siconos text format of 3D frictional contact problems ("fc3d" local problems,
/// as in siconos/numerics/src/FrictionContact/test/data): whitespace separated
///
///   d (= 3), nc, W (3 nc x 3 nc, dense storage 0 or sparse block storage 1), q (3 nc), mu (nc),
///   optionally one trailing integer that is not part of the problem.
///
/// Dense storage: `0 n n n n` then n*n values in column-major order. Sparse block storage:
/// `1 n n nbblocks blocknumber0 blocknumber1`, the cumulative row-block ends, the cumulative
/// column-block ends, `filled1 filled2`, filled1 block-row pointers (CSR over blocks), filled2
/// block-column indices, then for each stored block in block-row order its index (0, 1, ...)
/// followed by its values in column-major order.
///
/// Siconos' problem "u = W r + q, r in K, u in K*" maps to Problem with N = W (dense), r = q and
/// the same mu; Siconos' unknown impulse r is our gamma.

#include "rheofeed/ccp/problem.hpp"

#include <istream>
#include <string>

namespace rheofeed::ccp {

/// Reads the fc3d file at `path` into a dense Problem. Throws std::runtime_error when the file
/// cannot be opened or is malformed; the message starts with the path and names the section,
/// the token index (0-based, over whitespace-separated tokens) and line (1-based) of the fault:
/// truncated file, non-numeric or non-finite value, negative mu, unsupported dimension,
/// inconsistent sizes or block counts, unexpected trailing data.
///
/// Limits, checked before anything of the claimed size is allocated: only a regular file
/// (a FIFO, a directory or a device is refused from stat, never opened) of at most 1 GiB;
/// 1 <= nc <= 5461 (the dense W of 3 nc x 3 nc doubles within 2 GiB); the values a header
/// claims (dense W, sparse block pattern and block values) must be present in the file; in
/// sparse storage every diagonal entry of W must lie in a stored block (else W is singular) and
/// the dense W is built only after the whole file has been read and checked. Other properties
/// of the values (symmetry, definiteness) are Problem::validate()'s.
Problem readFc3dFile(const std::string& path);

/// Parses fc3d text from `in` (at most 1 GiB is read); `source_name` (e.g. the path) prefixes
/// error messages. Same contract as readFc3dFile.
Problem parseFc3d(std::istream& in, const std::string& source_name);

}  // namespace rheofeed::ccp

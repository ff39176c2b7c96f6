// SPDX-License-Identifier: MIT
#include "rheofeed/ccp/fc3d_reader.hpp"

#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <limits>
#include <new>
#include <sstream>
#include <stdexcept>
#include <string>
#include <system_error>
#include <vector>

namespace rheofeed::ccp {

namespace {

namespace fs = std::filesystem;

// Only 3D contact problems (normal + two tangential directions) are supported.
constexpr long kDimension = 3;
// The reader builds a dense Problem: W is 3 nc x 3 nc doubles, 72 nc^2 bytes. Its memory is
// capped at 2 GiB, so nc <= sqrt(2^31 / 8) / 3 = 5461 (a header claiming 1e7 contacts asked for
// 7.2e15 bytes and ended in std::bad_alloc).
constexpr long kMaxContacts = 5461;
// Files are read whole into memory once (no per-token copies). 1 GiB holds a dense W of ~2400
// contacts at ~20 characters per value; larger problems are written in sparse block storage.
constexpr std::uintmax_t kMaxFileBytes = std::uintmax_t{1} << 30;

std::string sourcePrefix(const std::string& source) {
  return "fc3d reader: " + source + ": ";
}

// Whitespace-separated tokens read in place from the text, with the number of tokens left
// (counted once up front, so that claimed sizes are compared with the data before anything of
// that size is allocated) and typed reads that report where a fault is.
class TokenReader {
 public:
  TokenReader(std::string text, std::string source)
      : text_(std::move(text)), source_(std::move(source)) {
    bool in_token = false;
    for (const char c : text_) {
      const bool space = std::isspace(static_cast<unsigned char>(c)) != 0;
      if (!space && !in_token) ++total_;
      in_token = !space;
    }
  }

  bool atEnd() const { return taken_ >= total_; }
  std::size_t position() const { return taken_; }
  std::size_t remaining() const { return total_ - taken_; }

  [[noreturn]] void fail(const std::string& section, const std::string& what) const {
    throw std::runtime_error(sourcePrefix(source_) + section + ": " + what);
  }

  // A fault at the token read last.
  [[noreturn]] void failLast(const std::string& section, const std::string& what) const {
    std::ostringstream message;
    message << what << " (token " << (taken_ == 0 ? 0 : taken_ - 1) << ", line " << last_line_
            << ")";
    fail(section, message.str());
  }

  long readInteger(const std::string& section, const std::string& what) {
    const std::string token = take(section, what);
    const char* begin = token.c_str();
    char* end = nullptr;
    errno = 0;
    const long value = std::strtol(begin, &end, 10);
    if (end == begin || *end != '\0' || errno == ERANGE) {
      failLast(section, "expected an integer (" + what + "), got '" + token + "'");
    }
    return value;
  }

  // Reads a finite number; `name` with indices i (and j when >= 0) names it in messages.
  double readNumber(const std::string& section, const char* name, long i, long j = -1) {
    auto describe = [&]() {
      return std::string(name) + (j < 0 ? "[" + std::to_string(i) + "]"
                                        : "(" + std::to_string(i) + ", " + std::to_string(j) + ")");
    };
    const std::string token = take(section, describe());
    const char* begin = token.c_str();
    char* end = nullptr;
    const double value = std::strtod(begin, &end);
    if (end == begin || *end != '\0') {
      failLast(section, "expected a number (" + describe() + "), got '" + token + "'");
    }
    if (!std::isfinite(value)) {
      failLast(section, describe() + " = '" + token + "' is not a finite number");
    }
    return value;
  }

  // Reads an integer that must equal `expected`.
  void expectInteger(long expected, const std::string& section, const std::string& what) {
    const long value = readInteger(section, what);
    if (value != expected) {
      failLast(section,
               what + " is " + std::to_string(value) + ", expected " + std::to_string(expected));
    }
  }

  // Refuses a claim of `needed` more tokens (described by `what`) when fewer are left.
  void expectTokens(std::uintmax_t needed, const std::string& section,
                    const std::string& what) const {
    if (needed > remaining()) {
      fail(section, what + " need at least " + std::to_string(needed) +
                        " more values, but the file holds only " + std::to_string(remaining()) +
                        " more tokens (truncated file or wrong header)");
    }
  }

 private:
  std::string take(const std::string& section, const std::string& what) {
    while (pos_ < text_.size() && std::isspace(static_cast<unsigned char>(text_[pos_]))) {
      if (text_[pos_] == '\n') ++line_;
      ++pos_;
    }
    if (pos_ >= text_.size()) {
      std::ostringstream message;
      message << "unexpected end of file while reading " << what << " (file truncated after "
              << total_ << " tokens)";
      fail(section, message.str());
    }
    const std::size_t begin = pos_;
    while (pos_ < text_.size() && !std::isspace(static_cast<unsigned char>(text_[pos_]))) ++pos_;
    ++taken_;
    last_line_ = line_;
    return text_.substr(begin, pos_ - begin);
  }

  std::string text_;
  std::string source_;
  std::size_t pos_ = 0, taken_ = 0, total_ = 0;
  long line_ = 1, last_line_ = 0;
};

// Allocates the dense W (n x n, zero) after the data was checked; a refusal names its size.
Eigen::MatrixXd allocateW(const TokenReader& in, long n) {
  try {
    return Eigen::MatrixXd::Zero(n, n);
  } catch (const std::bad_alloc&) {
    in.fail("W", "cannot allocate the dense " + std::to_string(n) + " x " + std::to_string(n) +
                     " matrix (" + std::to_string(8.0 * n * n / (1 << 20)) + " MiB)");
  }
}

// W as read: dense values straight into `dense`, or the stored blocks of a sparse file (the
// dense matrix is allocated only once the whole file has been read and checked).
struct WData {
  Eigen::MatrixXd dense;
  struct Block {
    long row0, rows, col0, cols;
    std::size_t first;  // index of its first value in `values` (column-major)
  };
  std::vector<Block> blocks;
  std::vector<double> values;
  bool sparse = false;
};

void readDense(TokenReader& in, long n, WData& w) {
  const std::string section = "W (dense storage)";
  in.expectInteger(n, section, "row count");
  in.expectInteger(n, section, "column count");
  in.expectInteger(n, section, "repeated row count");
  in.expectInteger(n, section, "repeated column count");
  const auto nn = static_cast<std::uintmax_t>(n) * static_cast<std::uintmax_t>(n);
  in.expectTokens(nn, section, "W (" + std::to_string(n) + " x " + std::to_string(n) + ")");
  w.dense = allocateW(in, n);
  for (long col = 0; col < n; ++col) {
    for (long row = 0; row < n; ++row) {
      w.dense(row, col) = in.readNumber(section, "W", row, col);
    }
  }
}

// Reads `count` cumulative block ends that must be increasing and end at n.
std::vector<long> readBlockEnds(TokenReader& in, long count, long n, const std::string& section) {
  std::vector<long> ends(static_cast<std::size_t>(count));
  long previous = 0;
  for (long b = 0; b < count; ++b) {
    ends[b] = in.readInteger(section, "block end " + std::to_string(b));
    if (ends[b] <= previous || ends[b] > n) {
      in.failLast(section, "block end " + std::to_string(b) + " = " + std::to_string(ends[b]) +
                               " is not increasing within (" + std::to_string(previous) + ", " +
                               std::to_string(n) + "]");
    }
    previous = ends[b];
  }
  if (count > 0 && ends.back() != n) {
    in.failLast(section, "last block end is " + std::to_string(ends.back()) +
                             ", expected n = " + std::to_string(n));
  }
  return ends;
}

void readSparseBlock(TokenReader& in, long n, WData& w) {
  w.sparse = true;
  const std::string header = "W (sparse block storage) header";
  in.expectInteger(n, header, "row count");
  in.expectInteger(n, header, "column count");
  const long nb_blocks = in.readInteger(header, "nbblocks");
  const long block_rows = in.readInteger(header, "blocknumber0");
  const long block_cols = in.readInteger(header, "blocknumber1");
  if (nb_blocks < 1 || block_rows < 1 || block_cols < 1 || block_rows > n || block_cols > n ||
      nb_blocks > block_rows * block_cols) {
    in.failLast(header, "inconsistent block counts: nbblocks = " + std::to_string(nb_blocks) +
                            ", blocknumber0 = " + std::to_string(block_rows) + ", blocknumber1 = " +
                            std::to_string(block_cols) + " for n = " + std::to_string(n) +
                            " (expected 1 <= nbblocks <= blocknumber0 blocknumber1, 1 <= "
                            "blocknumber0, blocknumber1 <= n)");
  }
  // The ends, the pattern and one index per block must be there before anything of these sizes
  // is allocated (q and mu, at most 4 nc doubles, are checked as they are read).
  in.expectTokens(static_cast<std::uintmax_t>(2 * block_rows + block_cols + 3 + 2 * nb_blocks),
                  header, "the block ends, the block pattern and the blocks");
  const std::vector<long> row_ends = readBlockEnds(in, block_rows, n, "W row-block ends");
  const std::vector<long> col_ends = readBlockEnds(in, block_cols, n, "W column-block ends");
  const std::string pattern = "W block pattern";
  in.expectInteger(block_rows + 1, pattern, "filled1 (block-row pointer count)");
  in.expectInteger(nb_blocks, pattern, "filled2 (stored block count)");
  std::vector<long> row_pointers(static_cast<std::size_t>(block_rows + 1));
  for (long b = 0; b <= block_rows; ++b) {
    row_pointers[b] = in.readInteger(pattern, "block-row pointer " + std::to_string(b));
    const long previous = b == 0 ? 0 : row_pointers[b - 1];
    if ((b == 0 && row_pointers[b] != 0) || row_pointers[b] < previous ||
        row_pointers[b] > nb_blocks) {
      in.failLast(pattern, "block-row pointer " + std::to_string(b) + " = " +
                               std::to_string(row_pointers[b]) +
                               " is not a non-decreasing pointer from 0 into " +
                               std::to_string(nb_blocks) + " blocks");
    }
  }
  if (row_pointers.back() != nb_blocks) {
    in.failLast(pattern, "last block-row pointer is " + std::to_string(row_pointers.back()) +
                             ", expected nbblocks = " + std::to_string(nb_blocks));
  }
  std::vector<long> col_indices(static_cast<std::size_t>(nb_blocks));
  for (long k = 0; k < nb_blocks; ++k) {
    col_indices[k] = in.readInteger(pattern, "block-column index " + std::to_string(k));
    if (col_indices[k] < 0 || col_indices[k] >= block_cols) {
      in.failLast(pattern, "block-column index " + std::to_string(k) + " = " +
                               std::to_string(col_indices[k]) + " is outside [0, " +
                               std::to_string(block_cols) + ")");
    }
  }
  // The blocks' extents; every diagonal entry of W must lie in a stored block (else W_ii is
  // zero: the problem is singular, and Problem::validate would refuse it after a dense W of
  // 72 nc^2 bytes had been built from a small file).
  std::uintmax_t value_count = 0;
  std::vector<long> cover(static_cast<std::size_t>(n) + 1, 0);  // difference array
  for (long block_row = 0; block_row < block_rows; ++block_row) {
    const long row0 = block_row == 0 ? 0 : row_ends[block_row - 1];
    for (long k = row_pointers[block_row]; k < row_pointers[block_row + 1]; ++k) {
      const long block_col = col_indices[k];
      const long col0 = block_col == 0 ? 0 : col_ends[block_col - 1];
      WData::Block b{row0, row_ends[block_row] - row0, col0, col_ends[block_col] - col0, 0};
      b.first = static_cast<std::size_t>(value_count);
      value_count += static_cast<std::uintmax_t>(b.rows) * static_cast<std::uintmax_t>(b.cols);
      const long d0 = std::max(b.row0, b.col0), d1 = std::min(b.row0 + b.rows, b.col0 + b.cols);
      if (d0 < d1) {
        ++cover[d0];
        --cover[d1];
      }
      w.blocks.push_back(b);
    }
  }
  long covered = 0;
  for (long i = 0; i < n; ++i) {
    covered += cover[i];
    if (covered == 0) {
      in.fail(pattern, "no stored block holds the diagonal entry W(" + std::to_string(i) + ", " +
                           std::to_string(i) + ") of contact " + std::to_string(i / kDimension) +
                           ": W would be singular");
    }
  }
  in.expectTokens(value_count + static_cast<std::uintmax_t>(nb_blocks), pattern,
                  "the " + std::to_string(nb_blocks) + " blocks (" + std::to_string(value_count) +
                      " values and their indices)");
  w.values.resize(static_cast<std::size_t>(value_count));
  for (std::size_t k = 0; k < w.blocks.size(); ++k) {
    const WData::Block& b = w.blocks[k];
    long block_row = 0;
    while (row_pointers[block_row + 1] <= static_cast<long>(k)) ++block_row;
    const std::string section = "W block " + std::to_string(k) + " (block row " +
                                std::to_string(block_row) + ", block column " +
                                std::to_string(col_indices[k]) + ")";
    in.expectInteger(static_cast<long>(k), section, "block index");
    for (long c = 0; c < b.cols; ++c) {
      for (long r = 0; r < b.rows; ++r) {
        w.values[b.first + static_cast<std::size_t>(c * b.rows + r)] =
            in.readNumber(section, "block value", r, c);
      }
    }
  }
}

[[noreturn]] void refuseFile(const std::string& path, const std::string& what) {
  throw std::runtime_error(sourcePrefix(path) + what);
}

// Reads the whole stream, refusing more than kMaxFileBytes.
std::string readText(std::istream& in, const std::string& source) {
  std::string text;
  char buffer[1 << 16];
  while (in) {
    in.read(buffer, sizeof buffer);
    text.append(buffer, static_cast<std::size_t>(in.gcount()));
    if (text.size() > kMaxFileBytes) {
      throw std::runtime_error(sourcePrefix(source) + "more than " + std::to_string(kMaxFileBytes) +
                               " bytes; at most " + std::to_string(kMaxFileBytes >> 20) +
                               " MiB are read");
    }
  }
  if (in.bad()) throw std::runtime_error(sourcePrefix(source) + "I/O error while reading");
  return text;
}

}  // namespace

Problem parseFc3d(std::istream& in, const std::string& source_name) {
  TokenReader tokens(readText(in, source_name), source_name);
  if (tokens.atEnd()) tokens.fail("header", "the file holds no data");
  const std::string header = "header";
  const long dimension = tokens.readInteger(header, "dimension d");
  if (dimension != kDimension) {
    tokens.failLast(header,
                    "unsupported dimension d = " + std::to_string(dimension) + ", expected 3");
  }
  const long nc = tokens.readInteger(header, "number of contacts nc");
  if (nc < 1 || nc > kMaxContacts) {
    tokens.failLast(header, "number of contacts nc = " + std::to_string(nc) + " is outside [1, " +
                                std::to_string(kMaxContacts) +
                                "] (the dense W of 3 nc x 3 nc doubles is capped at 2 GiB)");
  }
  const long n = kDimension * nc;
  const long storage = tokens.readInteger("W storage", "storage type");
  WData w;
  if (storage == 0) {
    readDense(tokens, n, w);
  } else if (storage == 1) {
    readSparseBlock(tokens, n, w);
  } else {
    tokens.failLast("W storage",
                    "unknown storage type " + std::to_string(storage) + " (expected 0 or 1)");
  }
  Eigen::VectorXd q(n);
  for (long i = 0; i < n; ++i) q[i] = tokens.readNumber("q", "q", i);
  Eigen::VectorXd mu(nc);
  for (long i = 0; i < nc; ++i) {
    mu[i] = tokens.readNumber("mu", "mu", i);
    if (mu[i] < 0) {
      tokens.failLast("mu", "mu[" + std::to_string(i) + "] = " + std::to_string(mu[i]) +
                                " is negative; a friction coefficient must be >= 0");
    }
  }
  if (!tokens.atEnd()) {
    tokens.readInteger("trailing data", "the optional trailing integer");
    if (!tokens.atEnd()) {
      tokens.readInteger("trailing data", "nothing");  // names the first extra token
      tokens.failLast("trailing data",
                      "unexpected data after mu and the optional trailing integer");
    }
  }
  if (w.sparse) {
    w.dense = allocateW(tokens, n);
    for (const WData::Block& b : w.blocks) {
      for (long c = 0; c < b.cols; ++c) {
        for (long r = 0; r < b.rows; ++r) {
          w.dense(b.row0 + r, b.col0 + c) =
              w.values[b.first + static_cast<std::size_t>(c * b.rows + r)];
        }
      }
    }
  }
  return Problem::makeDense(std::move(w.dense), std::move(q), std::move(mu));
}

Problem readFc3dFile(const std::string& path) {
  // Kind and size from stat first: a FIFO, a device or a directory is never opened.
  std::error_code ec;
  const fs::file_status status = fs::status(path, ec);
  const auto refuse = [&path](const std::string& what) { refuseFile(path, what); };
  if (status.type() == fs::file_type::not_found) refuse("cannot open the file: file not found");
  if (ec) refuse("cannot open the file: " + ec.message());
  switch (status.type()) {
    case fs::file_type::regular:
      break;
    case fs::file_type::directory:
      refuseFile(path, "is a directory, not a regular file");
    case fs::file_type::fifo:
      refuseFile(path, "is a FIFO (named pipe), not a regular file");
    case fs::file_type::socket:
      refuseFile(path, "is a socket, not a regular file");
    case fs::file_type::character:
    case fs::file_type::block:
      refuseFile(path, "is a device, not a regular file");
    default:
      refuse("is not a regular file");
  }
  const std::uintmax_t bytes = fs::file_size(path, ec);
  if (ec) refuse("cannot read the file size: " + ec.message());
  if (bytes > kMaxFileBytes) {
    refuse("the file is " + std::to_string(bytes) + " bytes; at most " +
           std::to_string(kMaxFileBytes >> 20) + " MiB are read");
  }
  std::ifstream file(path, std::ios::binary);
  if (!file) refuse("cannot open the file");
  return parseFc3d(file, path);
}

}  // namespace rheofeed::ccp

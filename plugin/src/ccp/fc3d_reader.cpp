// SPDX-License-Identifier: MIT
#include "rheofeed/ccp/fc3d_reader.hpp"

#include <cerrno>
#include <cstdlib>
#include <fstream>
#include <limits>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

namespace rheofeed::ccp {

namespace {

// Only 3D contact problems (normal + two tangential directions) are supported.
constexpr long kDimension = 3;
// Guards against absurd sizes in corrupt headers before anything is allocated.
constexpr long kMaxContacts = 10'000'000;

struct Token {
  std::string text;
  long line = 0;
};

// Whitespace-separated tokens with their line numbers, and typed reads that report where a
// fault is.
class TokenReader {
 public:
  TokenReader(std::istream& in, std::string source) : source_(std::move(source)) {
    std::string line;
    long line_number = 0;
    while (std::getline(in, line)) {
      ++line_number;
      std::istringstream words(line);
      std::string word;
      while (words >> word) tokens_.push_back({word, line_number});
    }
    if (in.bad()) fail("reading", "I/O error while reading the file");
  }

  bool atEnd() const { return next_ >= tokens_.size(); }
  std::size_t position() const { return next_; }

  [[noreturn]] void fail(const std::string& section, const std::string& what) const {
    std::ostringstream message;
    message << "fc3d reader: " << source_ << ": " << section << ": " << what;
    throw std::runtime_error(message.str());
  }

  [[noreturn]] void failAt(std::size_t index, const std::string& section,
                           const std::string& what) const {
    std::ostringstream message;
    message << what << " (token " << index;
    if (index < tokens_.size()) message << ", line " << tokens_[index].line;
    message << ")";
    fail(section, message.str());
  }

  long readInteger(const std::string& section, const std::string& what) {
    const Token& token = take(section, what);
    const char* begin = token.text.c_str();
    char* end = nullptr;
    errno = 0;
    const long value = std::strtol(begin, &end, 10);
    if (end == begin || *end != '\0' || errno == ERANGE) {
      failAt(next_ - 1, section, "expected an integer (" + what + "), got '" + token.text + "'");
    }
    return value;
  }

  // Reads a number; `name` with indices i (and j when >= 0) names it in error messages only.
  double readNumber(const std::string& section, const char* name, long i, long j = -1) {
    auto describe = [&]() {
      return std::string(name) + (j < 0 ? "[" + std::to_string(i) + "]"
                                        : "(" + std::to_string(i) + ", " + std::to_string(j) + ")");
    };
    if (atEnd()) take(section, describe());
    const Token& token = tokens_[next_++];
    const char* begin = token.text.c_str();
    char* end = nullptr;
    const double value = std::strtod(begin, &end);
    if (end == begin || *end != '\0') {
      failAt(next_ - 1, section,
             "expected a number (" + describe() + "), got '" + token.text + "'");
    }
    return value;
  }

  // Reads an integer that must equal `expected`.
  void expectInteger(long expected, const std::string& section, const std::string& what) {
    const long value = readInteger(section, what);
    if (value != expected) {
      failAt(next_ - 1, section,
             what + " is " + std::to_string(value) + ", expected " + std::to_string(expected));
    }
  }

 private:
  const Token& take(const std::string& section, const std::string& what) {
    if (atEnd()) {
      std::ostringstream message;
      message << "unexpected end of file while reading " << what << " (file truncated after "
              << tokens_.size() << " tokens)";
      fail(section, message.str());
    }
    return tokens_[next_++];
  }

  std::string source_;
  std::vector<Token> tokens_;
  std::size_t next_ = 0;
};

void readDense(TokenReader& in, long n, Eigen::MatrixXd& w) {
  const std::string section = "W (dense storage)";
  in.expectInteger(n, section, "row count");
  in.expectInteger(n, section, "column count");
  in.expectInteger(n, section, "repeated row count");
  in.expectInteger(n, section, "repeated column count");
  w.resize(n, n);
  for (long col = 0; col < n; ++col) {
    for (long row = 0; row < n; ++row) {
      w(row, col) = in.readNumber(section, "W", row, col);
    }
  }
}

// Reads `count` cumulative block ends that must be increasing and end at n.
std::vector<long> readBlockEnds(TokenReader& in, long count, long n, const std::string& section) {
  std::vector<long> ends(count);
  long previous = 0;
  for (long b = 0; b < count; ++b) {
    ends[b] = in.readInteger(section, "block end " + std::to_string(b));
    if (ends[b] <= previous || ends[b] > n) {
      in.failAt(in.position() - 1, section,
                "block end " + std::to_string(b) + " = " + std::to_string(ends[b]) +
                    " is not increasing within (" + std::to_string(previous) + ", " +
                    std::to_string(n) + "]");
    }
    previous = ends[b];
  }
  if (count > 0 && ends.back() != n) {
    in.failAt(
        in.position() - 1, section,
        "last block end is " + std::to_string(ends.back()) + ", expected n = " + std::to_string(n));
  }
  return ends;
}

void readSparseBlock(TokenReader& in, long n, Eigen::MatrixXd& w) {
  const std::string header = "W (sparse block storage) header";
  in.expectInteger(n, header, "row count");
  in.expectInteger(n, header, "column count");
  const long nb_blocks = in.readInteger(header, "nbblocks");
  const long block_rows = in.readInteger(header, "blocknumber0");
  const long block_cols = in.readInteger(header, "blocknumber1");
  if (nb_blocks < 0 || block_rows < 1 || block_cols < 1 || block_rows > n || block_cols > n ||
      nb_blocks > block_rows * block_cols) {
    in.failAt(in.position() - 1, header,
              "inconsistent block counts: nbblocks = " + std::to_string(nb_blocks) +
                  ", blocknumber0 = " + std::to_string(block_rows) + ", blocknumber1 = " +
                  std::to_string(block_cols) + " for n = " + std::to_string(n));
  }
  const std::vector<long> row_ends = readBlockEnds(in, block_rows, n, "W row-block ends");
  const std::vector<long> col_ends = readBlockEnds(in, block_cols, n, "W column-block ends");
  const std::string pattern = "W block pattern";
  in.expectInteger(block_rows + 1, pattern, "filled1 (block-row pointer count)");
  in.expectInteger(nb_blocks, pattern, "filled2 (stored block count)");
  std::vector<long> row_pointers(block_rows + 1);
  for (long b = 0; b <= block_rows; ++b) {
    row_pointers[b] = in.readInteger(pattern, "block-row pointer " + std::to_string(b));
    const long previous = b == 0 ? 0 : row_pointers[b - 1];
    if ((b == 0 && row_pointers[b] != 0) || row_pointers[b] < previous ||
        row_pointers[b] > nb_blocks) {
      in.failAt(in.position() - 1, pattern,
                "block-row pointer " + std::to_string(b) + " = " + std::to_string(row_pointers[b]) +
                    " is not a non-decreasing pointer from 0 "
                    "into " +
                    std::to_string(nb_blocks) + " blocks");
    }
  }
  if (row_pointers.back() != nb_blocks) {
    in.failAt(in.position() - 1, pattern,
              "last block-row pointer is " + std::to_string(row_pointers.back()) +
                  ", expected nbblocks = " + std::to_string(nb_blocks));
  }
  std::vector<long> col_indices(nb_blocks);
  for (long k = 0; k < nb_blocks; ++k) {
    col_indices[k] = in.readInteger(pattern, "block-column index " + std::to_string(k));
    if (col_indices[k] < 0 || col_indices[k] >= block_cols) {
      in.failAt(in.position() - 1, pattern,
                "block-column index " + std::to_string(k) + " = " + std::to_string(col_indices[k]) +
                    " is outside [0, " + std::to_string(block_cols) + ")");
    }
  }
  w.setZero(n, n);
  for (long block_row = 0; block_row < block_rows; ++block_row) {
    const long row0 = block_row == 0 ? 0 : row_ends[block_row - 1];
    const long rows = row_ends[block_row] - row0;
    for (long k = row_pointers[block_row]; k < row_pointers[block_row + 1]; ++k) {
      const long block_col = col_indices[k];
      const long col0 = block_col == 0 ? 0 : col_ends[block_col - 1];
      const long cols = col_ends[block_col] - col0;
      const std::string section = "W block " + std::to_string(k) + " (block row " +
                                  std::to_string(block_row) + ", block column " +
                                  std::to_string(block_col) + ")";
      in.expectInteger(k, section, "block index");
      for (long c = 0; c < cols; ++c) {
        for (long r = 0; r < rows; ++r) {
          w(row0 + r, col0 + c) = in.readNumber(section, "block value", r, c);
        }
      }
    }
  }
}

}  // namespace

Problem parseFc3d(std::istream& in, const std::string& source_name) {
  TokenReader tokens(in, source_name);
  const std::string header = "header";
  const long dimension = tokens.readInteger(header, "dimension d");
  if (dimension != kDimension) {
    tokens.failAt(0, header,
                  "unsupported dimension d = " + std::to_string(dimension) + ", expected 3");
  }
  const long nc = tokens.readInteger(header, "number of contacts nc");
  if (nc < 1 || nc > kMaxContacts) {
    tokens.failAt(1, header,
                  "number of contacts nc = " + std::to_string(nc) + " is outside [1, " +
                      std::to_string(kMaxContacts) + "]");
  }
  const long n = kDimension * nc;
  const long storage = tokens.readInteger("W storage", "storage type");
  Eigen::MatrixXd w;
  if (storage == 0) {
    readDense(tokens, n, w);
  } else if (storage == 1) {
    readSparseBlock(tokens, n, w);
  } else {
    tokens.failAt(tokens.position() - 1, "W storage",
                  "unknown storage type " + std::to_string(storage) + " (expected 0 or 1)");
  }
  Eigen::VectorXd q(n);
  for (long i = 0; i < n; ++i) q[i] = tokens.readNumber("q", "q", i);
  Eigen::VectorXd mu(nc);
  for (long i = 0; i < nc; ++i) mu[i] = tokens.readNumber("mu", "mu", i);
  if (!tokens.atEnd()) {
    const std::size_t first_extra = tokens.position();
    tokens.readInteger("trailing data", "the optional trailing integer");
    if (!tokens.atEnd()) {
      tokens.failAt(first_extra + 1, "trailing data",
                    "unexpected data after mu and the optional trailing integer");
    }
  }
  return Problem::makeDense(std::move(w), std::move(q), std::move(mu));
}

Problem readFc3dFile(const std::string& path) {
  std::ifstream file(path);
  if (!file) {
    throw std::runtime_error("fc3d reader: " + path + ": cannot open the file");
  }
  return parseFc3d(file, path);
}

}  // namespace rheofeed::ccp

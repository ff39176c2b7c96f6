// SPDX-License-Identifier: MIT
// Tests of fc3d_reader.hpp: both storages, orientation of W, trailing data, and error messages
// that name the file and the place of the fault.

#include "rheofeed/ccp/fc3d_reader.hpp"

#include "test_support.hpp"

#include <gtest/gtest.h>
#include <sys/stat.h>

#include <cerrno>
#include <cstring>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <string>

namespace rheofeed::ccp {
namespace {

namespace fs = std::filesystem;

// Writes `text` to a fresh file in gtest's temporary directory and returns its path.
std::string writeTempFile(const std::string& name, const std::string& text) {
  const fs::path dir = fs::path(testing::TempDir()) / "rheofeed_fc3d_reader_test";
  fs::create_directories(dir);
  const fs::path path = dir / name;
  std::ofstream(path) << text;
  return path.string();
}

// The error message of reading `path`, or "" when it reads fine.
std::string readError(const std::string& path) {
  try {
    readFc3dFile(path);
  } catch (const std::runtime_error& error) {
    return error.what();
  }
  return "";
}

// One contact, dense storage, a non-symmetric W to pin down the column-major order.
const char* const kDenseOneContact =
    "3\n1\n0\n3\n3\n3 3\n"
    "1 2 3\n"   // column 0
    "4 5 6\n"   // column 1
    "7 8 10\n"  // column 2
    "-1 0.5 0.25\n"
    "0.3\n";

// Two contacts, sparse block storage: blocks (0,0), (0,1), (1,1) with distinct values.
const char* const kSparseTwoContacts =
    "3\n2\n1\n6\n6\n"
    "3\n2\n2\n"   // nbblocks, blocknumber0, blocknumber1
    "3 6\n3 6\n"  // row-block ends, column-block ends
    "3\n3\n"      // filled1, filled2
    "0 2 3\n"     // block-row pointers
    "0 1 1\n"     // block-column indices
    "0\n1 2 3 4 5 6 7 8 9\n"
    "1\n11 12 13 14 15 16 17 18 19\n"
    "2\n21 22 23 24 25 26 27 28 29\n"
    "0 1 2 3 4 5\n"
    "0.5 0.7\n"
    "1\n";

TEST(Fc3dReader, ReadsDenseStorageColumnMajor) {
  const Problem problem = readFc3dFile(writeTempFile("dense.dat", kDenseOneContact));
  ASSERT_EQ(problem.numContacts(), 1);
  Eigen::Matrix3d expected;
  expected << 1, 4, 7,  //
      2, 5, 8,          //
      3, 6, 10;
  EXPECT_EQ(problem.delassus, Eigen::MatrixXd(expected));
  EXPECT_EQ(problem.r, Eigen::Vector3d(-1, 0.5, 0.25));
  EXPECT_EQ(problem.mu(0), 0.3);
  EXPECT_EQ(problem.form, DelassusForm::Dense);
}

TEST(Fc3dReader, ReadsSparseBlockStorage) {
  const Problem problem = readFc3dFile(writeTempFile("sparse.dat", kSparseTwoContacts));
  ASSERT_EQ(problem.numContacts(), 2);
  Eigen::MatrixXd expected = Eigen::MatrixXd::Zero(6, 6);
  for (int k = 0; k < 9; ++k) {
    const int row = k % 3, col = k / 3;  // column-major inside a block
    expected(row, col) = 1 + k;
    expected(row, 3 + col) = 11 + k;
    expected(3 + row, 3 + col) = 21 + k;
  }
  EXPECT_EQ(problem.delassus, expected);
  EXPECT_EQ(problem.r, (Eigen::VectorXd(6) << 0, 1, 2, 3, 4, 5).finished());
  EXPECT_EQ(problem.mu, Eigen::Vector2d(0.5, 0.7));
}

TEST(Fc3dReader, ToleratesOneTrailingIntegerOnly) {
  EXPECT_EQ(readError(writeTempFile("trailing1.dat", std::string(kDenseOneContact) + "1\n")), "");
  const std::string path = writeTempFile("trailing2.dat", std::string(kDenseOneContact) + "1 2\n");
  const std::string message = readError(path);
  RHEOFEED_EXPECT_CONTAINS(message, path);
  RHEOFEED_EXPECT_CONTAINS(message, "trailing data");
}

TEST(Fc3dReader, MissingFileNamesThePath) {
  const std::string path = (fs::path(testing::TempDir()) / "no_such_dir" / "missing.dat").string();
  const std::string message = readError(path);
  RHEOFEED_EXPECT_CONTAINS(message, path);
  RHEOFEED_EXPECT_CONTAINS(message, "cannot open");
}

TEST(Fc3dReader, TruncatedFileNamesPathAndSection) {
  std::string text = kDenseOneContact;
  text = text.substr(0, text.find("-1 0.5"));  // cut before q
  const std::string path = writeTempFile("truncated.dat", text);
  const std::string message = readError(path);
  RHEOFEED_EXPECT_CONTAINS(message, path);
  RHEOFEED_EXPECT_CONTAINS(message, "q: unexpected end of file while reading q[0]");
}

TEST(Fc3dReader, NonNumericTokenNamesPathTokenAndLine) {
  std::string text = kDenseOneContact;
  text.replace(text.find("5 6"), 1, "abc");  // W(1, 1): token 11, line 8
  const std::string path = writeTempFile("bad_token.dat", text);
  const std::string message = readError(path);
  RHEOFEED_EXPECT_CONTAINS(message, path);
  RHEOFEED_EXPECT_CONTAINS(message, "W (dense storage)");
  RHEOFEED_EXPECT_CONTAINS(message, "got 'abc'");
  RHEOFEED_EXPECT_CONTAINS(message, "W(1, 1)");
  RHEOFEED_EXPECT_CONTAINS(message, "token 11, line 8");
}

TEST(Fc3dReader, WrongDimensionIsRefused) {
  std::string text = kDenseOneContact;
  text[0] = '2';
  const std::string path = writeTempFile("dimension.dat", text);
  const std::string message = readError(path);
  RHEOFEED_EXPECT_CONTAINS(message, path);
  RHEOFEED_EXPECT_CONTAINS(message, "unsupported dimension d = 2");
}

TEST(Fc3dReader, WrongMatrixSizeIsRefused) {
  std::string text = kDenseOneContact;
  text.replace(text.find("3 3\n"), 3, "3 4");  // repeated column count
  const std::string message = readError(writeTempFile("size.dat", text));
  RHEOFEED_EXPECT_CONTAINS(message, "repeated column count is 4, expected 3");
}

TEST(Fc3dReader, InconsistentBlockCountsAreRefused) {
  std::string text = kSparseTwoContacts;
  text.replace(text.find("3\n3\n0 2 3"), 4, "3\n4\n");  // filled2 = 4 but nbblocks = 3
  const std::string path = writeTempFile("blocks.dat", text);
  const std::string message = readError(path);
  RHEOFEED_EXPECT_CONTAINS(message, path);
  RHEOFEED_EXPECT_CONTAINS(message, "W block pattern");
  RHEOFEED_EXPECT_CONTAINS(message, "filled2 (stored block count) is 4, expected 3");
}

TEST(Fc3dReader, BlockIndexOutOfSequenceIsRefused) {
  std::string text = kSparseTwoContacts;
  text.replace(text.find("1\n11 12"), 1, "5");
  const std::string message = readError(writeTempFile("block_index.dat", text));
  RHEOFEED_EXPECT_CONTAINS(message, "W block 1 (block row 0, block column 1)");
  RHEOFEED_EXPECT_CONTAINS(message, "block index is 5, expected 1");
}

TEST(Fc3dReader, ParsesFromStreamWithSourceName) {
  std::istringstream in("3 1 0 3 3 3 3 1 0 0 0 1 0 0 0 1 1 2");
  try {
    parseFc3d(in, "in-memory");
    FAIL() << "expected an error for the missing q[2] and mu";
  } catch (const std::runtime_error& error) {
    RHEOFEED_EXPECT_CONTAINS(std::string(error.what()), "in-memory: q:");
  }
}

// ---- Limits (issue 9): claimed sizes against the data, kinds of file, values -------------------

// The message of parsing `text` from memory as "mem.dat", or "" when it parses.
std::string parseError(const std::string& text) {
  std::istringstream in(text);
  try {
    parseFc3d(in, "mem.dat");
  } catch (const std::runtime_error& error) {
    return error.what();
  }
  return "";
}

TEST(Fc3dReaderLimits, HeaderClaimingTenMillionContactsIsRefusedWithTheCap) {
  const std::string path = writeTempFile("huge_nc.dat", "3\n10000000\n0\n");
  const std::string message = readError(path);
  RHEOFEED_EXPECT_CONTAINS(message, path);
  RHEOFEED_EXPECT_CONTAINS(message, "nc = 10000000 is outside [1, 5461]");
  RHEOFEED_EXPECT_CONTAINS(message, "2 GiB");
}

TEST(Fc3dReaderLimits, DenseHeaderClaimingMoreValuesThanTheFileHoldsIsRefusedBeforeAllocating) {
  // 5000 contacts: W would be 15000 x 15000 (1.8 GB); the file holds 3 values.
  const std::string message = parseError("3 5000 0 15000 15000 15000 15000 1 2 3");
  RHEOFEED_EXPECT_CONTAINS(message, "mem.dat: W (dense storage)");
  RHEOFEED_EXPECT_CONTAINS(message, "need at least 225000000 more values");
  RHEOFEED_EXPECT_CONTAINS(message, "holds only 3 more tokens");
}

TEST(Fc3dReaderLimits, SparseFileWithOneHugeBlockIsRefusedBeforeAllocating) {
  // One 15000 x 15000 block claimed, 9 values present.
  const std::string message =
      parseError("3 5000 1 15000 15000 1 1 1 15000 15000 2 1 0 1 0 0 1 2 3 4 5 6 7 8 9");
  RHEOFEED_EXPECT_CONTAINS(message, "W block pattern");
  RHEOFEED_EXPECT_CONTAINS(message, "the 1 blocks (225000000 values and their indices)");
}

TEST(Fc3dReaderLimits, SparseFileMissingDiagonalBlocksIsRefusedBeforeBuildingW) {
  // 5000 contacts in 5000 block rows and columns, but only block (0, 0) stored: a small file
  // whose dense W (1.8 GB) would be zero but for one block.
  std::ostringstream text;
  text << "3 5000 1 15000 15000 1 5000 5000\n";
  for (int pass = 0; pass < 2; ++pass) {
    for (int b = 1; b <= 5000; ++b) text << 3 * b << " ";
    text << "\n";
  }
  text << "5001 1\n0";
  for (int b = 1; b <= 5000; ++b) text << " 1";
  text << "\n0\n0\n1 0 0 0 1 0 0 0 1\n";
  const std::string message = parseError(text.str());
  RHEOFEED_EXPECT_CONTAINS(message,
                           "no stored block holds the diagonal entry W(3, 3) of contact 1");
  RHEOFEED_EXPECT_CONTAINS(message, "singular");
}

TEST(Fc3dReaderLimits, NonFiniteValuesAreRefusedWithTheirPlace) {
  std::string text = kDenseOneContact;
  text.replace(text.find("5 6"), 1, "nan");
  std::string message = readError(writeTempFile("nan.dat", text));
  RHEOFEED_EXPECT_CONTAINS(message, "W(1, 1) = 'nan' is not a finite number");
  text = kDenseOneContact;
  text.replace(text.find("0.5 0.25"), 3, "1e999");
  message = readError(writeTempFile("inf.dat", text));
  RHEOFEED_EXPECT_CONTAINS(message, "q: q[1] = '1e999' is not a finite number");
}

TEST(Fc3dReaderLimits, NegativeFrictionCoefficientIsRefused) {
  std::string text = kSparseTwoContacts;
  text.replace(text.find("0.5 0.7"), 7, "0.5 -0.7");
  const std::string path = writeTempFile("negative_mu.dat", text);
  const std::string message = readError(path);
  RHEOFEED_EXPECT_CONTAINS(message, path);
  RHEOFEED_EXPECT_CONTAINS(message, "mu[1] = -0.700000 is negative");
  RHEOFEED_EXPECT_CONTAINS(message, ">= 0");
}

TEST(Fc3dReaderLimits, TrailingGarbageIsRefused) {
  const std::string message =
      readError(writeTempFile("garbage.dat", std::string(kDenseOneContact) + "1 abc\n"));
  RHEOFEED_EXPECT_CONTAINS(message, "trailing data");
  RHEOFEED_EXPECT_CONTAINS(message, "got 'abc'");
}

TEST(Fc3dReaderLimits, TruncatedSparseBlocksAreRefused) {
  std::string text = kSparseTwoContacts;
  text = text.substr(0, text.find("2\n21 22"));  // the third block is missing
  const std::string message = readError(writeTempFile("truncated_sparse.dat", text));
  RHEOFEED_EXPECT_CONTAINS(message, "W block pattern");
  RHEOFEED_EXPECT_CONTAINS(message, "truncated file or wrong header");
}

TEST(Fc3dReaderLimits, FifoIsRefusedWithoutBlocking) {
  const fs::path dir = fs::path(testing::TempDir()) / "rheofeed_fc3d_reader_test";
  fs::create_directories(dir);
  const fs::path fifo = dir / "problem.fifo";
  fs::remove(fifo);
  ASSERT_EQ(mkfifo(fifo.c_str(), 0600), 0) << std::strerror(errno);
  const std::string message = readError(fifo.string());  // would block if opened
  RHEOFEED_EXPECT_CONTAINS(message, fifo.string());
  RHEOFEED_EXPECT_CONTAINS(message, "is a FIFO (named pipe), not a regular file");
  fs::remove(fifo);
}

TEST(Fc3dReaderLimits, DirectoryAndDeviceAreRefused) {
  RHEOFEED_EXPECT_CONTAINS(readError(testing::TempDir()), "is a directory, not a regular file");
  if (fs::exists("/dev/zero")) {
    RHEOFEED_EXPECT_CONTAINS(readError("/dev/zero"), "is a device, not a regular file");
  }
}

TEST(Fc3dReaderLimits, FileBeyondTheSizeCapIsRefusedBeforeReading) {
  const std::string path = writeTempFile("big.dat", "3 1");
  fs::resize_file(path, (std::uintmax_t{1} << 30) + 1);  // sparse: nothing is written
  const std::string message = readError(path);
  RHEOFEED_EXPECT_CONTAINS(message, "the file is 1073741825 bytes; at most 1024 MiB are read");
  fs::remove(path);
}

TEST(Fc3dReaderLimits, EmptyFileIsRefused) {
  RHEOFEED_EXPECT_CONTAINS(readError(writeTempFile("empty.dat", "  \n")),
                           "header: the file holds no data");
}

TEST(Fc3dReaderLimits, ZeroStoredBlocksAreRefused) {
  std::string text = kSparseTwoContacts;
  text.replace(text.find("3\n2\n2\n"), 6, "0\n2\n2\n");
  RHEOFEED_EXPECT_CONTAINS(readError(writeTempFile("no_blocks.dat", text)),
                           "inconsistent block counts: nbblocks = 0");
}

}  // namespace
}  // namespace rheofeed::ccp

// SPDX-License-Identifier: MIT
// Siconos fc3d writer (fc3d_writer.hpp): sparse block storage of the Delassus operator.
#include "rheofeed/ccp/fc3d_writer.hpp"

#include <Eigen/SparseCore>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <vector>

namespace rheofeed::ccp {

namespace {

// The Delassus operator as a column-major sparse matrix (3 nc x 3 nc).
SparseMatrix delassusSparse(const Problem& problem) {
  if (problem.form == DelassusForm::MatrixFree) {
    SparseMatrix n = problem.d.transpose() * (problem.minv * problem.d);
    return n;
  }
  return problem.delassus.sparseView(0.0, 0.0);
}

}  // namespace

std::string writeFc3d(const Problem& problem, std::ostream& out) {
  const Eigen::Index nc = problem.numContacts();
  if (nc < 1) return "writeFc3d: the problem has no contact (fc3d needs nc >= 1)";
  const Eigen::Index n = 3 * nc;
  const SparseMatrix w = delassusSparse(problem);
  // Nonzero 3 x 3 blocks by (block row, block column); the diagonal ones always.
  std::map<std::pair<Eigen::Index, Eigen::Index>, Eigen::Matrix3d> blocks;
  for (Eigen::Index i = 0; i < nc; ++i) blocks[{i, i}] = Eigen::Matrix3d::Zero();
  for (Eigen::Index col = 0; col < w.outerSize(); ++col) {
    for (SparseMatrix::InnerIterator it(w, col); it; ++it) {
      if (it.value() == 0.0) continue;
      auto [entry, fresh] = blocks.try_emplace({it.row() / 3, col / 3}, Eigen::Matrix3d::Zero());
      (void)fresh;
      entry->second(it.row() % 3, col % 3) = it.value();
    }
  }
  char buffer[64];
  auto number = [&](double value) {
    std::snprintf(buffer, sizeof buffer, "%.17g", value);
    return buffer;
  };
  out << "3\n" << nc << "\n";
  out << "1 " << n << " " << n << " " << blocks.size() << " " << nc << " " << nc << "\n";
  for (int pass = 0; pass < 2; ++pass) {  // row-block ends, then column-block ends
    for (Eigen::Index i = 0; i < nc; ++i) out << 3 * (i + 1) << (i + 1 < nc ? " " : "\n");
  }
  out << nc + 1 << " " << blocks.size() << "\n";
  std::vector<std::size_t> row_pointers(static_cast<std::size_t>(nc) + 1, 0);
  for (const auto& entry : blocks) ++row_pointers[static_cast<std::size_t>(entry.first.first) + 1];
  for (std::size_t i = 1; i < row_pointers.size(); ++i) row_pointers[i] += row_pointers[i - 1];
  for (std::size_t i = 0; i < row_pointers.size(); ++i) {
    out << row_pointers[i] << (i + 1 < row_pointers.size() ? " " : "\n");
  }
  for (const auto& entry : blocks) out << entry.first.second << " ";
  out << "\n";
  std::size_t index = 0;
  for (const auto& entry : blocks) {
    out << index++ << "\n";
    for (int c = 0; c < 3; ++c) {
      for (int r = 0; r < 3; ++r) out << number(entry.second(r, c)) << (r < 2 ? " " : "\n");
    }
  }
  for (Eigen::Index i = 0; i < n; ++i) out << number(problem.r[i]) << "\n";
  for (Eigen::Index i = 0; i < nc; ++i) out << number(problem.mu[i]) << "\n";
  if (!out) return "writeFc3d: the stream failed while writing";
  return {};
}

std::string writeFc3dFile(const Problem& problem, const std::string& path) {
  const std::string temporary = path + ".partial";
  {
    std::ofstream file(temporary);
    if (!file) return "writeFc3dFile: cannot open " + temporary + " for writing";
    if (std::string error = writeFc3d(problem, file); !error.empty()) {
      file.close();
      std::filesystem::remove(temporary);
      return error + " (" + path + ")";
    }
    file.close();
    if (!file) {
      std::filesystem::remove(temporary);
      return "writeFc3dFile: writing " + temporary + " failed";
    }
  }
  std::error_code error;
  std::filesystem::rename(temporary, path, error);
  if (error)
    return "writeFc3dFile: cannot rename " + temporary + " to " + path + ": " + error.message();
  return {};
}

}  // namespace rheofeed::ccp

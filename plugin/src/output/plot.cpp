// SPDX-License-Identifier: MIT
#include "rheofeed/output/plot.hpp"

#include <cstdio>
#include <filesystem>
#include <sstream>
#include <system_error>

namespace rheofeed::scene {

bool plotPng(const std::string& script,
             const std::vector<std::pair<std::string, std::string>>& datablocks,
             const std::string& path) {
  const std::string tmp = path + ".partial.png";
  std::ostringstream full;
  full << "set terminal pngcairo size 1000,600 noenhanced\nset output '" << tmp << "'\n";
  for (const auto& [name, csv] : datablocks) {
    full << "$" << name << " << EOD\n";
    const std::size_t first_newline = csv.find('\n');  // skip the CSV header
    full << (first_newline == std::string::npos ? "" : csv.substr(first_newline + 1));
    full << "EOD\n";
  }
  full << script << "\nset output\n";
  std::error_code ec;
  if (std::filesystem::path(path).has_parent_path()) {
    std::filesystem::create_directories(std::filesystem::path(path).parent_path(), ec);
  }
  FILE* pipe = popen("gnuplot 2>&1 >/dev/null", "w");
  if (!pipe) {
    std::fprintf(stderr, "rheofeed: cannot start gnuplot; %s not written\n", path.c_str());
    return false;
  }
  const std::string text = full.str();
  const bool written = std::fwrite(text.data(), 1, text.size(), pipe) == text.size();
  const int status = pclose(pipe);
  if (!written || status != 0 || !std::filesystem::exists(tmp)) {
    std::filesystem::remove(tmp, ec);
    std::fprintf(stderr,
                 "rheofeed: gnuplot failed (is Debian's gnuplot-nox installed?); %s not written\n",
                 path.c_str());
    return false;
  }
  std::filesystem::rename(tmp, path, ec);
  if (ec) {
    std::filesystem::remove(tmp, ec);
    return false;
  }
  return true;
}

}  // namespace rheofeed::scene

// SPDX-License-Identifier: MIT
#include "rheofeed/output/plot.hpp"

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <system_error>

namespace rheofeed::scene {
std::string shellQuoted(const std::string& text) {
  std::string out = "'";
  for (char c : text) out += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return out + "'";
}

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
  // gnuplot's own messages (a warning such as a series with no valid points, or the error that
  // stopped it) go to a log beside the plot and then to stderr, named by the plot.
  const std::string log = path + ".gnuplot.log";
  FILE* pipe = popen(("gnuplot >/dev/null 2>" + shellQuoted(log)).c_str(), "w");
  if (!pipe) {
    std::fprintf(stderr, "rheofeed: cannot start gnuplot; %s not written\n", path.c_str());
    return false;
  }
  const std::string text = full.str();
  const bool written = std::fwrite(text.data(), 1, text.size(), pipe) == text.size();
  const int status = pclose(pipe);
  {
    std::ifstream messages(log);
    std::string line;
    while (std::getline(messages, line)) {
      const std::size_t start = line.find_first_not_of(" \t");
      if (start == std::string::npos) continue;
      std::fprintf(stderr, "rheofeed: %s: gnuplot: %s\n", path.c_str(), line.c_str() + start);
    }
  }
  std::filesystem::remove(log, ec);
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

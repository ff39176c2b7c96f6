// SPDX-License-Identifier: MIT
#include "rheofeed/output/plot.hpp"

#include <pthread.h>
#include <signal.h>
#include <stdlib.h>
#include <time.h>
#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <system_error>

namespace rheofeed::scene {

namespace {

// `text` in single quotes, each ' in it written as `quote`.
std::string singleQuoted(const std::string& text, const std::string& quote) {
  std::string out = "'";
  for (char c : text) out += c == '\'' ? quote : std::string(1, c);
  return out + "'";
}

// `text` as a gnuplot single-quoted string: each ' doubled.
std::string gnuplotQuoted(const std::string& text) {
  return singleQuoted(text, "''");
}

// A new empty file in the temporary folder for gnuplot's messages; empty when none can be made.
std::string newLogFile() {
  std::error_code ec;
  std::string name =
      (std::filesystem::temp_directory_path(ec) / "rheofeed_gnuplot_XXXXXX").string();
  if (ec) return {};
  const int fd = mkstemp(name.data());
  if (fd < 0) return {};
  close(fd);
  return name;
}

// Writes `text` to `pipe` with SIGPIPE blocked in this thread, so that a gnuplot that exits
// early (or never started) makes the write fail instead of killing the process; a SIGPIPE the
// write raised is taken off the thread's pending set before the mask is restored.
bool writeToPipe(FILE* pipe, const std::string& text) {
  sigset_t pipe_signal, old_mask, pending;
  sigemptyset(&pipe_signal);
  sigaddset(&pipe_signal, SIGPIPE);
  pthread_sigmask(SIG_BLOCK, &pipe_signal, &old_mask);
  sigpending(&pending);
  const bool was_pending = sigismember(&pending, SIGPIPE) == 1;
  const bool written =
      std::fwrite(text.data(), 1, text.size(), pipe) == text.size() && std::fflush(pipe) == 0;
  sigpending(&pending);
  if (!was_pending && sigismember(&pending, SIGPIPE) == 1) {
    const timespec no_wait{0, 0};
    sigtimedwait(&pipe_signal, nullptr, &no_wait);
  }
  pthread_sigmask(SIG_SETMASK, &old_mask, nullptr);
  return written;
}

}  // namespace

std::string shellQuoted(const std::string& text) {
  return singleQuoted(text, "'\\''");
}

bool plotPng(const std::string& script,
             const std::vector<std::pair<std::string, std::string>>& datablocks,
             const std::string& path) {
  const std::string tmp = path + ".partial.png";
  std::ostringstream full;
  full << "set terminal pngcairo size 1000,600 noenhanced\nset output " << gnuplotQuoted(tmp)
       << "\n";
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
  // stopped it) go to a temporary log and then to stderr, named by the plot; without a log they
  // go to stderr directly.
  const std::string log = newLogFile();
  const std::string command =
      "gnuplot >/dev/null" + (log.empty() ? std::string() : " 2>" + shellQuoted(log));
  FILE* pipe = popen(command.c_str(), "w");
  if (!pipe) {
    if (!log.empty()) std::filesystem::remove(log, ec);
    std::fprintf(stderr, "rheofeed: cannot start gnuplot; %s not written\n", path.c_str());
    return false;
  }
  const bool written = writeToPipe(pipe, full.str());
  const int status = pclose(pipe);
  if (!log.empty()) {
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
  }
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

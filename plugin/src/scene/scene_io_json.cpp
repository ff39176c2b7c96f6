// SPDX-License-Identifier: MIT
// Scene files, the text -> DOM step (scene_io.cpp reads the DOM into a Scene): a SAX handler
// that builds nlohmann's DOM and knows the JSON path of the value being read, so that a
// duplicate key or a number that overflows a double is named by its path; syntax errors by
// line and column, quoting at most a line's worth of what the lexer read. Also the error type.
#include <algorithm>
#include <set>
#include <sstream>
#include <vector>

#include "scene_io_internal.hpp"

namespace rheofeed::scene {
namespace io {

void fail(const std::string& path, const std::string& problem) {
  throw SceneFileError("", path, problem);
}

std::string describe(const json& v) {
  if (v.is_object()) return "an object";
  if (v.is_array()) return "an array of " + std::to_string(v.size());
  std::string s = v.dump();
  return s.size() > 40 ? s.substr(0, 37) + "..." : s;
}

std::string show(double v) {
  std::ostringstream out;
  out.precision(10);
  out << v;
  return out.str();
}

// ---- Text to DOM -------------------------------------------------------------------------------

// At most this many characters of what the lexer read are quoted in a syntax error: a line's
// worth (a token can be the whole file: an unterminated string of 444 KB was quoted in full).
constexpr std::size_t kMaxQuoted = 60;

// nlohmann's "...; last read: '<token>'" with the token cut to its last kMaxQuoted characters
// (where the error is), marked "...".
std::string shortenLastRead(const std::string& problem) {
  const std::string mark = "last read: '";
  const std::size_t start = problem.find(mark);
  if (start == std::string::npos) return problem;
  const std::size_t begin = start + mark.size();
  const std::size_t end = problem.rfind('\'');
  if (end == std::string::npos || end <= begin || end - begin <= kMaxQuoted) return problem;
  return problem.substr(0, begin) + "..." + problem.substr(end - kMaxQuoted);
}

// Builds the DOM like nlohmann's own parser, and besides knows the JSON path of the value being
// read, so that a duplicate key or a number that overflows a double (1e999) is reported with it.
class DomBuilder final : public nlohmann::json_sax<json> {
 public:
  explicit DomBuilder(json& root) : root_(root) {}

  bool null() override { return value(nullptr); }
  bool boolean(bool v) override { return value(v); }
  bool number_integer(number_integer_t v) override { return value(v); }
  bool number_unsigned(number_unsigned_t v) override { return value(v); }
  bool number_float(number_float_t v, const string_t&) override { return value(v); }
  bool string(string_t& v) override { return value(v); }
  bool binary(binary_t&) override { return value(nullptr); }  // never in JSON text
  bool start_object(std::size_t) override { return open(json::object()); }
  bool end_object() override { return close(); }
  bool start_array(std::size_t) override { return open(json::array()); }
  bool end_array() override { return close(); }
  bool key(string_t& k) override {
    Frame& f = frames_.back();
    if (!f.keys.insert(k).second) {
      path_ = join(pathOf(frames_.size() - 1), k);
      problem_ = "duplicate key (each key may appear once per object)";
      return false;
    }
    f.key = k;
    slot_ = &(*containers_.back())[k];
    return true;
  }
  bool parse_error(std::size_t byte, const std::string& token,
                   const nlohmann::json::exception& e) override {
    byte_ = byte;
    if (e.id == 406) {  // out_of_range.406: number overflow
      path_ = pathOf(frames_.size());
      problem_ = "the number " + token + " is not finite (it overflows a double)";
    } else {  // drop nlohmann's "[json.exception...] parse error at line L, column C: "
      std::string what = e.what();
      const std::size_t column = what.find("column ");
      const std::size_t colon = what.find(": ", column == std::string::npos ? 0 : column);
      if (colon != std::string::npos) what.erase(0, colon + 2);
      problem_ = what.rfind("syntax error", 0) == 0 ? "JSON " + what : "JSON syntax error: " + what;
      problem_ = shortenLastRead(problem_);
    }
    return false;
  }

  const std::string& path() const { return path_; }
  const std::string& problem() const { return problem_; }
  std::size_t byte() const { return byte_; }

 private:
  struct Frame {
    bool array = false;
    std::size_t index = 0;  // array: index of the element being read
    std::string key;        // object: key of the element being read
    std::set<std::string> keys;
  };

  static std::string join(const std::string& path, const std::string& key) {
    return path.empty() ? key : path + "." + key;
  }
  // The path of the element being read at depth n (n frames).
  std::string pathOf(std::size_t n) const {
    std::string p;
    for (std::size_t i = 0; i < n; ++i) {
      const Frame& f = frames_[i];
      if (f.array) {
        p += "[" + std::to_string(f.index) + "]";
      } else if (!f.key.empty()) {
        p = join(p, f.key);
      }
    }
    return p;
  }
  json* place(json v) {
    if (containers_.empty()) {
      root_ = std::move(v);
      return &root_;
    }
    json& top = *containers_.back();
    if (top.is_array()) {
      top.push_back(std::move(v));
      return &top.back();
    }
    *slot_ = std::move(v);
    return slot_;
  }
  void elementDone() {
    if (!frames_.empty() && frames_.back().array) ++frames_.back().index;
  }
  bool value(json v) {
    place(std::move(v));
    elementDone();
    return true;
  }
  bool open(json v) {
    const bool array = v.is_array();
    containers_.push_back(place(std::move(v)));
    frames_.push_back(Frame{array, 0, {}, {}});
    return true;
  }
  bool close() {
    containers_.pop_back();
    frames_.pop_back();
    elementDone();
    return true;
  }

  json& root_;
  std::vector<json*> containers_;  // open objects and arrays, innermost last
  std::vector<Frame> frames_;
  json* slot_ = nullptr;  // the value slot of the last key read
  std::string path_, problem_;
  std::size_t byte_ = 0;
};

json parseText(const std::string& text) {
  json root;
  DomBuilder builder(root);
  if (json::sax_parse(text, &builder)) return root;
  int line = 0, column = 0;
  if (builder.byte() > 0) {  // byte: characters read when the error was found
    const std::size_t end = std::min(builder.byte(), text.size());
    line = 1;
    std::size_t line_start = 0;
    for (std::size_t i = 0; i + 1 < end; ++i) {
      if (text[i] == '\n') {
        ++line;
        line_start = i + 1;
      }
    }
    column = std::max(1, static_cast<int>(end - line_start));
  }
  throw SceneFileError("", builder.path(), builder.problem(), line, column);
}

}  // namespace io

SceneFileError::SceneFileError(std::string source, std::string path, std::string problem, int line,
                               int column)
    : std::invalid_argument([&] {
        std::string s = source;
        if (line > 0) s += ":" + std::to_string(line) + ":" + std::to_string(column);
        if (!path.empty()) s += (s.empty() ? "" : ": ") + path;
        return s + (s.empty() ? "" : ": ") + problem;
      }()),
      source_(std::move(source)),
      path_(std::move(path)),
      problem_(std::move(problem)),
      line_(line),
      column_(column) {}

}  // namespace rheofeed::scene

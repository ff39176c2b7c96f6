// SPDX-License-Identifier: MIT
// writeViewer (animation.hpp): the page template (view.html.in, embedded at build time as
// kViewHtml), three.js copied from Debian's libjs-three, the .glb as a script.
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <stdexcept>

#include "rheofeed/output/animation.hpp"
#include "rheofeed/output/output.hpp"

#ifndef RHEOFEED_THREE_DIR
#define RHEOFEED_THREE_DIR "/usr/share/javascript/three"
#endif

namespace rheofeed::scene {
namespace detail {
extern const char* const kViewHtml;  // view_html.cpp, generated from view.html.in
}  // namespace detail

namespace {

namespace fs = std::filesystem;

// The files of libjs-three the page loads: source (relative to the three.js folder) and the
// name beside the page (in three/).
constexpr const char* kThreeFiles[][2] = {
    {"three.min.js", "three.min.js"},
    {"examples/js/loaders/GLTFLoader.js", "GLTFLoader.js"},
    {"examples/js/controls/OrbitControls.js", "OrbitControls.js"}};

std::string readFile(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw std::runtime_error("cannot read " + path.string());
  std::ostringstream s;
  s << in.rdbuf();
  if (!in && !in.eof()) throw std::runtime_error("read failed: " + path.string());
  return s.str();
}

// The three.js folder: $RHEOFEED_THREE_DIR, the one found at build time, Debian's.
fs::path threeDir() {
  std::vector<fs::path> tried;
  if (const char* env = std::getenv("RHEOFEED_THREE_DIR"); env && *env) tried.emplace_back(env);
  tried.emplace_back(RHEOFEED_THREE_DIR);
  tried.emplace_back("/usr/share/javascript/three");
  std::string names;
  for (const fs::path& dir : tried) {
    bool complete = true;
    for (const auto& file : kThreeFiles) complete = complete && fs::is_regular_file(dir / file[0]);
    if (complete) return dir;
    names += (names.empty() ? "" : ", ") + dir.string();
  }
  throw std::runtime_error(
      "view.html needs three.js (three.min.js, examples/js/loaders/GLTFLoader.js, "
      "examples/js/controls/OrbitControls.js); not found in " +
      names + " (install Debian's libjs-three, or set RHEOFEED_THREE_DIR)");
}

std::string base64(const std::string& bytes) {
  static const char kDigits[] = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  out.reserve((bytes.size() + 2) / 3 * 4);
  std::size_t i = 0;
  for (; i + 2 < bytes.size(); i += 3) {
    const unsigned v = (static_cast<unsigned char>(bytes[i]) << 16) |
                       (static_cast<unsigned char>(bytes[i + 1]) << 8) |
                       static_cast<unsigned char>(bytes[i + 2]);
    for (int k = 3; k >= 0; --k) out += kDigits[(v >> (6 * k)) & 63];
  }
  if (const std::size_t rest = bytes.size() - i; rest > 0) {
    unsigned v = static_cast<unsigned char>(bytes[i]) << 16;
    if (rest == 2) v |= static_cast<unsigned char>(bytes[i + 1]) << 8;
    out += kDigits[(v >> 18) & 63];
    out += kDigits[(v >> 12) & 63];
    out += rest == 2 ? kDigits[(v >> 6) & 63] : '=';
    out += '=';
  }
  return out;
}

std::string htmlEscaped(const std::string& text) {
  std::string out;
  for (char c : text) {
    switch (c) {
      case '&':
        out += "&amp;";
        break;
      case '<':
        out += "&lt;";
        break;
      case '>':
        out += "&gt;";
        break;
      case '"':
        out += "&quot;";
        break;
      case '\'':
        out += "&#39;";
        break;
      default:
        out += c;
    }
  }
  return out;
}

// A file name as a relative URL: every byte outside [A-Za-z0-9._~-] percent-encoded.
std::string urlEscaped(const std::string& name) {
  std::string out;
  for (unsigned char c : name) {
    const bool plain = (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') ||
                       c == '.' || c == '_' || c == '~' || c == '-';
    if (plain) {
      out += static_cast<char>(c);
    } else {
      char hex[4];
      std::snprintf(hex, sizeof hex, "%%%02X", c);
      out += hex;
    }
  }
  return out;
}

void replaceAll(std::string& text, const std::string& field, const std::string& value) {
  for (std::size_t at = text.find(field); at != std::string::npos;
       at = text.find(field, at + value.size())) {
    text.replace(at, field.size(), value);
  }
}

}  // namespace

fs::path writeViewer(const fs::path& folder, const std::string& glb_name,
                     const std::vector<std::string>& plots) {
  const std::string glb = readFile(folder / glb_name);
  const fs::path three = threeDir();
  for (const auto& file : kThreeFiles) {
    writeFileAtomically(folder / "three" / file[1], readFile(three / file[0]));
  }
  const std::string script = glb_name + ".js";
  writeFileAtomically(folder / script, "// The bytes of " + glb_name +
                                           " (base64) for view.html.\n" +
                                           "window.rheofeedGlb = \"" + base64(glb) + "\";\n");
  std::string figures;
  for (const std::string& plot : plots) {
    figures += "\n  <figure><img src=\"" + htmlEscaped(urlEscaped(plot)) + "\" alt=\"" +
               htmlEscaped(plot) + "\"><figcaption>" + htmlEscaped(plot) + "</figcaption></figure>";
  }
  std::string html = detail::kViewHtml;
  replaceAll(html, "{{TITLE}}", htmlEscaped(fs::path(glb_name).stem().string()));
  replaceAll(html, "{{GLB_SCRIPT}}", htmlEscaped(urlEscaped(script)));
  replaceAll(html, "{{PLOTS}}", figures);
  const fs::path page = folder / "view.html";
  writeFileAtomically(page, html);
  return page;
}

}  // namespace rheofeed::scene

#include "app/scene_loading.h"

#include <cctype>
#include <cstdio>
#include <map>
#include <string>
#include <vector>

#include "scene/builtin_scenes.h"
#include "scene/pbrt_loader.h"

namespace tessera {
namespace {

// A scene can warn about every one of its 100,000 curves: each distinct
// warning is printed a few times (with its file:line), then counted.
constexpr int kShownPerWarning = 3;
constexpr int kShownInAll = 50;

// "file:line: message" -> "message" (w itself where it has no location).
std::string without_location(const std::string& w) {
  for (size_t at = w.find(": "); at != std::string::npos; at = w.find(": ", at + 1)) {
    size_t digits = at;
    while (digits > 0 && std::isdigit(static_cast<unsigned char>(w[digits - 1]))) --digits;
    if (digits < at && digits > 0 && w[digits - 1] == ':') return w.substr(at + 2);
  }
  return w;
}

void print_warnings(const std::vector<std::string>& warnings) {
  std::map<std::string, int> seen;  // by message without its location
  std::vector<std::string> order;
  int shown = 0, hidden = 0;
  for (const std::string& w : warnings) {
    const std::string message = without_location(w);
    const int n = ++seen[message];
    if (n == 1) order.push_back(message);
    if (n <= kShownPerWarning && shown < kShownInAll) {
      std::fprintf(stderr, "tessera: warning: %s\n", w.c_str());
      ++shown;
    } else {
      ++hidden;
    }
  }
  if (hidden == 0) return;
  int summaries = 0;
  for (const std::string& message : order) {
    if (seen[message] <= kShownPerWarning || summaries == kShownInAll) continue;
    std::fprintf(stderr, "tessera: warning: %d times in all: %s\n", seen[message], message.c_str());
    ++summaries;
  }
  std::fprintf(stderr, "tessera: warning: %zu warnings in all, %d of them shown\n", warnings.size(), shown);
}

}  // namespace

SceneDesc load_scene_or_builtin(const std::string& path) {
  SceneDesc d = path.empty() ? load_builtin_cornell_box() : load_pbrt_file(path);
  if (d.source.empty()) d.source = path;
  print_warnings(d.warnings);
  return d;
}

}  // namespace tessera

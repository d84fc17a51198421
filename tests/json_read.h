// Reading what the CLI writes (stats JSON, `compare --json`) in tests: a
// whole file as text, and numbers by key.
#pragma once

#include <cmath>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <regex>
#include <string>
#include <vector>

namespace tessera::testing {

inline std::string read_text(const std::filesystem::path& p) {
  std::ifstream f(p, std::ios::binary);
  return std::string((std::istreambuf_iterator<char>(f)), {});
}

// The first `"key": number` in a JSON text; NaN when absent (so it equals nothing).
inline double json_number(const std::string& json, const std::string& key) {
  std::smatch m;
  if (!std::regex_search(json, m, std::regex("\"" + key + "\": *(-?[0-9.eE+-]+)"))) return std::nan("");
  return std::stod(m[1]);
}

// Every `"key": number` in order (e.g. one per pass).
inline std::vector<double> json_numbers(const std::string& json, const std::string& key) {
  std::vector<double> out;
  const std::regex re("\"" + key + "\": *(-?[0-9.eE+-]+)");
  for (auto it = std::sregex_iterator(json.begin(), json.end(), re); it != std::sregex_iterator(); ++it)
    out.push_back(std::stod((*it)[1]));
  return out;
}

}  // namespace tessera::testing

// Reading what the CLI writes (stats JSON, `compare --json`) in tests: a
// whole file as text, and numbers by key, parsed with nlohmann-json (so a
// test also fails when the output is not JSON, e.g. a bare nan).
#pragma once

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

namespace tessera::testing {

inline std::string read_text(const std::filesystem::path& p) {
  std::ifstream f(p, std::ios::binary);
  return std::string((std::istreambuf_iterator<char>(f)), {});
}

// Every number under `key`, anywhere in the document, in document order
// (keys keep the order they were written in: e.g. the top-level value, then
// one per pass). The text from its first '{' to its last '}' must be JSON:
// else a test failure is added and there are none.
inline std::vector<double> json_numbers(const std::string& json, const std::string& key) {
  std::vector<double> out;
  // The object itself: a command's output may carry log lines around it.
  const size_t first = json.find('{'), last = json.rfind('}');
  const nlohmann::ordered_json doc =
      first == std::string::npos || last == std::string::npos || last < first
          ? nlohmann::ordered_json(nlohmann::ordered_json::value_t::discarded)
          : nlohmann::ordered_json::parse(json.substr(first, last - first + 1), nullptr, false);
  if (doc.is_discarded()) {
    ADD_FAILURE() << "not JSON: " << json.substr(0, 200);
    return out;
  }
  auto walk = [&](const auto& self, const nlohmann::ordered_json& v) -> void {
    if (v.is_object()) {
      for (auto it = v.begin(); it != v.end(); ++it) {
        if (it.key() == key && it.value().is_number()) out.push_back(it.value().get<double>());
        self(self, it.value());
      }
    } else if (v.is_array()) {
      for (const auto& e : v) self(self, e);
    }
  };
  walk(walk, doc);
  return out;
}

// The first number under `key`; NaN when there is none (so it equals nothing).
inline double json_number(const std::string& json, const std::string& key) {
  const std::vector<double> all = json_numbers(json, key);
  return all.empty() ? std::nan("") : all.front();
}

}  // namespace tessera::testing

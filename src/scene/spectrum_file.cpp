#include "scene/spectrum_file.h"

#include <charconv>
#include <filesystem>
#include <cmath>
#include <fstream>
#include <sstream>

#include "scene/scene_desc.h"

namespace tessera {
namespace {

[[noreturn]] void fail(const std::string& name, const std::string& reason) {
  throw SceneError("cannot read spectrum file '" + name + "': " + reason);
}

}  // namespace

std::vector<Float> parse_spectrum_text(const std::string& text, const std::string& name) {
  std::vector<Float> values;
  std::istringstream lines(text);
  int line_number = 0;
  for (std::string line; std::getline(lines, line);) {
    ++line_number;
    line = line.substr(0, line.find('#'));
    std::istringstream words(line);
    for (std::string w; words >> w;) {
      double v = 0;
      auto [end, ec] = std::from_chars(w.data(), w.data() + w.size(), v);
      if (ec != std::errc() || end != w.data() + w.size() || !std::isfinite(v))
        fail(name, "line " + std::to_string(line_number) + ": '" + w.substr(0, 32) + "' is not a finite number");
      values.push_back(static_cast<Float>(v));
    }
  }
  if (values.empty()) fail(name, "no wavelength/value pairs");
  if (values.size() % 2 != 0) fail(name, "odd count of numbers (" + std::to_string(values.size()) + "): expected wavelength/value pairs");
  for (size_t i = 2; i < values.size(); i += 2)
    if (!(values[i] > values[i - 2]))
      fail(name, "wavelengths must increase (" + std::to_string(values[i - 2]) + " is followed by " +
                     std::to_string(values[i]) + ")");
  return values;
}

std::vector<Float> read_spectrum_file(const std::string& path) {
  // Measured spectra are a few kilobytes; anything far larger is not one.
  constexpr uintmax_t kMaxBytes = uintmax_t(16) << 20;
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec)) fail(path, "not a regular file");
  if (std::filesystem::file_size(path, ec) > kMaxBytes) fail(path, "larger than 16 MiB");
  std::ifstream in(path, std::ios::binary);
  if (!in) fail(path, "cannot open it");
  std::ostringstream text;
  text << in.rdbuf();
  if (in.bad()) fail(path, "read error");
  return parse_spectrum_text(text.str(), path);
}

}  // namespace tessera

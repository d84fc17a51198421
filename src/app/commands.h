// The `tessera` subcommands. Each registers its options on the CLI11 app and
// returns the process exit code when run.
#pragma once

#include <CLI/CLI.hpp>
#include <functional>
#include <string>

namespace tessera {

using CommandRunner = std::function<int()>;

// Whether `in` is one number and nothing else (NaN and Inf included: the
// callers bound it).
inline bool parse_number(const std::string& in, double* v) {
  size_t used = 0;
  try {
    *v = std::stod(in, &used);
  } catch (const std::exception&) {
    return false;
  }
  return used == in.size();
}

// A finite number > 0; the error reads "must be a positive number, got 'X'"
// (CLI11's PositiveNumber prints its whole double range).
inline CLI::Validator positive_number() {
  return CLI::Validator(
      [](std::string& in) -> std::string {
        double v = 0;
        if (parse_number(in, &v) && v > 0 && v < 1e300) return {};
        return "must be a positive number, got '" + in + "'";
      },
      "POSITIVE");
}

// A finite number in [lo, hi] (CLI11's Range lets NaN through).
inline CLI::Validator finite_range(double lo, double hi) {
  return CLI::Validator(
      [lo, hi](std::string& in) -> std::string {
        double v = 0;
        if (parse_number(in, &v) && v >= lo && v <= hi) return {};
        return "must be a number from " + CLI::detail::to_string(lo) + " to " + CLI::detail::to_string(hi) + ", got '" +
               in + "'";
      },
      "NUMBER");
}

CommandRunner add_render_command(CLI::App& app);
CommandRunner add_info_command(CLI::App& app);
CommandRunner add_compare_command(CLI::App& app);
CommandRunner add_bench_rays_command(CLI::App& app);
CommandRunner add_guide_viz_command(CLI::App& app);

}  // namespace tessera

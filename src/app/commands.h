// The `tessera` subcommands. Each registers its options on the CLI11 app and
// returns the process exit code when run.
#pragma once

#include <CLI/CLI.hpp>
#include <functional>

namespace tessera {

using CommandRunner = std::function<int()>;

CommandRunner add_render_command(CLI::App& app);
CommandRunner add_info_command(CLI::App& app);
CommandRunner add_compare_command(CLI::App& app);
CommandRunner add_bench_rays_command(CLI::App& app);
CommandRunner add_guide_viz_command(CLI::App& app);

}  // namespace tessera

// Runs the tessera binary (or mpirun with it) from a test: exit code and
// everything it printed.
#pragma once

#include <sys/wait.h>

#include <array>
#include <cstdio>
#include <string>

namespace tessera::testing {

struct RunResult {
  int exit_code;
  std::string output;  // stdout + stderr
};

inline RunResult run_shell(const std::string& command) {
  FILE* p = popen((command + " 2>&1").c_str(), "r");
  std::string out;
  std::array<char, 4096> buf;
  while (size_t n = fread(buf.data(), 1, buf.size(), p)) out.append(buf.data(), n);
  int status = pclose(p);
  return {WIFEXITED(status) ? WEXITSTATUS(status) : 128, out};
}

// `tessera ARGS`
inline RunResult run(const std::string& args) { return run_shell(std::string(TESSERA_BINARY) + " " + args); }

// `mpirun -np N tessera ARGS`, allowed to run as root and on more ranks than cores.
inline RunResult run_mpi(int ranks, const std::string& args) {
  return run_shell("OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 mpirun --oversubscribe -np " +
                   std::to_string(ranks) + " " + TESSERA_BINARY + " " + args);
}

}  // namespace tessera::testing

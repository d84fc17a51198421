// Writing an output without destroying anything: every file Tessera writes
// (images, stats, checkpoints, guides) goes through write_output, and every
// render checks its output paths against each other and against its inputs
// before it starts (check_output_collisions).
//
// - A regular file (or a path where nothing is yet) is written to a temporary
//   file beside it and renamed over it: a failed or killed write never leaves
//   a half-written file, and the old file stays until the new one is whole.
// - A FIFO, a character device (/dev/null, a terminal) or "-" (stdout) is
//   written through: the bytes go to it, the node itself is never replaced.
// - A symbolic link is followed: its target is written, the link stays.
// - A folder, a block device or a socket is refused (check_output_path).
#pragma once

#include <functional>
#include <string>
#include <vector>

namespace tessera {

// Fails (std::runtime_error, one line naming `option` and `path`) when `path`
// cannot take an output: its folder is missing or not writable, or it is a
// folder, a block device or a socket. "-" (stdout) only where stdout_ok.
void check_output_path(const std::string& path, const char* option, bool stdout_ok = false);

// Writes the output at `path` with write(p), which creates the whole file at
// p (a temporary path with the same extension, so that format writers that
// go by it still do).
void write_output(const std::string& path, const std::function<void(const std::string& p)>& write);

// A path the render reads or writes, and what named it ("-o", "--resume",
// "scene file", ...).
struct NamedPath {
  std::string what;
  std::string path;
};

// Fails (one line naming both) when an output is the same file as another
// output or as an input: the same path spelled differently, a link to it or
// a hard link all count. Character devices and stdout are shared freely.
// An output may equal an input only when allowed(output, input) says so
// (a checkpoint that continues the one it resumes).
void check_output_collisions(
    const std::vector<NamedPath>& outputs, const std::vector<NamedPath>& inputs,
    const std::function<bool(const NamedPath& output, const NamedPath& input)>& allowed = {});

// The file a path names once symbolic links are followed (the path itself
// where none is); fails on a loop of links.
std::string follow_links(const std::string& path);

}  // namespace tessera

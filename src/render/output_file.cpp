#include "render/output_file.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <stdexcept>
#include <string>

namespace tessera {
namespace {

namespace fs = std::filesystem;

constexpr int kMaxLinkHops = 40;  // as the kernel's own limit (ELOOP)

std::string quoted(const std::string& what, const std::string& path) { return what + " '" + path + "'"; }

std::string errno_text() { return std::strerror(errno); }

// The process's umask, read without changing it (umask() would, for a
// moment, for every thread).
mode_t current_umask() {
  std::ifstream f("/proc/self/status");
  std::string line;
  while (std::getline(f, line)) {
    if (line.rfind("Umask:", 0) == 0) return static_cast<mode_t>(std::stoul(line.substr(6), nullptr, 8));
  }
  return 022;
}

// A new empty file beside `near` (in `dir`) whose name ends in near's
// extension, with `mode`; its path.
std::string make_temporary(const fs::path& dir, const fs::path& near, mode_t mode) {
  const std::string ext = near.extension().string();
  std::string name = (dir / ("." + near.filename().string() + ".XXXXXX" + ext)).string();
  const int fd = mkstemps(name.data(), static_cast<int>(ext.size()));
  if (fd < 0) throw std::runtime_error("cannot create a temporary file in '" + dir.string() + "': " + errno_text());
  fchmod(fd, mode);
  close(fd);
  return name;
}

void copy_to_fd(const std::string& from, int fd, const std::string& to_name) {
  std::ifstream in(from, std::ios::binary);
  char buf[1 << 16];
  while (in) {
    in.read(buf, sizeof buf);
    const char* p = buf;
    std::streamsize left = in.gcount();
    while (left > 0) {
      const ssize_t n = ::write(fd, p, static_cast<size_t>(left));
      if (n < 0 && errno == EINTR) continue;
      if (n <= 0) throw std::runtime_error("writing " + to_name + ": " + errno_text());
      p += n;
      left -= n;
    }
  }
}

// Writes through a node that must not be replaced (FIFO, character device,
// stdout): the whole file is made first, so that a format writer that seeks
// (EXR) still can, then its bytes go to the node.
void write_through(const std::string& path, const std::function<void(const std::string&)>& write) {
  const std::string tmp = make_temporary(fs::temp_directory_path(), path == "-" ? fs::path("stdout") : fs::path(path), 0600);
  try {
    write(tmp);
    if (path == "-") {
      std::fflush(stdout);
      copy_to_fd(tmp, STDOUT_FILENO, "stdout");
    } else {
      const int fd = open(path.c_str(), O_WRONLY | O_CLOEXEC);
      if (fd < 0) throw std::runtime_error("cannot open '" + path + "' for writing: " + errno_text());
      try {
        copy_to_fd(tmp, fd, "'" + path + "'");
      } catch (...) {
        close(fd);
        throw;
      }
      close(fd);
    }
  } catch (...) {
    unlink(tmp.c_str());
    throw;
  }
  unlink(tmp.c_str());
}

// A file's identity: its device and inode where it exists (links and other
// spellings of it agree), else its absolute path with links followed.
// Empty: shared freely (stdout, a character device).
std::string identity(const std::string& path) {
  if (path.empty() || path == "-") return "";
  const std::string target = follow_links(path);
  struct stat st {};
  if (stat(target.c_str(), &st) == 0) {
    if (S_ISCHR(st.st_mode)) return "";
    return "inode " + std::to_string(st.st_dev) + ":" + std::to_string(st.st_ino);
  }
  std::error_code ec;
  const fs::path canonical = fs::weakly_canonical(fs::absolute(target), ec);
  return "path " + (ec ? target : canonical.string());
}

}  // namespace

std::string follow_links(const std::string& path) {
  fs::path p = path;
  for (int hops = 0; hops <= kMaxLinkHops; ++hops) {
    struct stat st {};
    if (lstat(p.c_str(), &st) != 0 || !S_ISLNK(st.st_mode)) return p.string();
    std::error_code ec;
    const fs::path target = fs::read_symlink(p, ec);
    if (ec) return p.string();
    p = target.is_absolute() ? target : p.parent_path() / target;
  }
  throw std::runtime_error("'" + path + "': too many levels of symbolic links");
}

void check_output_path(const std::string& path, const char* option, bool stdout_ok) {
  if (path.empty()) return;
  const std::string what = quoted(option, path) + ": ";
  if (path == "-") {
    if (stdout_ok) return;
    throw std::runtime_error(what + "this output cannot go to stdout");
  }
  const std::string target = follow_links(path);
  struct stat st {};
  if (stat(target.c_str(), &st) == 0) {
    if (S_ISDIR(st.st_mode)) throw std::runtime_error(what + "is a folder");
    if (S_ISBLK(st.st_mode)) throw std::runtime_error(what + "is a block device: refusing to write over it");
    if (S_ISSOCK(st.st_mode)) throw std::runtime_error(what + "is a socket");
    if (S_ISFIFO(st.st_mode) || S_ISCHR(st.st_mode)) {
      if (access(target.c_str(), W_OK) != 0) throw std::runtime_error(what + "is not writable");
      return;  // written through, never replaced
    }
  }
  fs::path dir = fs::path(target).parent_path();
  if (dir.empty()) dir = ".";
  std::error_code ec;
  if (!fs::is_directory(dir, ec)) throw std::runtime_error(what + "folder '" + dir.string() + "' does not exist");
  if (access(dir.c_str(), W_OK) != 0) throw std::runtime_error(what + "folder '" + dir.string() + "' is not writable");
  // Permission bits do not say everything (root passes access() for /proc or
  // a read-only mount): create a file there, as the outputs will be.
  std::string probe = (dir / ".tessera-write-check-XXXXXX").string();
  const int fd = mkstemp(probe.data());
  if (fd < 0) throw std::runtime_error(what + "folder '" + dir.string() + "' is not writable (" + errno_text() + ")");
  close(fd);
  unlink(probe.c_str());
}

void write_output(const std::string& path, const std::function<void(const std::string& p)>& write) {
  if (path == "-") return write_through(path, write);
  const std::string target = follow_links(path);
  struct stat st {};
  const bool exists = stat(target.c_str(), &st) == 0;
  if (exists && (S_ISFIFO(st.st_mode) || S_ISCHR(st.st_mode))) return write_through(target, write);
  if (exists && !S_ISREG(st.st_mode)) throw std::runtime_error("'" + path + "' is not a regular file: not replaced");
  // Temporary + rename, with the mode the file has (or would get).
  const mode_t mode = exists ? (st.st_mode & 07777) : (0666 & ~current_umask());
  fs::path dir = fs::path(target).parent_path();
  if (dir.empty()) dir = ".";
  const std::string tmp = make_temporary(dir, fs::path(target), mode);
  try {
    write(tmp);
    fs::rename(tmp, target);
  } catch (...) {
    unlink(tmp.c_str());
    throw;
  }
}

void check_output_collisions(const std::vector<NamedPath>& outputs, const std::vector<NamedPath>& inputs,
                             const std::function<bool(const NamedPath&, const NamedPath&)>& allowed) {
  std::vector<std::string> ids, input_ids;
  for (const NamedPath& o : outputs) ids.push_back(identity(o.path));
  for (const NamedPath& in : inputs) input_ids.push_back(identity(in.path));
  for (size_t i = 0; i < outputs.size(); ++i) {
    if (ids[i].empty()) continue;
    for (size_t j = 0; j < i; ++j) {
      if (ids[j] == ids[i])
        throw std::runtime_error(quoted(outputs[j].what, outputs[j].path) + " and " + quoted(outputs[i].what, outputs[i].path) +
                                 " are the same file: one would overwrite the other");
    }
    for (size_t k = 0; k < inputs.size(); ++k) {
      if (input_ids[k] != ids[i] || (allowed && allowed(outputs[i], inputs[k]))) continue;
      throw std::runtime_error(quoted(outputs[i].what, outputs[i].path) + " would overwrite an input of this render (" +
                               quoted(inputs[k].what, inputs[k].path) + ")");
    }
  }
}

}  // namespace tessera

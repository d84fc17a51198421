// libFuzzer target over `tessera render`'s command line and its output
// checks (render/output_file.h: check_output_path, check_output_collisions,
// write_output), run in-process through the same CLI11 command that main()
// registers (app/commands.h).
//
// An input is up to 4 commands separated by a line "%%"; each line of a
// command is one argument after `tessera render`. The commands run in turn
// in one sandbox folder, so a later one may --resume a checkpoint or
// --guide-in a guide that an earlier one wrote. The folder is made afresh
// for every input and holds a tiny 8x8 scene (with an Include and a PLY
// mesh it reads), a folder, a FIFO (fifo.exr, drained by a thread), links
// to each of these, to /dev/null, to nothing and to themselves, and a hard
// link to the scene.
//
// Sandbox: the commands run with the sandbox as the current folder and as
// TMPDIR; every argument that is an absolute path other than /dev/null is
// moved under the sandbox and ".." is never passed, so no input can name a
// file outside it. Work is capped: --spp, --time, --max-depth, --threads,
// --res and the guide's sizes are lowered to small values where the
// command line would accept them (values it refuses are kept, to exercise
// the refusals), and --res 8x8, --spp 1 and --threads 1 are added where the
// command line has none. Arguments that would make the render read the FIFO
// (a scene, --resume, --guide-in) are replaced: reading a FIFO nobody
// writes waits for ever, by design.
//
// A clear error (a non-zero exit status with a message) is a correct
// answer. A crash, a sanitizer report, a hang, an escaping exception, or a
// command that replaces the FIFO, creates anything in /dev or changes a
// file its scene reads is a finding. scripts/fuzz.sh builds and runs
// it ("cli" target); the suite replays tests/fuzz/cli_corpus through it.
#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <CLI/CLI.hpp>

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <new>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "app/commands.h"
#include "guidecache/neural/neural_view.h"
#include "scene/scene_desc.h"

namespace {

namespace fs = std::filesystem;

constexpr size_t kMaxCommands = 4, kMaxArgs = 48, kMaxArgLength = 256;

const char* kScene =
    "LookAt 0 0 -5  0 0 0  0 1 0\n"
    "Camera \"perspective\" \"float fov\" [ 45 ]\n"
    "Sampler \"independent\" \"integer pixelsamples\" [ 1 ]\n"
    "Integrator \"volpath\" \"integer maxdepth\" [ 3 ]\n"
    "Film \"rgb\" \"integer xresolution\" [ 8 ] \"integer yresolution\" [ 8 ] \"string filename\" [ \"scene.png\" ]\n"
    "WorldBegin\n"
    "LightSource \"point\" \"rgb I\" [ 10 10 10 ] \"point3 from\" [ 0 2 -3 ]\n"
    "Include \"inc.pbrt\"\n";
const char* kInclude =
    "Material \"diffuse\" \"rgb reflectance\" [ 0.5 0.5 0.5 ]\n"
    "Shape \"plymesh\" \"string filename\" [ \"mesh.ply\" ]\n"
    "Material \"dielectric\"\n"
    "Shape \"sphere\" \"float radius\" [ 0.5 ]\n";
const char* kPly =
    "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\nproperty float z\n"
    "element face 2\nproperty list uchar int vertex_indices\nend_header\n"
    "-3 -3 1\n3 -3 1\n3 3 1\n-3 3 1\n3 0 1 2\n3 0 2 3\n";

// The files the scene reads, which no command may change.
const std::map<std::string, std::string>& inputs() {
  static const std::map<std::string, std::string> files = {
      {"scene.pbrt", kScene}, {"inc.pbrt", kInclude}, {"mesh.ply", kPly}};
  return files;
}

[[noreturn]] void finding(const std::string& what) {
  std::fprintf(stderr, "fuzz_render_cli: %s\n", what.c_str());
  std::abort();
}

std::string read_file(const fs::path& p) {
  std::ifstream f(p, std::ios::binary);
  std::ostringstream s;
  s << f.rdbuf();
  return s.str();
}

struct Sandbox {
  fs::path root, box, fifo;
  ino_t fifo_inode = 0;
  size_t dev_entries = 0;
};

size_t count_entries(const fs::path& dir) {
  std::error_code ec;
  size_t n = 0;
  for (fs::directory_iterator it(dir, ec), end; !ec && it != end; it.increment(ec)) ++n;
  return n;
}

const Sandbox& sandbox() {
  static const Sandbox s = [] {
    Sandbox s;
    s.root = fs::temp_directory_path() / ("tessera-fuzz-cli-" + std::to_string(getpid()));
    fs::remove_all(s.root);
    s.box = s.root / "box";
    fs::create_directories(s.box);
    fs::create_directories(s.root / "tmp");
    s.fifo = s.box / "fifo.exr";
    if (mkfifo(s.fifo.c_str(), 0644) != 0) finding("cannot make the FIFO");
    struct stat st {};
    stat(s.fifo.c_str(), &st);
    s.fifo_inode = st.st_ino;
    // Held open for reading and writing: a writer's open never waits, and
    // the thread drains what it writes.
    const int fd = open(s.fifo.c_str(), O_RDWR | O_CLOEXEC);
    if (fd < 0) finding("cannot open the FIFO");
    std::thread([fd] {
      char buf[1 << 16];
      while (read(fd, buf, sizeof buf) != 0) {
      }
    }).detach();
    setenv("TMPDIR", (s.root / "tmp").c_str(), 1);  // write_output's temporaries for FIFOs and devices
    s.dev_entries = count_entries("/dev");
    return s;
  }();
  static const bool cleaned_at_exit = std::atexit([] {
    std::error_code ec;
    fs::remove_all(sandbox().root, ec);
  }) == 0;
  (void)cleaned_at_exit;
  return s;
}

// The sandbox as every input starts: the FIFO stays, the rest is made anew.
void reset_box(const Sandbox& s) {
  for (const fs::directory_entry& e : fs::directory_iterator(s.box))
    if (e.path() != s.fifo) fs::remove_all(e.path());
  for (const auto& [name, text] : inputs()) std::ofstream(s.box / name, std::ios::binary) << text;
  fs::create_directory(s.box / "dir");
  std::ofstream(s.box / "dir" / "old.exr") << "not an image";
  fs::create_directory(s.box / "readonly");
  fs::permissions(s.box / "readonly", fs::perms::owner_read | fs::perms::owner_exec);
  std::ofstream(s.box / "ro.exr") << "read-only";
  fs::permissions(s.box / "ro.exr", fs::perms::owner_read);
  fs::create_symlink("out.exr", s.box / "link-new.exr");      // to nothing yet
  fs::create_symlink("scene.pbrt", s.box / "link-scene.exr");  // to an input
  fs::create_symlink("inc.pbrt", s.box / "link-inc.json");
  fs::create_symlink("dir", s.box / "link-dir");
  fs::create_symlink("fifo.exr", s.box / "link-fifo.json");
  fs::create_symlink("/dev/null", s.box / "null.exr");
  fs::create_symlink("loop-b.exr", s.box / "loop-a.exr");
  fs::create_symlink("loop-a.exr", s.box / "loop-b.exr");
  fs::create_symlink("missing/out.exr", s.box / "link-missing.exr");
  fs::create_hard_link(s.box / "scene.pbrt", s.box / "hard-scene.exr");
}

ino_t inode_of(const fs::path& p) {
  struct stat st {};
  return stat(p.c_str(), &st) == 0 ? st.st_ino : 0;
}

// The fixture files a command reads: those of the scene it renders, found
// as an argument that follows no option (or one given as --opt=value).
std::vector<std::string> files_read(const Sandbox& s, const std::vector<std::string>& args) {
  for (size_t i = 0; i < args.size(); ++i) {
    if (args[i].empty() || args[i][0] == '-') continue;
    if (i > 0 && args[i - 1].size() > 1 && args[i - 1][0] == '-' && args[i - 1].find('=') == std::string::npos) continue;
    const ino_t ino = inode_of(fs::path(args[i]).is_absolute() ? fs::path(args[i]) : s.box / args[i]);
    if (ino == 0) continue;
    if (ino == inode_of(s.box / "scene.pbrt")) return {"scene.pbrt", "inc.pbrt", "mesh.ply"};
    if (ino == inode_of(s.box / "inc.pbrt")) return {"inc.pbrt", "mesh.ply"};
    if (ino == inode_of(s.box / "mesh.ply")) return {"mesh.ply"};
  }
  return {};
}

// What a command must leave as it was: the FIFO, the files its scene read
// (checked before the command, as inodes may change), nothing new in /dev.
void check_box(const Sandbox& s, const std::vector<std::string>& read, const std::string& command) {
  struct stat st {};
  if (lstat(s.fifo.c_str(), &st) != 0 || !S_ISFIFO(st.st_mode) || st.st_ino != s.fifo_inode)
    finding("the FIFO was replaced by: " + command);
  for (const std::string& name : read)
    if (read_file(s.box / name) != inputs().at(name)) finding(name + ", which the scene reads, was changed by: " + command);
  if (count_entries("/dev") > s.dev_entries) finding("a file appeared in /dev after: " + command);
  // Another command's scene may be a file this one was free to write over.
  for (const auto& [name, text] : inputs())
    if (read_file(s.box / name) != text) std::ofstream(s.box / name, std::ios::binary | std::ios::trunc) << text;
}

bool is_output_option(const std::string& opt) {
  return opt == "-o" || opt == "--output" || opt == "--stats" || opt == "--preview" || opt == "--checkpoint" ||
         opt == "--guide-out";
}

// Whether `path` (relative to the sandbox) is the FIFO, by any spelling or link.
bool names_fifo(const Sandbox& s, const std::string& path) {
  if (path.empty() || path.size() > kMaxArgLength) return false;
  struct stat st {};
  const fs::path p = fs::path(path).is_absolute() ? fs::path(path) : s.box / path;
  return stat(p.c_str(), &st) == 0 && S_ISFIFO(st.st_mode) && st.st_ino == s.fifo_inode;
}

// A path confined to the sandbox: absolute paths move under it, but /dev/null.
std::string confine(const Sandbox& s, const std::string& value) {
  if (value.empty() || value[0] != '/' || value == "/dev/null") return value;
  return s.box.string() + value;
}

std::string replace_all(std::string t, const std::string& from, const std::string& to) {
  for (size_t at = t.find(from); at != std::string::npos; at = t.find(from, at + to.size())) t.replace(at, from.size(), to);
  return t;
}

// One argument as the sandbox allows it (see the top of the file).
std::string sandboxed(const Sandbox& s, std::string t) {
  t = replace_all(t, "..", "._");
  if (t.empty() || t[0] != '-') return confine(s, t);
  const size_t eq = t.find('=');
  std::string head = replace_all(t.substr(0, eq), "/", "_");
  return eq == std::string::npos ? head : head + "=" + confine(s, t.substr(eq + 1));
}

// Lowers a value the command line would accept to `cap`; keeps the rest.
std::string capped_integer(const std::string& v, int64_t cap, int64_t hi, bool zero_too = false) {
  int64_t n = 0;
  if (!CLI::detail::lexical_cast(v, n)) return v;
  return (n > cap && n <= hi) || (zero_too && n == 0) ? std::to_string(cap) : v;
}

std::string capped_value(const std::string& opt, const std::string& v) {
  if (opt == "--spp") return capped_integer(v, 2, int64_t(1) << 30);
  if (opt == "--max-depth") return capped_integer(v, 5, int64_t(1) << 20);
  if (opt == "--threads") return capped_integer(v, 1, 4096, /*zero_too=*/true);
  if (opt == "--neural-steps") return capped_integer(v, 2, 1024);
  if (opt == "--neural-width") return capped_integer(v, 16, tessera::kNeuralMaxWidth);
  if (opt == "--neural-targets") return capped_integer(v, 64, int64_t(1) << 20);
  if (opt == "--neural-table") return capped_integer(v, tessera::kNeuralMinTableLog2, tessera::kNeuralMaxTableLog2);
  double d = 0;
  if (opt == "--time") return tessera::parse_number(v, &d) && d > 0.05 && d < 1e300 ? "0.05" : v;
  if (opt == "--guide-budget") return tessera::parse_number(v, &d) && d > 4 && d <= 1048576 ? "4" : v;
  if (opt == "--res") {
    long long w = 0, h = 0;
    char x = 0, rest = 0;
    if (std::sscanf(v.c_str(), "%lld%c%lld%c", &w, &x, &h, &rest) == 3 && x == 'x' && w > 0 && h > 0 &&
        w <= tessera::kMaxFilmDimension && h <= tessera::kMaxFilmDimension && w * h <= tessera::kMaxFilmPixels &&
        w * h > 256)
      return "8x8";
  }
  return v;
}

std::vector<std::string> sandboxed_command(const Sandbox& s, const std::vector<std::string>& raw) {
  std::vector<std::string> args;
  for (const std::string& r : raw) args.push_back(sandboxed(s, r));
  bool has_res = false, has_spp = false, has_time = false, has_target = false, has_threads = false;
  for (size_t i = 0; i < args.size(); ++i) {
    const size_t eq = args[i].find('=');
    const std::string opt = args[i].substr(0, eq);
    has_res |= opt == "--res";
    has_spp |= opt == "--spp";
    has_time |= opt == "--time";
    has_target |= opt == "--target-error";
    has_threads |= opt == "--threads";
    if (eq != std::string::npos) {
      std::string value = capped_value(opt, args[i].substr(eq + 1));
      if (!is_output_option(opt) && names_fifo(s, value)) value = "no-fifo";
      args[i] = opt + "=" + value;
    } else if (opt.size() > 1 && opt[0] == '-' && i + 1 < args.size()) {
      args[i + 1] = capped_value(opt, args[i + 1]);
    }
    // Read where no output option names it: the render would wait for a writer.
    if (eq == std::string::npos && names_fifo(s, args[i]) && (i == 0 || !is_output_option(args[i - 1])))
      args[i] = "no-fifo";
  }
  std::vector<std::string> added;
  if (!has_res) added.insert(added.end(), {"--res", "8x8"});
  if (!has_spp && !has_time && !has_target) added.insert(added.end(), {"--spp", "1"});
  if (has_target && !has_time && !has_spp) added.insert(added.end(), {"--time", "0.05"});
  if (!has_threads) added.insert(added.end(), {"--threads", "1"});
  args.insert(args.begin(), added.begin(), added.end());
  return args;
}

// `tessera render ARGS` as main() runs it; its exit status.
int run_render(const std::vector<std::string>& args) {
  CLI::App app{"tessera"};
  app.require_subcommand(0, 1);
  const tessera::CommandRunner run = tessera::add_render_command(app);
  std::vector<std::string> argv_text = {"tessera", "render"};
  argv_text.insert(argv_text.end(), args.begin(), args.end());
  std::vector<char*> argv;
  for (std::string& a : argv_text) argv.push_back(a.data());
  try {
    app.parse(static_cast<int>(argv.size()), argv.data());
  } catch (const CLI::ParseError& e) {
    return app.exit(e);
  }
  try {
    return run();
  } catch (const tessera::SceneError& e) {
    std::fprintf(stderr, "tessera: error: %s\n", e.what());
    return 2;
  } catch (const std::bad_alloc&) {
    std::fprintf(stderr, "tessera: error: out of memory\n");
    return 1;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "tessera: error: %s\n", e.what());
    return 1;
  }
}

std::vector<std::vector<std::string>> parse_commands(const std::string& text) {
  std::vector<std::vector<std::string>> commands(1);
  std::istringstream in(text);
  std::string line;
  while (std::getline(in, line)) {
    if (line == "%%") {
      if (commands.size() == kMaxCommands) break;
      commands.emplace_back();
    } else if (commands.back().size() < kMaxArgs) {
      // An argument ends at its first NUL, as the command line exec hands
      // over does: the caps below must see what tessera will read.
      commands.back().push_back(line.substr(0, std::min(line.find('\0'), kMaxArgLength)));
    }
  }
  return commands;
}

std::string joined(const std::vector<std::string>& args) {
  std::string s = "render";
  for (const std::string& a : args) s += " '" + a + "'";
  return s;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const Sandbox& s = sandbox();
  const std::vector<std::vector<std::string>> commands =
      parse_commands(std::string(reinterpret_cast<const char*>(data), size));
  reset_box(s);
  const fs::path home = fs::current_path();
  for (const std::vector<std::string>& raw : commands) {
    const std::vector<std::string> args = sandboxed_command(s, raw);
    const std::vector<std::string> read = files_read(s, args);
    fs::current_path(s.box);
    const int rc = run_render(args);
    fs::current_path(home);
    (void)rc;  // any exit status is an answer; only what the command broke is a finding
    check_box(s, read, joined(args));
  }
  return 0;
}

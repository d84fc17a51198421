#include "scene/scene_file.h"

#include <zlib.h>

#include <filesystem>

#include <array>
#include <streambuf>

namespace tessera {
namespace {

// A read-only streambuf over zlib's gzFile, which passes plain files through
// unchanged: the parser reads a scene of any size in chunks either way.
class GzStreamBuf : public std::streambuf {
 public:
  explicit GzStreamBuf(gzFile file) : file_(file) {}
  ~GzStreamBuf() override { gzclose(file_); }
  GzStreamBuf(const GzStreamBuf&) = delete;
  GzStreamBuf& operator=(const GzStreamBuf&) = delete;

 protected:
  int_type underflow() override {
    if (gptr() < egptr()) return traits_type::to_int_type(*gptr());
    const int got = gzread(file_, buf_.data(), static_cast<unsigned>(buf_.size()));
    if (got <= 0) return traits_type::eof();  // the end, or damaged data: the parser reports what it has
    setg(buf_.data(), buf_.data(), buf_.data() + got);
    return traits_type::to_int_type(*gptr());
  }

 private:
  gzFile file_;
  std::array<char, 1 << 16> buf_{};
};

class GzIStream : public std::istream {
 public:
  explicit GzIStream(gzFile file) : std::istream(nullptr), buf_(file) { rdbuf(&buf_); }

 private:
  GzStreamBuf buf_;
};

}  // namespace

std::unique_ptr<std::istream> open_scene_file(const std::string& path) {
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec)) return nullptr;  // zlib opens a folder and reads nothing
  gzFile f = gzopen(path.c_str(), "rb");
  if (f == nullptr) return nullptr;
  return std::make_unique<GzIStream>(f);
}

}  // namespace tessera

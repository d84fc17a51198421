// A scene file's text as a stream: plain or gzip-compressed (pbrt-v4 reads
// scene.pbrt.gz and gzipped Includes), decided by the content, as zlib does.
#pragma once

#include <istream>
#include <memory>
#include <string>

namespace tessera {

// The file's (decompressed) text; null when it cannot be opened.
std::unique_ptr<std::istream> open_scene_file(const std::string& path);

}  // namespace tessera

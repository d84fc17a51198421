// Plain values to and from binary streams, as their bytes: for files read
// back by the same build on the same kind of machine (packed scenes, the
// GPU check's fixtures), never for files that travel between builds.
#pragma once

#include <istream>
#include <ostream>
#include <stdexcept>
#include <string>

namespace tessera {

template <class T>
void write_pod(std::ostream& out, const T& v) {
  out.write(reinterpret_cast<const char*>(&v), sizeof(T));
}

// Throws std::runtime_error naming `what` when the stream ends first.
template <class T>
void read_pod(std::istream& in, T* v, const char* what) {
  if (!in.read(reinterpret_cast<char*>(v), sizeof(T))) throw std::runtime_error(std::string(what) + ": truncated");
}

}  // namespace tessera

// Encoding of farm messages and checkpoints with cereal. Ranks of one farm
// run the same binary on the same architecture, so plain (native-endian)
// binary archives serve; arrays of plain structs travel as raw bytes.
#pragma once

#include <cereal/archives/binary.hpp>
#include <cereal/types/string.hpp>
#include <cereal/types/vector.hpp>
#include <istream>
#include <ostream>
#include <streambuf>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <vector>

#include "comm/transport.h"

namespace tessera {

// A vector of trivially copyable elements as (count, raw bytes).
template <class T>
struct RawVector {
  std::vector<T>& v;
  template <class Archive>
  void save(Archive& ar) const {
    static_assert(std::is_trivially_copyable_v<T>);
    ar(static_cast<uint64_t>(v.size()));
    ar(cereal::binary_data(v.data(), v.size() * sizeof(T)));
  }
  template <class Archive>
  void load(Archive& ar) {
    static_assert(std::is_trivially_copyable_v<T>);
    uint64_t n = 0;
    ar(n);
    if (n > (uint64_t(1) << 40) / sizeof(T)) throw std::runtime_error("absurd array size");
    v.resize(static_cast<size_t>(n));
    ar(cereal::binary_data(v.data(), v.size() * sizeof(T)));
  }
};
template <class T>
RawVector<T> raw(std::vector<T>& v) {
  return RawVector<T>{v};
}
template <class T>
RawVector<T> raw(const std::vector<T>& v) {
  return RawVector<T>{const_cast<std::vector<T>&>(v)};
}

// A trivially copyable value as raw bytes.
template <class T>
auto raw_value(T& value) {
  static_assert(std::is_trivially_copyable_v<std::remove_const_t<T>>);
  return cereal::binary_data(const_cast<std::remove_const_t<T>*>(&value), sizeof(T));
}

// Stream buffers straight over a message's bytes: no string in between
// (a round of the guide's learning is megabytes, and a farm sends one per
// Adam step).
class BytesOut : public std::streambuf {
 public:
  explicit BytesOut(Bytes& bytes) : bytes_(bytes) {}

 protected:
  std::streamsize xsputn(const char* s, std::streamsize n) override {
    bytes_.insert(bytes_.end(), reinterpret_cast<const uint8_t*>(s), reinterpret_cast<const uint8_t*>(s) + n);
    return n;
  }
  int_type overflow(int_type c) override {
    if (!traits_type::eq_int_type(c, traits_type::eof())) bytes_.push_back(static_cast<uint8_t>(c));
    return traits_type::not_eof(c);
  }
  // tellp() only: the bytes only grow.
  pos_type seekoff(off_type off, std::ios_base::seekdir dir, std::ios_base::openmode which) override {
    if (off != 0 || dir != std::ios_base::cur || !(which & std::ios_base::out)) return pos_type(off_type(-1));
    return pos_type(static_cast<off_type>(bytes_.size()));
  }

 private:
  Bytes& bytes_;
};

// Readers may look ahead and seek back (load_guide reads the magic first).
class BytesIn : public std::streambuf {
 public:
  explicit BytesIn(const Bytes& bytes) {
    char* begin = const_cast<char*>(reinterpret_cast<const char*>(bytes.data()));
    setg(begin, begin, begin + bytes.size());
  }

 protected:
  pos_type seekoff(off_type off, std::ios_base::seekdir dir, std::ios_base::openmode which) override {
    if (!(which & std::ios_base::in)) return pos_type(off_type(-1));
    const off_type base = dir == std::ios_base::beg ? 0 : dir == std::ios_base::cur ? gptr() - eback() : egptr() - eback();
    if (base + off < 0 || base + off > egptr() - eback()) return pos_type(off_type(-1));
    setg(eback(), eback() + base + off, egptr());
    return pos_type(base + off);
  }
  pos_type seekpos(pos_type pos, std::ios_base::openmode which) override {
    return seekoff(off_type(pos), std::ios_base::beg, which);
  }
};

template <class T>
Bytes encode(const T& message) {
  Bytes bytes;
  BytesOut buffer(bytes);
  std::ostream os(&buffer);
  {
    cereal::BinaryOutputArchive ar(os);
    ar(const_cast<T&>(message));
  }
  return bytes;
}

// Throws std::runtime_error for bytes that are not a T.
template <class T>
T decode(const Bytes& bytes) {
  BytesIn buffer(bytes);
  std::istream is(&buffer);
  T message;
  try {
    cereal::BinaryInputArchive ar(is);
    ar(message);
  } catch (const cereal::Exception& e) {
    throw std::runtime_error(std::string("malformed message (") + e.what() + ")");
  }
  return message;
}

}  // namespace tessera

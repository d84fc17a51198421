// Encoding of farm messages and checkpoints with cereal. Ranks of one farm
// run the same binary on the same architecture, so plain (native-endian)
// binary archives serve; arrays of plain structs travel as raw bytes.
#pragma once

#include <cereal/archives/binary.hpp>
#include <cereal/types/string.hpp>
#include <cereal/types/vector.hpp>
#include <sstream>
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

template <class T>
Bytes encode(const T& message) {
  std::ostringstream os(std::ios::binary);
  {
    cereal::BinaryOutputArchive ar(os);
    ar(const_cast<T&>(message));
  }
  const std::string s = os.str();
  return Bytes(s.begin(), s.end());
}

// Throws std::runtime_error for bytes that are not a T.
template <class T>
T decode(const Bytes& bytes) {
  std::istringstream is(std::string(bytes.begin(), bytes.end()), std::ios::binary);
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

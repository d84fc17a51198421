// Eight floats (or 32-bit integers) computed side by side, for the neural
// guide's inference (neural_guide.h): its hash-grid levels and blocks of
// output bins come in eights. On the CPU a lane group is a GCC/Clang vector
// (one AVX register, or two SSE ones in the portable build); GCC's loop
// vectoriser does not find these loops by itself (they stayed scalar). On
// the GPU, and for other compilers, it is a plain array with the same
// operations lane by lane. Only IEEE +, -, *, comparisons, conversions and
// integer arithmetic are offered. On the CPU nothing is fused
// (-ffp-contract=off): the AVX2 and portable builds compute the same bits.
// nvcc fuses a*b+c by default (--fmad), so device results may differ from
// the CPU's in the last bits. TESSERA_LANES_PLAIN forces the plain arrays on
// the CPU too (to check them against the vectors: the same bits).
#pragma once

#include <cstdint>
#include <cstring>

#include "kernels/device.h"

namespace tessera {

constexpr uint32_t kLanes8 = 8;

#if defined(__GNUC__) && !defined(__CUDACC__) && !defined(TESSERA_LANES_PLAIN)

// Always inlined: the AVX2 and portable copies of the inference each get
// their own, never a call across (the two pass vectors differently).
// TESSERA_LANES_FN marks the kernels' own functions that take or return
// lanes by value.
#define TESSERA_LANES_INLINE inline __attribute__((always_inline))
#define TESSERA_LANES_FN TESSERA_LANES_INLINE

typedef float F8 __attribute__((vector_size(32)));
typedef uint32_t U8 __attribute__((vector_size(32)));
typedef int32_t I8 __attribute__((vector_size(32)));

TESSERA_LANES_INLINE F8 lanes_load(const float* p) {
  F8 v;
  memcpy(&v, p, sizeof v);
  return v;
}
TESSERA_LANES_INLINE void lanes_store(float* p, const F8& v) { memcpy(p, &v, sizeof v); }
TESSERA_LANES_INLINE F8 lanes_splat(float x) { return x - F8{}; }  // x - (+0) keeps -0 (x + 0 would not)
TESSERA_LANES_INLINE U8 lanes_splat_u(uint32_t x) { return U8{} + x; }
TESSERA_LANES_INLINE F8 lanes_make(const float (&x)[kLanes8]) { return lanes_load(x); }
TESSERA_LANES_INLINE U8 lanes_make_u(const uint32_t (&x)[kLanes8]) {
  U8 v;
  memcpy(&v, x, sizeof v);
  return v;
}
// a > b ? x : y, lane by lane (false for NaN).
TESSERA_LANES_INLINE F8 lanes_select_gt(const F8& a, const F8& b, const F8& x, const F8& y) { return a > b ? x : y; }
TESSERA_LANES_INLINE U8 lanes_select_le_u(const U8& a, const U8& b, const U8& x, const U8& y) { return a <= b ? x : y; }
// Whether a > b in any lane (false for NaN): the lane masks ORed in four
// 64-bit words, not eight lanes taken out one by one.
TESSERA_LANES_INLINE bool lanes_any_gt(const F8& a, const F8& b) {
  typedef int64_t W4 __attribute__((vector_size(32)));
  const W4 m = reinterpret_cast<W4>(a > b);
  return ((m[0] | m[1]) | (m[2] | m[3])) != 0;
}
TESSERA_LANES_INLINE U8 lanes_min_u(const U8& a, const U8& b) { return a < b ? a : b; }
// Truncation of non-negative floats below 2^31 to integers, and back.
TESSERA_LANES_INLINE U8 lanes_trunc_u(const F8& x) { return reinterpret_cast<U8>(__builtin_convertvector(x, I8)); }
TESSERA_LANES_INLINE I8 lanes_trunc_i(const F8& x) { return __builtin_convertvector(x, I8); }
TESSERA_LANES_INLINE F8 lanes_float(const U8& x) { return __builtin_convertvector(reinterpret_cast<I8>(x), F8); }
TESSERA_LANES_INLINE F8 lanes_float_i(const I8& x) { return __builtin_convertvector(x, F8); }
TESSERA_LANES_INLINE F8 lanes_bits_to_float(const U8& x) { return reinterpret_cast<F8>(x); }
TESSERA_LANES_INLINE U8 lanes_u(const I8& x) { return reinterpret_cast<U8>(x); }

#else

#define TESSERA_LANES_FN TESSERA_HOST_DEVICE inline

template <class T>
struct Lanes8 {
  T v[kLanes8];
  TESSERA_HOST_DEVICE T operator[](uint32_t k) const { return v[k]; }
  TESSERA_HOST_DEVICE T& operator[](uint32_t k) { return v[k]; }
};
using F8 = Lanes8<float>;
using U8 = Lanes8<uint32_t>;
using I8 = Lanes8<int32_t>;

#define TESSERA_LANES_OP(T, OP)                                                          \
  TESSERA_HOST_DEVICE inline Lanes8<T> operator OP(const Lanes8<T>& a, const Lanes8<T>& b) { \
    Lanes8<T> r;                                                                         \
    for (uint32_t k = 0; k < kLanes8; ++k) r.v[k] = a.v[k] OP b.v[k];                   \
    return r;                                                                            \
  }                                                                                      \
  TESSERA_HOST_DEVICE inline Lanes8<T> operator OP(const Lanes8<T>& a, T b) {             \
    Lanes8<T> r;                                                                         \
    for (uint32_t k = 0; k < kLanes8; ++k) r.v[k] = a.v[k] OP b;                        \
    return r;                                                                            \
  }                                                                                      \
  TESSERA_HOST_DEVICE inline Lanes8<T> operator OP(T a, const Lanes8<T>& b) {             \
    Lanes8<T> r;                                                                         \
    for (uint32_t k = 0; k < kLanes8; ++k) r.v[k] = a OP b.v[k];                        \
    return r;                                                                            \
  }                                                                                      \
  TESSERA_HOST_DEVICE inline Lanes8<T>& operator OP##=(Lanes8<T>& a, const Lanes8<T>& b) { \
    a = a OP b;                                                                          \
    return a;                                                                            \
  }
TESSERA_LANES_OP(float, +)
TESSERA_LANES_OP(float, -)
TESSERA_LANES_OP(float, *)
TESSERA_LANES_OP(uint32_t, +)
TESSERA_LANES_OP(uint32_t, -)
TESSERA_LANES_OP(uint32_t, *)
TESSERA_LANES_OP(uint32_t, ^)
TESSERA_LANES_OP(uint32_t, &)
TESSERA_LANES_OP(uint32_t, <<)
TESSERA_LANES_OP(int32_t, +)
TESSERA_LANES_OP(int32_t, -)
#undef TESSERA_LANES_OP

TESSERA_HOST_DEVICE inline F8 lanes_load(const float* p) {
  F8 r;
  for (uint32_t k = 0; k < kLanes8; ++k) r.v[k] = p[k];
  return r;
}
TESSERA_HOST_DEVICE inline void lanes_store(float* p, const F8& v) {
  for (uint32_t k = 0; k < kLanes8; ++k) p[k] = v.v[k];
}
TESSERA_HOST_DEVICE inline F8 lanes_splat(float x) {
  F8 r;
  for (uint32_t k = 0; k < kLanes8; ++k) r.v[k] = x;
  return r;
}
TESSERA_HOST_DEVICE inline U8 lanes_splat_u(uint32_t x) {
  U8 r;
  for (uint32_t k = 0; k < kLanes8; ++k) r.v[k] = x;
  return r;
}
TESSERA_HOST_DEVICE inline F8 lanes_make(const float (&x)[kLanes8]) { return lanes_load(x); }
TESSERA_HOST_DEVICE inline U8 lanes_make_u(const uint32_t (&x)[kLanes8]) {
  U8 r;
  for (uint32_t k = 0; k < kLanes8; ++k) r.v[k] = x[k];
  return r;
}
TESSERA_HOST_DEVICE inline F8 lanes_select_gt(const F8& a, const F8& b, const F8& x, const F8& y) {
  F8 r;
  for (uint32_t k = 0; k < kLanes8; ++k) r.v[k] = a.v[k] > b.v[k] ? x.v[k] : y.v[k];
  return r;
}
TESSERA_HOST_DEVICE inline U8 lanes_select_le_u(const U8& a, const U8& b, const U8& x, const U8& y) {
  U8 r;
  for (uint32_t k = 0; k < kLanes8; ++k) r.v[k] = a.v[k] <= b.v[k] ? x.v[k] : y.v[k];
  return r;
}
TESSERA_HOST_DEVICE inline bool lanes_any_gt(const F8& a, const F8& b) {
  bool any = false;
  for (uint32_t k = 0; k < kLanes8; ++k) any = any || a.v[k] > b.v[k];
  return any;
}
TESSERA_HOST_DEVICE inline U8 lanes_min_u(const U8& a, const U8& b) {
  U8 r;
  for (uint32_t k = 0; k < kLanes8; ++k) r.v[k] = a.v[k] < b.v[k] ? a.v[k] : b.v[k];
  return r;
}
// Lane by lane: r[k] = f(a[k]).
template <class R, class T, class F>
TESSERA_HOST_DEVICE inline Lanes8<R> lanes_map(const Lanes8<T>& a, F f) {
  Lanes8<R> r;
  for (uint32_t k = 0; k < kLanes8; ++k) r.v[k] = f(a.v[k]);
  return r;
}
TESSERA_HOST_DEVICE inline U8 lanes_trunc_u(const F8& x) {
  return lanes_map<uint32_t>(x, [](float v) { return static_cast<uint32_t>(static_cast<int32_t>(v)); });
}
TESSERA_HOST_DEVICE inline I8 lanes_trunc_i(const F8& x) {
  return lanes_map<int32_t>(x, [](float v) { return static_cast<int32_t>(v); });
}
TESSERA_HOST_DEVICE inline F8 lanes_float(const U8& x) {
  return lanes_map<float>(x, [](uint32_t v) { return static_cast<float>(static_cast<int32_t>(v)); });
}
TESSERA_HOST_DEVICE inline F8 lanes_float_i(const I8& x) {
  return lanes_map<float>(x, [](int32_t v) { return static_cast<float>(v); });
}
TESSERA_HOST_DEVICE inline F8 lanes_bits_to_float(const U8& x) {
  return lanes_map<float>(x, [](uint32_t v) {
    float f;
    memcpy(&f, &v, sizeof f);
    return f;
  });
}
TESSERA_HOST_DEVICE inline U8 lanes_u(const I8& x) {
  return lanes_map<uint32_t>(x, [](int32_t v) { return static_cast<uint32_t>(v); });
}

#endif

}  // namespace tessera

// The CPU's inference entry points (guidecache/neural/neural_view.h: neural_infer_cpu
// and neural_value_cpu): each function body compiled twice, for AVX2 and for the portable
// x86-64 baseline, and picked once by what the processor supports. The
// inference is a few thousand independent multiply-adds per vertex; AVX2
// halves its time. Without FMA (not enabled here, and -ffp-contract=off)
// every lane computes the same IEEE operations in the same order in either
// copy, and no libm function is called: the results are bit-identical with
// and without AVX2 (tested). (Elsewhere the renderer calls libm's sin, cos
// and pow, which glibc may compute differently on machines with FMA.)
#include "guidecache/neural/neural_view.h"

namespace tessera {

#if defined(__GNUC__) && defined(__x86_64__)
__attribute__((target("avx2"), flatten)) void neural_infer_avx2(const NeuralGuideView& v, const Vec3& p, const Vec3& n,
                                                                NeuralSite* site) {
  neural_infer(v, p, n, site);
}
bool neural_infer_has_avx2() { return __builtin_cpu_supports("avx2"); }
__attribute__((target("avx2"), flatten)) static Float neural_value_avx2(const NeuralGuideView& v, const Vec3& p,
                                                                        const Vec3& n, uint32_t y_bin) {
  return neural_value(v, p, n, y_bin);
}
#else
void neural_infer_avx2(const NeuralGuideView& v, const Vec3& p, const Vec3& n, NeuralSite* site) {
  neural_infer(v, p, n, site);
}
bool neural_infer_has_avx2() { return false; }
static Float neural_value_avx2(const NeuralGuideView& v, const Vec3& p, const Vec3& n, uint32_t y_bin) {
  return neural_value(v, p, n, y_bin);
}
#endif

__attribute__((flatten)) void neural_infer_portable(const NeuralGuideView& v, const Vec3& p, const Vec3& n,
                                                    NeuralSite* site) {
  neural_infer(v, p, n, site);
}

void neural_infer_cpu(const NeuralGuideView& v, const Vec3& p, const Vec3& n, NeuralSite* site) {
  using Infer = void (*)(const NeuralGuideView&, const Vec3&, const Vec3&, NeuralSite*);
  static const Infer infer = neural_infer_has_avx2() ? &neural_infer_avx2 : &neural_infer_portable;
  infer(v, p, n, site);
}

__attribute__((flatten)) static Float neural_value_portable(const NeuralGuideView& v, const Vec3& p, const Vec3& n,
                                                            uint32_t y_bin) {
  return neural_value(v, p, n, y_bin);
}

Float neural_value_cpu(const NeuralGuideView& v, const Vec3& p, const Vec3& n, uint32_t y_bin) {
  using Value = Float (*)(const NeuralGuideView&, const Vec3&, const Vec3&, uint32_t);
  static const Value value = neural_infer_has_avx2() ? &neural_value_avx2 : &neural_value_portable;
  return value(v, p, n, y_bin);
}

}  // namespace tessera

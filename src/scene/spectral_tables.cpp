#include "scene/spectral_tables.h"

#include <cstring>
#include <stdexcept>

#include "scene/cie_tables.h"
#include "scene/rgb_spectrum_fit.h"

// The table file written by tools/gen_rgb_spectrum_table at build time,
// placed in read-only data (TESSERA_RGB_SPECTRUM_TABLE is its path).
#define TESSERA_STR2(x) #x
#define TESSERA_STR(x) TESSERA_STR2(x)
asm(".section .rodata\n"
    ".balign 16\n"
    ".global tessera_rgb_spectrum_table_begin\n"
    "tessera_rgb_spectrum_table_begin:\n"
    ".incbin \"" TESSERA_STR(TESSERA_RGB_SPECTRUM_TABLE) "\"\n"
    ".global tessera_rgb_spectrum_table_end\n"
    "tessera_rgb_spectrum_table_end:\n"
    ".previous\n");
extern "C" const char tessera_rgb_spectrum_table_begin[];
extern "C" const char tessera_rgb_spectrum_table_end[];

namespace tessera {

SpectralView SpectralTables::view() const {
  SpectralView v;
  v.enabled = true;
  v.cmf = cmf.data();
  v.illuminant = illuminant.data();
  v.table_scale = scale;
  v.table = coeffs;
  v.res = res;
  v.rgb_from_xyz = rgb_from_xyz;
  v.inv_y_integral = inv_y_integral;
  return v;
}

const SpectralTables& srgb_spectral_tables() {
  static const SpectralTables t = [] {
    SpectralTables s;
    const char* p = tessera_rgb_spectrum_table_begin;
    const size_t size = static_cast<size_t>(tessera_rgb_spectrum_table_end - tessera_rgb_spectrum_table_begin);
    int32_t res = 0;
    if (size < 12 || std::memcmp(p, "TSRGBSP1", 8) != 0) throw std::runtime_error("embedded RGB-to-spectrum table is damaged");
    std::memcpy(&res, p + 8, 4);
    const size_t expect = 12 + sizeof(float) * (static_cast<size_t>(res) + 9ull * res * res * res);
    if (res < 4 || res > 256 || size < expect) throw std::runtime_error("embedded RGB-to-spectrum table is damaged");
    s.res = res;
    s.scale = reinterpret_cast<const float*>(p + 12);  // 4-byte aligned: .balign 16 + 12
    s.coeffs = s.scale + res;
    const SrgbColourSystem& cs = srgb_colour_system();
    s.cmf.resize(kCieSamples * 3);
    s.illuminant.resize(kCieSamples);
    for (int i = 0; i < kCieSamples; ++i) {
      for (int c = 0; c < 3; ++c) s.cmf[i * 3 + c] = kCie1931Xyz[i][c];
      s.illuminant[i] = static_cast<Float>(kCieD65[i] * cs.d65_luminance_scale);
    }
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 3; ++c) s.rgb_from_xyz[c][r] = static_cast<Float>(cs.rgb_from_xyz[r][c]);  // glm: [column][row]
    s.inv_y_integral = static_cast<Float>(1.0 / cs.y_integral);
    return s;
  }();
  return t;
}

}  // namespace tessera

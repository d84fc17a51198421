// Build-time tool: fits the RGB-to-spectrum table (scene/rgb_spectrum_fit.h)
// and writes it as the binary the renderer embeds (scene/spectral_tables.cpp):
// "TSRGBSP1", int32 res, float scale[res], float coeffs[3][res][res][res][3].
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <thread>

#include "scene/rgb_spectrum_fit.h"

int main(int argc, char** argv) {
  if (argc != 3) {
    std::fprintf(stderr, "usage: %s <resolution> <output file>\n", argv[0]);
    return 2;
  }
  const int res = std::atoi(argv[1]);
  if (res < 4 || res > 256) {
    std::fprintf(stderr, "gen_rgb_spectrum_table: resolution %s out of range [4, 256]\n", argv[1]);
    return 2;
  }
  const tessera::RgbSpectrumTable t = tessera::build_rgb_spectrum_table(res, std::thread::hardware_concurrency());
  std::FILE* f = std::fopen(argv[2], "wb");
  if (!f) {
    std::fprintf(stderr, "gen_rgb_spectrum_table: cannot write %s\n", argv[2]);
    return 1;
  }
  const int32_t r = res;
  bool ok = std::fwrite("TSRGBSP1", 1, 8, f) == 8 && std::fwrite(&r, sizeof r, 1, f) == 1 &&
            std::fwrite(t.scale.data(), sizeof(float), t.scale.size(), f) == t.scale.size() &&
            std::fwrite(t.coeffs.data(), sizeof(float), t.coeffs.size(), f) == t.coeffs.size();
  ok = std::fclose(f) == 0 && ok;
  if (!ok) {
    std::fprintf(stderr, "gen_rgb_spectrum_table: writing %s failed\n", argv[2]);
    std::remove(argv[2]);
    return 1;
  }
  return 0;
}

// libFuzzer target over the NanoVDB reader (the "nanovdb" medium's .nvdb
// files): the bytes are written to a file and read as pbrt-v4 reads its
// density grid. A damaged file must end in a std::runtime_error naming it,
// or read into finite, non-negative values; a crash, a sanitizer report, a
// hang or runaway memory is a finding. scripts/fuzz.sh builds and runs it
// ("nanovdb" target); the suite replays tests/fuzz/nvdb_corpus through it.
#include <unistd.h>

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <fstream>
#include <stdexcept>
#include <string>

#include "scene/nanovdb_grid.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  static const std::string path = "/tmp/tessera_fuzz_nvdb_" + std::to_string(::getpid()) + ".nvdb";
  {
    std::ofstream f(path, std::ios::binary | std::ios::trunc);
    f.write(reinterpret_cast<const char*>(data), static_cast<std::streamsize>(size));
  }
  for (bool density : {true, false}) {
    try {
      const tessera::NanoVdbGrid g = tessera::read_nanovdb_grid(path, density ? "density" : "temperature", density);
      for (float v : g.lattice.values)  // the reader promises finite values (and non-negative densities)
        if (!std::isfinite(v) || (density && v < 0.f)) std::abort();
    } catch (const std::runtime_error&) {
      // A clear error is the right answer to a damaged file.
    }
  }
  return 0;
}

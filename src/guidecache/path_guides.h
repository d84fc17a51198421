// The one place that names every per-path guide: the guide a
// specialisation's paths run with (kernels/effects.h: kSpecGuiding,
// kSpecNeural). A new guide is a folder beside none/, table/ and neural/,
// its specialisation bit, and a line here.
#pragma once

#include "guidecache/neural/neural_path_guide.h"
#include "guidecache/none/no_path_guide.h"
#include "guidecache/table/table_path_guide.h"
#include "kernels/effects.h"

namespace tessera {

// table and neural: the views of the pass's guide (only the specialisation's
// own is read); first: the pixel's first-vertex site the CPU tile loop keeps
// for the network (null: none).
template <uint32_t Spec>
TESSERA_HOST_DEVICE inline auto make_path_guide(const GuideView& table, const NeuralGuideView& neural,
                                                NeuralFirstSite* first) {
  if constexpr ((Spec & kSpecGuiding) != 0 && (Spec & kSpecNeural) != 0)
    return NeuralPathGuide(neural, first);
  else if constexpr ((Spec & kSpecGuiding) != 0)
    return TablePathGuide(table);
  else
    return NoPathGuide{};
}

}  // namespace tessera

// The one place naming every guide's host-side types: what a pass's kernels
// read of a guide (its view) and what the stats report of it. A guide fills
// its own member and leaves the others empty, so that the Guide interface
// (guide.h) names none of them. A new guide adds a member to each (and a
// line to path_guides.h, which names the per-path guides).
#pragma once

#include "guidecache/neural/neural_guide.h"
#include "guidecache/table/guide_field.h"

namespace tessera {

struct GuideViews {
  GuideView table;
  NeuralGuideView neural;
};

struct GuideStats {
  GuideFieldStats table;
  NeuralGuideStats neural;
};

}  // namespace tessera

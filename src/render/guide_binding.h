// Points a pass's tile settings at a guide: the view its kernels read (the
// table's or the network's) and where the network's learning targets go.
#pragma once

#include "guidecache/guide_kinds.h"
#include "render/render_tile.h"

namespace tessera {

inline void bind_guide(Guide& guide, TileSettings* settings) {
  GuideViews v;
  guide.views(&v);
  settings->path.guide = v.table;
  settings->path.neural = v.neural;
  settings->neural_log = guide.training_log();
}

}  // namespace tessera

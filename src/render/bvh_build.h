// Builds the portable BVH (kernels/bvh.h) over a built scene's triangles on
// the host: binned SAH (Wald 2007), flattened depth first; two levels where
// the scene has instances (a tree per prototype, one over the world's
// triangles and the instances).
#pragma once

#include <vector>

#include "kernels/bvh.h"

namespace tessera {

struct BvhBuild {
  std::vector<BvhNode> nodes;
  std::vector<uint32_t> triangles;
  std::vector<uint32_t> prototype_roots;  // per prototype (kernels/instance.h)
  int depth = 0;  // of the deepest leaf (root = 0) of any one tree, below kBvhStackSize
  BvhView view() const {
    return BvhView{nodes.data(), triangles.data(), static_cast<uint32_t>(nodes.size()),
                   static_cast<uint32_t>(triangles.size()), prototype_roots.data(),
                   static_cast<uint32_t>(prototype_roots.size())};
  }
};

// Moving triangles are bounded over both time steps. Leaves hold at most
// kBvhMaxLeaf triangles, except where kBvhStackSize - 1 levels are used up.
constexpr int kBvhMaxLeaf = 4;
BvhBuild build_bvh(const SceneView& scene);

}  // namespace tessera

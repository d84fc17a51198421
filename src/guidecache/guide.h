// The host side of a guide, as the renderer, the farm, checkpoints and stats
// see it: the Q-table (guide_field.h) and the network (neural_guide.h) are
// its two implementations. Per pass: the views the kernels read (and learn
// into), then the learning combined in rounds. A round's accumulators are
// 64-bit integers that a farm sums across ranks (integer sums do not depend
// on which rank rendered what) before every rank folds the same sums in:
// the table has one round (its visit and value sums); the network has a
// round of target statistics and then one per optimiser step (fixed-point
// gradients). No MPI here.
#pragma once

#include <cstdint>
#include <iosfwd>
#include <memory>
#include <string>
#include <vector>

#include "guidecache/table/guide_view.h"
#include "guidecache/neural/neural_view.h"

namespace tessera {

struct GuideViews;  // guide_kinds.h
struct GuideStats;
class NeuralTrainingLog;

class Guide {
 public:
  virtual ~Guide() = default;
  // What stats and logs call it: qtable, qlearning or neural.
  virtual std::string mode() const = 0;
  // Specialisation bits a guided pass adds (kSpecGuiding, and kSpecNeural).
  virtual uint32_t spec_bits() const = 0;
  // The read side for a pass (valid until the next fold): fills the view the
  // kernels use and leaves the others empty.
  virtual void views(GuideViews* out) = 0;
  // Where the CPU backends put the pass's learning targets (network only:
  // the table's go to the accumulators in its view).
  virtual NeuralTrainingLog* training_log() { return nullptr; }

  // Between passes: for each round r < rounds(), round_accumulators(r) is
  // summed across ranks (a single process: as it is), then fold_round(r).
  virtual uint32_t rounds() const = 0;
  // The most rounds a pass can take (a farm keeps a copy of the guide as the
  // pass began while later rounds may still need it: master/stand_in.h).
  virtual uint32_t max_rounds() const { return 1; }
  virtual std::vector<uint64_t>& round_accumulators(uint32_t round) = 0;
  virtual void fold_round(uint32_t round) = 0;

  // Whether passes that learn from every sample should be one sample per
  // pixel each. The network's targets bootstrap from the network as it
  // stood at the start of the pass, so what it learns converges per pass
  // (a fixed number of light bounces deeper each time), not per sample.
  virtual bool single_sample_learning_passes() const { return false; }
  // A fixed mixture weight of guided sampling (--guide-mix).
  virtual void set_guide_prob(Float p) = 0;
  // Versioned binary serialisation tied to a scene fingerprint.
  virtual void save(std::ostream& out, uint64_t scene_fingerprint) const = 0;
  // Its own member of *out; the others empty.
  virtual void fill_stats(GuideStats* out) const = 0;
  // Same kind and same state, bit for bit.
  virtual bool same_as(const Guide& other) const = 0;
};

// A pass's learning, every round: reduce(accumulators) sums them across
// ranks (or does nothing on one process), then the round is folded in.
// rounds() is read again after each fold (a pass without targets has
// nothing to train on); it is the same on every rank, as it follows the
// summed round 0. The farm's master and workers both run this loop.
template <class Reduce>
void combine_guide_rounds(Guide& guide, Reduce&& reduce) {
  for (uint32_t r = 0; r < guide.rounds(); ++r) {
    reduce(guide.round_accumulators(r));
    guide.fold_round(r);
  }
}

// Loads what Guide::save wrote, whichever kind (told by its header).
// Throws std::runtime_error when the stream is no guide, has another
// version, or was learned on another scene.
std::unique_ptr<Guide> load_guide(std::istream& in, uint64_t scene_fingerprint);

}  // namespace tessera

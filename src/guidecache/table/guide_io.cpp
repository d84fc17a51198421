// Serialisation of the guide cache with cereal (portable binary: the same
// bytes on every little- or big-endian machine).
#include <cereal/archives/portable_binary.hpp>
#include <cereal/types/vector.hpp>
#include <cstring>
#include <istream>
#include <new>
#include <ostream>
#include <stdexcept>
#include <string>

#include "guidecache/table/guide_field.h"

namespace glm {
template <class Archive>
void serialize(Archive& ar, glm::vec3& v) {
  ar(v.x, v.y, v.z);
}
}  // namespace glm

namespace tessera {

template <class Archive>
void serialize(Archive& ar, GuideNode& n) {
  ar(n.child, n.cell);
}

template <class Archive>
void serialize(Archive& ar, GuideConfig& c) {
  uint32_t target = static_cast<uint32_t>(c.target);
  ar(c.grid, c.budget_bytes, c.split_updates, c.max_depth, c.guide_prob, c.light_guide_prob, c.floor, target,
     c.max_learned_lights, c.nee_gain, c.nee_min_prob, c.learn_mix);
  c.target = static_cast<GuideTarget>(target);
}

template <class Archive>
void serialize(Archive& ar, GuideFieldStats& s) {
  ar(s.updates, s.rejected_nonfinite, s.rejected_large, s.splits, s.budget_reached, s.mix_out_of_range);
}

template <class Archive>
void GuideField::serialize(Archive& ar) {
  ar(config_, lo_, extent_, bins_, lights_, fixed_scale_, max_target_, nodes_, node_depth_, value_, visits_,
     normal_sum_, cell_updates_, totals_);
}

namespace {
constexpr char kMagic[] = "tessera-guide-cache";
constexpr uint32_t kVersion = 4;  // 2: next-event statistics per cell; 3: mixture statistics; 4: six mixture candidates
}  // namespace

void GuideField::save(std::ostream& out, uint64_t scene_fingerprint) const {
  out.write(kMagic, sizeof kMagic);
  cereal::PortableBinaryOutputArchive ar(out);
  ar(kVersion, scene_fingerprint);
  const_cast<GuideField*>(this)->serialize(ar);
  if (!out) throw std::runtime_error("write failed");
}

GuideField GuideField::load(std::istream& in, uint64_t scene_fingerprint) {
  GuideField f;
  char magic[sizeof kMagic] = {};
  if (!in.read(magic, sizeof magic) || std::memcmp(magic, kMagic, sizeof kMagic) != 0)
    throw std::runtime_error("not a Tessera guide cache");
  try {
    cereal::PortableBinaryInputArchive ar(in);
    uint32_t version = 0;
    uint64_t fingerprint = 0;
    ar(version, fingerprint);
    if (version != kVersion)
      throw std::runtime_error("guide cache version " + std::to_string(version) + ", this build reads version " +
                               std::to_string(kVersion));
    if (fingerprint != scene_fingerprint) throw std::runtime_error("guide cache was learned on another scene");
    f.serialize(ar);
  } catch (const cereal::Exception& e) {
    throw std::runtime_error(std::string("corrupt or truncated guide cache (") + e.what() + ")");
  } catch (const std::bad_alloc&) {
    throw std::runtime_error("corrupt guide cache (absurd array sizes)");
  } catch (const std::length_error&) {
    throw std::runtime_error("corrupt guide cache (absurd array sizes)");
  }
  // Structural checks: a damaged file must not index out of bounds later.
  const size_t cells = f.cell_updates_.size();
  bool ok = f.config_.grid >= 2 && f.config_.grid <= 64 && f.bins_ == f.config_.grid * f.config_.grid &&
            f.nodes_.size() >= kGuideNormalClasses && f.node_depth_.size() == f.nodes_.size() &&
            f.value_.size() == cells * f.stride() && f.visits_.size() == f.value_.size() &&
            f.normal_sum_.size() == 3 * cells;
  for (size_t i = 0; ok && i < f.nodes_.size(); ++i) {
    const GuideNode& n = f.nodes_[i];
    ok = n.child >= 0 ? size_t(n.child) + 8 <= f.nodes_.size() && size_t(n.child) > i
                      : n.cell >= 0 && size_t(n.cell) < cells;
  }
  if (!ok) throw std::runtime_error("corrupt guide cache (inconsistent sizes)");
  f.build_bin_dirs();
  f.build_distributions();
  f.resize_accumulators();
  return f;
}

}  // namespace tessera

// Serialisation of the guide cache with cereal (portable binary: the same
// bytes on every little- or big-endian machine), and the checks a loaded
// cache passes before anything reads it.
#include <cereal/archives/portable_binary.hpp>
#include <cereal/types/vector.hpp>
#include <cfloat>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <istream>
#include <new>
#include <ostream>
#include <sstream>
#include <stdexcept>
#include <string>

#include "guidecache/guide_file.h"
#include "guidecache/table/guide_field.h"

namespace glm {
template <class Archive>
void serialize(Archive& ar, glm::vec3& v) {
  ar(v.x, v.y, v.z);
}
}  // namespace glm

namespace tessera {
namespace {

// A bool as the byte cereal writes for it; on loading, a byte other than 0
// or 1 is refused (reading it into a bool would be undefined).
bool load_flag(uint8_t byte, const char* name) {
  if (byte > 1) throw std::runtime_error(std::string("corrupt guide cache (") + name + " is " + std::to_string(byte) + ", not 0 or 1)");
  return byte == 1;
}

}  // namespace

template <class Archive>
void serialize(Archive& ar, GuideConfig& c) {
  uint32_t target = static_cast<uint32_t>(c.target);
  uint8_t learn_mix = c.learn_mix ? 1 : 0;
  ar(c.grid, c.budget_bytes, c.split_updates, c.max_depth, c.guide_prob, c.light_guide_prob, c.floor, target,
     c.max_learned_lights, c.nee_gain, c.nee_min_prob, learn_mix);
  c.target = static_cast<GuideTarget>(target);
  c.learn_mix = load_flag(learn_mix, "the mixture-learning flag");
}

template <class Archive>
void serialize(Archive& ar, GuideFieldStats& s) {
  uint8_t budget_reached = s.budget_reached ? 1 : 0;
  ar(s.updates, s.rejected_nonfinite, s.rejected_large, s.splits, budget_reached, s.mix_out_of_range);
  s.budget_reached = load_flag(budget_reached, "the budget-reached flag");
}

template <class Archive>
void serialize(Archive& ar, GuideNode& n) {
  ar(n.child, n.cell);
}

template <class Archive>
void GuideField::serialize(Archive& ar) {
  ar(config_, lo_, extent_, bins_, lights_, fixed_scale_, max_target_, nodes_, node_depth_, value_, visits_,
     normal_sum_, cell_updates_, totals_);
}

namespace {
constexpr char kMagic[] = "tessera-guide-cache";
// 2: next-event statistics per cell; 3: mixture statistics; 4: six mixture
// candidates; 5: the payload's size and checksum ahead of it (guide_file.h),
// the fingerprint inside it. Version 4's fields are version 5's: a version 4
// file is read with every range check, without a checksum (it has none), so
// caches and checkpoints saved before still load.
constexpr uint32_t kVersion = 5;
constexpr uint32_t kUncheckedVersion = 4;

template <class Archive>
void read_fingerprint(Archive& ar, uint64_t scene_fingerprint) {
  uint64_t fingerprint = 0;
  ar(fingerprint);
  if (fingerprint != scene_fingerprint) throw std::runtime_error("guide cache was learned on another scene");
}

}  // namespace

void GuideField::save(std::ostream& out, uint64_t scene_fingerprint) const {
  std::ostringstream body(std::ios::binary);
  {
    cereal::PortableBinaryOutputArchive ar(body);
    ar(scene_fingerprint);
    const_cast<GuideField*>(this)->serialize(ar);
  }
  const std::string payload = body.str();
  out.write(kMagic, sizeof kMagic);
  cereal::PortableBinaryOutputArchive ar(out);
  ar(kVersion, static_cast<uint64_t>(payload.size()), guide_payload_checksum(payload));
  out.write(payload.data(), static_cast<std::streamsize>(payload.size()));
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
    ar(version);
    if (version == kVersion) {
      uint64_t size = 0, checksum = 0;
      ar(size, checksum);
      std::istringstream payload(read_guide_payload(in, size, checksum, "guide cache"), std::ios::binary);
      cereal::PortableBinaryInputArchive body(payload);
      read_fingerprint(body, scene_fingerprint);
      f.serialize(body);
      if (payload.peek() != std::istream::traits_type::eof())
        throw std::runtime_error("corrupt guide cache (bytes after its fields)");
    } else if (version == kUncheckedVersion) {
      read_fingerprint(ar, scene_fingerprint);
      f.serialize(ar);
    } else {
      throw std::runtime_error("guide cache version " + std::to_string(version) + ", this build reads versions " +
                               std::to_string(kUncheckedVersion) + " and " + std::to_string(kVersion));
    }
  } catch (const cereal::Exception& e) {
    throw std::runtime_error(std::string("corrupt or truncated guide cache (") + e.what() + ")");
  } catch (const std::bad_alloc&) {
    throw std::runtime_error("corrupt guide cache (absurd array sizes)");
  } catch (const std::length_error&) {
    throw std::runtime_error("corrupt guide cache (absurd array sizes)");
  }
  // A damaged file must not index out of bounds later, nor bias a render
  // with a value or a probability no learning could have made.
  for (std::string problem : {f.settings_problem(), f.tree_problem(), f.values_problem()})
    if (!problem.empty()) throw std::runtime_error("corrupt guide cache (" + problem + ")");
  f.build_bin_dirs();
  f.build_distributions();
  f.resize_accumulators();
  if (const std::string problem = f.distributions_problem(); !problem.empty())
    throw std::runtime_error("corrupt guide cache (" + problem + ")");
  return f;
}

namespace {

std::string show(double v) {
  char b[32];
  std::snprintf(b, sizeof b, "%g", v);
  return b;
}

// "" when p is a probability, else what is wrong with it.
std::string probability_problem(const char* name, Float p) {
  if (std::isfinite(p) && p >= 0.f && p <= 1.f) return "";
  return std::string(name) + " is " + show(p) + ", not in [0, 1]";
}

// The constructor sets both from the brightest emitter r: scale 2^24 / r,
// largest target 2^20 r (either may overflow a float where r is extreme).
bool fixed_point_consistent(Float scale, Float max_target) {
  constexpr double kProduct = 17592186044416.0;  // 2^44
  constexpr double kSlack = 1.0 + 1e-5;           // the division's rounding
  if (!(scale > 0.f) || !(max_target > 0.f) || (std::isinf(scale) && std::isinf(max_target))) return false;
  if (std::isinf(max_target)) return static_cast<double>(scale) * FLT_MAX < kProduct * kSlack;
  if (std::isinf(scale)) return static_cast<double>(max_target) * FLT_MAX < kProduct * kSlack;
  const double product = static_cast<double>(scale) * static_cast<double>(max_target);
  return product < kProduct * kSlack && product > kProduct / kSlack;
}

}  // namespace

std::string GuideField::settings_problem() const {
  const GuideConfig& c = config_;
  if (c.grid < 2 || c.grid > 64) return "direction grid " + std::to_string(c.grid) + ", not 2 to 64";
  if (bins_ != c.grid * c.grid) return std::to_string(bins_) + " direction bins for a grid of " + std::to_string(c.grid);
  if (c.budget_bytes < 1 || c.budget_bytes > (1ull << 40)) return "memory budget of " + std::to_string(c.budget_bytes) + " bytes";
  if (c.split_updates > (1ull << 40)) return "split threshold " + std::to_string(c.split_updates);
  if (c.max_depth > 255) return "octree depth limit " + std::to_string(c.max_depth) + ", over 255";
  for (const auto& [name, p] : {std::pair{"the guide probability", c.guide_prob},
                                std::pair{"the learned-light probability", c.light_guide_prob},
                                std::pair{"the floor", c.floor}, std::pair{"the least next-event probability", c.nee_min_prob}})
    if (std::string problem = probability_problem(name, p); !problem.empty()) return problem;
  if (!std::isfinite(c.nee_gain) || c.nee_gain < 0.f) return "next-event gain " + show(c.nee_gain);
  if (static_cast<uint32_t>(c.target) > 1) return "learning rule " + std::to_string(static_cast<uint32_t>(c.target));
  if (c.max_learned_lights > (1u << 20) || lights_ > c.max_learned_lights || lights_ == 1 || lights_ == 2)
    return std::to_string(lights_) + " learned lights (at most " + std::to_string(c.max_learned_lights) + ")";
  if (!std::isfinite(lo_.x) || !std::isfinite(lo_.y) || !std::isfinite(lo_.z) || !std::isfinite(extent_) ||
      !(extent_ > 0.f) || !std::isfinite(lo_.x + extent_) || !std::isfinite(lo_.y + extent_) || !std::isfinite(lo_.z + extent_))
    return "bounds (" + show(lo_.x) + ", " + show(lo_.y) + ", " + show(lo_.z) + ") size " + show(extent_);
  if (!fixed_point_consistent(fixed_scale_, max_target_))
    return "fixed-point scale " + show(fixed_scale_) + " and largest target " + show(max_target_) + " disagree";
  return "";
}

// The octrees as fold() grows them: six roots, each inner node with eight
// children of its own one level deeper, each cell owned by one leaf, and
// one split counted per inner node.
std::string GuideField::tree_problem() const {
  const size_t cells = cell_updates_.size(), nodes = nodes_.size();
  if (nodes < kGuideNormalClasses || node_depth_.size() != nodes) return "node counts";
  if (value_.size() != cells * stride() || visits_.size() != value_.size() || normal_sum_.size() != 3 * cells)
    return "array sizes do not match " + std::to_string(cells) + " cells";
  std::vector<uint8_t> has_parent(nodes, 0), has_leaf(cells, 0);
  uint64_t inner = 0;
  for (size_t i = 0; i < nodes; ++i) {
    const GuideNode& n = nodes_[i];
    if (i < kGuideNormalClasses && node_depth_[i] != 0) return "root " + std::to_string(i) + " at depth " + std::to_string(node_depth_[i]);
    if (i >= kGuideNormalClasses && !has_parent[i]) return "node " + std::to_string(i) + " has no parent";
    if (n.child < 0) {
      if (n.child != -1 || n.cell < 0 || size_t(n.cell) >= cells || has_leaf[size_t(n.cell)])
        return "leaf " + std::to_string(i) + " and its cell " + std::to_string(n.cell);
      has_leaf[size_t(n.cell)] = 1;
      continue;
    }
    if (n.cell != -1 || size_t(n.child) <= i || size_t(n.child) + 8 > nodes || node_depth_[i] >= config_.max_depth)
      return "inner node " + std::to_string(i) + " and its children at " + std::to_string(n.child);
    for (size_t k = size_t(n.child); k < size_t(n.child) + 8; ++k) {
      if (has_parent[k] || node_depth_[k] != node_depth_[i] + 1) return "node " + std::to_string(k) + "'s parent or depth";
      has_parent[k] = 1;
    }
    ++inner;
  }
  if (cells != kGuideNormalClasses + 7 * inner) return std::to_string(cells) + " cells for " + std::to_string(nodes) + " nodes";
  if (totals_.splits != inner)
    return std::to_string(totals_.splits) + " splits counted for " + std::to_string(inner) + " made";
  return "";
}

// Every value is a mean of non-negative, finite targets.
std::string GuideField::values_problem() const {
  for (size_t i = 0; i < value_.size(); ++i)
    if (!std::isfinite(value_[i]) || value_[i] < 0.f)
      return "cell " + std::to_string(i / stride()) + ", entry " + std::to_string(i % stride()) + ": value " + show(value_[i]);
  return "";
}

// Finite values can still sum past a float's range.
std::string GuideField::distributions_problem() const {
  for (size_t c = 0; c < irradiance_.size(); ++c)
    if (!std::isfinite(irradiance_[c]) || !std::isfinite(nee_prob_[c]) || !std::isfinite(cell_mix_[c]))
      return "cell " + std::to_string(c) + ": its values sum past a float's range";
  return "";
}

}  // namespace tessera

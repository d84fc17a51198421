// Serialisation of the neural guide with cereal (portable binary), and the
// one loader for either kind of guide (told by the file's magic).
#include <cereal/archives/portable_binary.hpp>
#include <cereal/types/vector.hpp>
#include <cmath>
#include <cstring>
#include <istream>
#include <new>
#include <ostream>
#include <stdexcept>
#include <sstream>
#include <string>

#include "guidecache/guide_file.h"
#include "guidecache/table/guide_field.h"
#include "guidecache/neural/neural_guide.h"

namespace tessera {

template <class Archive>
void serialize(Archive& ar, NeuralGuideConfig& c) {
  ar(c.width, c.steps_per_pass, c.learning_rate, c.guide_prob, c.floor, c.tile_targets, c.table_log2, c.seed);
}

template <class Archive>
void NeuralGuide::serialize(Archive& ar) {
  ar(config_, lights_, lo_.x, lo_.y, lo_.z, extent_, radiance_scale_, max_target_, scale_, params_, adam_m_, adam_v_, steps_);
  ar(totals_.targets, totals_.rejected_nonfinite, totals_.rejected_large, totals_.dropped, totals_.gradient_clamped,
     totals_.nonfinite_gradients, totals_.loss, totals_.pass_loss);
}

namespace {
constexpr char kNeuralMagic[] = "tessera-neural-guide";
constexpr char kTableMagic[] = "tessera-guide-cache";
// 2: the hash table's size is a setting; 3: learned light selection; 4: bins
// numbered by tiles (version 3's, numbered row-major, are read and
// renumbered); 5: the learned mixture weight (versions 3 and 4 are read
// with none chosen yet, learning it); 6: the payload's size and checksum
// ahead of it (guide_file.h), the fingerprint and version 5's fields inside
// it. Versions 3 to 5 are read with every range check, without a checksum.
constexpr uint32_t kNeuralVersion = 6;
constexpr uint32_t kNeuralUncheckedVersion = 5;
constexpr uint32_t kNeuralRowMajorVersion = 3;
}  // namespace

void NeuralGuide::save(std::ostream& out, uint64_t scene_fingerprint) const {
  std::ostringstream body(std::ios::binary);
  {
    cereal::PortableBinaryOutputArchive ar(body);
    ar(scene_fingerprint);
    const_cast<NeuralGuide*>(this)->serialize(ar);
    // Version 5's fields, after version 4's.
    const uint8_t learn_mix = config_.learn_mix ? 1 : 0;
    ar(learn_mix, mix_candidate_, totals_.mix_vertices, totals_.mix_rejected);
  }
  const std::string payload = body.str();
  out.write(kNeuralMagic, sizeof kNeuralMagic);
  cereal::PortableBinaryOutputArchive ar(out);
  ar(kNeuralVersion, static_cast<uint64_t>(payload.size()), guide_payload_checksum(payload));
  out.write(payload.data(), static_cast<std::streamsize>(payload.size()));
  if (!out) throw std::runtime_error("write failed");
}

// The fingerprint and the fields (of `version`'s layout) from `ar`.
template <class Archive>
void NeuralGuide::read_fields(Archive& ar, uint32_t version, uint64_t scene_fingerprint) {
  uint64_t fingerprint = 0;
  ar(fingerprint);
  if (fingerprint != scene_fingerprint) throw std::runtime_error("neural guide was learned on another scene");
  serialize(ar);
  if (version >= 5) {
    uint8_t learn_mix = 0;
    ar(learn_mix, mix_candidate_, totals_.mix_vertices, totals_.mix_rejected);
    if (learn_mix > 1) throw std::runtime_error("corrupt neural guide (mixture setting)");
    config_.learn_mix = learn_mix == 1;
  }
}

std::unique_ptr<NeuralGuide> NeuralGuide::load(std::istream& in, uint64_t scene_fingerprint) {
  auto g = std::make_unique<NeuralGuide>();
  char magic[sizeof kNeuralMagic] = {};
  if (!in.read(magic, sizeof magic) || std::memcmp(magic, kNeuralMagic, sizeof kNeuralMagic) != 0)
    throw std::runtime_error("not a Tessera neural guide");
  uint32_t version = 0;
  try {
    cereal::PortableBinaryInputArchive ar(in);
    ar(version);
    if (version < kNeuralRowMajorVersion || version > kNeuralVersion)
      throw std::runtime_error("neural guide version " + std::to_string(version) + ", this build reads versions " +
                               std::to_string(kNeuralRowMajorVersion) + " to " + std::to_string(kNeuralVersion));
    if (version > kNeuralUncheckedVersion) {
      uint64_t size = 0, checksum = 0;
      ar(size, checksum);
      std::istringstream payload(read_guide_payload(in, size, checksum, "neural guide"), std::ios::binary);
      cereal::PortableBinaryInputArchive body(payload);
      g->read_fields(body, version, scene_fingerprint);
      if (payload.peek() != std::istream::traits_type::eof())
        throw std::runtime_error("corrupt neural guide (bytes after its fields)");
    } else {
      g->read_fields(ar, version, scene_fingerprint);
    }
  } catch (const cereal::Exception& e) {
    throw std::runtime_error(std::string("corrupt or truncated neural guide (") + e.what() + ")");
  } catch (const std::bad_alloc&) {
    throw std::runtime_error("corrupt neural guide (absurd array sizes)");
  } catch (const std::length_error&) {
    throw std::runtime_error("corrupt neural guide (absurd array sizes)");
  }
  // Every field a later pass relies on: a damaged file is refused here, never rendered with.
  const NeuralGuideConfig& c = g->config_;
  if (c.table_log2 < kNeuralMinTableLog2 || c.table_log2 > kNeuralMaxTableLog2)
    throw std::runtime_error("corrupt neural guide (hash table size out of range)");
  if (g->lights_ != 0 && (g->lights_ < kNeuralMinLights || g->lights_ > kNeuralMaxLights))
    throw std::runtime_error("corrupt neural guide (light count out of range)");
  const NeuralLayout L = g->layout();
  auto finite_in = [](float x, float lo, float hi) { return std::isfinite(x) && x >= lo && x <= hi; };
  bool ok = c.width >= 1 && c.width <= kNeuralMaxWidth && c.steps_per_pass >= 1 && c.steps_per_pass <= 1024 &&
            c.tile_targets >= 1 && c.tile_targets <= (1u << 20) && finite_in(c.learning_rate, 1e-9f, 1.f) &&
            finite_in(c.guide_prob, 0.f, 1.f) && finite_in(c.floor, 0.f, 1.f) && g->params_.size() == L.size() &&
            g->adam_m_.size() == L.size() && g->adam_v_.size() == L.size() && finite_in(g->extent_, 1e-30f, 3e38f) &&
            finite_in(g->radiance_scale_, 1e-30f, 3e38f) && finite_in(g->max_target_, 1e-30f, 3.4e38f) &&
            finite_in(g->scale_, 0.f, 3e38f) && std::isfinite(g->lo_.x) && std::isfinite(g->lo_.y) &&
            std::isfinite(g->lo_.z) && (g->mix_candidate_ == -1 || (g->mix_candidate_ >= static_cast<int32_t>(kNeuralMixFirstCandidate) &&
                                        g->mix_candidate_ < static_cast<int32_t>(kNeuralMixFirstCandidate + kNeuralMixCandidates)));
  for (size_t i = 0; ok && i < L.size(); ++i)
    ok = std::isfinite(g->params_[i]) && std::isfinite(g->adam_m_[i]) && std::isfinite(g->adam_v_[i]) && g->adam_v_[i] >= 0.f;
  if (!ok) throw std::runtime_error("corrupt neural guide (inconsistent or non-finite fields)");
  // A file that numbered the bins row-major: each bin's output (its weights,
  // bias and both Adam moments) moves to the bin's number in tiles.
  if (version == kNeuralRowMajorVersion) {
    const uint32_t outs = L.outputs();
    for (std::vector<float>* a : {&g->params_, &g->adam_m_, &g->adam_v_}) {
      const std::vector<float> row_major = *a;
      for (uint32_t j = 0; j < kNeuralBins; ++j) {
        const uint32_t to = neural_bin_at(j / kNeuralGrid, j % kNeuralGrid);
        for (uint32_t i = 0; i < c.width; ++i) (*a)[L.w3() + i * outs + to] = row_major[L.w3() + i * outs + j];
        (*a)[L.b3() + to] = row_major[L.b3() + j];
      }
    }
  }
  g->build_bin_dirs();
  return g;
}

std::unique_ptr<Guide> load_guide(std::istream& in, uint64_t scene_fingerprint) {
  char magic[sizeof kNeuralMagic] = {};
  const std::streampos start = in.tellg();
  in.read(magic, sizeof magic);
  in.clear();
  in.seekg(start);
  if (std::memcmp(magic, kNeuralMagic, sizeof kNeuralMagic) == 0) return NeuralGuide::load(in, scene_fingerprint);
  if (std::memcmp(magic, kTableMagic, sizeof kTableMagic) != 0) throw std::runtime_error("not a Tessera guide cache or neural guide");
  return std::make_unique<GuideField>(GuideField::load(in, scene_fingerprint));
}

}  // namespace tessera

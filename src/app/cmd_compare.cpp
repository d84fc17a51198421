// tessera compare IMAGE.exr REFERENCE.exr [--json] [--block B]
#include <cstdio>
#include <filesystem>

#include <nlohmann/json.hpp>

#include "app/commands.h"
#include "render/error_estimate.h"
#include "render/image_metrics.h"
#include "render/image_output.h"
#include "scene/image_io.h"

namespace tessera {
namespace {

// relMSE an EXR's own variance layer predicts for it (< 0: no variance layer).
double own_estimate(const std::string& path, const ImageRgb& mean) {
  if (std::filesystem::path(path).extension() != ".exr") return -1.0;
  // Below kMinSppForErrorEstimate the variance layer holds zeros or noise, not an estimate.
  const std::optional<double> spp = read_exr_number(path, "spp");
  if (spp && *spp < static_cast<double>(kMinSppForErrorEstimate)) return -1.0;
  std::optional<ImageRgb> var = read_exr_variance(path);
  if (!var) return -1.0;
  try {
    ErrorEstimate e = estimate_rel_mse(mean, *var);
    if (e.unusable_pixels > 0)
      std::fprintf(stderr, "tessera: %s: no error estimate: %llu of %llu pixels have a mean that is not finite or a variance that is negative, saturated or not finite\n",
                   path.c_str(), static_cast<unsigned long long>(e.unusable_pixels),
                   static_cast<unsigned long long>(static_cast<uint64_t>(mean.width) * mean.height));
    return e.valid ? e.rel_mse : -1.0;
  } catch (const std::invalid_argument& ex) {
    throw std::runtime_error(path + ": " + ex.what());
  }
}

int run_compare(const std::string& image, const std::string& reference, bool json, int32_t block) {
  ImageRgb a = to_image_rgb(load_image(image)), f = to_image_rgb(load_image(reference));
  ImageErrors e;
  BlockAgreement b;
  try {
    e = compare_images(a, f);
    b = compare_blocks(a, f, block);
  } catch (const std::invalid_argument& ex) {
    throw std::runtime_error(image + " vs " + reference + ": " + ex.what());
  }
  // From the variance layers: the error the image expects of itself, and the
  // reference's own noise, which the measured relMSE includes (about additively).
  const double image_est = own_estimate(image, a), reference_est = own_estimate(reference, f);
  if (json) {
    // nlohmann-json writes a number that is not finite as null; a worst
    // block ratio of null says no block was bright enough to judge.
    nlohmann::ordered_json j;
    j["relmse"] = e.rel_mse;
    j["mape"] = e.mape;
    j["rmse"] = e.rmse;
    j["estimated_relmse"] = image_est;
    j["reference_estimated_relmse"] = reference_est;
    j["nonfinite_pixels"] = e.nonfinite_pixels;
    j["reference_nonfinite_pixels"] = e.reference_nonfinite_pixels;
    j["pixels"] = e.pixels;
    j["mean_rgb"] = {e.mean_image[0], e.mean_image[1], e.mean_image[2]};
    j["reference_mean_rgb"] = {e.mean_reference[0], e.mean_reference[1], e.mean_reference[2]};
    j["block"] = b.block;
    j["blocks_judged"] = b.judged_blocks;
    j["worst_block_ratio"] = b.judged_blocks > 0 ? nlohmann::ordered_json(b.worst_ratio) : nlohmann::ordered_json();
    j["worst_block_x"] = b.worst_x;
    j["worst_block_y"] = b.worst_y;
    j["blocks_off_fraction"] = b.fraction_off;
    std::printf("%s\n", j.dump().c_str());
  } else {
    std::printf("relMSE:           %.6g\n", e.rel_mse);
    std::printf("MAPE:             %.6g\n", e.mape);
    std::printf("RMSE:             %.6g\n", e.rmse);
    if (image_est >= 0) std::printf("relMSE estimated: %.6g (from the image's variance layer)\n", image_est);
    if (reference_est >= 0) std::printf("reference noise:  %.6g (relMSE its variance layer predicts; part of the relMSE above)\n", reference_est);
    std::printf("mean RGB:         %.5g %.5g %.5g (reference %.5g %.5g %.5g)\n", e.mean_image[0], e.mean_image[1],
                e.mean_image[2], e.mean_reference[0], e.mean_reference[1], e.mean_reference[2]);
    std::printf("NaN/Inf pixels:   %llu (reference: %llu) of %llu\n", static_cast<unsigned long long>(e.nonfinite_pixels),
                static_cast<unsigned long long>(e.reference_nonfinite_pixels), static_cast<unsigned long long>(e.pixels));
    if (b.judged_blocks == 0) {
      std::printf("%dx%d blocks:       none bright enough to judge\n", b.block, b.block);
    } else {
      std::printf("worst %dx%d block:  %.4g (image/reference luminance) at block (%d, %d), pixels (%d, %d)\n", b.block,
                  b.block, b.worst_ratio, b.worst_x, b.worst_y, b.worst_x * b.block, b.worst_y * b.block);
      std::printf("blocks off >%g%%:  %.4g%% of %llu judged (%dx%d blocks)\n", 100 * kBlockTolerance,
                  100 * b.fraction_off, static_cast<unsigned long long>(b.judged_blocks), b.blocks_x, b.blocks_y);
    }
  }
  return 0;
}

}  // namespace

CommandRunner add_compare_command(CLI::App& app) {
  struct Args {
    std::string image, reference;
    bool json = false;
    int32_t block = kDefaultBlockSize;
  };
  auto a = std::make_shared<Args>();
  CLI::App* c = app.add_subcommand("compare", "Error metrics of an image against a reference (relMSE, MAPE, RMSE, NaN/Inf, block agreement)");
  c->add_option("image", a->image, "Image to judge (EXR)")->required()->check(CLI::ExistingFile);
  c->add_option("reference", a->reference, "Reference image (EXR)")->required()->check(CLI::ExistingFile);
  c->add_flag("--json", a->json, "Machine-readable output");
  c->add_option("--block", a->block,
                "Block side in pixels for block agreement: the worst ratio of block mean luminances and the share of "
                "blocks off by more than 10 %")
      ->check(CLI::Range(1, 1 << 20));
  return [a] { return run_compare(a->image, a->reference, a->json, a->block); };
}

}  // namespace tessera

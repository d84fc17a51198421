#include "render/snapshots.h"

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <stdexcept>

#include "render/output_file.h"
#include "render/renderer.h"

namespace tessera {

SnapshotPolicy parse_snapshot_policy(const std::string& text) {
  SnapshotPolicy p;
  if (text == "doubling") {
    p.doubling = true;
    return p;
  }
  size_t used = 0;
  double s = 0.0;
  try {
    s = std::stod(text, &used);
  } catch (const std::exception&) {
    used = 0;
  }
  if (used != text.size() || !(s > 0) || !std::isfinite(s))
    throw std::runtime_error("--snapshot-every: expected a positive number of seconds or 'doubling', got '" + text + "'");
  p.every_s = s;
  return p;
}

SnapshotWriter::SnapshotWriter(SnapshotPolicy policy, const std::string& output_exr, ExrMetadata base, bool resumed)
    : policy_(policy), base_(std::move(base)) {
  const std::filesystem::path out(output_exr);
  stem_ = out.stem().string();
  dir_ = (out.parent_path() / (stem_ + "-snapshots")).string();
  if (resumed) return;
  // Only files this writer makes: <stem>-NNNNNNspp.exr and snapshots.csv.
  std::error_code ec;
  for (const auto& entry : std::filesystem::directory_iterator(dir_, ec)) {
    const std::string name = entry.path().filename().string();
    const bool ours = name == "snapshots.csv" ||
                      (name.rfind(stem_ + "-", 0) == 0 && name.size() > 7 && name.substr(name.size() - 7) == "spp.exr");
    if (ours) std::filesystem::remove(entry.path(), ec);
  }
}

void SnapshotWriter::on_pass_end(const RenderResult& so_far) {
  const RenderStats& s = so_far.stats;
  bool due = false;
  if (policy_.every_s > 0 && s.seconds - last_s_ >= policy_.every_s) due = true;
  if (policy_.doubling && s.spp >= next_spp_) due = true;
  if (!due) return;
  last_s_ = s.seconds;
  while (next_spp_ <= s.spp) next_spp_ *= 2;

  std::error_code ec;
  std::filesystem::create_directories(dir_, ec);
  if (ec) throw std::runtime_error("--snapshot-every: cannot create " + dir_ + ": " + ec.message());
  char name[64];
  std::snprintf(name, sizeof name, "-%06uspp.exr", s.spp);
  SnapshotRecord r;
  r.file = (std::filesystem::path(dir_) / (stem_ + name)).string();
  r.spp = s.spp;
  r.seconds = s.seconds;
  r.render_seconds = s.seconds - s.pass_end_seconds;
  r.estimated_rel_mse = s.estimated_rel_mse;

  ExrMetadata meta = base_;
  add_render_metadata(&meta, s);
  meta.numbers["render_seconds"] = r.render_seconds;
  const ImageRgb mean = film_mean(so_far.film), var = film_variance_of_mean(so_far.film);
  add_variance_metadata(&meta, var);
  write_output(r.file, [&](const std::string& p) { write_exr(p, mean, &var, meta); });

  const std::string csv = (std::filesystem::path(dir_) / "snapshots.csv").string();
  const bool fresh = !std::filesystem::exists(csv);
  std::ofstream f(csv, std::ios::app);
  if (fresh) f << "file,spp,seconds,render_seconds,estimated_relmse\n";
  char line[512];
  std::snprintf(line, sizeof line, "%s,%u,%.6f,%.6f,%.9g\n", std::filesystem::path(r.file).filename().c_str(), r.spp,
                r.seconds, r.render_seconds, r.estimated_rel_mse);
  f << line;
  if (!f) throw std::runtime_error("--snapshot-every: cannot write " + csv);
  records_.push_back(r);
}

}  // namespace tessera

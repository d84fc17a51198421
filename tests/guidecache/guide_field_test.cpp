// The guide cache on its own: sampling matches its pdf, the pdf integrates to
// one, folding is the running mean of the targets whatever their order,
// degenerate fields stay usable, and serialisation round-trips exactly.
#include <gtest/gtest.h>

#include <cmath>
#include <sstream>
#include <vector>

#include "guidecache/table/guide_field.h"
#include "guidecache/table/guiding.h"
#include "kernels/rng.h"

namespace tessera {
namespace {

GuideField make_field(GuideConfig cfg = {}, uint32_t lights = 0) {
  return GuideField(cfg, Vec3(0.f), Vec3(1.f), lights, 1.f);
}

// Gives cell 0's bins a peaked, uneven radiance field and folds it in.
void teach_peaked(GuideField& f, int32_t cell) {
  GuideView g = f.view();
  for (uint32_t b = 0; b < g.bins; ++b) {
    Float target = (b % 7 == 0) ? 50.f : (b % 3 == 0 ? 1.f : 0.f);
    guide_record(g, cell, b, target);
  }
  f.fold();
}

TEST(GuideSampling, PdfIntegratesToOneOverTheSphere) {
  GuideField f = make_field();
  int32_t cell = f.find_cell(Vec3(0.5f), Vec3(0, 0, 1));
  teach_peaked(f, cell);
  GuideView g = f.view();
  // Midpoint rule on a fine equal-area grid: every point has weight 4 pi / N.
  const int n = 400;
  double sum = 0.0;
  for (int y = 0; y < n; ++y)
    for (int x = 0; x < n; ++x) {
      Vec3 d = glm::normalize(equal_area_square_to_sphere(Vec2((x + 0.5f) / n, (y + 0.5f) / n)));
      sum += guide_pdf(g, cell, d);
    }
  EXPECT_NEAR(sum * 4.0 * M_PI / (double(n) * n), 1.0, 1e-3);
}

// Pearson chi-square of guided samples binned on a grid finer than the
// guide's own, against the expected counts from guide_pdf.
TEST(GuideSampling, SamplesFollowThePdfChiSquare) {
  GuideField f = make_field();
  int32_t cell = f.find_cell(Vec3(0.5f), Vec3(0, 0, 1));
  teach_peaked(f, cell);
  GuideView g = f.view();
  const int res = 24;  // 2x the guide's grid per side
  const int samples = 400000;
  std::vector<double> observed(res * res, 0.0), expected(res * res, 0.0);
  int mismatches = 0;
  Rng rng = Rng::for_sample(7, 0, 0);
  for (int i = 0; i < samples; ++i) {
    Vec3 d;
    Float pdf;
    uint32_t bin;
    Float ub = rng.uniform();
    Vec2 u = rng.uniform2();
    ASSERT_TRUE(guide_sample(g, cell, ub, u, &d, &pdf, &bin));
    ASSERT_GT(pdf, 0.f);
    // The sampled bin's density; mapping back may differ only within float
    // rounding of a bin edge.
    if (std::abs(pdf - guide_pdf(g, cell, d)) > 1e-6f * pdf) ++mismatches;
    Vec2 sq = equal_area_sphere_to_square(d);
    int ix = std::min(res - 1, int(sq.x * res)), iy = std::min(res - 1, int(sq.y * res));
    observed[iy * res + ix] += 1.0;
  }
  for (int y = 0; y < res; ++y)
    for (int x = 0; x < res; ++x) {
      Vec3 d = glm::normalize(equal_area_square_to_sphere(Vec2((x + 0.5f) / res, (y + 0.5f) / res)));
      expected[y * res + x] = guide_pdf(g, cell, d) * (4.0 * M_PI / (res * res)) * samples;
    }
  double chi2 = 0.0;
  int dof = -1;
  for (int i = 0; i < res * res; ++i) {
    if (expected[i] < 5.0) continue;
    chi2 += (observed[i] - expected[i]) * (observed[i] - expected[i]) / expected[i];
    ++dof;
  }
  EXPECT_LE(mismatches, samples / 10000);
  ASSERT_GT(dof, 100);
  // Wilson-Hilferty: chi2 > dof + 4.5 sqrt(2 dof) has p < 1e-5 under H0.
  EXPECT_LT(chi2, dof + 4.5 * std::sqrt(2.0 * dof)) << "dof " << dof;
}

// The alias table realises exactly the probabilities it reports.
TEST(GuideSampling, AliasTableRealisesItsProbabilities) {
  GuideField f = make_field();
  int32_t cell = f.find_cell(Vec3(0.5f), Vec3(0, 0, 1));
  teach_peaked(f, cell);
  GuideView g = f.view();
  std::vector<double> realised(g.bins, 0.0);
  const GuideAlias* t = g.dir_alias + size_t(cell) * g.bins;
  for (uint32_t i = 0; i < g.bins; ++i) {
    realised[i] += t[i].keep / g.bins;
    realised[t[i].alias] += (1.0 - t[i].keep) / g.bins;
    EXPECT_EQ(t[i].alias_pmf, t[t[i].alias].pmf);
  }
  double total = 0;
  for (uint32_t i = 0; i < g.bins; ++i) {
    EXPECT_NEAR(realised[i], t[i].pmf, 1e-6) << "bin " << i;
    total += t[i].pmf;
  }
  EXPECT_NEAR(total, 1.0, 1e-5);
}

// guide_sample places a direction inside the bin it drew, for every grid the
// CLI accepts: its row and column come from a float multiply, not an integer
// division, so rows that are exact multiples of the grid must not round down.
TEST(GuideSampling, SampledDirectionLiesInItsBinForEveryGrid) {
  for (uint32_t grid = 2; grid <= 64; ++grid) {
    GuideConfig cfg;
    cfg.grid = grid;
    GuideField f = make_field(cfg);  // nothing learned: every bin equally likely
    GuideView g = f.view();
    const int32_t cell = f.find_cell(Vec3(0.5f), Vec3(0, 0, 1));
    const Vec2 corners[] = {Vec2(0.5f), Vec2(0.05f, 0.05f), Vec2(0.95f, 0.05f), Vec2(0.05f, 0.95f), Vec2(0.95f)};
    for (uint32_t b = 0; b < g.bins; ++b) {
      const Float u_bin = (static_cast<Float>(b) + 0.5f) / static_cast<Float>(g.bins);
      for (const Vec2& u : corners) {
        Vec3 d;
        Float pdf = 0.f;
        uint32_t bin = ~0u;
        ASSERT_TRUE(guide_sample(g, cell, u_bin, u, &d, &pdf, &bin));
        ASSERT_EQ(bin, b) << "grid " << grid;
        ASSERT_EQ(guide_bin_of(g, d), b) << "grid " << grid << " u " << u.x << "," << u.y;
      }
    }
  }
}

TEST(GuideSampling, PeakedFieldPrefersBrightBinsFacingTheNormal) {
  GuideField f = make_field();
  int32_t cell = f.find_cell(Vec3(0.5f), Vec3(0, 0, 1));
  GuideView g0 = f.view();
  uint32_t up = guide_bin_of(g0, glm::normalize(Vec3(0.2f, 0.1f, 1.f)));
  uint32_t down = guide_bin_of(g0, glm::normalize(Vec3(0.2f, 0.1f, -1.f)));
  guide_record(g0, cell, up, 10.f);
  guide_record(g0, cell, down, 10.f);
  f.fold();
  GuideView g = f.view();
  // The bin below the surface gets only the floor: cos weighting about the normal.
  EXPECT_GT(guide_bin_pdf(g, cell, up), 20.f * guide_bin_pdf(g, cell, down));
  EXPECT_GT(guide_bin_pdf(g, cell, down), 0.f);
}

TEST(GuideField, AllZeroFieldSamplesUniformly) {
  GuideField f = make_field();
  GuideView g = f.view();
  for (uint32_t b = 0; b < g.bins; ++b) EXPECT_NEAR(guide_bin_pdf(g, 0, b), 1.f / (4.f * kPi), 1e-5f);
}

// A cell samples from the guide only once it has learned some light above
// its surface; light learned only behind it does not count.
TEST(GuideField, CellsGuideOnlyAfterLearningLightAboveTheSurface) {
  GuideConfig cfg;
  cfg.guide_prob = 0.7f;
  GuideField f = make_field(cfg);
  const int32_t up = f.find_cell(Vec3(0.5f), Vec3(0, 0, 1)), down = f.find_cell(Vec3(0.5f), Vec3(0, 0, -1));
  EXPECT_EQ(f.view().cell_guide_prob(up), 0.f);
  GuideView g = f.view();
  const uint32_t below = guide_bin_of(g, Vec3(0, 0, -1)), above = guide_bin_of(g, Vec3(0, 0, 1));
  guide_record(g, up, below, 5.f);
  f.fold();
  EXPECT_EQ(f.view().cell_guide_prob(up), 0.f);
  g = f.view();
  guide_record(g, up, above, 5.f);
  f.fold();
  EXPECT_EQ(f.view().cell_guide_prob(up), 0.7f);
  EXPECT_EQ(f.view().cell_guide_prob(down), 0.f);
  f.set_guide_prob(0.25f);
  EXPECT_EQ(f.view().cell_guide_prob(up), 0.25f);
}

TEST(GuideField, HugeBinKeepsEveryOtherBinPossible) {
  GuideField f = make_field();
  GuideView g = f.view();
  uint32_t bright = guide_bin_of(g, Vec3(0, 0, 1));
  ASSERT_TRUE(guide_record(g, 4, bright, 1e5f));  // within the fixed-point range of a scale-1 field
  f.fold();
  g = f.view();
  for (uint32_t b = 0; b < g.bins; ++b) {
    EXPECT_GT(guide_bin_pdf(g, 4, b), 0.f) << b;
    EXPECT_TRUE(std::isfinite(guide_bin_pdf(g, 4, b)));
  }
}

TEST(GuideField, NonFiniteAndOutOfRangeTargetsAreRejectedAndCounted) {
  GuideField f = make_field();
  GuideView g = f.view();
  EXPECT_FALSE(guide_record(g, 0, 3, std::nanf("")));
  EXPECT_FALSE(guide_record(g, 0, 3, INFINITY));
  EXPECT_FALSE(guide_record(g, 0, 3, -1.f));
  EXPECT_FALSE(guide_record(g, 0, 3, 1e8f));  // beyond 2^20 x the brightest emitter (1)
  EXPECT_TRUE(guide_record(g, 0, 3, 2.f));
  f.fold();
  GuideFieldStats s = f.stats();
  EXPECT_EQ(s.rejected_nonfinite, 3u);
  EXPECT_EQ(s.rejected_large, 1u);
  EXPECT_EQ(s.updates, 1u);
  EXPECT_FLOAT_EQ(f.cell_values(0)[3], 2.f);
}

TEST(GuideField, FoldIsTheRunningMeanWithVisitCountLearningRate) {
  GuideField f = make_field();
  // Sequential updates Q += (t - Q) / (1 + visits) over two passes.
  std::vector<std::vector<Float>> passes = {{1.f, 2.f, 6.f}, {3.f, 0.5f}};
  double q = 0.0, visits = 0.0;
  for (const auto& pass : passes) {
    GuideView g = f.view();
    for (Float t : pass) {
      guide_record(g, 2, 10, t);
      q += (t - q) / (1.0 + visits);
      visits += 1.0;
    }
    f.fold();
  }
  EXPECT_NEAR(f.cell_values(2)[10], q, 1e-6);
}

TEST(GuideField, FoldDoesNotDependOnUpdateOrder) {
  GuideField a = make_field(), b = make_field();
  std::vector<Float> targets;
  Rng rng = Rng::for_sample(1, 2, 3);
  for (int i = 0; i < 5000; ++i) targets.push_back(rng.uniform() * 3.f);
  GuideView ga = a.view(), gb = b.view();
  for (size_t i = 0; i < targets.size(); ++i) guide_record(ga, 1, uint32_t(i % 144), targets[i]);
  for (size_t i = targets.size(); i-- > 0;) guide_record(gb, 1, uint32_t(i % 144), targets[i]);
  a.fold();
  b.fold();
  EXPECT_TRUE(a == b);
}

TEST(GuideField, BusyCellsSplitAndChildrenInheritValues) {
  GuideConfig cfg;
  cfg.split_updates = 100;
  GuideField f = make_field(cfg);
  int32_t cell = f.find_cell(Vec3(0.25f), Vec3(0, 0, 1));
  GuideView g = f.view();
  for (int i = 0; i < 200; ++i) guide_record(g, cell, 5, 4.f);
  f.fold();
  EXPECT_EQ(f.num_cells(), 6u + 7u);
  EXPECT_EQ(f.stats().splits, 1u);
  int32_t a = f.find_cell(Vec3(0.1f), Vec3(0, 0, 1)), b = f.find_cell(Vec3(0.9f), Vec3(0, 0, 1));
  EXPECT_NE(a, b);
  EXPECT_FLOAT_EQ(f.cell_values(a)[5], 4.f);
  EXPECT_FLOAT_EQ(f.cell_values(b)[5], 4.f);
  // Other normal classes are untouched.
  EXPECT_EQ(f.find_cell(Vec3(0.1f), Vec3(0, 0, -1)), f.find_cell(Vec3(0.9f), Vec3(0, 0, -1)));
}

TEST(GuideField, SplittingStopsAtTheMemoryBudget) {
  GuideConfig cfg;
  cfg.split_updates = 10;
  cfg.budget_bytes = 6 * 5000 + 8 * 5000;  // room for ~13 cells of ~4 KB at most
  GuideField f = make_field(cfg);
  for (int pass = 0; pass < 6; ++pass) {
    GuideView g = f.view();
    for (uint32_t c = 0; c < f.num_cells(); ++c)
      for (int i = 0; i < 20; ++i) guide_record(g, int32_t(c), 0, 1.f);
    f.fold();
  }
  EXPECT_TRUE(f.stats().budget_reached);
  EXPECT_LE(f.stats().bytes, cfg.budget_bytes);
}

// Lookups start from the flattened top levels (GuideView::top_nodes); they
// must find the leaf the plain descent from the root finds, for trees that
// are deep in one corner and shallow elsewhere, and for points outside.
TEST(GuideField, TopGridFindsTheSameLeafAsTheDescentFromTheRoot) {
  GuideConfig cfg;
  cfg.split_updates = 10;
  cfg.budget_bytes = 64ull << 20;
  GuideField f = make_field(cfg);
  for (int pass = 0; pass < 6; ++pass) {
    GuideView g = f.view();
    for (int k = 0; k < 40; ++k) {  // busy near one corner, for every normal class
      const Vec3 p(0.3f + 0.004f * k, 0.3f, 0.31f);
      for (Vec3 n : {Vec3(1, 0, 0), Vec3(0, -1, 0), Vec3(0, 0, 1)}) guide_record(g, guide_find_cell(g, p, n), 0, 1.f);
    }
    f.fold();
  }
  ASSERT_GT(f.num_cells(), 8u * 6u);  // deeper than the top grid somewhere
  const GuideView with_top = f.view();
  ASSERT_NE(with_top.top_nodes, nullptr);
  GuideView from_root = with_top;
  from_root.top_nodes = nullptr;
  Rng rng = Rng::for_sample(5, 0, 0);
  for (int i = 0; i < 200000; ++i) {
    const Vec3 p = Vec3(rng.uniform(), rng.uniform(), rng.uniform()) * 1.4f - 0.2f;
    const Vec3 n = glm::normalize(Vec3(rng.uniform(), rng.uniform(), rng.uniform()) - 0.5f);
    ASSERT_EQ(guide_find_cell(with_top, p, n), guide_find_cell(from_root, p, n)) << p.x << " " << p.y << " " << p.z;
  }
}

TEST(GuideField, OppositeNormalsNeverShareACell) {
  GuideField f = make_field();
  for (Vec3 n : {Vec3(1, 0, 0), Vec3(0, 1, 0), Vec3(0, 0, 1)})
    EXPECT_NE(f.find_cell(Vec3(0.5f), n), f.find_cell(Vec3(0.5f), -n));
}

TEST(GuideField, LearnedLightSelectionFollowsContributions) {
  GuideField f = make_field({}, 3);
  ASSERT_EQ(f.learned_lights(), 3u);
  GuideView g = f.view();
  guide_record(g, 0, g.bins + 0, 0.f);
  guide_record(g, 0, g.bins + 1, 9.f);
  guide_record(g, 0, g.bins + 2, 1.f);
  f.fold();
  g = f.view();
  Distribution1DView d = g.light_distribution(0);
  EXPECT_GT(d.discrete_pmf(1), 0.8f);
  EXPECT_GT(d.discrete_pmf(0), 0.f);  // the floor: never impossible
  EXPECT_NEAR(d.discrete_pmf(0) + d.discrete_pmf(1) + d.discrete_pmf(2), 1.f, 1e-6f);
}

// Learned light selection takes its share only in cells that have learned
// some light; elsewhere selection stays power-based.
TEST(GuideField, LearnedLightShareOnlyWhereLightWasLearned) {
  GuideConfig cfg;
  cfg.light_guide_prob = 0.8f;
  GuideField f = make_field(cfg, 3);
  GuideView g = f.view();
  EXPECT_EQ(g.cell_light_prob[0], 0.f);
  EXPECT_EQ(g.cell_light_prob[1], 0.f);
  guide_record(g, 0, g.bins + 2, 4.f);
  guide_record(g, 1, g.bins + 2, 0.f);  // an occluded light teaches nothing
  f.fold();
  g = f.view();
  EXPECT_EQ(g.cell_light_prob[0], 0.8f);
  EXPECT_EQ(g.cell_light_prob[1], 0.f);
}

// Next-event estimation's probability per cell: the share of the reflected
// light its shadow rays brought (direct D against the learned indirect I),
// times the gain, between nee_min_prob and 1; 1 until both have 64 visits.
TEST(GuideField, NextEventProbabilityFollowsTheDirectShare) {
  GuideConfig cfg;
  cfg.nee_gain = 4.f;
  cfg.nee_min_prob = 0.1f;
  GuideField f = make_field(cfg);
  GuideView g = f.view();
  auto record = [&](int32_t cell, int n, Float direct, Float indirect) {
    for (int i = 0; i < n; ++i) {
      guide_record(g, cell, g.nee_entry, direct);
      guide_record(g, cell, g.nee_entry + 1, indirect);
    }
  };
  record(0, 100, 0.f, 1.f);   // shadow rays never arrive: the floor
  record(1, 100, 1.f, 39.f);  // 2.5 % direct: 4 x 0.025
  record(2, 100, 1.f, 1.f);   // half direct: always
  record(3, 63, 0.f, 1.f);    // too few vertices to judge
  record(4, 100, 0.f, 0.f);   // nothing reflected: nothing to judge
  f.fold();
  g = f.view();
  EXPECT_FLOAT_EQ(g.nee_prob[0], 0.1f);
  EXPECT_NEAR(g.nee_prob[1], 0.1f, 1e-6f);
  EXPECT_EQ(g.nee_prob[2], 1.f);
  EXPECT_EQ(g.nee_prob[3], 1.f);
  EXPECT_EQ(g.nee_prob[4], 1.f);
  record(1, 100, 3.f, 37.f);  // means now 2 and 38: 4 x 0.05
  f.fold();
  EXPECT_NEAR(f.view().nee_prob[1], 0.2f, 1e-6f);
  // Gain 0 (--guide-nee always): every vertex traces its shadow ray.
  f.set_nee_gain(0.f);
  for (uint32_t c = 0; c < f.num_cells(); ++c) EXPECT_EQ(f.view().nee_prob[c], 1.f);
  EXPECT_FALSE(f.stats().learned_nee);
}

// The learned mixture weight: the candidate with the smallest mean second
// moment, once every candidate has 128 vertices; a fixed --guide-mix wins.
TEST(GuideField, MixtureWeightIsTheCandidateWithTheSmallestSecondMoment) {
  GuideConfig cfg;
  cfg.guide_prob = 0.5f;
  GuideField f = make_field(cfg);
  GuideView g = f.view();
  const Float moments[kGuideMixEntries] = {6.f, 5.f, 4.f, 3.f, 1.f, 2.f};
  for (int i = 0; i < 128; ++i)
    for (uint32_t k = 0; k < kGuideMixEntries; ++k) guide_record(g, 0, g.mix_entry + k, moments[k]);
  for (int i = 0; i < 127; ++i)
    for (uint32_t k = 0; k < kGuideMixEntries; ++k) guide_record(g, 1, g.mix_entry + k, moments[k]);
  f.fold();
  g = f.view();
  EXPECT_FLOAT_EQ(g.cell_mix[0], guide_mix_candidate(4));
  EXPECT_FLOAT_EQ(guide_mix_candidate(4), 0.65f);
  EXPECT_FLOAT_EQ(guide_mix_candidate(0), 0.05f) << "a cell can all but switch its guide off";
  EXPECT_EQ(g.cell_mix[1], 0.5f);  // too few vertices yet
  EXPECT_EQ(f.stats().mix_learned_cells, 0u) << "no cell has learned light, so none guides";
  f.set_guide_prob(0.3f);
  for (uint32_t c = 0; c < f.num_cells(); ++c) EXPECT_EQ(f.view().cell_mix[c], 0.3f);
  EXPECT_FALSE(f.view().learn_mix);
}

// One guided vertex's record: for each candidate a_k, (f cos T / s)^2 /
// (p_k p_cur) with p_k = a_k guide + (1 - a_k) bsdf and s = irradiance / pi.
TEST(GuideField, MixtureStatisticsAreImportanceWeightedSecondMoments) {
  GuideField f = make_field();
  teach_peaked(f, 0);
  GuideView g = f.view();
  const Float scale = g.irradiance[0] * kInvPi;
  ASSERT_GT(scale, 0.f);
  GuideMixSample m;
  m.fcos = 0.3f;
  m.guide_pdf = 2.f;
  m.bsdf_pdf = 0.5f;
  m.mix_pdf = 0.5f * 2.f + 0.5f * 0.5f;
  guide_record_mix(g, 0, m, 3.f);
  // A sample beyond the fixed-point range is counted, not recorded.
  m.fcos = 1e20f;
  guide_record_mix(g, 0, m, 3.f);
  f.fold();
  const Float* v = f.cell_values(0) + g.mix_entry;
  const double x = 0.3 * 3.0 / scale;
  for (uint32_t k = 0; k < kGuideMixEntries; ++k) {
    const double a = guide_mix_candidate(k), pk = a * 2.0 + (1.0 - a) * 0.5;
    EXPECT_NEAR(v[k], x * x / (pk * 1.25), 1e-5 * x * x) << "candidate " << k;
  }
  EXPECT_EQ(f.stats().mix_out_of_range, 1u);
}

// With MIS-weighted emission along the direction and a next-event sample at
// the vertex, each candidate weighs both by the power heuristic against its
// own mixture density: L_k = T + Le w(p_k, p_l) for the direction, plus
// (f cos tr Le w(p_l, p_k(w_l)) / (p_l s))^2 for the shadow ray.
TEST(GuideField, MixtureStatisticsWeighMisEmissionAndNextEventByEachCandidate) {
  GuideField f = make_field();
  teach_peaked(f, 0);
  GuideView g = f.view();
  const double scale = g.irradiance[0] * kInvPi;
  GuideMixSample m;
  m.fcos = 0.3f;
  m.guide_pdf = 0.05f;  // the guide looks elsewhere ...
  m.bsdf_pdf = 0.3f;    // ... the BSDF towards the emitter
  m.mix_pdf = 0.5f * 0.05f + 0.5f * 0.3f;
  m.emitted = 4.f;
  m.light_pdf = 0.2f;
  m.nee_value = 0.25f;
  m.nee_light_pdf = 0.4f;
  m.nee_guide_pdf = 0.05f;
  m.nee_bsdf_pdf = 0.3f;
  guide_record_mix(g, 0, m, 0.1f);
  f.fold();
  const Float* v = f.cell_values(0) + g.mix_entry;
  auto power = [](double a, double b) { return a * a / (a * a + b * b); };
  for (uint32_t k = 0; k < kGuideMixEntries; ++k) {
    const double a = guide_mix_candidate(k), pk = a * 0.05 + (1.0 - a) * 0.3;
    const double dir = 0.3 * (0.1 + 4.0 * power(pk, 0.2)) / scale;
    const double nee = 0.25 * power(0.4, pk) / (0.4 * scale);
    const double expected = dir * dir / (pk * m.mix_pdf) + nee * nee;
    EXPECT_NEAR(v[k], expected, 1e-5 * expected) << "candidate " << k;
  }
}

// Grid lookups clamp, and map NaN (a degenerate hit point or direction) to
// cell 0 instead of converting it to an integer (undefined behaviour).
TEST(GuideField, GridLookupsClampAndSurviveNaN) {
  EXPECT_EQ(guide_grid_index(std::nanf(""), 8), 0u);
  EXPECT_EQ(guide_grid_index(-3.f, 8), 0u);
  EXPECT_EQ(guide_grid_index(2.5f, 8), 2u);
  EXPECT_EQ(guide_grid_index(7.99f, 8), 7u);
  EXPECT_EQ(guide_grid_index(1e30f, 8), 7u);
  GuideField f = make_field();
  const GuideView g = f.view();
  const Float nan = std::nanf("");
  EXPECT_LT(guide_bin_of(g, Vec3(nan, nan, nan)), g.bins);
  EXPECT_GE(guide_find_cell(g, Vec3(nan, 0.f, 1e30f), Vec3(0.f, 0.f, 1.f)), 0);
}

TEST(GuideSerialisation, RoundTripIsExact) {
  GuideConfig cfg;
  cfg.split_updates = 50;
  GuideField f = make_field(cfg, 3);
  GuideView g = f.view();
  Rng rng = Rng::for_sample(3, 1, 4);
  for (int i = 0; i < 2000; ++i) guide_record(g, 0, uint32_t(rng.next_u32() % g.stride), rng.uniform() * 5.f);
  f.fold();
  std::stringstream ss;
  f.save(ss, 1234);
  GuideField back = GuideField::load(ss, 1234);
  EXPECT_TRUE(back == f);
  // Same distributions, bit for bit.
  GuideView a = f.view(), b = back.view();
  for (uint32_t c = 0; c < f.num_cells(); ++c)
    for (uint32_t j = 0; j < a.bins; ++j) EXPECT_EQ(guide_bin_pdf(a, int32_t(c), j), guide_bin_pdf(b, int32_t(c), j));
}

TEST(GuideSerialisation, OtherSceneOrGarbageIsAClearError) {
  GuideField f = make_field();
  std::stringstream ss;
  f.save(ss, 1);
  try {
    GuideField::load(ss, 2);
    FAIL() << "loaded a cache made for another scene";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("another scene"), std::string::npos) << e.what();
  }
  std::stringstream junk("this is not a guide cache at all");
  EXPECT_THROW(GuideField::load(junk, 1), std::runtime_error);
  std::string bytes;
  {
    std::stringstream full;
    f.save(full, 1);
    bytes = full.str();
  }
  std::stringstream truncated(bytes.substr(0, bytes.size() / 2));
  EXPECT_THROW(GuideField::load(truncated, 1), std::runtime_error);
}

}  // namespace
}  // namespace tessera

// The labelled-image point sampler: the boundary distance against hand-checked
// images and a brute-force L1 distance on random label images, the schedules
// (only powers / multiples of N survive without randomisation, including
// N = 3 where a floating-point log test fails), randomisation, labels and
// coordinates carried, background mapping, output modes, joggle, identical
// results for any thread count, and the errors for bad options.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <limits>
#include <random>
#include <set>
#include <vector>

#include "image/image_test_util.hpp"
#include "tessera/prep/sample_image.hpp"

namespace {

using namespace image_test;
using tessera::boundary_distance;
using tessera::LabelImage;
using tessera::LabelledPoints;
using tessera::sample_image;
using tessera::SampleImageOptions;
using tessera::SampleOutput;
using tessera::SampleSchedule;

constexpr std::int32_t kFar = std::numeric_limits<std::int32_t>::max();

LabelImage make_image(std::int64_t nx, std::int64_t ny, std::int64_t nz, std::vector<std::int32_t> labels) {
  LabelImage img;
  img.geometry.dim = nz == 0 ? 2 : 3;
  img.geometry.size = {nx, ny, nz == 0 ? 1 : nz};
  img.labels = std::move(labels);
  return img;
}

/// Brute force: boundary voxels by definition, then 1 + min L1 distance.
std::vector<std::int32_t> brute_distance(const LabelImage& img, const std::vector<std::int32_t>& select) {
  const auto& g = img.geometry;
  auto sel = [&](std::int32_t l) {
    return select.empty() ? l >= 0 : std::find(select.begin(), select.end(), l) != select.end();
  };
  std::vector<std::array<std::int64_t, 3>> boundary;
  for (std::int64_t k = 0; k < g.size[2]; ++k)
    for (std::int64_t j = 0; j < g.size[1]; ++j)
      for (std::int64_t i = 0; i < g.size[0]; ++i) {
        const std::int32_t l = img.labels[g.index(i, j, k)];
        bool b = false;
        const std::int64_t nb[6][3] = {{i - 1, j, k}, {i + 1, j, k}, {i, j - 1, k},
                                       {i, j + 1, k}, {i, j, k - 1}, {i, j, k + 1}};
        for (const auto& n : nb) {
          if (n[0] < 0 || n[1] < 0 || n[2] < 0 || n[0] >= g.size[0] || n[1] >= g.size[1] || n[2] >= g.size[2])
            continue;
          const std::int32_t m = img.labels[g.index(n[0], n[1], n[2])];
          if (m != l && (sel(l) || sel(m))) b = true;
        }
        if (b) boundary.push_back({i, j, k});
      }
  std::vector<std::int32_t> d(g.n_voxels(), kFar);
  if (boundary.empty()) return d;
  for (std::int64_t k = 0; k < g.size[2]; ++k)
    for (std::int64_t j = 0; j < g.size[1]; ++j)
      for (std::int64_t i = 0; i < g.size[0]; ++i) {
        std::int64_t best = std::numeric_limits<std::int64_t>::max();
        for (const auto& b : boundary)
          best = std::min(best, std::abs(b[0] - i) + std::abs(b[1] - j) + std::abs(b[2] - k));
        d[g.index(i, j, k)] = static_cast<std::int32_t>(best + 1);
      }
  return d;
}

/// Voxel index of a point (no joggle) — checks it lies exactly on a centre.
std::size_t voxel_of(const LabelImage& img, const LabelledPoints& pts, std::size_t p) {
  const auto& g = img.geometry;
  std::int64_t idx[3] = {0, 0, 0};
  for (int a = 0; a < g.dim; ++a) {
    const std::size_t au = static_cast<std::size_t>(a);
    const double t = (pts.coords[p * static_cast<std::size_t>(g.dim) + au] - g.origin[au]) / g.spacing[au];
    idx[a] = std::llround(t);
    EXPECT_EQ(pts.coords[p * static_cast<std::size_t>(g.dim) + au],
              g.origin[au] + static_cast<double>(idx[a]) * g.spacing[au]);
  }
  return g.index(idx[0], idx[1], idx[2]);
}

bool is_power(std::int64_t d, std::int64_t n) {
  std::int64_t p = 1;
  while (p < d) p *= n;
  return p == d;
}

/// Random blobs: a few labelled balls (some of negative label) in label 0.
LabelImage blobs(std::int64_t n, std::uint32_t seed, int dim = 3) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(0, static_cast<double>(n));
  const std::int64_t nz = dim == 3 ? n : 0;
  LabelImage img = make_image(n, n, nz, std::vector<std::int32_t>(static_cast<std::size_t>(n * n * std::max<std::int64_t>(nz, 1)), 0));
  for (int b = 0; b < 6; ++b) {
    const double c[3] = {u(rng), u(rng), dim == 3 ? u(rng) : 0.0};
    const double r = 0.1 * static_cast<double>(n) + 0.15 * u(rng);
    const std::int32_t label = b == 5 ? -2 : 1 + b % 3;
    for (std::int64_t k = 0; k < img.geometry.size[2]; ++k)
      for (std::int64_t j = 0; j < n; ++j)
        for (std::int64_t i = 0; i < n; ++i) {
          const double dx = static_cast<double>(i) - c[0], dy = static_cast<double>(j) - c[1],
                       dz = static_cast<double>(k) - c[2];
          if (dx * dx + dy * dy + dz * dz < r * r) img.labels[img.geometry.index(i, j, k)] = label;
        }
  }
  return img;
}

// ------------------------------------------------------------------ distance

TEST(image_distance, HandChecked1D) {
  const LabelImage img = make_image(8, 1, 0, {0, 0, 0, 1, 1, 1, 1, 1});
  EXPECT_EQ(boundary_distance(img, {}), (std::vector<std::int32_t>{3, 2, 1, 1, 2, 3, 4, 5}));
}

TEST(image_distance, HandChecked2D) {
  std::vector<std::int32_t> lab(25, 0);
  lab[12] = 1;  // centre voxel (2, 2)
  const LabelImage img = make_image(5, 5, 0, lab);
  const std::vector<std::int32_t> expected = {4, 3, 2, 3, 4,  //
                                              3, 2, 1, 2, 3,  //
                                              2, 1, 1, 1, 2,  //
                                              3, 2, 1, 2, 3,  //
                                              4, 3, 2, 3, 4};
  EXPECT_EQ(boundary_distance(img, {}), expected);
  EXPECT_EQ(boundary_distance(img, {1}), expected);
}

TEST(image_distance, BoundaryFoundAcrossRows) {
  // 9 x 3, label 1 only at (8, 2): boundary voxels (8, 2), (7, 2) and (8, 1),
  // the last one only visible between rows.
  std::vector<std::int32_t> lab(27, 0);
  lab[8 + 9 * 2] = 1;
  const LabelImage img = make_image(9, 3, 0, lab);
  const auto d = boundary_distance(img, {});
  EXPECT_EQ(d, brute_distance(img, {}));
  EXPECT_EQ(d[0], 10);       // (0, 0): 7 + 2 to (7, 2) or 8 + 1 to (8, 1), plus 1
  EXPECT_EQ(d[8], 2);        // (8, 0): next to (8, 1)
  EXPECT_EQ(d[7 + 9], 2);    // (7, 1)
}

TEST(image_distance, MatchesBruteForceOnRandomImages) {
  std::mt19937 rng(7);
  for (int trial = 0; trial < 40; ++trial) {
    const bool three = trial % 2 == 0;
    const std::int64_t nx = 3 + rng() % 9, ny = 1 + rng() % 8, nz = three ? 1 + rng() % 7 : 0;
    const std::size_t n = static_cast<std::size_t>(nx * ny * (three ? nz : 1));
    std::vector<std::int32_t> lab(n);
    const bool sparse = trial % 4 < 2;
    for (auto& l : lab) {
      if (sparse)
        l = rng() % 23 == 0 ? static_cast<std::int32_t>(1 + rng() % 2) : 0;
      else
        l = static_cast<std::int32_t>(rng() % 4) - 1;  // -1 .. 2
    }
    const LabelImage img = make_image(nx, ny, nz, lab);
    for (const std::vector<std::int32_t>& sel :
         {std::vector<std::int32_t>{}, std::vector<std::int32_t>{1}, std::vector<std::int32_t>{0, 2}}) {
      bool any = false;
      for (auto l : lab) any = any || (sel.empty() ? l >= 0 : std::find(sel.begin(), sel.end(), l) != sel.end());
      if (!any) continue;
      SCOPED_TRACE(::testing::Message() << "trial " << trial << " size " << nx << "x" << ny << "x" << nz
                                        << " selection size " << sel.size());
      EXPECT_EQ(boundary_distance(img, sel), brute_distance(img, sel));
    }
  }
}

TEST(image_distance, NoBoundaryIsFar) {
  const LabelImage img = make_image(4, 3, 2, std::vector<std::int32_t>(24, 5));
  const auto d = boundary_distance(img, {});
  EXPECT_TRUE(std::all_of(d.begin(), d.end(), [](std::int32_t v) { return v == kFar; }));
  // Stripes 0 | 1 | 2 selecting only 0: the 1 | 2 interface is not a boundary.
  std::vector<std::int32_t> lab(9 * 2);
  for (std::int64_t j = 0; j < 2; ++j)
    for (std::int64_t i = 0; i < 9; ++i) lab[static_cast<std::size_t>(i + 9 * j)] = static_cast<std::int32_t>(i / 3);
  const LabelImage s = make_image(9, 2, 0, lab);
  const auto ds = boundary_distance(s, {0});
  EXPECT_EQ(ds, brute_distance(s, {0}));
  EXPECT_EQ(ds[5], 3);  // (5, 0): 2 from the boundary voxel (3, 0), plus 1
  EXPECT_EQ(ds[8], 6);
  // Uniform image: sampling finds nothing (every distance is far).
  SampleImageOptions o;
  o.randomize = false;
  EXPECT_EQ(sample_image(img, o).size(), 0u);
}

// ------------------------------------------------------------------ schedule

TEST(image_sampler, ExponentialScheduleIsAnExactIntegerTest) {
  // A 400 x 1 strip: label 1 at x = 0. Boundary voxels x = 0, 1, so d(x) = x
  // for x >= 1 and d(0) = 1.
  std::vector<std::int32_t> lab(400, 0);
  lab[0] = 1;
  LabelImage img = make_image(400, 1, 0, lab);
  img.geometry.spacing = {0.5, 2, 1};
  img.geometry.origin = {-3, 7, 0};
  for (int n : {2, 3, 5, 7}) {
    SampleImageOptions o;
    o.randomize = false;
    o.step = n;
    const LabelledPoints pts = sample_image(img, o);
    std::vector<std::int64_t> got, want{0};
    for (std::size_t p = 0; p < pts.size(); ++p) got.push_back(static_cast<std::int64_t>(voxel_of(img, pts, p)));
    for (std::int64_t x = 1; x < 400; ++x)
      if (is_power(x, n)) want.push_back(x);
    EXPECT_EQ(got, want) << "N = " << n;
    for (std::size_t p = 0; p < pts.size(); ++p) EXPECT_EQ(pts.coords[2 * p + 1], 7.0);
  }
  SampleImageOptions lin;
  lin.randomize = false;
  lin.schedule = SampleSchedule::linear;
  lin.step = 4;
  const LabelledPoints pts = sample_image(img, lin);
  std::vector<std::int64_t> got, want{0, 1};
  for (std::size_t p = 0; p < pts.size(); ++p) got.push_back(static_cast<std::int64_t>(voxel_of(img, pts, p)));
  for (std::int64_t x = 4; x < 400; x += 4) want.push_back(x);
  EXPECT_EQ(got, want);
}

TEST(image_sampler, OnlyScheduledDistancesSurvive) {
  LabelImage img = blobs(24, 3);
  img.geometry.spacing = {0.5, 0.25, 2};
  img.geometry.origin = {1, -2, 3};
  const auto d = boundary_distance(img, {});
  for (SampleSchedule sch : {SampleSchedule::exponential, SampleSchedule::linear}) {
    for (int step : {2, 3}) {
      SampleImageOptions o;
      o.randomize = false;
      o.schedule = sch;
      o.step = step;
      const LabelledPoints pts = sample_image(img, o);
      std::set<std::size_t> got;
      for (std::size_t p = 0; p < pts.size(); ++p) {
        const std::size_t v = voxel_of(img, pts, p);
        got.insert(v);
        EXPECT_EQ(pts.labels[p], img.labels[v]);  // labels carried
      }
      std::set<std::size_t> want;
      for (std::size_t v = 0; v < d.size(); ++v)
        if (sch == SampleSchedule::exponential ? is_power(d[v], step) : (d[v] == 1 || d[v] % step == 0))
          want.insert(v);
      EXPECT_EQ(got, want);
      EXPECT_EQ(got.size(), pts.size());  // no voxel twice
    }
  }
}

TEST(image_sampler, RandomisedKeepsWithProbabilityOneOverDistance) {
  const LabelImage img = blobs(40, 11);
  const auto d = boundary_distance(img, {});
  SampleImageOptions all;
  all.randomize = false;
  all.schedule = SampleSchedule::linear;
  all.step = 1;  // every voxel a candidate
  SampleImageOptions o = all;
  o.randomize = true;
  o.seed = 99;
  const LabelledPoints pts = sample_image(img, o);
  std::vector<std::size_t> kept_at(64, 0), total_at(64, 0);
  for (std::size_t v = 0; v < d.size(); ++v)
    if (d[v] < 64) ++total_at[static_cast<std::size_t>(d[v])];
  for (std::size_t p = 0; p < pts.size(); ++p) {
    const std::size_t v = voxel_of(img, pts, p);
    if (d[v] < 64) ++kept_at[static_cast<std::size_t>(d[v])];
  }
  EXPECT_EQ(kept_at[1], total_at[1]);  // probability 1
  for (int dist : {2, 3, 4}) {
    const double n = static_cast<double>(total_at[static_cast<std::size_t>(dist)]), p = 1.0 / dist;
    ASSERT_GT(n, 500);
    EXPECT_NEAR(static_cast<double>(kept_at[static_cast<std::size_t>(dist)]), n * p, 5 * std::sqrt(n * p * (1 - p)))
        << "distance " << dist;
  }
  // The same seed gives the same points, another seed others.
  EXPECT_EQ(sample_image(img, o).coords, pts.coords);
  o.seed = 100;
  EXPECT_NE(sample_image(img, o).coords, pts.coords);
  // Probability range: [1, 1] keeps every candidate, [0, 0] none.
  o.probability_range = {1, 1};
  EXPECT_EQ(sample_image(img, o).coords, sample_image(img, all).coords);
  o.probability_range = {0, 0};
  EXPECT_EQ(sample_image(img, o).size(), 0u);
  // A floor: with [0.5, 1] at least half of the d = 4 voxels stay.
  o.probability_range = {0.5, 1};
  const LabelledPoints half = sample_image(img, o);
  std::size_t k4 = 0;
  for (std::size_t p = 0; p < half.size(); ++p) k4 += d[voxel_of(img, half, p)] == 4;
  const double n4 = static_cast<double>(total_at[4]);
  EXPECT_NEAR(static_cast<double>(k4), 0.5 * n4, 5 * std::sqrt(0.25 * n4));
}

// ------------------------------------------------------------------ labels and output modes

TEST(image_sampler, BackgroundMappingAndOutputModes) {
  const LabelImage img = blobs(20, 5);
  SampleImageOptions o;
  o.select = {1};
  o.seed = 4;
  o.background_label = -5;
  const LabelledPoints all = sample_image(img, o);
  o.output = SampleOutput::labelled;
  const LabelledPoints lab = sample_image(img, o);
  o.output = SampleOutput::background;
  const LabelledPoints bg = sample_image(img, o);
  ASSERT_GT(lab.size(), 0u);
  ASSERT_GT(bg.size(), 0u);
  EXPECT_EQ(all.size(), lab.size() + bg.size());
  for (std::int32_t l : lab.labels) EXPECT_EQ(l, 1);
  for (std::int32_t l : bg.labels) EXPECT_EQ(l, -5);
  // all = labelled + background, merged in voxel order.
  std::size_t a = 0, b = 0;
  for (std::size_t p = 0; p < all.size(); ++p) {
    const bool is_lab = all.labels[p] == 1;
    const LabelledPoints& src = is_lab ? lab : bg;
    std::size_t& q = is_lab ? a : b;
    ASSERT_LT(q, src.size());
    EXPECT_EQ(all.coords[3 * p], src.coords[3 * q]);
    EXPECT_EQ(all.coords[3 * p + 1], src.coords[3 * q + 1]);
    EXPECT_EQ(all.coords[3 * p + 2], src.coords[3 * q + 2]);
    ++q;
  }
  // Without the mapping, background points keep their own labels (0, 2, 3, -2).
  o.output = SampleOutput::background;
  o.background_label.reset();
  const LabelledPoints own = sample_image(img, o);
  ASSERT_EQ(own.size(), bg.size());
  std::set<std::int32_t> seen(own.labels.begin(), own.labels.end());
  EXPECT_EQ(seen.count(1), 0u);
  EXPECT_GT(seen.count(0), 0u);
  for (std::size_t p = 0; p < own.size(); ++p) EXPECT_EQ(own.labels[p], img.labels[voxel_of(img, own, p)]);
}

TEST(image_sampler, JoggleStaysInTheVoxel) {
  LabelImage img = blobs(16, 8);
  img.geometry.spacing = {1, 0.5, 2};
  SampleImageOptions o;
  o.seed = 12;
  const LabelledPoints centred = sample_image(img, o);
  for (double j : {0.2, 0.5, 3.0}) {
    o.joggle = j;
    const LabelledPoints moved = sample_image(img, o);
    ASSERT_EQ(moved.size(), centred.size());  // the same voxels are kept
    EXPECT_EQ(moved.labels, centred.labels);
    const double r = std::min(j, 0.5) * 0.5;  // times the smallest spacing
    double largest = 0;
    for (std::size_t p = 0; p < moved.size(); ++p) {
      double r2 = 0;
      for (int a = 0; a < 3; ++a) {
        const double dlt = moved.coords[3 * p + static_cast<std::size_t>(a)] - centred.coords[3 * p + static_cast<std::size_t>(a)];
        r2 += dlt * dlt;
      }
      largest = std::max(largest, std::sqrt(r2));
    }
    EXPECT_LT(largest, r + 1e-12);
    EXPECT_GT(largest, 0.5 * r);  // it does move
  }
}

TEST(image_sampler, SameResultForAnyThreadCount) {
  const LabelImage img = blobs(64, 21);
  SampleImageOptions o;
  o.seed = 5;
  o.joggle = 0.3;
  o.threads = 1;
  const LabelledPoints one = sample_image(img, o);
  for (int t : {2, 3, 8}) {
    o.threads = t;
    const LabelledPoints many = sample_image(img, o);
    EXPECT_EQ(many.coords, one.coords) << t << " threads";
    EXPECT_EQ(many.labels, one.labels) << t << " threads";
  }
  const LabelImage flat = blobs(200, 4, 2);
  o.threads = 1;
  const LabelledPoints f1 = sample_image(flat, o);
  o.threads = 2;
  EXPECT_EQ(sample_image(flat, o).coords, f1.coords);
  EXPECT_EQ(f1.dim, 2);
}

// ------------------------------------------------------------------ errors

TEST(image_sampler, BadOptionsAndInput) {
  const LabelImage img = blobs(10, 2);
  auto err = [&](SampleImageOptions o, std::initializer_list<std::string_view> parts) {
    expect_error(input_error([&] { sample_image(img, o); }), parts);
  };
  SampleImageOptions o;
  o.step = 1;
  err(o, {"step", ">= 2"});
  o.schedule = SampleSchedule::linear;
  o.step = 0;
  err(o, {"step", ">= 1"});
  o = {};
  o.probability_range = {0.6, 0.2};
  err(o, {"probability"});
  o.probability_range = {-0.1, 1};
  err(o, {"probability"});
  o.probability_range = {0, 1.5};
  err(o, {"probability"});
  o = {};
  o.background_label = 0;
  err(o, {"background label", "< 0"});
  o = {};
  o.select = {1, 77};
  err(o, {"unknown label 77"});
  o = {};
  o.joggle = -1;
  err(o, {"joggle"});
  o.joggle = std::nan("");
  err(o, {"joggle"});

  const LabelImage neg = make_image(3, 3, 0, std::vector<std::int32_t>(9, -1));
  expect_error(input_error([&] { sample_image(neg, {}); }), {"empty selection"});
  expect_error(input_error([&] { boundary_distance(neg, {}); }), {"empty selection"});
  LabelImage wrong = make_image(3, 3, 0, std::vector<std::int32_t>(8, 0));
  expect_error(input_error([&] { sample_image(wrong, {}); }), {"mismatched sizes"});
  LabelImage empty = make_image(0, 3, 0, {});
  expect_error(input_error([&] { sample_image(empty, {}); }), {"empty"});
  LabelImage bad_spacing = make_image(3, 3, 0, std::vector<std::int32_t>(9, 0));
  bad_spacing.geometry.spacing = {1, 0, 1};
  expect_error(input_error([&] { sample_image(bad_spacing, {}); }), {"spacing"});
}

}  // namespace

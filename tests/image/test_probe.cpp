// probe: trilinear (bilinear) interpolation reproduces linear fields, returns
// the voxel value exactly at voxel centres, includes the far faces, marks
// outside points, and rejects NaN coordinates and inconsistent images.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>
#include <vector>

#include "image/image_test_util.hpp"
#include "tessera/prep/probe.hpp"

namespace {

using namespace image_test;
using tessera::probe;
using tessera::ProbeOptions;
using tessera::ScalarImage;

ScalarImage linear_image(int dim, std::array<double, 4> c) {
  ScalarImage img;
  img.geometry.dim = dim;
  img.geometry.size = {7, 5, dim == 3 ? 4 : 1};
  img.geometry.spacing = {0.5, 1.25, dim == 3 ? 0.75 : 1.0};
  img.geometry.origin = {-1, 2, dim == 3 ? 0.5 : 0.0};
  const auto& g = img.geometry;
  img.values.resize(g.n_voxels());
  for (std::int64_t k = 0; k < g.size[2]; ++k)
    for (std::int64_t j = 0; j < g.size[1]; ++j)
      for (std::int64_t i = 0; i < g.size[0]; ++i) {
        const double x = g.origin[0] + static_cast<double>(i) * g.spacing[0];
        const double y = g.origin[1] + static_cast<double>(j) * g.spacing[1];
        const double z = g.origin[2] + static_cast<double>(k) * g.spacing[2];
        img.values[g.index(i, j, k)] = c[0] + c[1] * x + c[2] * y + (dim == 3 ? c[3] * z : 0.0);
      }
  return img;
}

TEST(image_probe, LinearFieldsAreReproduced) {
  const std::array<double, 4> c{0.3, 1.5, -2.0, 0.7};
  for (int dim : {2, 3}) {
    const ScalarImage img = linear_image(dim, c);
    const auto& g = img.geometry;
    std::mt19937_64 rng(dim);
    std::vector<double> pts;
    const std::size_t n = 5000;  // also runs the parallel path
    for (std::size_t p = 0; p < n; ++p)
      for (int a = 0; a < dim; ++a) {
        const std::size_t au = static_cast<std::size_t>(a);
        std::uniform_real_distribution<double> u(g.origin[au],
                                                 g.origin[au] + static_cast<double>(g.size[au] - 1) * g.spacing[au]);
        pts.push_back(u(rng));
      }
    const auto r = probe(img, pts);
    ASSERT_EQ(r.values.size(), n);
    for (std::size_t p = 0; p < n; ++p) {
      const double* q = &pts[p * static_cast<std::size_t>(dim)];
      const double expect = c[0] + c[1] * q[0] + c[2] * q[1] + (dim == 3 ? c[3] * q[2] : 0.0);
      ASSERT_EQ(r.valid[p], 1);
      ASSERT_NEAR(r.values[p], expect, 1e-12) << "dim " << dim << " point " << p;
    }
  }
}

TEST(image_probe, VoxelCentresGiveTheVoxelValueExactly) {
  ScalarImage img;
  img.geometry.size = {4, 3, 5};
  img.geometry.spacing = {0.1, 0.3, 0.7};
  img.geometry.origin = {0.1, -0.2, 3.3};
  std::mt19937_64 rng(3);
  std::normal_distribution<double> nd;
  img.values.resize(img.geometry.n_voxels());
  for (double& v : img.values) v = nd(rng);
  img.values[img.geometry.index(1, 1, 1)] = std::numeric_limits<double>::quiet_NaN();  // must not leak
  const auto& g = img.geometry;
  std::vector<double> pts;
  for (std::int64_t k = 0; k < g.size[2]; ++k)
    for (std::int64_t j = 0; j < g.size[1]; ++j)
      for (std::int64_t i = 0; i < g.size[0]; ++i) {
        pts.push_back(g.origin[0] + static_cast<double>(i) * g.spacing[0]);
        pts.push_back(g.origin[1] + static_cast<double>(j) * g.spacing[1]);
        pts.push_back(g.origin[2] + static_cast<double>(k) * g.spacing[2]);
      }
  const auto r = probe(img, pts);
  for (std::size_t v = 0; v < g.n_voxels(); ++v) {
    EXPECT_EQ(r.valid[v], 1) << v;
    if (std::isnan(img.values[v]))
      EXPECT_TRUE(std::isnan(r.values[v]));
    else
      EXPECT_EQ(r.values[v], img.values[v]) << "voxel " << v;
  }
}

// Voxel centres of a raster far from 0 (UTM northing 4.5e6 m, 0.1 m voxels:
// one ulp of a coordinate is 9e-9 voxel, past the 1e-9 slack alone): every
// centre computed as origin + i * spacing is inside and exact, the far row
// and column included, and half a voxel beyond is outside.
TEST(image_probe, VoxelCentresOfARasterFarFromZero) {
  ScalarImage img;
  img.geometry.dim = 2;
  img.geometry.size = {100, 100, 1};
  img.geometry.spacing = {0.1, 0.1, 1.0};
  img.geometry.origin = {600000.05, 4500000.05, 0.0};
  const auto& g = img.geometry;
  img.values.resize(g.n_voxels());
  for (std::size_t v = 0; v < img.values.size(); ++v) img.values[v] = static_cast<double>(v);
  std::vector<double> pts;
  for (std::int64_t j = 0; j < g.size[1]; ++j)
    for (std::int64_t i = 0; i < g.size[0]; ++i) {
      pts.push_back(g.origin[0] + static_cast<double>(i) * g.spacing[0]);
      pts.push_back(g.origin[1] + static_cast<double>(j) * g.spacing[1]);
    }
  pts.push_back(g.origin[0] + 99.5 * g.spacing[0]);
  pts.push_back(g.origin[1]);
  const auto r = probe(img, pts);
  for (std::size_t v = 0; v < g.n_voxels(); ++v) {
    ASSERT_EQ(r.valid[v], 1) << "voxel " << v;
    ASSERT_EQ(r.values[v], img.values[v]) << "voxel " << v;
  }
  EXPECT_EQ(r.valid.back(), 0);
}

TEST(image_probe, OutsidePointsAndFarFaces) {
  const ScalarImage img = linear_image(3, {1, 0, 0, 0});  // constant 1
  const auto& g = img.geometry;
  const double x1 = g.origin[0] + 6 * g.spacing[0], y1 = g.origin[1] + 4 * g.spacing[1],
               z1 = g.origin[2] + 3 * g.spacing[2];
  const double inf = std::numeric_limits<double>::infinity();
  const std::vector<double> pts = {
      x1,   y1,   z1,                     // far corner: inside
      g.origin[0], g.origin[1], g.origin[2],  // near corner: inside
      x1,   0.5 * (g.origin[1] + y1), z1,     // on far faces
      x1 + 1e-6, y1, z1,                  // just beyond x
      -5,   3,    1,                      // outside
      0,    y1 + 1, 1,                    // outside y
      0,    3,    inf,                    // outside at infinity
  };
  const auto r = probe(img, pts);
  const std::vector<std::uint8_t> valid = {1, 1, 1, 0, 0, 0, 0};
  EXPECT_EQ(r.valid, valid);
  for (std::size_t p = 0; p < valid.size(); ++p) {
    if (valid[p])
      EXPECT_EQ(r.values[p], 1.0) << p;
    else
      EXPECT_TRUE(std::isnan(r.values[p])) << p;  // default outside value
  }
  ProbeOptions o;
  o.outside_value = -7;
  const auto r2 = probe(img, pts, o);
  EXPECT_EQ(r2.values[4], -7);
  EXPECT_EQ(r2.values[0], 1);
}

TEST(image_probe, DegenerateAxisAndTwoD) {
  // A 3D image one voxel thick: only z == origin is inside.
  ScalarImage img;
  img.geometry.size = {2, 2, 1};
  img.geometry.origin = {0, 0, 4};
  img.values = {0, 1, 2, 3};  // f = x + 2y
  const auto r = probe(img, std::vector<double>{0.5, 0.5, 4, 0.5, 0.5, 4.5, 1, 1, 4});
  EXPECT_EQ(r.valid, (std::vector<std::uint8_t>{1, 0, 1}));
  EXPECT_DOUBLE_EQ(r.values[0], 1.5);
  EXPECT_EQ(r.values[2], 3);
  // 2D: bilinear on a non-linear (bilinear) field is exact too.
  ScalarImage flat;
  flat.geometry.dim = 2;
  flat.geometry.size = {2, 2, 1};
  flat.values = {0, 0, 0, 1};  // f = x * y
  const auto b = probe(flat, std::vector<double>{0.25, 0.5, 1, 1, 0.5, 0.5});
  EXPECT_DOUBLE_EQ(b.values[0], 0.125);
  EXPECT_EQ(b.values[1], 1);
  EXPECT_DOUBLE_EQ(b.values[2], 0.25);
}

TEST(image_probe, Errors) {
  const ScalarImage img = linear_image(3, {0, 1, 1, 1});
  const double nan = std::numeric_limits<double>::quiet_NaN();
  expect_error(input_error([&] { probe(img, std::vector<double>{0, 0, 0, 1, nan, 1}); }), {"point 1", "NaN"});
  expect_error(input_error([&] { probe(img, std::vector<double>{0, 0}); }), {"multiple"});
  ScalarImage bad = img;
  bad.values.pop_back();
  expect_error(input_error([&] { probe(bad, std::vector<double>{0, 0, 0}); }), {"mismatched sizes"});
  ScalarImage empty;
  empty.geometry.size = {0, 1, 1};
  expect_error(input_error([&] { probe(empty, std::vector<double>{0, 0, 0}); }), {"empty"});
  // No points: no values.
  EXPECT_EQ(probe(img, std::vector<double>{}).values.size(), 0u);
}

TEST(image_probe, NonFinitePointsAreOutsideWhenKept) {
  // An organized cloud's missing returns (NaN points) are outside, as an
  // infinite coordinate is; the other points' values are unchanged.
  const ScalarImage img = linear_image(3, {0.3, 1.5, -2.0, 0.7});
  const double nan = std::numeric_limits<double>::quiet_NaN(), inf = std::numeric_limits<double>::infinity();
  const std::vector<double> pts = {0, 3, 1, nan, 3, 1, 0.5, 2.5, 1.5, 0, nan, nan, -inf, 3, 1, 0, 3, inf};
  ProbeOptions o;
  o.keep_non_finite = true;
  o.outside_value = -7;
  const auto r = probe(img, pts, o);
  const std::vector<std::uint8_t> valid = {1, 0, 1, 0, 0, 0};
  EXPECT_EQ(r.valid, valid);
  const auto finite = probe(img, std::vector<double>{0, 3, 1, 0.5, 2.5, 1.5});
  EXPECT_EQ(r.values[0], finite.values[0]);
  EXPECT_EQ(r.values[2], finite.values[1]);
  for (std::size_t p : {1, 3, 4, 5}) EXPECT_EQ(r.values[p], -7.0) << p;
}

}  // namespace

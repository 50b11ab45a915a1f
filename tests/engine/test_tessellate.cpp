// The parallel driver, tessera::engine::tessellate, driven directly with a
// compositor of our own (the public extension point, as in
// examples/volume_sum): cells do not depend on where their generator's
// coordinates are read from (Generators::slots or the input order) nor on
// the thread count, a malformed Generators is refused, and a work cap
// abandons the costly cells only.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstdint>
#include <numbers>
#include <random>
#include <span>
#include <stdexcept>
#include <vector>

#include "tessera/engine/tessellate.hpp"
#include "tessera/kernels/hull.hpp"
#include "tessera/kernels/locator.hpp"
#include "tessera/kernels/tile.hpp"

namespace {

namespace kernels = tessera::kernels;

// Every cell's vertices, bit for bit, by generator: (planes' ids, position).
template <class CellT>
struct Record {
  struct Batch {
    std::vector<std::int32_t> gen;
    std::vector<std::vector<double>> cells;
  };
  std::vector<std::vector<double>> by_gen;

  void add(Batch& b, std::int32_t gen, const kernels::BuildStatus& st, CellT& cell) {
    std::vector<double> out;
    if (st.has_cell)
      for (const auto& v : cell.vertices())
        for (int d = 0; d < CellT::dim; ++d) {
          out.push_back(v.y[d]);
          out.push_back(cell.planes()[v.p[d]].id);
        }
    b.gen.push_back(gen);
    b.cells.push_back(std::move(out));
  }
  void finish(std::span<Batch> batches) {
    for (const Batch& b : batches)
      for (std::size_t t = 0; t < b.gen.size(); ++t) {
        const auto g = static_cast<std::size_t>(b.gen[t]);
        if (by_gen.size() <= g) by_gen.resize(g + 1);
        by_gen[g] = b.cells[t];
      }
  }
};

// A pass over every point of `locator`, in its bin order.
template <int D>
tessera::engine::Generators<D> generators(const std::vector<double>& points, const kernels::BinLocator<D>& locator,
                                          const std::array<double, D>& lo, const std::array<double, D>& hi,
                                          std::span<const std::int32_t> order, const kernels::ExactContext& exact) {
  tessera::engine::Generators<D> gens;
  gens.coords = points.data();
  gens.locator = &locator;
  gens.lo = lo;
  gens.hi = hi;
  gens.order = order;
  gens.exact = &exact;
  return gens;
}

template <class CellT>
struct Scene {
  static constexpr int D = CellT::dim;
  std::vector<double> points;
  std::array<double, D> lo{}, hi{};
  kernels::ExactContext exact;
  std::vector<std::int32_t> order;
  std::vector<std::uint32_t> slots;

  explicit Scene(std::size_t n) {
    std::mt19937_64 rng(7);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    points.resize(n * D);
    for (double& x : points) x = u(rng);
    for (int d = 0; d < D; ++d) hi[static_cast<std::size_t>(d)] = 1.0;
    exact.points = points.data();
    exact.dim = D;
    for (int d = 0; d < D; ++d) exact.hi[static_cast<std::size_t>(d)] = 1.0;
  }

  std::vector<std::vector<double>> run(bool with_slots, int threads) {
    kernels::BinLocator<D> locator(points, {}, lo, hi, 2.0);
    order.assign(locator.size(), 0);
    slots.assign(locator.size(), 0);
    for (std::size_t k = 0; k < locator.size(); ++k) {
      order[k] = locator.id(k);
      slots[k] = static_cast<std::uint32_t>(k);
    }
    tessera::engine::Generators<D> gens = generators<D>(points, locator, lo, hi, order, exact);
    if (with_slots) gens.slots = slots;
    tessera::engine::EngineOptions opt;
    opt.threads = threads;
    Record<CellT> rec;
    tessera::engine::tessellate<CellT>(gens, rec, opt);
    return rec.by_gen;
  }
};

template <class CellT>
void same_cells_whatever_the_source(std::size_t n) {
  Scene<CellT> scene(n);
  const auto base = scene.run(false, 1);
  ASSERT_EQ(base.size(), n);
  for (const auto& cell : base) EXPECT_FALSE(cell.empty());
  EXPECT_EQ(scene.run(true, 1), base) << "slots changed a cell";
  EXPECT_EQ(scene.run(true, 2), base) << "two threads changed a cell";
}

TEST(Tessellate, SlotsGiveTheSameCells3D) { same_cells_whatever_the_source<kernels::Hull>(3000); }
TEST(Tessellate, SlotsGiveTheSameCells2D) { same_cells_whatever_the_source<kernels::Tile>(5000); }

TEST(Tessellate, SlotsOfTheWrongLengthAreRefused) {
  Scene<kernels::Hull> scene(100);
  kernels::BinLocator<3> locator(scene.points, {}, scene.lo, scene.hi, 2.0);
  std::vector<std::int32_t> order(locator.size());
  for (std::size_t k = 0; k < locator.size(); ++k) order[k] = locator.id(k);
  std::vector<std::uint32_t> slots(order.size() - 1, 0);
  tessera::engine::Generators<3> gens = generators<3>(scene.points, locator, scene.lo, scene.hi, order, scene.exact);
  gens.slots = slots;
  Record<kernels::Hull> rec;
  EXPECT_THROW(tessera::engine::tessellate<kernels::Hull>(gens, rec, {}), std::invalid_argument);
}

// How many cells a pass abandons at EngineOptions::work_cap, and how many it
// builds.
struct CapCount {
  struct Batch {
    std::size_t capped = 0, built = 0;
  };
  std::size_t capped = 0, built = 0;
  void add(Batch& b, std::int32_t, const kernels::BuildStatus& st, kernels::Hull&) {
    b.capped += st.capped;
    b.built += st.has_cell;
    if (st.capped) EXPECT_FALSE(st.has_cell);
  }
  void finish(std::span<Batch> batches) {
    for (const Batch& b : batches) {
      capped += b.capped;
      built += b.built;
    }
  }
};

CapCount run_capped(std::vector<double>& points, std::array<double, 3> lo, std::array<double, 3> hi,
                    std::uint64_t cap, std::uint64_t* exact_calls = nullptr) {
  kernels::ExactContext exact;
  exact.points = points.data();
  exact.dim = 3;
  exact.lo = lo;
  exact.hi = hi;
  kernels::BinLocator<3> locator(points, {}, lo, hi, 2.0);
  std::vector<std::int32_t> order(locator.size());
  for (std::size_t k = 0; k < locator.size(); ++k) order[k] = locator.id(k);
  const tessera::engine::Generators<3> gens = generators<3>(points, locator, lo, hi, order, exact);
  tessera::engine::EngineOptions opt;
  opt.threads = 2;
  opt.work_cap = cap;
  CapCount count;
  const std::uint64_t calls = tessera::engine::tessellate<kernels::Hull>(gens, count, opt);
  if (exact_calls != nullptr) *exact_calls = calls;
  return count;
}

CapCount run_capped(std::vector<double>& points, double box, std::uint64_t cap) {
  return run_capped(points, {-box, -box, -box}, {box, box, box}, cap);
}

TEST(Tessellate, WorkCapAbandonsOnlyCostlyCells) {
  // Uniform cells do ~300 units of work (BuildStatus::work): a cap of 64
  // times that abandons none, a cap of 10 every one.
  std::mt19937_64 rng(8);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  std::vector<double> uniform(3 * 2000);
  for (double& x : uniform) x = u(rng);
  const CapCount loose = run_capped(uniform, 1.0, 64 * 307);
  EXPECT_EQ(loose.capped, 0u);
  EXPECT_EQ(loose.built, 2000u);
  const CapCount tight = run_capped(uniform, 1.0, 10);
  EXPECT_EQ(tight.capped, 2000u);
  // Points on one sphere: every cell reaches the centre and tests every
  // point there (the pilot's stall, delaunay.cpp's pilot_work_cap).
  std::normal_distribution<double> g;
  std::vector<double> sphere;
  for (int i = 0; i < 3000; ++i) {
    const double x = g(rng), y = g(rng), z = g(rng), r = std::sqrt(x * x + y * y + z * z);
    sphere.insert(sphere.end(), {x / r, y / r, z / r});
  }
  const CapCount stalled = run_capped(sphere, 1.1, 64 * 307);
  EXPECT_GT(stalled.capped, 2900u);
}

TEST(Tessellate, WorkCapStopsWithinAShell) {
  // 4,000 points on a circle and one 50 radii above its centre: the box is
  // tall, so one shell of bins around a circle point holds most of the
  // circle, and every clip test near the axis, where the points' bisectors
  // all meet, is an exact tie. Checked only between shells, the cap let
  // each cell test its whole shell: the pilot's 1,024 cells took 0.8 s of
  // a run whose cells then took 0.04 s (an exact evaluation counts 32
  // units against the cap, CellBuilder::exact_weight).
  std::mt19937_64 rng(9);
  std::uniform_real_distribution<double> u(0, 2 * std::numbers::pi);
  std::vector<double> cone;
  for (int i = 0; i < 4000; ++i) {
    const double t = u(rng);
    cone.insert(cone.end(), {std::cos(t), std::sin(t), 0.0});
  }
  cone.insert(cone.end(), {0.0, 0.0, 50.0});
  const std::uint64_t cap = 64 * 307;
  std::uint64_t calls = 0;
  const CapCount c = run_capped(cone, {-1.1, -1.1, -0.5}, {1.1, 1.1, 50.5}, cap, &calls);
  EXPECT_GT(c.capped, 3000u);
  // Each cell stops once past the cap: at most cap / 32 evaluations, and
  // one clip's more.
  EXPECT_LT(calls, (c.capped + c.built) * (cap / kernels::CellBuilder<kernels::Hull>::exact_weight + 200));
}

}  // namespace

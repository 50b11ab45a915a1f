// Input validation of tessera::voronoi.
//
// What this proves: every malformed input is rejected with tessera::InputError
// carrying a one-line message (never a crash, hang or silent garbage), and the
// legitimate edge cases next to each rejected one are accepted and correct:
// a single point in an explicit box, 2D bounds whose unused z range is empty,
// points outside explicit bounds dropped on request, coplanar 3D points in an
// explicit box or on a tilted plane.
#include <gtest/gtest.h>

#include <limits>

#include "helpers.hpp"

namespace {

using namespace cells_test;

/// Runs f, requires an InputError with a non-empty single-line message
/// containing `needle`; returns the message.
template <class F>
std::string expect_input_error(F&& f, const std::string& what, const std::string& needle = "") {
  try {
    f();
  } catch (const tessera::InputError& e) {
    const std::string m = e.what();
    EXPECT_FALSE(m.empty()) << what;
    EXPECT_EQ(m.find('\n'), std::string::npos) << what << ": message is not one line: " << m;
    if (!needle.empty()) EXPECT_NE(m.find(needle), std::string::npos) << what << ": message lacks '" << needle << "': " << m;
    return m;
  } catch (const std::exception& e) {
    ADD_FAILURE() << what << ": threw a non-InputError: " << e.what();
    return {};
  }
  ADD_FAILURE() << what << ": did not throw";
  return {};
}

tessera::Cells call(const std::vector<double>& pts, int dim, const std::vector<std::int32_t>& labels,
                    const tessera::VoronoiOptions& o) {
  return tessera::voronoi(std::span<const double>(pts), dim, std::span<const std::int32_t>(labels), o);
}

TEST(BadInput, Empty) {
  for (int dim : {2, 3}) {
    expect_input_error([&] { run({}, dim); }, "empty, default bounds");
    expect_input_error([&] { run({}, dim, unit_box()); }, "empty, explicit bounds");
  }
}

TEST(BadInput, SinglePoint) {
  // Default bounds: one point has zero extent, there is no domain.
  expect_input_error([] { run({0.5, 0.5, 0.5}, 3); }, "single point 3D default bounds");
  expect_input_error([] { run({0.5, 0.5}, 2); }, "single point 2D default bounds");
  // Explicit bounds: one cell that is the whole box.
  for (int dim : {2, 3}) {
    SCOPED_TRACE(::testing::Message() << "dim " << dim);
    const auto box = make_bounds({-1, 2, 0}, {3, 2.5, 7});
    const std::vector<double> p = dim == 2 ? std::vector<double>{0.0, 2.1} : std::vector<double>{0.0, 2.1, 6.0};
    const auto c = run(p, dim, box);
    check_invariants(c, p, {}, "single point");
    ASSERT_EQ(c.n_cells(), 1u);
    EXPECT_EQ(c.cell_of, std::vector<std::int32_t>{0});
    EXPECT_NEAR(c.volume[0], box_volume(box, dim), 1e-14 * box_volume(box, dim));
    for (int a = 0; a < dim; ++a) EXPECT_NEAR(c.centroid[a], 0.5 * (box.lo[a] + box.hi[a]), 1e-14 * 7);
    EXPECT_EQ(c.num_faces[0], 2 * dim);
    EXPECT_TRUE(c.neighbors.empty());
    EXPECT_EQ(c.n_vertices(), dim == 2 ? 4u : 8u);
  }
}

TEST(BadInput, NonFinite) {
  const double bad[] = {std::numeric_limits<double>::quiet_NaN(), std::numeric_limits<double>::infinity(),
                        -std::numeric_limits<double>::infinity()};
  for (int dim : {2, 3})
    for (double x : bad)
      for (int at : {0, 7, 10 * dim - 1}) {  // first coordinate, a middle one, the last one
        auto p = random_points(10, dim, 1);
        p[at] = x;
        const std::string what = "dim " + std::to_string(dim) + " value " + std::to_string(x) + " at " + std::to_string(at);
        expect_input_error([&] { run(p, dim); }, what + " default bounds");
        expect_input_error([&] { run(p, dim, unit_box()); }, what + " explicit bounds");
      }
  // Non-finite explicit bounds.
  auto p = random_points(10, 3, 2);
  auto nb = unit_box();
  nb.hi[1] = std::numeric_limits<double>::quiet_NaN();
  expect_input_error([&] { run(p, 3, nb); }, "NaN in bounds");
  auto ib = unit_box();
  ib.lo[2] = -std::numeric_limits<double>::infinity();
  expect_input_error([&] { run(p, 3, ib); }, "-Inf in bounds");
}

TEST(BadInput, Dimension) {
  const auto p = random_points(12, 1, 3);  // 12 doubles: a multiple of 1, 2, 3, 4, 6
  for (int dim : {-1, 0, 1, 4, 6}) {
    auto o = options(3);
    o.dim = dim;
    expect_input_error([&] { call(p, dim, {}, o); }, "dim " + std::to_string(dim));
  }
}

TEST(BadInput, LengthNotMultipleOfDim) {
  expect_input_error([] { run(random_points(10, 1, 4), 3); }, "10 doubles, dim 3");
  expect_input_error([] { run(random_points(9, 1, 5), 2); }, "9 doubles, dim 2");
  expect_input_error([] { run(random_points(10, 1, 4), 3, unit_box()); }, "10 doubles, dim 3, explicit bounds");
}

TEST(BadInput, LabelsLength) {
  for (int dim : {2, 3}) {
    const auto p = random_points(20, dim, 6);
    for (std::size_t len : {1u, 19u, 21u, 40u})
      expect_input_error([&] { run(p, dim, std::nullopt, std::vector<std::int32_t>(len, 0)); },
                         "labels of length " + std::to_string(len) + " for 20 points");
    // The right length is fine.
    EXPECT_NO_THROW(run(p, dim, std::nullopt, std::vector<std::int32_t>(20, 1)));
  }
}

TEST(BadInput, EmptyOrInvertedBounds) {
  const auto p3 = random_points(20, 3, 7, make_bounds({0.2, 0.2, 0.2}, {0.8, 0.8, 0.8}));
  for (int axis = 0; axis < 3; ++axis) {
    auto eq = unit_box();
    eq.hi[axis] = eq.lo[axis];
    expect_input_error([&] { run(p3, 3, eq); }, "lo == hi on axis " + std::to_string(axis));
    auto inv = unit_box();
    std::swap(inv.lo[axis], inv.hi[axis]);
    expect_input_error([&] { run(p3, 3, inv); }, "lo > hi on axis " + std::to_string(axis));
  }
  const auto p2 = random_points(20, 2, 8, make_bounds({0.2, 0.2, 0}, {0.8, 0.8, 0}));
  for (int axis = 0; axis < 2; ++axis) {
    auto eq = make_bounds({0, 0, 0}, {1, 1, 0});
    eq.hi[axis] = eq.lo[axis];
    expect_input_error([&] { run(p2, 2, eq); }, "2D lo == hi on axis " + std::to_string(axis));
  }
  // In 2D the z range is unused: an empty one is fine.
  const auto c = run(p2, 2, make_bounds({0, 0, 0}, {1, 1, 0}));
  check_invariants(c, p2, {}, "2D bounds with empty z range");
}

TEST(BadInput, PointsOutsideExplicitBounds) {
  for (int dim : {2, 3}) {
    SCOPED_TRACE(::testing::Message() << "dim " << dim);
    auto p = random_points(100, dim, 9);  // in the unit box
    const std::vector<std::size_t> out_ids = {0, 41, 99};
    p[0 * dim + 0] = -0.25;               // below lo on x
    p[41 * dim + 1] = 1.5;                // above hi on y
    p[99 * dim + (dim - 1)] = 2.0;        // above hi on the last axis
    expect_input_error([&] { run(p, dim, unit_box()); }, "points outside explicit bounds");

    auto o = options(dim, unit_box());
    o.ignore_outside_points = true;
    const auto c = call(p, dim, {}, o);
    std::vector<std::int32_t> got = c.ignored_outside_bounds;
    std::sort(got.begin(), got.end());
    EXPECT_EQ(got, (std::vector<std::int32_t>{0, 41, 99}));
    for (auto i : out_ids) EXPECT_EQ(c.cell_of[i], -1) << "ignored point " << i;
    EXPECT_EQ(c.n_cells(), 97u);
    check_invariants(c, p, {}, "ignore_outside_points");  // the rest still tile the box
    // ...and the remaining cells are the cells of the inside points alone.
    std::vector<double> inside;
    std::vector<std::size_t> ids;
    for (std::size_t i = 0; i < 100; ++i)
      if (std::find(out_ids.begin(), out_ids.end(), i) == out_ids.end()) {
        ids.push_back(i);
        for (int a = 0; a < dim; ++a) inside.push_back(p[i * dim + a]);
      }
    const auto ci = run(inside, dim, unit_box());
    for (std::size_t t = 0; t < ids.size(); ++t)
      EXPECT_NEAR(c.volume[c.cell_of[ids[t]]], ci.volume[ci.cell_of[t]], 1e-12) << "point " << ids[t];
  }
}

TEST(BadInput, AllPointsOutside) {
  for (int dim : {2, 3}) {
    auto p = random_points(20, dim, 10, make_bounds({2, 2, 2}, {3, 3, 3}));
    expect_input_error([&] { run(p, dim, unit_box()); }, "all points outside");
    auto o = options(dim, unit_box());
    o.ignore_outside_points = true;
    expect_input_error([&] { call(p, dim, {}, o); }, "all points outside, ignore_outside_points");
  }
}

TEST(BadInput, Coplanar3DWithDefaultBounds) {
  // Axis-aligned plane z = 0.3.
  auto p = random_points(50, 3, 11);
  for (std::size_t i = 0; i < 50; ++i) p[3 * i + 2] = 0.3;
  expect_input_error([&] { run(p, 3); }, "coplanar z = 0.3", "--dim 2");
  // Points with the same y (a plane normal to y) are rejected the same way.
  auto py = random_points(30, 3, 12);
  for (std::size_t i = 0; i < 30; ++i) py[3 * i + 1] = -2.5;
  expect_input_error([&] { run(py, 3); }, "coplanar y = -2.5", "--dim 2");
  // DECISION (implemented so by the lead): only a zero-extent default box is an
  // error. Points exactly on a TILTED plane (x + y + z = 10) have a box of
  // positive extent and are a legitimate, maximally degenerate input: the
  // result must be a valid tessellation.
  std::vector<double> q;
  for (int x = 0; x < 8; ++x)
    for (int y = 0; y < 8; ++y) q.insert(q.end(), {double(x), double(y), double(10 - x - y)});
  check_invariants(run(q, 3), q, {}, "coplanar x + y + z = 10, default bounds");
  // With explicit bounds coplanar points are a legitimate (degenerate) input:
  // every cell is a prism spanning the box.
  const auto box = make_bounds({-0.01, -0.01, 0}, {1.01, 1.01, 1});
  const auto c = run(p, 3, box);
  check_invariants(c, p, {}, "coplanar points in an explicit box");
  // The prisms are the 2D cells times the box height (1): same area, same neighbours.
  std::vector<double> flat;
  for (std::size_t i = 0; i < 50; ++i) flat.insert(flat.end(), {p[3 * i], p[3 * i + 1]});
  const auto c2d = run(flat, 2, box);
  for (std::size_t i = 0; i < 50; ++i) {
    EXPECT_NEAR(c.volume[c.cell_of[i]], c2d.volume[c2d.cell_of[i]], 1e-12) << "point " << i;
    EXPECT_EQ(neighbours_of(c, c.cell_of[i]), neighbours_of(c2d, c2d.cell_of[i])) << "point " << i;
    EXPECT_EQ(c.num_faces[c.cell_of[i]], c2d.num_faces[c2d.cell_of[i]] + 2) << "point " << i;
  }
}

}  // namespace

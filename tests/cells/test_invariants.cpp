// Invariants of the tessellation, on random and on DEGENERATE inputs (no joggle).
//
// check_invariants (helpers.hpp) proves, for each result: the cells partition
// the box (volume sum == domain to 1e-12 relative), adjacency is symmetric,
// every merged vertex has a key of dim+1 ascending ids, sits where its key
// says (equidistant from its generators, on its box planes) and is used by
// exactly the cells of its key, every 3D cell is a closed oriented surface
// with V-E+F = 2, every 2D cell a closed chain, and the mesh integrates to
// the reported volume and centroid. On lattices the tests also check the
// known exact cells (unit cubes/squares).
#include <gtest/gtest-spi.h>
#include <gtest/gtest.h>

#include <map>

#include <cstdio>
#include <numbers>
#include <string>

#include "helpers.hpp"
#include "common/hostile_points.hpp"
#include "tessera/delaunay.hpp"
#include "tessera/io/points.hpp"

namespace {

using namespace cells_test;

// ------------------------------------------------------------------ random

TEST(Invariants, Random10k2D) {
  const auto pts = random_points(10000, 2, 101);
  check_invariants(run(pts, 2, unit_box()), pts, {}, "random 10k 2D explicit box");
  check_invariants(run(pts, 2), pts, {}, "random 10k 2D default box");
}

TEST(Invariants, Random10k3D) {
  const auto pts = random_points(10000, 3, 102);
  check_invariants(run(pts, 3, unit_box()), pts, {}, "random 10k 3D explicit box");
  const auto far = make_bounds({100, -0.02, 5}, {103, -0.01, 5.5});  // off the origin, thin in y
  const auto p2 = random_points(10000, 3, 103, far);
  check_invariants(run(p2, 3, far), p2, {}, "random 10k 3D far thin box");
}

/// Runs the checker on a corrupted result with failures intercepted; returns
/// whether some failure message contains `needle`.
bool checker_reports(const tessera::Cells& c, const std::vector<double>& pts, const std::string& needle) {
  ::testing::TestPartResultArray results;
  {
    ::testing::ScopedFakeTestPartResultReporter rep(::testing::ScopedFakeTestPartResultReporter::INTERCEPT_ONLY_CURRENT_THREAD, &results);
    check_invariants(c, pts, {}, "corrupted", {true, 1e-12, false});
  }
  for (int i = 0; i < results.size(); ++i)
    if (std::string(results.GetTestPartResult(i).message()).find(needle) != std::string::npos) return true;
  return false;
}

// The checker itself is not vacuous: small corruptions of a valid result are caught.
TEST(Invariants, CheckerCatchesCorruption) {
  const auto pts = random_points(200, 3, 104);
  const auto good = run(pts, 3, unit_box());
  {
    auto c = good;  // one face turned inside out
    std::reverse(c.face_vertices.begin() + c.face_vertex_offsets[0], c.face_vertices.begin() + c.face_vertex_offsets[1]);
    EXPECT_TRUE(checker_reports(c, pts, "no reverse"));
  }
  {
    auto c = good;  // cell 0 forgets its last neighbour
    c.neighbors.erase(c.neighbors.begin() + c.neighbor_offsets[1] - 1);
    for (std::size_t k = 1; k < c.neighbor_offsets.size(); ++k) --c.neighbor_offsets[k];
    EXPECT_TRUE(checker_reports(c, pts, "asymmetric"));
  }
  {
    auto c = good;  // a volume off by 1e-6 relative
    c.volume[5] *= 1 + 1e-6;
    EXPECT_TRUE(checker_reports(c, pts, "volume sum"));
  }
  {
    auto c = good;  // a vertex moved by 1e-6
    c.vertices[3 * 20 + 1] += 1e-6;
    EXPECT_TRUE(checker_reports(c, pts, "vertex 20"));
  }
}

// validate()'s exact check of sampled measures (front/validate_measures.cpp):
// a cell's volume, centroid or corner off by far less than the volume sum can
// show is caught, and named; a corrupt key is reported.
TEST(Invariants, ValidateChecksSampledMeasuresExactly) {
  for (const int dim : {2, 3}) {
    SCOPED_TRACE(dim);
    const auto pts = random_points(400, dim, 105);
    const auto good = run(pts, dim, unit_box());
    const tessera::ValidationReport r = tessera::validate(good, {}, pts);
    EXPECT_TRUE(r.ok);
    EXPECT_GE(r.measures_checked, 64u);  // the 64 spread cells at least; the smallest and longest overlap them
    EXPECT_LE(r.measure_rel_error, 1e-13);
    {
      auto four = good;  // validate runs in the cells' thread count: the same report in four
      four.threads_used = 4;
      four.neighbors.erase(four.neighbors.begin() + four.neighbor_offsets[1] - 1);  // and a one-sided spoke
      for (std::size_t j = 1; j < four.neighbor_offsets.size(); ++j) --four.neighbor_offsets[j];
      auto one = four;
      one.threads_used = 1;
      const tessera::ValidationReport r4 = tessera::validate(four, {}, pts), r1 = tessera::validate(one, {}, pts);
      EXPECT_EQ(r4.asymmetric_spokes, 1u);
      EXPECT_EQ(r4.asymmetric_spokes, r1.asymmetric_spokes);
      EXPECT_EQ(r4.measures_checked, r1.measures_checked);
      EXPECT_EQ(r4.measure_rel_error, r1.measure_rel_error);
      EXPECT_EQ(r4.measure_worst, r1.measure_worst);
      EXPECT_EQ(r4.vertex_rel_error, r1.vertex_rel_error);
      EXPECT_EQ(r4.vertex_worst, r1.vertex_worst);
      EXPECT_EQ(r4.messages, r1.messages);
    }
    const std::size_t k = static_cast<std::size_t>(
        std::min_element(good.volume.begin(), good.volume.end()) - good.volume.begin());  // always sampled
    const std::string name = "cell of point " + std::to_string(good.generator[k]);
    {
      auto c = good;  // off by 1e-7: the sum moves by ~1e-11 relative
      c.volume[k] *= 1 + 1e-7;
      EXPECT_TRUE(tessera::validate(c, {}).ok);  // without the points, blind to it
      const tessera::ValidationReport bad = tessera::validate(c, {}, pts);
      EXPECT_FALSE(bad.ok);
      EXPECT_EQ(bad.measure_worst, good.generator[k]);
      EXPECT_NEAR(bad.measure_rel_error, 1e-7, 1e-9);
      ASSERT_FALSE(bad.messages.empty());
      EXPECT_NE(bad.messages.front().find(name), std::string::npos) << bad.messages.front();
    }
    {
      auto c = good;  // a centroid moved by 1e-7 (the cells are ~0.05 across)
      c.centroid[k * static_cast<std::size_t>(dim)] += 1e-7;
      EXPECT_TRUE(tessera::validate(c, {}).ok);
      const tessera::ValidationReport bad = tessera::validate(c, {}, pts);
      EXPECT_FALSE(bad.ok);
      ASSERT_FALSE(bad.messages.empty());
      EXPECT_NE(bad.messages.front().find(name + ": centroid"), std::string::npos) << bad.messages.front();
    }
    EXPECT_LE(r.vertex_rel_error, 1e-12);
    EXPECT_GE(r.vertex_worst, 0);
    const auto Du = static_cast<std::size_t>(dim);
    // A corner of cell k: the first vertex of its first face.
    const std::int32_t v = good.face_vertices[static_cast<std::size_t>(
        good.face_vertex_offsets[static_cast<std::size_t>(good.cell_face_offsets[k])])];
    {
      auto c = good;  // that corner moved by 1e-7: no measure changes
      c.vertices[static_cast<std::size_t>(v) * Du] += 1e-7;
      EXPECT_TRUE(tessera::validate(c, {}).ok);
      const tessera::ValidationReport bad = tessera::validate(c, {}, pts);
      EXPECT_FALSE(bad.ok);
      EXPECT_EQ(bad.vertex_worst, v);
      EXPECT_GT(bad.vertex_rel_error, 1e-7);
      ASSERT_FALSE(bad.messages.empty());
      EXPECT_NE(bad.messages.front().find("merged vertex " + std::to_string(v)), std::string::npos)
          << bad.messages.front();
    }
    {
      auto c = good;  // its key names one bisector twice: no such point, reported, not thrown
      std::int32_t* key = c.vertex_keys.data() + static_cast<std::size_t>(v) * (Du + 1);
      std::int32_t other = -1;
      for (std::size_t d = 0; d <= Du; ++d)
        if (key[d] != good.generator[k]) {
          if (other < 0) other = key[d];
          key[d] = other;
        }
      tessera::ValidationReport bad;
      ASSERT_NO_THROW(bad = tessera::validate(c, {}, pts));
      EXPECT_FALSE(bad.ok);
      bool named = false;
      for (const auto& m : bad.messages) named |= m.find(name + ": a corner's key names planes") != std::string::npos;
      EXPECT_TRUE(named);
    }
    const std::vector<double> fewer(pts.begin(), pts.end() - dim);
    EXPECT_THROW(tessera::validate(good, {}, fewer), std::invalid_argument);
    // Labels of another input (10 for these points) were taken as none.
    const std::vector<std::int32_t> ten(10, 0);
    EXPECT_THROW(tessera::validate(good, ten, pts), std::invalid_argument);
  }
}

// ------------------------------------------------------------------ lattices

/// Points on a lattice whose cells are all the same known box: checks each
/// cell's volume, centroid (== its point) and, for each axis neighbour, that
/// it is listed and the shared face has the full area; the total face measure
/// is the cell's full surface, so any extra (symbolic) faces have zero area.
void check_lattice_cells(const tessera::Cells& c, const std::vector<double>& pts, int dim, int k, double h,
                         const std::string& what) {
  SCOPED_TRACE(what);
  const double cell_vol = std::pow(h, dim);
  const double face = std::pow(h, dim - 1);
  std::size_t bad = 0;
  auto id_of = [&](std::array<int, 3> ix) {
    return dim == 2 ? ix[0] * k + ix[1] : (ix[0] * k + ix[1]) * k + ix[2];
  };
  for (std::size_t i = 0; i < pts.size() / dim; ++i) {
    const auto cell = c.cell_of[i];
    ASSERT_GE(cell, 0);
    if (!(std::abs(c.volume[cell] - cell_vol) <= 1e-9 * cell_vol) && ++bad <= 5)
      ADD_FAILURE() << "point " << i << " volume " << c.volume[cell] << " expected " << cell_vol;
    for (int a = 0; a < dim; ++a)
      if (!(std::abs(c.centroid[cell * dim + a] - pts[i * dim + a]) <= 1e-9 * h) && ++bad <= 5)
        ADD_FAILURE() << "point " << i << " centroid axis " << a << " " << c.centroid[cell * dim + a];
    std::array<int, 3> ix{0, 0, 0};
    {
      std::size_t r = i;
      for (int a = dim - 1; a >= 0; --a) {
        ix[a] = int(r % k);
        r /= k;
      }
    }
    auto nb = neighbours_of(c, cell);
    auto mm = mesh_face_measures(c, cell);
    double total = 0;
    for (auto [s, m] : mm) total += m;
    if (!(std::abs(total - 2 * dim * face) <= 1e-9 * face) && ++bad <= 5)
      ADD_FAILURE() << "point " << i << " total face measure " << total << " expected " << 2 * dim * face;
    for (int a = 0; a < dim; ++a)
      for (int step : {-1, 1}) {
        auto jx = ix;
        jx[a] += step;
        if (jx[a] < 0 || jx[a] >= k) continue;
        const int j = id_of(jx);
        if (!std::binary_search(nb.begin(), nb.end(), j) && ++bad <= 5)
          ADD_FAILURE() << "point " << i << " does not list its axis neighbour " << j;
        if (!(std::abs(mm[j] - face) <= 1e-9 * face) && ++bad <= 5)
          ADD_FAILURE() << "point " << i << " face to axis neighbour " << j << " measure " << mm[j];
      }
  }
  EXPECT_EQ(bad, 0u);
}

TEST(Invariants, IntegerGrid3D) {
  for (int k : {8, 10}) {
    const auto pts = grid_points(k, 3);
    const auto box = make_bounds({-0.5, -0.5, -0.5}, {k - 0.5, k - 0.5, k - 0.5});
    const auto c = run(pts, 3, box);
    check_invariants(c, pts, {}, "integer grid " + std::to_string(k) + "^3");
    check_lattice_cells(c, pts, 3, k, 1.0, "integer grid " + std::to_string(k) + "^3");
    check_invariants(run(pts, 3), pts, {}, "integer grid default box " + std::to_string(k) + "^3");
  }
}

TEST(Invariants, TenthGrid3D) {
  // Spacing 0.1 is not representable: the points are a slightly irregular grid
  // whose co-spherical quadruples are only nearly so.
  const int k = 10;
  const auto pts = grid_points(k, 3, 0.1);
  const auto box = make_bounds({-0.05, -0.05, -0.05}, {0.1 * (k - 1) + 0.05, 0.1 * (k - 1) + 0.05, 0.1 * (k - 1) + 0.05});
  const auto c = run(pts, 3, box);
  check_invariants(c, pts, {}, "0.1 grid 10^3");
  check_lattice_cells(c, pts, 3, k, 0.1, "0.1 grid 10^3");
  check_invariants(run(pts, 3), pts, {}, "0.1 grid 10^3 default box");
}

TEST(Invariants, VoxelCentres3D) {
  const int k = 10;
  const auto pts = grid_points(k, 3, 1.0, 0.5);
  const auto box = make_bounds({0, 0, 0}, {double(k), double(k), double(k)});
  const auto c = run(pts, 3, box);
  check_invariants(c, pts, {}, "voxel centres 10^3");
  check_lattice_cells(c, pts, 3, k, 1.0, "voxel centres 10^3");
}

TEST(Invariants, RotatedLattice3D) {
  // A unit grid under a generic rotation: every 8 neighbouring points are
  // co-spherical up to rounding. Cells of interior points far from the box are
  // unit cubes.
  const int k = 8;
  const double A = 0.3, B = 0.7, C = 1.1;
  const double R[3][3] = {
      {std::cos(A) * std::cos(B), std::cos(A) * std::sin(B) * std::sin(C) - std::sin(A) * std::cos(C),
       std::cos(A) * std::sin(B) * std::cos(C) + std::sin(A) * std::sin(C)},
      {std::sin(A) * std::cos(B), std::sin(A) * std::sin(B) * std::sin(C) + std::cos(A) * std::cos(C),
       std::sin(A) * std::sin(B) * std::cos(C) - std::cos(A) * std::sin(C)},
      {-std::sin(B), std::cos(B) * std::sin(C), std::cos(B) * std::cos(C)}};
  const auto g = grid_points(k, 3);
  std::vector<double> pts(g.size());
  for (std::size_t i = 0; i < g.size() / 3; ++i)
    for (int r = 0; r < 3; ++r) pts[3 * i + r] = R[r][0] * g[3 * i] + R[r][1] * g[3 * i + 1] + R[r][2] * g[3 * i + 2];
  const auto c = run(pts, 3);
  check_invariants(c, pts, {}, "rotated lattice 8^3");
  std::size_t checked = 0;
  for (std::size_t i = 0; i < g.size() / 3; ++i) {
    bool interior = true;
    for (int a = 0; a < 3; ++a) {
      interior &= g[3 * i + a] >= 1 && g[3 * i + a] <= k - 2;
      interior &= pts[3 * i + a] - c.bounds.lo[a] > 0.9 && c.bounds.hi[a] - pts[3 * i + a] > 0.9;
    }
    if (!interior) continue;
    ++checked;
    EXPECT_NEAR(c.volume[c.cell_of[i]], 1.0, 1e-9) << "interior point " << i;
    for (int a = 0; a < 3; ++a) EXPECT_NEAR(c.centroid[3 * c.cell_of[i] + a], pts[3 * i + a], 1e-9);
  }
  EXPECT_GT(checked, 50u);
}

// Rectilinear grids: each axis's coordinates from a list of its own, with
// full mantissas and uneven steps (voxel centres of a 0.7 x 0.7 x 1.2 scan,
// stretched CFD grids), the points in shuffled order. Every cell corner is an
// exact tie of the 2^dim points around it (the corners of any axis-aligned
// box are cospherical), which BoxTiePredicate decides from the coordinates'
// pattern. Each cell is the box between the midpoints to its axis
// neighbours (the domain's planes at the ends): its volume, centroid and axis
// neighbours are checked against that, by the search and by insertion, and
// 1 and 2 threads give identical cells.
TEST(Invariants, RectilinearGrids) {
  std::mt19937_64 rng(2026);
  std::uniform_real_distribution<double> step(0.3, 1.7);
  for (int dim : {2, 3}) {
    const int k = dim == 3 ? 9 : 24;
    std::array<std::vector<double>, 3> axis;
    std::array<double, 3> lo{}, hi{};
    for (int a = 0; a < dim; ++a) {
      double x = 0.35 * (a + 1);
      for (int m = 0; m < k; ++m) axis[a].push_back(x += 0.7 * step(rng));
      lo[a] = axis[a].front() - 0.5;
      hi[a] = axis[a].back() + 0.5;
    }
    const auto box = make_bounds(lo, hi);
    std::vector<std::array<int, 3>> at;
    for (int m = 0; m < (dim == 3 ? k * k * k : k * k); ++m)
      at.push_back({m % k, (m / k) % k, dim == 3 ? m / (k * k) : 0});
    std::shuffle(at.begin(), at.end(), rng);
    std::vector<double> pts;
    for (const auto& ix : at)
      for (int a = 0; a < dim; ++a) pts.push_back(axis[a][static_cast<std::size_t>(ix[a])]);
    // The cell's extent along axis a, from the point at index m.
    auto extent = [&](int a, int m, double& from, double& to) {
      const auto& v = axis[a];
      from = m == 0 ? lo[a] : 0.5 * (v[m - 1] + v[m]);
      to = m == k - 1 ? hi[a] : 0.5 * (v[m] + v[m + 1]);
    };
    std::map<std::array<int, 3>, std::int32_t> id_of;
    for (std::size_t i = 0; i < at.size(); ++i) id_of[at[i]] = static_cast<std::int32_t>(i);
    for (const auto method : {tessera::CellMethod::search, tessera::CellMethod::insertion}) {
      SCOPED_TRACE(std::string(dim == 3 ? "3D" : "2D") + (method == tessera::CellMethod::search ? " search" : " insertion"));
      auto o = options(dim, box, 1);
      o.cell_method = method;
      const auto c = tessera::voronoi(std::span<const double>(pts), dim, {}, o);
      check_invariants(c, pts, {}, "rectilinear grid");
      std::size_t bad = 0;
      for (std::size_t i = 0; i < at.size(); ++i) {
        const auto cell = c.cell_of[i];
        ASSERT_GE(cell, 0);
        double vol = 1;
        for (int a = 0; a < dim; ++a) {
          double from, to;
          extent(a, at[i][a], from, to);
          vol *= to - from;
          if (!(std::abs(c.centroid[static_cast<std::size_t>(cell) * dim + a] - 0.5 * (from + to)) <= 1e-12 * (hi[a] - lo[a])) &&
              ++bad <= 5)
            ADD_FAILURE() << "point " << i << " centroid axis " << a;
        }
        if (!(std::abs(c.volume[cell] - vol) <= 1e-12 * vol) && ++bad <= 5)
          ADD_FAILURE() << "point " << i << " volume " << c.volume[cell] << " expected " << vol;
        const auto nb = neighbours_of(c, cell);
        for (int a = 0; a < dim; ++a)
          for (int s : {-1, 1}) {
            auto jx = at[i];
            jx[a] += s;
            if (jx[a] < 0 || jx[a] >= k) continue;
            if (!std::binary_search(nb.begin(), nb.end(), id_of[jx]) && ++bad <= 5)
              ADD_FAILURE() << "point " << i << " does not list its axis neighbour " << id_of[jx];
          }
      }
      EXPECT_EQ(bad, 0u);
      auto o2 = o;
      o2.threads = 2;
      const auto c2 = tessera::voronoi(std::span<const double>(pts), dim, {}, o2);
      EXPECT_EQ(c2.volume, c.volume);
      EXPECT_EQ(c2.neighbors, c.neighbors);
      EXPECT_EQ(c2.neighbor_offsets, c.neighbor_offsets);
    }
  }
}

TEST(Invariants, FibonacciSphere3D) {
  // 500 points on a sphere (co-spherical up to rounding) plus its centre: the
  // centre's cell has ~500 faces, all meeting the nearly degenerate outer cells.
  const int m = 500;
  std::vector<double> pts;
  const double golden = std::numbers::pi * (3.0 - std::sqrt(5.0));
  for (int i = 0; i < m; ++i) {
    const double z = 1.0 - 2.0 * (i + 0.5) / m;
    const double r = std::sqrt(1.0 - z * z);
    pts.insert(pts.end(), {r * std::cos(golden * i), r * std::sin(golden * i), z});
  }
  pts.insert(pts.end(), {0.0, 0.0, 0.0});
  const auto c = run(pts, 3);
  check_invariants(c, pts, {}, "fibonacci sphere 500 + centre");
  EXPECT_EQ(c.n_cells(), std::size_t(m + 1));
  EXPECT_EQ(neighbours_of(c, c.cell_of[m]).size(), std::size_t(m)) << "the centre touches every sphere point";
}

/// m random points projected onto the unit sphere about the origin.
std::vector<double> unit_sphere_points(int m, std::uint64_t seed) {
  std::vector<double> pts = random_points(static_cast<std::size_t>(m), 3, seed);
  for (int i = 0; i < m; ++i) {
    double* p = pts.data() + 3 * i;
    for (int a = 0; a < 3; ++a) p[a] -= 0.5;
    const double len = std::sqrt(p[0] * p[0] + p[1] * p[1] + p[2] * p[2]);
    for (int a = 0; a < 3; ++a) p[a] /= len;
  }
  return pts;
}

/// `sphere`'s points with the origin added first or last, and its index.
std::pair<std::vector<double>, int> with_centre(const std::vector<double>& sphere, bool first) {
  std::vector<double> pts = sphere;
  pts.insert(first ? pts.begin() : pts.end(), {0.0, 0.0, 0.0});
  return {pts, first ? 0 : static_cast<int>(sphere.size() / 3)};
}

TEST(Invariants, HugeCell3D) {
  // A point inside a shell of 3,000 random points: its cell has 3,000 faces,
  // past the dense edge maps (Hull's plane-pair table and the face walk's,
  // dense_planes and dense_face_pairs = 1024), which would take planes^2
  // entries (20,000 points: 4.3 GB and 1.6 GB); past them both use sparse
  // maps. By search and by insertion (which assembles the centre's cell from
  // its star, in the hashed map), with the mesh, on 1 and 2 threads. The
  // centre comes last, then first: as the lowest id it owns its ~6,000
  // vertices, which its neighbours find by key order (the mesh's crowded
  // owners; scanned, 40,000 sphere points took 1.7 s there).
  const int m = 3000;
  const std::vector<double> sphere = unit_sphere_points(m, 91);
  for (bool centre_first : {false, true}) {
    SCOPED_TRACE(centre_first ? "centre first" : "centre last");
    const auto [pts, centre] = with_centre(sphere, centre_first);
    std::vector<std::int32_t> first;
    for (auto method : {tessera::CellMethod::search, tessera::CellMethod::insertion})
      for (int threads : {1, 2}) {
        tessera::VoronoiOptions o = options(3, std::nullopt, threads);
        o.cell_method = method;
        const tessera::Cells c = tessera::voronoi(pts, 3, {}, o);
        check_invariants(c, pts, {}, "3,000 sphere points + centre");
        if (method == tessera::CellMethod::insertion) EXPECT_EQ(c.assembled_from_stars, c.n_cells());
        const auto nb = neighbours_of(c, c.cell_of[centre]);
        EXPECT_EQ(nb.size(), std::size_t(m)) << "every sphere point's bisector is tangent to the centre's cell";
        EXPECT_EQ(c.num_faces[c.cell_of[centre]], m);
        if (first.empty()) first = nb;
        EXPECT_EQ(nb, first);
      }
  }
}

TEST(Invariants, HugeCell3DPastSixteenBits) {
  // Cells past 65,535 faces: the hull's local plane indices are 32-bit since
  // stop 59 (before, the centre of these points stopped the run with a
  // length error), and the mesh keeps such a cell's face numbers in two
  // 16-bit halves (CellsCompositor::Batch::wide). The centre of 70,000
  // points on a sphere, last (one thread) and first (two threads; its
  // ~140,000 vertices then owned by the lowest id), assembled from its star
  // in the hashed edge map, with the mesh. (By the search its clips are quadratic in its
  // faces: 11 s.) A mesh that read only the low halves would give its faces
  // the wrong neighbours and vertices: check_invariants integrates every
  // cell's faces from the mesh.
  const int m = 70000;
  const std::vector<double> sphere = unit_sphere_points(m, 93);
  for (bool centre_first : {false, true}) {
    SCOPED_TRACE(centre_first ? "centre first" : "centre last");
    const auto [pts, centre] = with_centre(sphere, centre_first);
    {
      const int threads = centre_first ? 2 : 1;
      tessera::VoronoiOptions o = options(3, std::nullopt, threads);
      o.cell_method = tessera::CellMethod::insertion;
      const tessera::Cells c = tessera::voronoi(pts, 3, {}, o);
      check_invariants(c, pts, {}, "70,000 sphere points + centre");
      EXPECT_EQ(c.assembled_from_stars, c.n_cells());
      const std::size_t cell = static_cast<std::size_t>(c.cell_of[centre]);
      EXPECT_EQ(c.num_faces[cell], m);
      EXPECT_EQ(neighbours_of(c, c.cell_of[centre]).size(), std::size_t(m));
      // Its faces in the mesh: one per sphere point, each naming it.
      std::vector<char> named(static_cast<std::size_t>(m) + 1, 0);
      for (std::int64_t f = c.cell_face_offsets[cell]; f < c.cell_face_offsets[cell + 1]; ++f)
        named[static_cast<std::size_t>(c.face_neighbor[static_cast<std::size_t>(f)])] = 1;
      EXPECT_EQ(std::count(named.begin(), named.end(), 1), m);
    }
  }
}

TEST(Invariants, HugeCell2D) {
  // Polygons past 65,534 edges: a tile's local plane indices are 32-bit
  // since stop 57 (before, these failed with a length error). The centre of
  // 70,000 points on a circle, its cell assembled from its star, with the
  // mesh, on 1 and 2 threads. (By the search its clips are quadratic in its
  // edges; the insertion is the automatic method's choice there.)
  const int m = 70000;
  std::vector<double> pts = random_points(static_cast<std::size_t>(m), 2, 94);
  for (int i = 0; i < m; ++i) {
    const double a = 2 * std::numbers::pi * pts[2 * i];
    pts[2 * i] = std::cos(a);
    pts[2 * i + 1] = std::sin(a);
  }
  pts.insert(pts.end(), {0.0, 0.0});
  for (int threads : {1, 2}) {
    tessera::VoronoiOptions o = options(2, std::nullopt, threads);
    o.cell_method = tessera::CellMethod::insertion;
    const tessera::Cells c = tessera::voronoi(pts, 2, {}, o);
    check_invariants(c, pts, {}, "70,000 circle points + centre");
    EXPECT_EQ(c.assembled_from_stars, c.n_cells());
    EXPECT_EQ(c.num_faces[c.cell_of[m]], m);
  }
  // Points on a parabola (t, t^2): the triangulation fans from the end at
  // t = 0, whose star holds every point (past the 16-bit indices' 65,520),
  // and thousands of its vertices are far out and ill-conditioned. It is
  // assembled, those vertices solved exactly (Hull::assemble's rule): clipped
  // by its 80,000 neighbours it took seconds, quadratic in them. (Not
  // check_invariants: the needle cells' areas from the merged mesh differ
  // from their own by up to ~1e-6, past its 1e-9, as before stop 57 at any
  // size; the library's validation and the area sum hold.)
  std::vector<double> curve = random_points(80000, 1, 95);
  std::vector<double> parabola;
  for (const double t : curve) parabola.insert(parabola.end(), {t, t * t});
  const tessera::Cells c = tessera::voronoi(parabola, 2, {}, options(2));
  EXPECT_TRUE(c.from_insertion);
  EXPECT_EQ(c.n_cells(), curve.size());
  EXPECT_EQ(c.assembled_from_stars, c.n_cells());
  EXPECT_TRUE(tessera::validate(c, {}).ok);
  double area = 0;
  for (const double v : c.volume) area += v;
  EXPECT_NEAR(area, box_volume(c.bounds, 2), 1e-12 * box_volume(c.bounds, 2));
  // At 400,000 points the end's star also has ill-conditioned vertices near
  // the box. Solved at once, they let its box cut decide; deferred (stop
  // 58, briefly), their wide bounds near a box plane gave the cell up to
  // the clips, 13.5M exact evaluations and 16 s, on two of three inputs.
  for (const std::uint64_t seed : {96, 97}) {
    std::vector<double> t = random_points(400000, 1, seed), big;
    for (const double x : t) big.insert(big.end(), {x, x * x});
    const tessera::Cells b = tessera::voronoi(big, 2, {}, options(2));
    EXPECT_LT(b.exact_predicate_calls, 1000u);  // (a dozen cells near the box's corners are clipped)
  }
}

// The centre of 3,000 points on a sphere, the only inside point: the pilot
// measures so few generators too (one band of them all, capped), finds the
// cell costly and takes it from its Delaunay star. Searched, its clips cost
// time quadratic in its 3,000 faces (40,000 points: 2.4 s, against 0.3 s).
// The labelled Delaunay declines its cells pass the same way where that costs
// more than the whole triangulation, filtered (outside_simplices counts it).
TEST(Invariants, HugeCellAloneInsideComesFromItsStar) {
  const int m = 3000;
  std::vector<double> pts = unit_sphere_points(m, 92);
  pts.insert(pts.begin(), {0.0, 0.0, 0.0});
  std::vector<std::int32_t> labels(static_cast<std::size_t>(m) + 1, -1);
  labels[0] = 0;
  const tessera::Cells c = tessera::voronoi(pts, 3, labels, options(3));
  EXPECT_TRUE(c.from_insertion);
  EXPECT_EQ(c.assembled_from_stars, 1u);
  ASSERT_EQ(c.n_cells(), 1u);
  EXPECT_EQ(c.num_faces[0], m);
  auto o = options(3);
  o.cell_method = tessera::CellMethod::search;
  const tessera::Cells s = tessera::voronoi(pts, 3, labels, o);
  EXPECT_EQ(neighbours_of(s, 0), neighbours_of(c, 0));
  EXPECT_NEAR(s.volume[0], c.volume[0], 1e-12 * c.volume[0]);

  // The Delaunay's pass declines where the cells cost more in all than the
  // whole triangulation: 20,000 sphere points (its pilot's cell is capped).
  const int big = 20000;
  std::vector<double> many = unit_sphere_points(big, 93);
  many.insert(many.begin(), {0.0, 0.0, 0.0});
  std::vector<std::int32_t> alone(static_cast<std::size_t>(big) + 1, -1);
  alone[0] = 0;
  tessera::DelaunayOptions d;
  d.dim = 3;
  const tessera::Delaunay dt = tessera::delaunay(many, 3, alone, d);
  EXPECT_EQ(dt.n_simplices(), 0u);
  EXPECT_GT(dt.outside_simplices, 0u) << "the whole triangulation was filtered";
}

TEST(Invariants, IntegerSphere3D) {
  // All 390 integer points with x^2+y^2+z^2 = 33^2: EXACTLY co-spherical (the
  // whole input is one degenerate configuration), plus the centre.
  const int r = 33;
  std::vector<double> pts;
  for (int x = -r; x <= r; ++x)
    for (int y = -r; y <= r; ++y)
      for (int z = -r; z <= r; ++z)
        if (x * x + y * y + z * z == r * r) pts.insert(pts.end(), {double(x), double(y), double(z)});
  ASSERT_EQ(pts.size() / 3, 390u);
  pts.insert(pts.end(), {0.0, 0.0, 0.0});
  const auto c = run(pts, 3);
  check_invariants(c, pts, {}, "integer sphere r=33 + centre");
  EXPECT_EQ(c.n_cells(), pts.size() / 3);
  EXPECT_EQ(neighbours_of(c, c.cell_of[390]).size(), 390u) << "the centre touches every sphere point";
}

TEST(Invariants, Grid2D) {
  const int k = 30;
  const auto pts = grid_points(k, 2);
  const auto box = make_bounds({-0.5, -0.5, 0}, {k - 0.5, k - 0.5, 0});
  const auto c = run(pts, 2, box);
  check_invariants(c, pts, {}, "integer grid 30^2");
  check_lattice_cells(c, pts, 2, k, 1.0, "integer grid 30^2");
  check_invariants(run(pts, 2), pts, {}, "integer grid 30^2 default box");

  const auto vox = grid_points(k, 2, 1.0, 0.5);
  const auto vb = make_bounds({0, 0, 0}, {double(k), double(k), 0});
  const auto cv = run(vox, 2, vb);
  check_invariants(cv, vox, {}, "pixel centres 30^2");
  check_lattice_cells(cv, vox, 2, k, 1.0, "pixel centres 30^2");

  const auto tenth = grid_points(k, 2, 0.1);
  check_invariants(run(tenth, 2), tenth, {}, "0.1 grid 30^2 default box");
}

TEST(Invariants, Circle2D) {
  // Exactly co-circular: the 324 integer points on x^2+y^2 = 32045^2, plus the centre.
  const long long r = 32045;
  std::vector<double> pts;
  for (long long x = -r; x <= r; ++x) {
    const long long y2 = r * r - x * x;
    long long y = (long long)std::llround(std::sqrt(double(y2)));
    while (y * y > y2) --y;
    while ((y + 1) * (y + 1) <= y2) ++y;
    if (y * y != y2) continue;
    pts.insert(pts.end(), {double(x), double(y)});
    if (y != 0) pts.insert(pts.end(), {double(x), double(-y)});
  }
  ASSERT_EQ(pts.size() / 2, 324u);
  pts.insert(pts.end(), {0.0, 0.0});
  const auto c = run(pts, 2);
  check_invariants(c, pts, {}, "integer circle + centre");
  EXPECT_EQ(neighbours_of(c, c.cell_of[324]).size(), 324u) << "the centre touches every circle point";

  // Nearly co-circular: cos/sin points, plus the centre.
  std::vector<double> q;
  for (int i = 0; i < 400; ++i)
    q.insert(q.end(), {std::cos(2 * std::numbers::pi * i / 400), std::sin(2 * std::numbers::pi * i / 400)});
  q.insert(q.end(), {0.0, 0.0});
  const auto cq = run(q, 2);
  check_invariants(cq, q, {}, "cos/sin circle + centre");
  EXPECT_EQ(neighbours_of(cq, cq.cell_of[400]).size(), 400u);
}

// ------------------------------------------------------------------ near / exact duplicates

/// Each base point i gets a partner at distance `sep` (a random direction, or
/// along +x when along_x): both must own a cell, list each other, and their
/// cells together must be the base point's cell without the partner.
void near_duplicates(int dim, const std::vector<double>& base, std::optional<tessera::Bounds> box, double sep,
                     bool along_x, std::uint64_t seed, const std::string& what) {
  SCOPED_TRACE(what);
  const std::size_t n = base.size() / dim;
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> nd;
  std::vector<double> pts = base;
  for (std::size_t i = 0; i < n; ++i) {
    std::array<double, 3> d{1, 0, 0};
    if (!along_x) {
      double s = 0;
      for (int a = 0; a < dim; ++a) s += (d[a] = nd(rng)) * d[a];
      for (int a = 0; a < dim; ++a) d[a] /= std::sqrt(s);
    }
    for (int a = 0; a < dim; ++a) pts.push_back(base[i * dim + a] + sep * d[a]);
  }
  const auto c = run(pts, dim, box);
  check_invariants(c, pts, {}, what);
  EXPECT_TRUE(c.duplicates.empty());
  const auto alone = run(base, dim, c.bounds);
  std::size_t bad = 0;
  for (std::size_t i = 0; i < n; ++i) {
    const auto a = c.cell_of[i], b = c.cell_of[n + i];
    ASSERT_GE(a, 0);
    ASSERT_GE(b, 0);
    auto na = neighbours_of(c, a), nb = neighbours_of(c, b);
    if (!std::binary_search(na.begin(), na.end(), std::int32_t(n + i)) ||
        !std::binary_search(nb.begin(), nb.end(), std::int32_t(i))) {
      if (++bad <= 5) ADD_FAILURE() << "near-duplicate pair " << i << "," << n + i << " are not neighbours";
    }
    const double v = alone.volume[alone.cell_of[i]];
    if (!(std::abs(c.volume[a] + c.volume[b] - v) <= 1e-9 * v) && ++bad <= 5)
      ADD_FAILURE() << "pair " << i << " volumes " << c.volume[a] << "+" << c.volume[b] << " != " << v;
  }
  EXPECT_EQ(bad, 0u);
}

TEST(Invariants, NearDuplicates) {
  near_duplicates(3, random_points(300, 3, 201), unit_box(), 1e-12, false, 1, "3D random pairs 1e-12");
  near_duplicates(2, random_points(500, 2, 202), unit_box(), 1e-12, false, 2, "2D random pairs 1e-12");
  // Pairs on a lattice, split along an axis: the splitting bisectors pass
  // (nearly) through the lattice's co-spherical vertices.
  near_duplicates(3, grid_points(5, 3), std::nullopt, 4e-12, true, 3, "3D grid pairs along x");
  near_duplicates(2, grid_points(10, 2), std::nullopt, 9e-12, true, 4, "2D grid pairs along x");
}

/// Inserts exact duplicates (including a triple and a copy placed BEFORE its
/// original) and checks: each duplicate is reported once as (dup, lowest id),
/// owns no cell, and the cells equal those of the input without duplicates.
void exact_duplicates(int dim, std::uint64_t seed) {
  SCOPED_TRACE(::testing::Message() << "dim " << dim);
  const std::size_t n0 = 200;
  std::vector<double> pts = random_points(n0, dim, seed);
  auto copy = [&](std::size_t from) {
    for (int a = 0; a < dim; ++a) pts.push_back(pts[from * dim + a]);
  };
  for (int a = 0; a < dim; ++a) pts[3 * dim + a] = pts[150 * dim + a];  // 3 and 150 coincide: 3 owns
  copy(5);
  copy(5);  // 5, 200, 201: a triple
  copy(17);
  copy(199);
  copy(150);  // 3, 150, 204
  const std::vector<std::pair<std::int32_t, std::int32_t>> want = {{150, 3}, {200, 5}, {201, 5}, {202, 17}, {203, 199}, {204, 3}};
  const auto c = run(pts, dim, unit_box());
  check_invariants(c, pts, {}, "exact duplicates");
  auto got = c.duplicates;
  std::sort(got.begin(), got.end());
  EXPECT_EQ(got, want);
  for (auto [d, o] : want) {
    EXPECT_EQ(c.cell_of[d], -1) << "duplicate " << d;
    EXPECT_GE(c.cell_of[o], 0) << "owner " << o;
  }
  EXPECT_EQ(c.n_cells(), n0 - 1);

  // Same cells as the deduplicated input (ids mapped back).
  std::vector<double> uniq;
  std::vector<std::int32_t> old_id;
  for (std::size_t i = 0; i < pts.size() / dim; ++i) {
    if (std::any_of(want.begin(), want.end(), [&](auto p) { return p.first == std::int32_t(i); })) continue;
    old_id.push_back(std::int32_t(i));
    for (int a = 0; a < dim; ++a) uniq.push_back(pts[i * dim + a]);
  }
  const auto u = run(uniq, dim, unit_box());
  ASSERT_EQ(u.n_cells(), c.n_cells());
  for (std::size_t k = 0; k < u.n_cells(); ++k) {
    const auto g = old_id[u.generator[k]];
    const auto ck = c.cell_of[g];
    ASSERT_GE(ck, 0);
    EXPECT_NEAR(c.volume[ck], u.volume[k], 1e-12 * u.volume[k]) << "generator " << g;
    std::vector<std::int32_t> mapped;
    for (auto j : neighbours_of(u, k)) mapped.push_back(old_id[j]);
    EXPECT_EQ(neighbours_of(c, ck), mapped) << "generator " << g;
  }
}

TEST(Invariants, ExactDuplicates) {
  exact_duplicates(2, 301);
  exact_duplicates(3, 302);
}

/// A pile of many copies of one point among distinct points: the pass leaves
/// the copies out of the locator, so the cells are those of the distinct
/// points, by the search and by the insertion, and every copy is reported.
/// (Kept in the locator, 70,000 copies made the search's cells beside the
/// pile clip by copy after copy past the 65,534-face limit, and 60,000 copies
/// alone took 97 s.)
TEST(Invariants, PileOfCopies) {
  for (int dim : {2, 3}) {
    SCOPED_TRACE("dim " + std::to_string(dim));
    const std::size_t copies = 70000, n0 = 2000;
    std::vector<double> pts = random_points(n0, dim, 420 + dim);
    for (std::size_t k = 1; k < copies; ++k)
      for (int a = 0; a < dim; ++a) pts.push_back(pts[a]);  // copies of point 0
    const auto base = run(std::vector<double>(pts.begin(), pts.begin() + static_cast<std::ptrdiff_t>(n0 * dim)), dim, unit_box());
    for (auto method : {tessera::CellMethod::search, tessera::CellMethod::insertion}) {
      auto o = options(dim, unit_box(), 2);
      o.cell_method = method;
      const auto c = tessera::voronoi(std::span<const double>(pts), dim, {}, o);
      ASSERT_EQ(c.duplicates.size(), copies - 1);
      for (std::size_t k = 0; k < c.duplicates.size(); ++k)
        EXPECT_EQ(c.duplicates[k], std::make_pair(static_cast<std::int32_t>(n0 + k), 0));
      ASSERT_EQ(c.n_cells(), n0);
      for (std::size_t i = 0; i < n0; ++i) {
        EXPECT_NEAR(c.volume[i], base.volume[i], 1e-12 * base.volume[i]) << "point " << i;
        EXPECT_EQ(neighbours_of(c, c.cell_of[i]), neighbours_of(base, base.cell_of[i])) << "point " << i;
      }
    }
  }
}

TEST(Invariants, DuplicatesOnGrid) {
  // Every point of a degenerate grid given twice: the second copies are all duplicates.
  for (int dim : {2, 3}) {
    auto pts = grid_points(dim == 2 ? 12 : 6, dim);
    const std::size_t n = pts.size() / dim;
    pts.insert(pts.end(), pts.begin(), pts.end());
    const auto c = run(pts, dim);
    check_invariants(c, pts, {}, "doubled grid dim " + std::to_string(dim));
    EXPECT_EQ(c.n_cells(), n);
    EXPECT_EQ(c.duplicates.size(), n);
    for (auto [d, o] : c.duplicates) EXPECT_EQ(std::size_t(d), std::size_t(o) + n);
  }
}

// ------------------------------------------------------------------ labels

/// Points labelled -1 clip their neighbours but own no cell: the inside cells
/// are exactly the cells of the unlabelled run (volume and neighbour list,
/// outside neighbours included), and the missing volume is the outside cells'.
void labelled(int dim, const std::vector<double>& pts, std::uint64_t seed, const std::string& what) {
  SCOPED_TRACE(what);
  const std::size_t n = pts.size() / dim;
  std::mt19937_64 rng(seed);
  std::vector<std::int32_t> labels(n);
  for (auto& l : labels) l = std::int32_t(rng() % 4) - 1;  // -1, 0, 1, 2
  const auto c = run(pts, dim, std::nullopt, labels);
  InvariantOptions io;
  io.all_inside = false;
  check_invariants(c, pts, labels, what, io);
  const auto all = run(pts, dim, c.bounds);
  double inside = 0, outside = 0;
  std::size_t n_inside = 0;
  for (std::size_t i = 0; i < n; ++i) {
    const double va = all.volume[all.cell_of[i]];
    if (labels[i] < 0) {
      EXPECT_EQ(c.cell_of[i], -1);
      outside += va;
      continue;
    }
    ++n_inside;
    const auto k = c.cell_of[i];
    ASSERT_GE(k, 0);
    inside += c.volume[k];
    EXPECT_NEAR(c.volume[k], va, 1e-12 * va) << "point " << i;
    EXPECT_EQ(neighbours_of(c, k), neighbours_of(all, all.cell_of[i])) << "point " << i;
  }
  EXPECT_EQ(c.n_cells(), n_inside);
  const double dom = box_volume(c.bounds, dim);
  EXPECT_LT(inside, dom);
  EXPECT_NEAR(inside + outside, dom, 1e-12 * dom);
}

TEST(Invariants, Labels) {
  labelled(3, random_points(2000, 3, 401), 1, "3D random labelled");
  labelled(2, random_points(2000, 2, 402), 2, "2D random labelled");
  labelled(3, grid_points(8, 3), 3, "3D grid labelled");
  labelled(2, grid_points(20, 2), 4, "2D grid labelled");
}

/// Duplicates whose labels differ: the lowest id of the group decides alone.
/// An inside copy of an outside point owns no cell (and is reported); an
/// outside copy of an inside point changes nothing. The result is the
/// labelled run without the higher copies.
TEST(Invariants, DuplicatesAcrossLabelsFollowTheLowestId) {
  for (int dim : {2, 3}) {
    SCOPED_TRACE("dim " + std::to_string(dim));
    auto pts = random_points(500, dim, 410 + dim);
    const std::size_t n = pts.size() / dim;
    std::vector<std::int32_t> labels(n, 0);
    for (std::size_t i = 0; i < n; i += 5) labels[i] = -1;
    // Copies of points 0..19 at ids n..n+19, with the opposite side's label.
    for (std::size_t i = 0; i < 20; ++i) {
      for (int d = 0; d < dim; ++d) pts.push_back(pts[i * dim + d]);
      labels.push_back(labels[i] < 0 ? 3 : -1);
    }
    const auto c = run(pts, dim, std::nullopt, labels);
    const auto base = run(std::vector<double>(pts.begin(), pts.begin() + static_cast<std::ptrdiff_t>(n * dim)), dim,
                          c.bounds, std::vector<std::int32_t>(labels.begin(), labels.begin() + static_cast<std::ptrdiff_t>(n)));
    std::vector<std::pair<std::int32_t, std::int32_t>> want;
    for (std::size_t i = 0; i < 20; ++i)
      if (labels[i] < 0) want.emplace_back(static_cast<std::int32_t>(n + i), static_cast<std::int32_t>(i));
    EXPECT_EQ(c.duplicates, want);  // only the inside copies are reported
    ASSERT_EQ(c.n_cells(), base.n_cells());
    for (std::size_t i = 0; i < 20; ++i) EXPECT_EQ(c.cell_of[n + i], -1) << "copy of point " << i;
    for (std::size_t i = 0; i < n; ++i) {
      ASSERT_EQ(c.cell_of[i], base.cell_of[i]) << "point " << i;
      if (c.cell_of[i] < 0) continue;
      EXPECT_EQ(c.volume[c.cell_of[i]], base.volume[base.cell_of[i]]) << "point " << i;
      EXPECT_EQ(neighbours_of(c, c.cell_of[i]), neighbours_of(base, base.cell_of[i])) << "point " << i;
    }
    // The insertion's cells follow the same rule.
    auto o = options(dim);
    o.cell_method = tessera::CellMethod::insertion;
    const auto ins = tessera::voronoi(std::span<const double>(pts), dim, std::span<const std::int32_t>(labels), o);
    EXPECT_EQ(ins.duplicates, want);
    EXPECT_EQ(ins.cell_of, c.cell_of);
  }
}

// ------------------------------------------------------------------ threads

/// The result is independent of the thread count: every vector is identical.
void same_for_threads(int dim, const std::vector<double>& pts, const std::vector<std::int32_t>& labels,
                      const std::string& what) {
  SCOPED_TRACE(what);
  const auto a = run(pts, dim, std::nullopt, labels, 1);
  const auto b = run(pts, dim, std::nullopt, labels, 2);
  EXPECT_EQ(a.threads_used, 1);
  EXPECT_GE(b.threads_used, 1);
  EXPECT_LE(b.threads_used, 2);
  expect_same_cells(a, b, "between 1 and 2 threads");
  if (a.exact_predicate_calls != b.exact_predicate_calls)
    std::printf("[ note ] %s: exact_predicate_calls %llu (1 thread) vs %llu (2 threads)\n", what.c_str(),
                (unsigned long long)a.exact_predicate_calls, (unsigned long long)b.exact_predicate_calls);
}

TEST(Invariants, ThreadCountDoesNotChangeResult) {
  same_for_threads(3, random_points(4000, 3, 501), {}, "3D random");
  same_for_threads(2, random_points(4000, 2, 502), {}, "2D random");
  same_for_threads(3, grid_points(8, 3), {}, "3D grid");
  auto pts = random_points(3000, 3, 503);
  std::mt19937_64 rng(5);
  std::vector<std::int32_t> labels(3000);
  for (auto& l : labels) l = std::int32_t(rng() % 3) - 1;
  pts.insert(pts.end(), pts.begin(), pts.begin() + 300);  // 100 duplicates
  labels.insert(labels.end(), labels.begin(), labels.begin() + 100);
  same_for_threads(3, pts, labels, "3D labelled with duplicates");
}

// Coordinates near 2^±410 (1e∓124) and 2^±500: the pass computes in a frame
// rescaled by a power of two, so the cells are those of the unit-scale
// points exactly, while their volumes in the input's units fall outside
// double's range. The validator then skips the volume checks (and says so)
// rather than failing on volumes a double cannot hold, and still checks the
// topology; at unit scale it checks the volumes as before.
TEST(Invariants, ExtremeScalesKeepTopologyAndSkipUnrepresentableVolumes) {
  for (int dim : {2, 3}) {
    const auto unit = random_points(400, dim, 611);
    const tessera::Cells u = run(unit, dim);
    const tessera::ValidationReport ru = tessera::validate(u, {});
    EXPECT_TRUE(ru.ok);
    EXPECT_TRUE(ru.volumes_checked);
    for (int e : {-410, 410, -500, 500}) {
      std::vector<double> p(unit);
      for (double& x : p) x = std::ldexp(x, e);
      const tessera::Cells c = run(p, dim);
      const tessera::ValidationReport r = tessera::validate(c, {});
      for (const auto& m : r.messages) ADD_FAILURE() << "dim " << dim << " 2^" << e << ": " << m;
      EXPECT_TRUE(r.ok) << "dim " << dim << " 2^" << e;
      // 2^(±410 dim) is within double's range in 2D (±820) but not in 3D (±1230).
      EXPECT_EQ(r.volumes_checked, dim == 2 && (e == -410 || e == 410)) << "dim " << dim << " 2^" << e;
      EXPECT_EQ(c.neighbors, u.neighbors) << "dim " << dim << " 2^" << e;
      EXPECT_EQ(c.neighbor_offsets, u.neighbor_offsets) << "dim " << dim << " 2^" << e;
      EXPECT_EQ(c.num_faces, u.num_faces) << "dim " << dim << " 2^" << e;
    }
  }
}

// Across scales computed with and without rescaling (front/pass.cpp,
// choose_scaling), the cells are those of the unit-scale points, bit for bit
// in their topology: every decision is exact and scaling by a power of two
// changes none. The
// candidates' sort keys once held r2 as a float, which overflowed past
// coordinates of 2^64 and underflowed below 2^-63: the stop rule then
// skipped nearer candidates (wrong cells, caught only by the mesh merge).
TEST(Invariants, PowerOfTwoScalesGiveTheSameCells) {
  for (int dim : {2, 3}) {
    const auto unit = random_points(300, dim, 612);
    const tessera::Cells u = run(unit, dim);
    for (int e : {-199, -150, -90, -70, -40, 40, 66, 70, 90, 150, 199}) {
      std::vector<double> p(unit);
      for (double& x : p) x = std::ldexp(x, e);
      const tessera::Cells c = run(p, dim);
      EXPECT_TRUE(tessera::validate(c, {}).ok) << "dim " << dim << " 2^" << e;
      EXPECT_EQ(c.neighbors, u.neighbors) << "dim " << dim << " 2^" << e;
      EXPECT_EQ(c.neighbor_offsets, u.neighbor_offsets) << "dim " << dim << " 2^" << e;
      EXPECT_EQ(c.face_vertices, u.face_vertices) << "dim " << dim << " 2^" << e;
    }
  }
}

// Five points near 1e-65, a few ulps apart (from the fuzz). Just above the
// old rescaling threshold (2^-200) they were computed unscaled, a vertex's
// Cramer numerator underflowed to 0 where it is 1e-85, and the cells
// disagreed ("cell vertices have no match"). Scaled by 2^k around that
// threshold; then beside points of size 1 (the pass shifts the whole range,
// 1e-71 to 1, up by 2^87); then, shifted by 2^-33, beside points of size
// 2^166: a range of more than 2^347 that no shift brings within the safe
// limits, so the vertex bounds carry filter::underflow_slack (without it this
// input fails: "cell vertices have no match").
TEST(Invariants, CoordinatesNearUnderflowKeepExactTopology) {
  const auto tiny = tessera::io::read_points(std::string(TESSERA_TEST_DATA_DIR) +
                                             "/tiny_coordinates_near_rescale_threshold_3d.npy").coords;
  for (int k = -6; k <= 8; ++k) {
    std::vector<double> p(tiny);
    for (double& x : p) x = std::ldexp(x, k);
    const tessera::Cells c = run(p, 3);
    const tessera::ValidationReport r = tessera::validate(c, {});
    for (const auto& m : r.messages) ADD_FAILURE() << "2^" << k << ": " << m;
  }
  std::vector<double> wide(tiny);
  wide.insert(wide.end(), {1.0, 1.0, 1.0, -1.0, 0.5, -1.0, 0.25, -1.0, 0.5});
  const tessera::Cells c = run(wide, 3);
  const tessera::ValidationReport r = tessera::validate(c, {});
  for (const auto& m : r.messages) ADD_FAILURE() << "beside unit points: " << m;
  same_for_threads(3, wide, {}, "tiny cluster beside unit points");
  std::vector<double> wider(tiny);
  for (double& x : wider) x = std::ldexp(x, -33);
  const double h = 0x1p166;
  wider.insert(wider.end(), {h, h, h, -h, h / 2, -h, h / 4, -h, h / 2});
  const tessera::Cells cw = run(wider, 3);
  const tessera::ValidationReport rw = tessera::validate(cw, {});
  for (const auto& m : rw.messages) ADD_FAILURE() << "beside points of 2^166: " << m;
  same_for_threads(3, wider, {}, "tiny cluster beside points of 2^166");
}

// Points a subnormal distance off the planes their neighbours span
// (subnormal_offset_points; the fuzz's Delaunay failures were of this kind):
// exact topology (symmetric spokes, every merged vertex shared by exactly its
// generators' cells, Euler characteristic), volumes summing to the domain's
// (slivers a subnormal thick are measured exactly; cells a subnormal across
// in every direction have volumes no double holds, counted as underflowed),
// and 1 vs 2 threads identical.
TEST(Invariants, SubnormalOffsetsKeepExactTopology) {
  std::size_t underflowed = 0;
  for (int dim : {2, 3})
    for (std::uint64_t seed = 1; seed <= 8; ++seed) {
      const std::vector<double> p = subnormal_offset_points(60, dim, seed + 100);
      const tessera::Cells c = run(p, dim);
      const tessera::ValidationReport r = tessera::validate(c, {});
      for (const auto& m : r.messages) ADD_FAILURE() << "dim " << dim << " seed " << seed << ": " << m;
      EXPECT_EQ(r.asymmetric_spokes, 0u) << "dim " << dim << " seed " << seed;
      EXPECT_EQ(r.bad_vertex_degree, 0u) << "dim " << dim << " seed " << seed;
      EXPECT_EQ(r.bad_euler, 0u) << "dim " << dim << " seed " << seed;
      underflowed += r.underflowed_volumes;
      same_for_threads(dim, p, {}, "subnormal offsets, dim " + std::to_string(dim) + " seed " + std::to_string(seed));
    }
  EXPECT_GT(underflowed, 0u) << "the sweep should include cells too small for a double's volume";
}

// Slivers thinner than the rounding of their own vertices (from the fuzz):
// five points within a few ulps of each other near 4e7, and 2D points at
// 4.7e80 whose y differ by 3e-244. Their float volumes cancelled to zero or
// below; measure() now detects the cancellation and measures such cells
// exactly, so every volume is positive and they sum to the domain's.
TEST(Invariants, SliverCellsGetExactPositiveVolumes) {
  for (const auto& [name, dim] : {std::pair{"cells_ulp_near_duplicates_3d", 3}, std::pair{"cells_underflowing_separation_2d", 2}}) {
    tessera::io::ReadOptions ro;
    ro.dim = dim;
    const auto p = tessera::io::read_points(std::string(TESSERA_TEST_DATA_DIR) + "/" + name + ".npy", ro).coords;
    for (int threads : {1, 2}) {
      const tessera::Cells c = run(p, dim, std::nullopt, {}, threads);
      const tessera::ValidationReport r = tessera::validate(c, {});
      for (const auto& m : r.messages) ADD_FAILURE() << name << ": " << m;
      for (double v : c.volume) EXPECT_GT(v, 0) << name;
    }
  }
}

}  // namespace

// Merged vertices on a box plane (their key names it) lie on it exactly and
// inside the box: the float solve had left such coordinates an ulp or so off,
// outside the box as often as not (a fuzz of the surface nets: 5.6e-17
// outside a unit box). Also at scales the pass rescales, in a box away from
// the origin, with labels, by either method, and with walls beside periodic
// axes.
TEST(Invariants, VerticesOnBoxPlanesLieOnThem) {
  for (const int dim : {2, 3}) {
    const auto far = make_bounds({100.1, -0.3, 5}, {103.7, -0.01, 5.9});
    for (const double scale : {1.0, std::ldexp(1.0, -170), std::ldexp(1.0, 170)}) {
      for (const bool insertion : {false, true}) {
        for (const bool periodic : {false, true}) {
          tessera::Bounds box = far;
          for (int a = 0; a < 3; ++a) {
            box.lo[a] *= scale;
            box.hi[a] *= scale;
          }
          auto pts = random_points(2000, dim, 881, far);
          for (double& x : pts) x *= scale;
          tessera::VoronoiOptions o;
          o.dim = dim;
          o.bounds = box;
          o.build_mesh = true;
          o.cell_method = insertion ? tessera::CellMethod::insertion : tessera::CellMethod::search;
          if (periodic) o.periodic = {true, false, false};  // walls along y (and z)
          std::vector<std::int32_t> labels(pts.size() / static_cast<std::size_t>(dim));
          for (std::size_t i = 0; i < labels.size(); ++i) labels[i] = i % 7 == 0 ? -1 : static_cast<int>(i % 3);
          const tessera::Cells c = tessera::voronoi(pts, dim, labels, o);
          const auto w = static_cast<std::size_t>(dim + 1);
          const std::size_t nv = c.vertex_keys.size() / w;
          ASSERT_GT(nv, 0u);
          std::size_t on_planes = 0;
          for (std::size_t v = 0; v < nv; ++v) {
            const double* x = &c.vertices[v * static_cast<std::size_t>(dim)];
            for (int a = 0; a < dim; ++a)
              if (!(periodic && a == 0)) {
                ASSERT_GE(x[a], c.bounds.lo[a]) << "dim " << dim << " scale " << scale << " vertex " << v;
                ASSERT_LE(x[a], c.bounds.hi[a]) << "dim " << dim << " scale " << scale << " vertex " << v;
              }
            for (std::size_t k = 0; k < w && c.vertex_keys[v * w + k] < 0; ++k) {
              const int plane = -1 - c.vertex_keys[v * w + k];
              ASSERT_EQ(x[plane / 2], plane % 2 ? c.bounds.hi[plane / 2] : c.bounds.lo[plane / 2])
                  << "dim " << dim << " scale " << scale << " vertex " << v << " plane " << -1 - plane;
              ++on_planes;
            }
          }
          EXPECT_GT(on_planes, 100u);
        }
      }
    }
  }
}

// Delaunay by incremental insertion (DelaunayMethod::insertion): the same rows
// as the cells pass, byte for byte, on general-position and degenerate input
// (lattices, co-spherical and co-planar points, where the symbolic
// perturbation chooses), the same duplicates, a valid triangulation; and the
// automatic choice takes it for surface samples, for inputs without ties on
// one or two threads, and where the cells pass would stall (points nearly
// on a sphere, near-coplanar hull faces). Its parallel phases
// give the serial rows for any thread count.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <random>
#include <string>
#include <utility>
#include <vector>

#include "common/hostile_points.hpp"
#include "insert_points.hpp"
#include "random_points.hpp"
#include "tessera/delaunay.hpp"

namespace {

tessera::Delaunay triangulate(const std::vector<double>& p, tessera::DelaunayMethod method, int threads = 2) {
  tessera::DelaunayOptions o;
  o.dim = 3;
  o.threads = threads;
  o.method = method;
  return tessera::delaunay(p, 3, {}, o);
}

void expect_valid(const tessera::Delaunay& dt, const std::vector<double>& p, const std::string& what) {
  const tessera::DelaunayReport r = tessera::validate(dt, p, {});
  for (const auto& m : r.messages) ADD_FAILURE() << what << ": " << m;
  EXPECT_TRUE(r.ok) << what;
}

std::vector<double> grid3(int k, double step = 1) {
  std::vector<double> p;
  for (int i = 0; i < k; ++i)
    for (int j = 0; j < k; ++j)
      for (int l = 0; l < k; ++l) p.insert(p.end(), {step * i, step * j, step * l});
  return p;
}

std::vector<std::pair<std::string, std::vector<double>>> inputs() {
  std::mt19937_64 rng(5);
  std::normal_distribution<double> g;
  std::vector<std::pair<std::string, std::vector<double>>> in;
  in.emplace_back("uniform", uniform_points(3000, 3, 41));
  {
    std::vector<double> blobs;  // clusters of very different density
    for (int c = 0; c < 6; ++c) {
      const double cx = g(rng), cy = g(rng), cz = g(rng), r = c % 2 ? 0.01 : 0.2;
      for (int i = 0; i < 400; ++i) blobs.insert(blobs.end(), {cx + r * g(rng), cy + r * g(rng), cz + r * g(rng)});
    }
    in.emplace_back("blobs", std::move(blobs));
  }
  in.emplace_back("terrain", height_field(3000, 42));  // needle cells
  {
    // A height field on a grid with a flat floor: co-planar hull facets with
    // co-circular points (the floor), vertical sides of co-planar points.
    std::vector<double> dem;
    for (int i = 0; i < 30; ++i)
      for (int j = 0; j < 30; ++j) dem.insert(dem.end(), {double(i), double(j), std::max(0.0, std::round(8 * std::sin(0.3 * i) * std::cos(0.2 * j)))});
    in.emplace_back("grid height field", std::move(dem));
  }
  in.emplace_back("lattice", grid3(9));
  in.emplace_back("lattice of step 0.1", grid3(7, 0.1));
  {
    std::vector<double> rot;  // a rotated lattice: inexact coordinates
    const double c = std::cos(0.3), s = std::sin(0.3);
    for (int i = 0; i < 7; ++i)
      for (int j = 0; j < 7; ++j)
        for (int l = 0; l < 7; ++l) rot.insert(rot.end(), {c * i - s * j, s * i + c * j, double(l)});
    in.emplace_back("rotated lattice", std::move(rot));
  }
  {
    std::vector<double> shells;  // integer points on two spheres: co-spherical
    for (int x = -7; x <= 7; ++x)
      for (int y = -7; y <= 7; ++y)
        for (int z = -7; z <= 7; ++z)
          if (x * x + y * y + z * z == 49 || x * x + y * y + z * z == 25) shells.insert(shells.end(), {double(x), double(y), double(z)});
    in.emplace_back("sphere shells", std::move(shells));
  }
  {
    std::vector<double> sphere;  // random points normalised onto a sphere
    for (int i = 0; i < 400; ++i) {
      double x = g(rng), y = g(rng), z = g(rng);
      const double r = std::sqrt(x * x + y * y + z * z);
      sphere.insert(sphere.end(), {x / r, y / r, z / r});
    }
    in.emplace_back("sphere", std::move(sphere));
  }
  in.emplace_back("cube faces", cube_face_points(200, 500, 46));
  {
    std::vector<double> spiral;  // near the moment curve: many thin hull simplices
    for (int i = 0; i < 300; ++i) {
      const double t = 0.05 * i;
      spiral.insert(spiral.end(), {t * std::cos(t), t * std::sin(t), 0.1 * t});
    }
    in.emplace_back("spiral", std::move(spiral));
  }
  {
    auto p = uniform_points(2000, 3, 43);  // near and exact duplicates
    for (int i = 0; i < 200; ++i) {
      const std::size_t a = static_cast<std::size_t>(i) * 3;
      p.insert(p.end(), {p[a] + 1e-12, p[a + 1], p[a + 2]});
      p.insert(p.end(), {p[a + 3], p[a + 4], p[a + 5]});
      if (i % 50 == 0) p.insert(p.end(), {p[a + 3], p[a + 4], p[a + 5]});  // a third copy
    }
    in.emplace_back("duplicates", std::move(p));
  }
  {
    // A blob far smaller than a bin, with exact copies: its bin is crowded
    // (duplicates found by sorting it, not pairwise).
    auto p = uniform_points(300, 3, 48);
    const auto blob = uniform_points(400, 3, 49);
    for (std::size_t i = 0; i < 400; ++i) {
      const double x[3] = {0.5 + 1e-4 * blob[3 * i], 0.5 + 1e-4 * blob[3 * i + 1], 0.5 + 1e-4 * blob[3 * i + 2]};
      p.insert(p.end(), x, x + 3);
      if (i % 7 == 0) p.insert(p.end(), x, x + 3);
      if (i % 21 == 0) p.insert(p.end(), x, x + 3);  // a third copy
    }
    in.emplace_back("crowded duplicates", std::move(p));
  }
  {
    // Points on a cylinder, all on the hull as they come: a thin band
    // (located by the hull walk) and a tall one.
    std::uniform_real_distribution<double> u;
    std::vector<double> band, tall;
    for (int i = 0; i < 1500; ++i) {
      const double t = 1.5 * u(rng), z = u(rng);
      band.insert(band.end(), {std::cos(t), std::sin(t), 1e-3 * z});
      tall.insert(tall.end(), {std::cos(4 * t), std::sin(4 * t), z});
    }
    in.emplace_back("thin cylindrical band", std::move(band));
    in.emplace_back("cylinder", std::move(tall));
  }
  in.emplace_back("subnormal offsets", subnormal_offset_points(300, 3, 7));
  {
    auto far = uniform_points(2000, 3, 44);  // far from the origin: large, rounded differences
    for (double& x : far) x = 1e9 + x;
    in.emplace_back("far from the origin", std::move(far));
  }
  return in;
}

TEST(Insertion, GivesTheRowsOfTheCellsPass) {
  for (const auto& [what, p] : inputs()) {
    const tessera::Delaunay cells = triangulate(p, tessera::DelaunayMethod::cells);
    for (const int threads : {1, 2}) {
      const tessera::Delaunay ins = triangulate(p, tessera::DelaunayMethod::insertion, threads);
      EXPECT_EQ(ins.simplices, cells.simplices) << what << ", threads " << threads;
      EXPECT_EQ(ins.duplicates, cells.duplicates) << what;
      EXPECT_EQ(ins.from_insertion, ins.n_simplices()) << what;
      EXPECT_EQ(ins.from_cells + ins.from_hull_completion, 0u) << what;
      EXPECT_TRUE(ins.hull_completed) << what;
    }
    expect_valid(triangulate(p, tessera::DelaunayMethod::insertion), p, what);
  }
}

TEST(Insertion, ParallelPhasesGiveTheSerialRows) {
  // Rounds from 8 points per thread on go through the parallel phases, so
  // even these small inputs take several, cut across two axes, with points
  // deferred along every cut; a surface (the sphere, the terrain) turns
  // them off after a phase that defers too many. Three and four workers
  // run on whatever cores there are: the partition does not depend on them.
  auto in = inputs();
  in.emplace_back("uniform 20k", uniform_points(20000, 3, 47));
  expect_phases_give_the_serial_rows(in, 3);
  // The phases did run and inserted most of their points: on uniform points
  // they defer only those along the cuts.
  tessera::front::InsertionStats stats = expect_phases_insert_most(uniform_points(20000, 3, 47), 3);
  // Some walks start from their guide vertex, in the phases too (the rows
  // above are the same whichever start a walk takes).
  EXPECT_GT(stats.guided, 100u);
  // A serial run runs none.
  insert_points(uniform_points(20000, 3, 47), 3, 1, 8, &stats);
  EXPECT_EQ(stats.phases, 0u);
  EXPECT_GT(stats.guided, 100u);
}

// Points on a sphere: an early phase, while the rounds are sparse, defers
// most of its points, and the phases stop; a round three times its size tries
// once more, and there the denser points defer a few percent, so the later
// rounds run in phases again (until stop 68 they stayed serial: 200k points
// 0.99 s on two threads, now 0.63 s). The rows are the serial ones.
TEST(Insertion, PhasesTryAgainAfterASparseRound) {
  std::mt19937_64 rng(4411);
  std::normal_distribution<double> g;
  std::vector<double> sphere;
  for (int i = 0; i < 100000; ++i) {
    const double x = g(rng), y = g(rng), z = g(rng);
    const double r = std::sqrt(x * x + y * y + z * z);
    sphere.insert(sphere.end(), {x / r, y / r, z / r});
  }
  tessera::front::InsertionStats stats;
  const auto rows = insert_points(sphere, 3, 2, 1024, &stats);
  EXPECT_EQ(stats.stopped, 1u);
  EXPECT_EQ(stats.resumed, 1u);
  EXPECT_GE(stats.phases, 3u);
  EXPECT_LT(3 * stats.deferred, stats.phase_points);
  EXPECT_EQ(rows, insert_points(sphere, 3, 1, 1024));
}

TEST(Insertion, TheStoreOfSimplicesIsSizedOnce) {
  // Uniform points need about 6.8 tetrahedra (2 triangles) per point; the
  // store reserves for that at the start and never grows, phases included
  // (a growth copies it, and the old copy's pages were touched for
  // nothing: stop 68 doubled the 3D store in the last round of every
  // uniform input). Surface samples need far more (a torus ~19 per
  // point), measured as the rounds go: one growth, to what all points need.
  for (const int dim : {2, 3}) {
    tessera::front::InsertionStats stats;
    insert_points(uniform_points(dim == 3 ? 100000 : 200000, dim, 77), dim, 2, 1024, &stats);
    EXPECT_GE(stats.phases, 4u) << dim << "D";
    EXPECT_EQ(stats.store_growths, 0u) << dim << "D";
  }
  std::mt19937_64 rng(9);
  std::uniform_real_distribution<double> angle(0.0, 2.0 * std::acos(-1.0));
  std::vector<double> torus;
  for (int i = 0; i < 60000; ++i) {
    const double u = angle(rng), v = angle(rng), r = 1.0 + 0.35 * std::cos(v);
    torus.insert(torus.end(), {r * std::cos(u), r * std::sin(u), 0.35 * std::sin(v)});
  }
  tessera::front::InsertionStats stats;
  const auto rows = insert_points(torus, 3, 2, 1024, &stats);
  EXPECT_GT(rows.size(), 12u * 60000u);
  EXPECT_EQ(stats.store_growths, 1u);
}

TEST(Insertion, ALongBoxIsInsertedInCubes) {
  // The same points in a unit cube and stretched 1e4 times along x (2D: a
  // square and a strip): the insertion order's curve cells are cubes
  // (squares) either way, so consecutive points lie as near each other,
  // and the walks that locate them take about as many steps (1.3 times
  // the cube's). Scaled per axis, the curve's cells were 1e4 times longer
  // than wide, and the walks took 15 (2D) and 19 (3D) times the cube's.
  for (const int dim : {2, 3}) {
    std::vector<double> cube = uniform_points(20000, dim, 51), box = cube;
    for (std::size_t i = 0; i < box.size(); i += static_cast<std::size_t>(dim)) box[i] *= 1e4;
    tessera::front::InsertionStats in_cube, in_box;
    insert_points(cube, dim, 1, 1024, &in_cube);
    insert_points(box, dim, 1, 1024, &in_box);
    EXPECT_LT(static_cast<double>(in_box.steps), 2.0 * static_cast<double>(in_cube.steps)) << dim << "D";
  }
}

TEST(Insertion, HullPointsAreLocatedAlongTheHull) {
  // Points on a thin band of a cylinder (3D) and on a circle's arc (2D),
  // each outside the hull of those before it. In 3D the plain walk from the
  // last point crosses the needle tetrahedra along the chord between them
  // (417 steps a point on 50,000; here 59 times the cube's steps); the walk
  // over the hull's facets takes a few (2.6 times), and is chosen for
  // taking fewer. In 2D the plain walk is short on an arc already: that
  // half only guards the choice against making it worse.
  std::mt19937_64 rng(58);
  std::uniform_real_distribution<double> u;
  for (const int dim : {2, 3}) {
    std::vector<double> p, cube = uniform_points(20000, dim, 52);
    for (int i = 0; i < 20000; ++i) {
      const double t = 1.5 * u(rng);
      p.insert(p.end(), {std::cos(t), std::sin(t)});
      if (dim == 3) p.push_back(1e-3 * u(rng));
    }
    tessera::front::InsertionStats on_band, in_cube;
    insert_points(p, dim, 1, 1024, &on_band);
    insert_points(cube, dim, 1, 1024, &in_cube);
    EXPECT_LT(static_cast<double>(on_band.steps), 4.0 * static_cast<double>(in_cube.steps)) << dim << "D";
  }
}

TEST(Insertion, FewAndFlatPoints) {
  // Fewer than four points, and coplanar points (on the tilted plane z = x + y,
  // so the box has extent): no tetrahedron, no error.
  for (const std::vector<double>& p : {std::vector<double>{0, 0, 0, 1, 0, 1, 0, 1, 1},
                                       std::vector<double>{0, 0, 0, 1, 0, 1, 0, 1, 1, 1, 1, 2, 0.5, 0.25, 0.75}}) {
    const tessera::Delaunay dt = triangulate(p, tessera::DelaunayMethod::insertion);
    EXPECT_EQ(dt.n_simplices(), 0u);
  }
  // Four points, one tetrahedron, listed with positive orientation.
  const std::vector<double> tet{0, 0, 0, 0, 1, 0, 1, 0, 0, 0, 0, 1};
  const tessera::Delaunay dt = triangulate(tet, tessera::DelaunayMethod::insertion);
  ASSERT_EQ(dt.n_simplices(), 1u);
  EXPECT_EQ(std::vector<std::int32_t>(dt.simplices.begin(), dt.simplices.end()), (std::vector<std::int32_t>{0, 1, 3, 2}));  // det[p1-p0, p3-p0, p2-p0] = +1
  // Collinear points then one off the line, then one off the plane.
  std::vector<double> line;
  for (int i = 0; i < 20; ++i) line.insert(line.end(), {double(i), 2.0 * i, 3.0 * i});
  line.insert(line.end(), {0.0, 1.0, 0.0, 0.0, 0.0, 1.0});
  const tessera::Delaunay l = triangulate(line, tessera::DelaunayMethod::insertion);
  EXPECT_EQ(l.simplices, triangulate(line, tessera::DelaunayMethod::cells).simplices);
  EXPECT_GT(l.n_simplices(), 0u);
}

TEST(Insertion, BadRequestsAreInputErrors) {
  tessera::DelaunayOptions o;
  o.method = tessera::DelaunayMethod::insertion;
  const auto p3 = uniform_points(100, 3, 1);
  o.dim = 3;
  // Labels are served (the whole triangulation's inside simplices); without
  // hull completion the insertion has nothing to build.
  const std::vector<std::int32_t> labels(100, 1);
  EXPECT_EQ(tessera::delaunay(p3, 3, labels, o).simplices, tessera::delaunay(p3, 3, {}, o).simplices);
  o.complete_hull = false;
  EXPECT_THROW(tessera::delaunay(p3, 3, {}, o), tessera::InputError);
  EXPECT_THROW(tessera::delaunay(p3, 3, labels, o), tessera::InputError);
}

TEST(Insertion, AutomaticChoiceFollowsThePilot) {
  // A 24k-point height field: the pilot finds its needle cells far costlier
  // than what they find, and insertion builds the rows the cells would, on
  // any thread count.
  const std::vector<double> terrain = height_field(24000, 9);
  for (const int threads : {2, 4}) {
    const tessera::Delaunay automatic = triangulate(terrain, tessera::DelaunayMethod::automatic, threads);
    EXPECT_EQ(automatic.from_insertion, automatic.n_simplices()) << threads;
    if (threads == 2) EXPECT_EQ(automatic.simplices, triangulate(terrain, tessera::DelaunayMethod::cells).simplices);
  }
  // Uniform points have no ties: insertion on one or two threads, the
  // cells beyond (they scale better).
  const auto uniform = uniform_points(25000, 3, 45);
  const tessera::Delaunay two = triangulate(uniform, tessera::DelaunayMethod::automatic, 2);
  EXPECT_EQ(two.from_insertion, two.n_simplices());
  const tessera::Delaunay four = triangulate(uniform, tessera::DelaunayMethod::automatic, 4);
  EXPECT_EQ(four.from_insertion, 0u);
  EXPECT_GT(four.from_cells, 0u);
  EXPECT_EQ(four.simplices, two.simplices);
  // A lattice's ties make insertion twice as slow: it stays with the cells.
  const std::vector<double> lattice = grid3(30);
  const tessera::Delaunay ties = triangulate(lattice, tessera::DelaunayMethod::automatic, 2);
  EXPECT_EQ(ties.from_insertion, 0u);
  EXPECT_GT(ties.from_cells, 0u);
}

// tessera::delaunay by insertion reports its progress (never decreasing,
// ending at 1) and stops when the callback throws Cancelled.
TEST(Insertion, ProgressAndCancellation) {
  const auto uniform = uniform_points(60000, 3, 47);
  tessera::DelaunayOptions o;
  o.dim = 3;
  o.threads = 2;
  o.method = tessera::DelaunayMethod::insertion;
  std::vector<double> seen;
  o.progress = [&](double f) { seen.push_back(f); };
  const tessera::Delaunay dt = tessera::delaunay(uniform, 3, {}, o);
  EXPECT_EQ(dt.from_insertion, dt.n_simplices());
  ASSERT_GE(seen.size(), 5u);
  EXPECT_TRUE(std::is_sorted(seen.begin(), seen.end()));
  EXPECT_EQ(seen.back(), 1.0);
  o.progress = [](double f) {
    if (f > 0.2) throw tessera::Cancelled();
  };
  EXPECT_THROW(tessera::delaunay(uniform, 3, {}, o), tessera::Cancelled);
}

TEST(Insertion, AutomaticChoiceTakesItWhereTheCellsPassWouldStall) {
  std::mt19937_64 rng(46);
  std::normal_distribution<double> g;
  // Points nearly on one sphere: every cell reaches the centre, where all
  // points are nearly cospherical, and tests every point, most exactly. The
  // pilot abandons its cells at its work cap (pilot_work_cap) and chooses
  // insertion; before the cap its first band alone ran for minutes.
  std::vector<double> sphere;
  for (int i = 0; i < 24000; ++i) {
    const double x = g(rng), y = g(rng), z = g(rng), r = std::sqrt(x * x + y * y + z * z);
    sphere.insert(sphere.end(), {x / r, y / r, z / r});
  }
  const tessera::Delaunay on_sphere = triangulate(sphere, tessera::DelaunayMethod::automatic);
  EXPECT_EQ(on_sphere.from_insertion, on_sphere.n_simplices());
  expect_valid(on_sphere, sphere, "sphere");
  // A rotated 28^3 lattice: its hull faces are coplanar to within rounding,
  // and each of completion's wraps scans a whole face, most of it exactly
  // (a 20^3 one took 8 s). On two threads the pilot sends it to insertion
  // (near-ties off any grid); on four it keeps the cells, and completion
  // stops at its budget (completion_budget) and hands over to insertion.
  std::vector<double> lattice;
  const double a = 0.3, b = 0.7;
  for (int i = 0; i < 28; ++i)
    for (int j = 0; j < 28; ++j)
      for (int k = 0; k < 28; ++k) {
        const double x = std::cos(a) * i - std::sin(a) * j, y = std::sin(a) * i + std::cos(a) * j;
        lattice.insert(lattice.end(), {x, std::cos(b) * y - std::sin(b) * k, std::sin(b) * y + std::cos(b) * k});
      }
  const tessera::Delaunay rotated = triangulate(lattice, tessera::DelaunayMethod::automatic, 4);
  EXPECT_EQ(rotated.from_insertion, rotated.n_simplices());
  EXPECT_EQ(rotated.from_cells, 0u);
  expect_valid(rotated, lattice, "rotated lattice");
  EXPECT_EQ(triangulate(lattice, tessera::DelaunayMethod::automatic, 2).simplices, rotated.simplices);
  // The progress of that hand-over never decreases (the insertion restarted
  // the bar at 0 after the cells had filled it) and ends at 1.
  tessera::DelaunayOptions o;
  o.dim = 3;
  o.threads = 4;
  std::vector<double> seen;
  o.progress = [&](double f) { seen.push_back(f); };
  EXPECT_EQ(tessera::delaunay(lattice, 3, {}, o).simplices, rotated.simplices);
  ASSERT_GE(seen.size(), 5u);
  EXPECT_TRUE(std::is_sorted(seen.begin(), seen.end()));
  EXPECT_EQ(seen.back(), 1.0);
}

}  // namespace

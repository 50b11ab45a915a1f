// Differential test against Voro++ 0.4.6 (Debian voro++-dev), same box.
//
// What this proves: on random 3D inputs (1000 and 20000 points), every cell's
// volume agrees with Voro++'s to 1e-9 relative and its face-neighbour set is
// the same, except for faces so small (< 1e-12 of the cell's scale squared)
// that Voro++'s 1e-11 vertex tolerance may have merged or created them; those
// are counted and printed (expected 0 on random input). Power cells against
// Voro++'s container_poly likewise, their empty cells included.
#ifdef TESSERA_HAVE_VORO

#include <gtest/gtest.h>

#include <cstdio>
#include <random>
#include <voro++.hh>

#include "helpers.hpp"

namespace {

using namespace cells_test;

struct VoroCell {
  double volume = 0;
  std::map<int, double> face_area;  // neighbour id (walls dropped) -> area
  bool computed = false;
};

/// Every cell of the n particles in `con` (an empty power cell is not computed).
template <class Container>
std::vector<VoroCell> voro_loop(Container& con, std::size_t n) {
  std::vector<VoroCell> out(n);
  voro::c_loop_all loop(con);
  voro::voronoicell_neighbor cell;
  std::vector<int> nb;
  std::vector<double> areas;
  if (loop.start()) do {
      if (!con.compute_cell(cell, loop)) continue;
      const int id = loop.pid();
      VoroCell& vc = out[id];
      vc.computed = true;
      vc.volume = cell.volume();
      cell.neighbors(nb);
      cell.face_areas(areas);
      for (std::size_t f = 0; f < nb.size(); ++f)
        if (nb[f] >= 0) vc.face_area[nb[f]] += areas[f];  // negative ids are the walls
    } while (loop.inc());
  return out;
}

/// Voro++'s cells of `pts` in the box b: container, or container_poly with `radii`.
std::vector<VoroCell> voro_cells(const std::vector<double>& pts, const tessera::Bounds& b,
                                 const std::vector<double>& radii = {}) {
  const std::size_t n = pts.size() / 3;
  // About 5 particles per block, non-periodic: cells are cut by the box walls.
  const int blocks = std::max(1, int(std::cbrt(double(n) / 5.0)));
  if (radii.empty()) {
    voro::container con(b.lo[0], b.hi[0], b.lo[1], b.hi[1], b.lo[2], b.hi[2], blocks, blocks, blocks, false,
                        false, false, 8);
    for (std::size_t i = 0; i < n; ++i) con.put(int(i), pts[3 * i], pts[3 * i + 1], pts[3 * i + 2]);
    return voro_loop(con, n);
  }
  voro::container_poly con(b.lo[0], b.hi[0], b.lo[1], b.hi[1], b.lo[2], b.hi[2], blocks, blocks, blocks, false,
                           false, false, 8);
  for (std::size_t i = 0; i < n; ++i) con.put(int(i), pts[3 * i], pts[3 * i + 1], pts[3 * i + 2], radii[i]);
  return voro_loop(con, n);
}

/// Voro++'s cells of `pts` in the box b cut by plane walls (wall_plane: n.x < d).
std::vector<VoroCell> voro_cells_in_walls(const std::vector<double>& pts, const tessera::Bounds& b,
                                          const std::vector<tessera::Wall>& walls) {
  const std::size_t n = pts.size() / 3;
  const int blocks = std::max(1, int(std::cbrt(double(n) / 5.0)));
  voro::container con(b.lo[0], b.hi[0], b.lo[1], b.hi[1], b.lo[2], b.hi[2], blocks, blocks, blocks, false, false,
                      false, 8);
  std::vector<voro::wall_plane> planes;
  planes.reserve(walls.size());
  for (std::size_t k = 0; k < walls.size(); ++k)
    planes.emplace_back(walls[k].normal[0], walls[k].normal[1], walls[k].normal[2], walls[k].offset, -7 - int(k));
  for (auto& w : planes) con.add_wall(w);
  for (std::size_t i = 0; i < n; ++i) con.put(int(i), pts[3 * i], pts[3 * i + 1], pts[3 * i + 2]);
  return voro_loop(con, n);
}

/// rmax > 0: power cells, radii uniform in [0, rmax).
void compare_with_voro(std::size_t n, std::uint64_t seed, double rmax = 0) {
  SCOPED_TRACE(::testing::Message() << "n " << n << " seed " << seed << " rmax " << rmax);
  const auto box = make_bounds({-1, 0, 2}, {1, 1.5, 3});
  const auto pts = random_points(n, 3, seed, box);
  std::vector<double> radii;
  std::mt19937_64 rng(seed + 1000);
  std::uniform_real_distribution<double> u(0.0, rmax);
  for (std::size_t i = 0; rmax > 0 && i < n; ++i) radii.push_back(u(rng));
  auto o = options(3, box);
  o.radii = radii;
  const auto c = tessera::voronoi(pts, 3, {}, o);
  const auto v = voro_cells(pts, box, radii);
  if (rmax == 0) ASSERT_EQ(c.n_cells(), n);

  std::size_t tolerated = 0, bad_volume = 0, bad_neighbours = 0, empty = 0;
  double vsum = 0;
  for (std::size_t i = 0; i < n; ++i) {
    const auto k = c.cell_of[i];
    if (rmax > 0 && (!v[i].computed || k < 0)) {  // a power cell may be empty, then for both
      EXPECT_EQ(v[i].computed, k >= 0) << "point " << i << ": empty for one of the two";
      empty += k < 0;
      continue;
    }
    ASSERT_TRUE(v[i].computed) << "Voro++ did not compute cell " << i;
    vsum += v[i].volume;
    ASSERT_GE(k, 0);
    if (!(std::abs(c.volume[k] - v[i].volume) <= 1e-9 * v[i].volume) && ++bad_volume <= 5)
      ADD_FAILURE() << "point " << i << " volume " << c.volume[k] << " Voro++ " << v[i].volume;

    const double tiny = 1e-12 * std::pow(v[i].volume, 2.0 / 3.0);
    auto nb = neighbours_of(c, k);
    std::set<int> tn(nb.begin(), nb.end()), vn;
    for (auto [j, a] : v[i].face_area) vn.insert(j);
    std::vector<int> diff;
    std::set_symmetric_difference(tn.begin(), tn.end(), vn.begin(), vn.end(), std::back_inserter(diff));
    std::map<int, double> mm;
    if (!diff.empty()) mm = mesh_face_measures(c, k);
    for (int j : diff) {
      // The face's area from whichever side reports it.
      const double a = vn.count(j) ? v[i].face_area.at(j) : (mm.count(j) ? mm[j] : 0.0);
      if (a < tiny) {
        ++tolerated;
      } else if (++bad_neighbours <= 5) {
        ADD_FAILURE() << "point " << i << " neighbour " << j << (vn.count(j) ? " only in Voro++" : " only in tessera")
                      << " (face area " << a << ")";
      }
    }
  }
  std::printf("[ voro++ ] n %zu seed %llu rmax %g: tiny-face neighbour mismatches tolerated: %zu; empty cells %zu\n",
              n, (unsigned long long)seed, rmax, tolerated, empty);
  EXPECT_NEAR(vsum, box_volume(box, 3), 1e-9 * box_volume(box, 3)) << "Voro++ itself should tile the box";
  EXPECT_EQ(bad_volume, 0u);
  EXPECT_EQ(bad_neighbours, 0u);
  // `tolerated` is only reported: Voro++'s own tolerance decides those faces.
}

TEST(VoroPlusPlus, Random1000) {
  compare_with_voro(1000, 601);
  compare_with_voro(1000, 602);
}

TEST(VoroPlusPlus, Random20000) { compare_with_voro(20000, 603); }

// Walls (VoronoiOptions::walls) against Voro++'s plane walls: the same
// volumes (1e-9) and neighbours, the polytope tiled by both.
TEST(VoroPlusPlus, PlaneWalls) {
  const auto box = make_bounds({0, 0, 0}, {1, 1, 1});
  const std::vector<tessera::Wall> walls = {{{1, 1, 1}, 2.1}, {{-1, 0.5, 0}, 0.3}, {{0.2, -1, 0.7}, 0.6}};
  std::vector<double> pts;
  for (const double x : random_points(12000, 3, 621, box)) pts.push_back(x);
  std::vector<double> in;
  for (std::size_t i = 0; i < pts.size() / 3; ++i) {
    bool keep = true;
    for (const auto& w : walls)
      keep &= w.normal[0] * pts[3 * i] + w.normal[1] * pts[3 * i + 1] + w.normal[2] * pts[3 * i + 2] < w.offset - 1e-9;
    if (keep) in.insert(in.end(), pts.begin() + 3 * i, pts.begin() + 3 * i + 3);
  }
  const std::size_t n = in.size() / 3;
  auto o = options(3, box);
  o.walls = walls;
  const auto c = tessera::voronoi(in, 3, {}, o);
  const auto v = voro_cells_in_walls(in, box, walls);
  ASSERT_EQ(c.n_cells(), n);
  std::size_t bad = 0, tolerated = 0;
  double vsum = 0, tsum = 0;
  for (std::size_t i = 0; i < n; ++i) {
    ASSERT_TRUE(v[i].computed) << "Voro++ did not compute cell " << i;
    const auto k = static_cast<std::size_t>(c.cell_of[i]);
    vsum += v[i].volume;
    tsum += c.volume[k];
    if (!(std::abs(c.volume[k] - v[i].volume) <= 1e-9 * v[i].volume) && ++bad <= 5)
      ADD_FAILURE() << "point " << i << " volume " << c.volume[k] << " Voro++ " << v[i].volume;
    auto nb = neighbours_of(c, k);
    std::set<int> tn(nb.begin(), nb.end()), vn;
    for (auto [j, a] : v[i].face_area) vn.insert(j);
    std::vector<int> diff;
    std::set_symmetric_difference(tn.begin(), tn.end(), vn.begin(), vn.end(), std::back_inserter(diff));
    const auto mm = mesh_face_measures(c, k);
    for (int j : diff) {
      const double a = vn.count(j) ? v[i].face_area.at(j) : (mm.count(j) ? mm.at(j) : 0.0);
      if (a < 1e-12 * std::pow(v[i].volume, 2.0 / 3.0)) ++tolerated;
      else if (++bad <= 5) ADD_FAILURE() << "point " << i << " neighbour " << j << " differs (face area " << a << ")";
    }
  }
  std::printf("[ voro++ ] walls: %zu cells, tiny-face mismatches tolerated %zu\n", n, tolerated);
  EXPECT_EQ(bad, 0u);
  EXPECT_NEAR(tsum, vsum, 1e-9 * vsum);
  EXPECT_NEAR(tsum, tessera::domain_volume(box, walls, 3), 1e-12);
}

// Power cells (VoronoiOptions::radii) against container_poly: radii up to
// half the mean spacing (overlapping spheres, a few cells empty), and up to
// twice it (over half of them empty).
TEST(VoroPlusPlus, PowerCells) {
  compare_with_voro(3000, 611, 0.05);
  compare_with_voro(3000, 612, 0.2);
}

/// Every cell of Voro++'s periodic container `con` (looped by Loop) against
/// Tessera's cells `c` of the same n points: the same volume (1e-9) and the
/// same set of neighbour ids (Voro++'s walls, negative, left out). Power
/// cells (a _poly container): an empty cell is empty for both.
template <class Loop, class Container>
void expect_same_periodic_cells(Container& con, const tessera::Cells& c, std::size_t n) {
  ASSERT_EQ(c.n_cells() + c.empty_cells.size(), n);
  Loop loop(con);
  voro::voronoicell_neighbor cell;
  std::vector<int> nb;
  std::size_t computed = 0, bad_volume = 0, bad_neighbours = 0;
  if (loop.start()) do {
      const int i = loop.pid();
      if (!con.compute_cell(cell, loop)) {
        EXPECT_EQ(c.cell_of[static_cast<std::size_t>(i)], -1) << "point " << i << " empty for Voro++ alone";
        continue;
      }
      ++computed;
      const auto k = static_cast<std::size_t>(c.cell_of[static_cast<std::size_t>(i)]);
      if (!(std::abs(c.volume[k] - cell.volume()) <= 1e-9 * cell.volume()) && ++bad_volume <= 5)
        ADD_FAILURE() << "point " << i << " volume " << c.volume[k] << " Voro++ " << cell.volume();
      cell.neighbors(nb);
      std::set<int> vn;
      for (int j : nb)
        if (j >= 0) vn.insert(j);
      const auto t = neighbours_of(c, k);
      const std::set<int> tn(t.begin(), t.end());
      if (tn != vn && ++bad_neighbours <= 5) ADD_FAILURE() << "point " << i << ": neighbour ids differ";
    } while (loop.inc());
  EXPECT_EQ(computed, c.n_cells());
  EXPECT_EQ(bad_volume, 0u);
  EXPECT_EQ(bad_neighbours, 0u);
}

// A periodic box (Voro++'s container with its periodic flags; Tessera's
// VoronoiOptions::periodic), fully and along x and z only: the same volumes
// and the same sets of neighbour ids. Points on a grid of 2^-30 so that
// Tessera's rounding to the box's grid leaves them as they are.
TEST(VoroPlusPlus, PeriodicBox) {
  const auto box = make_bounds({-1, 0, 2}, {1, 1.5, 3});
  const std::size_t n = 3000;
  auto pts = random_points(n, 3, 604, box);
  for (double& x : pts) x = std::ldexp(std::floor(std::ldexp(x, 30)), -30);
  for (const std::array<bool, 3> per : {std::array<bool, 3>{true, true, true}, std::array<bool, 3>{true, false, true}}) {
    SCOPED_TRACE(::testing::Message() << "periodic " << per[0] << per[1] << per[2]);
    voro::container con(box.lo[0], box.hi[0], box.lo[1], box.hi[1], box.lo[2], box.hi[2], 8, 8, 8, per[0], per[1],
                        per[2], 8);
    for (std::size_t i = 0; i < n; ++i) con.put(int(i), pts[3 * i], pts[3 * i + 1], pts[3 * i + 2]);
    auto o = tessera::VoronoiOptions{};
    o.dim = 3;
    o.bounds = box;
    o.threads = 2;
    o.periodic = per;
    expect_same_periodic_cells<voro::c_loop_all>(con, tessera::voronoi(pts, 3, {}, o), n);
  }
}

// Power cells in periodic boxes: container_poly with periodic flags (fully,
// and along x and z only), and container_periodic_poly (triclinic), against
// VoronoiOptions::radii with periodic axes. Radii on a dyadic grid (exact
// squares), up to half the mean spacing and up to 1.5 times it (a third of
// the cells empty).
TEST(VoroPlusPlus, PeriodicPowerCells) {
  const auto box = make_bounds({-1, 0, 2}, {1, 1.5, 3});
  const std::size_t n = 3000;
  auto pts = random_points(n, 3, 606, box);
  for (double& x : pts) x = std::ldexp(std::floor(std::ldexp(x, 30)), -30);
  std::mt19937_64 rng(607);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  for (const double rmax : {0.05, 0.15}) {
    std::vector<double> radii(n);
    for (double& r : radii) r = std::ldexp(std::floor(std::ldexp(u(rng) * rmax, 20)), -20);
    for (const std::array<bool, 3> per : {std::array<bool, 3>{true, true, true}, std::array<bool, 3>{true, false, true}}) {
      SCOPED_TRACE(::testing::Message() << "rmax " << rmax << " periodic " << per[0] << per[1] << per[2]);
      voro::container_poly con(box.lo[0], box.hi[0], box.lo[1], box.hi[1], box.lo[2], box.hi[2], 8, 8, 8, per[0],
                               per[1], per[2], 8);
      for (std::size_t i = 0; i < n; ++i) con.put(int(i), pts[3 * i], pts[3 * i + 1], pts[3 * i + 2], radii[i]);
      auto o = options(3, box, 2);
      o.periodic = per;
      o.radii = radii;
      const auto c = tessera::voronoi(pts, 3, {}, o);
      EXPECT_TRUE(c.power);
      if (rmax > 0.1) EXPECT_GT(c.empty_cells.size(), 100u);
      expect_same_periodic_cells<voro::c_loop_all>(con, c, n);
      const auto r = tessera::validate(c, {}, pts, radii);
      EXPECT_TRUE(r.ok) << (r.messages.empty() ? "" : r.messages[0]);
      EXPECT_GT(r.measures_checked, 0u);
    }
  }
  // Triclinic (container_periodic_poly), as TriclinicBox below.
  const double bx = 2, by = 1.5, bz = 1, bxy = 0.375, bxz = -0.5, byz = 0.25;
  const auto f = random_points(n, 3, 608, make_bounds({0, 0, 0}, {1, 1, 1}));
  std::vector<double> tp(3 * n), radii(n);
  for (std::size_t i = 0; i < n; ++i) {
    const double* t = f.data() + 3 * i;
    tp[3 * i] = std::ldexp(std::floor(std::ldexp(t[0] * bx + t[1] * bxy + t[2] * bxz, 30)), -30);
    tp[3 * i + 1] = std::ldexp(std::floor(std::ldexp(t[1] * by + t[2] * byz, 30)), -30);
    tp[3 * i + 2] = std::ldexp(std::floor(std::ldexp(t[2] * bz, 30)), -30);
    radii[i] = std::ldexp(std::floor(std::ldexp(u(rng) * 0.06, 20)), -20);
  }
  voro::container_periodic_poly con(bx, bxy, by, bxz, byz, bz, 8, 8, 8, 8);
  for (std::size_t i = 0; i < n; ++i) con.put(int(i), tp[3 * i], tp[3 * i + 1], tp[3 * i + 2], radii[i]);
  auto o = options(3, make_bounds({0, 0, 0}, {bx, by, bz}), 2);
  o.periodic = {true, true, true};
  o.tilt = {bxy, bxz, byz};
  o.radii = radii;
  const auto c = tessera::voronoi(tp, 3, {}, o);
  expect_same_periodic_cells<voro::c_loop_all_periodic>(con, c, n);
  const auto r = tessera::validate(c, {}, tp, radii);
  EXPECT_TRUE(r.ok) << (r.messages.empty() ? "" : r.messages[0]);
}

TEST(VoroPlusPlus, TriclinicBox) {
  // Voro++'s periodic container is triclinic with the same convention:
  // lattice vectors (bx, 0, 0), (bxy, by, 0), (bxz, byz, bz) from the origin.
  const double bx = 2, by = 1.5, bz = 1, bxy = 0.375, bxz = -0.5, byz = 0.25;
  const std::size_t n = 3000;
  const auto f = random_points(n, 3, 605, make_bounds({0, 0, 0}, {1, 1, 1}));
  std::vector<double> pts(3 * n);
  for (std::size_t i = 0; i < n; ++i) {
    const double* t = f.data() + 3 * i;
    pts[3 * i] = std::ldexp(std::floor(std::ldexp(t[0] * bx + t[1] * bxy + t[2] * bxz, 30)), -30);
    pts[3 * i + 1] = std::ldexp(std::floor(std::ldexp(t[1] * by + t[2] * byz, 30)), -30);
    pts[3 * i + 2] = std::ldexp(std::floor(std::ldexp(t[2] * bz, 30)), -30);
  }
  voro::container_periodic con(bx, bxy, by, bxz, byz, bz, 8, 8, 8, 8);
  for (std::size_t i = 0; i < n; ++i) con.put(int(i), pts[3 * i], pts[3 * i + 1], pts[3 * i + 2]);
  auto o = tessera::VoronoiOptions{};
  o.dim = 3;
  o.bounds = make_bounds({0, 0, 0}, {bx, by, bz});
  o.threads = 2;
  o.periodic = {true, true, true};
  o.tilt = {bxy, bxz, byz};
  expect_same_periodic_cells<voro::c_loop_all_periodic>(con, tessera::voronoi(pts, 3, {}, o), n);
}

}  // namespace

#endif  // TESSERA_HAVE_VORO

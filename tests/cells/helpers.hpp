// Shared helpers for the cell tests: deterministic point generators, a thin
// wrapper around tessera::voronoi, and an invariant checker that recomputes
// everything it can from the raw output (it never trusts one field to check
// another when the property can be derived from the geometry).
#pragma once

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <map>
#include <optional>
#include <random>
#include <set>
#include <span>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "tessera/cells.hpp"

namespace cells_test {

// ---------------------------------------------------------------- inputs

inline tessera::Bounds make_bounds(std::array<double, 3> lo, std::array<double, 3> hi) {
  tessera::Bounds b;
  b.lo = lo;
  b.hi = hi;
  return b;
}

inline tessera::Bounds unit_box() { return make_bounds({0, 0, 0}, {1, 1, 1}); }

/// n points uniform in the open box (strictly inside: never on a box plane).
inline std::vector<double> random_points(std::size_t n, int dim, std::uint64_t seed,
                                         const tessera::Bounds& b = unit_box()) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  std::vector<double> p(n * dim);
  for (std::size_t i = 0; i < n; ++i)
    for (int a = 0; a < dim; ++a) {
      double t = u(rng);
      while (t == 0.0) t = u(rng);
      p[i * dim + a] = b.lo[a] + t * (b.hi[a] - b.lo[a]);
    }
  return p;
}

/// k^dim grid: coordinate = offset + spacing * index (computed as one
/// multiplication so 0.1 spacing is the usual inexact value).
inline std::vector<double> grid_points(int k, int dim, double spacing = 1.0, double offset = 0.0) {
  std::vector<double> p;
  if (dim == 2) {
    for (int i = 0; i < k; ++i)
      for (int j = 0; j < k; ++j) {
        p.push_back(offset + spacing * i);
        p.push_back(offset + spacing * j);
      }
  } else {
    for (int i = 0; i < k; ++i)
      for (int j = 0; j < k; ++j)
        for (int l = 0; l < k; ++l) {
          p.push_back(offset + spacing * i);
          p.push_back(offset + spacing * j);
          p.push_back(offset + spacing * l);
        }
  }
  return p;
}

// ---------------------------------------------------------------- running

inline tessera::VoronoiOptions options(int dim, std::optional<tessera::Bounds> bounds = std::nullopt,
                                       int threads = 1) {
  tessera::VoronoiOptions o;
  o.dim = dim;
  o.bounds = bounds;
  o.threads = threads;
  return o;
}

inline tessera::Cells run(const std::vector<double>& pts, int dim,
                          std::optional<tessera::Bounds> bounds = std::nullopt,
                          const std::vector<std::int32_t>& labels = {}, int threads = 1) {
  return tessera::voronoi(std::span<const double>(pts), dim,
                          std::span<const std::int32_t>(labels), options(dim, bounds, threads));
}

inline double box_volume(const tessera::Bounds& b, int dim) {
  double v = 1;
  for (int a = 0; a < dim; ++a) v *= b.hi[a] - b.lo[a];
  return v;
}

inline double box_size(const tessera::Bounds& b, int dim) {
  double s = 0;
  for (int a = 0; a < dim; ++a) s = std::max(s, b.hi[a] - b.lo[a]);
  return s;
}

inline std::vector<std::int32_t> neighbours_of(const tessera::Cells& c, std::size_t cell) {
  return {c.neighbors.begin() + c.neighbor_offsets[cell],
          c.neighbors.begin() + c.neighbor_offsets[cell + 1]};
}

// ---------------------------------------------------------------- mesh geometry


using V3 = std::array<double, 3>;
inline V3 sub(const V3& a, const V3& b) { return {a[0] - b[0], a[1] - b[1], a[2] - b[2]}; }
inline V3 cross(const V3& a, const V3& b) {
  return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
}
inline double dot(const V3& a, const V3& b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
inline double norm(const V3& a) { return std::sqrt(dot(a, a)); }

inline V3 mesh_vertex(const tessera::Cells& c, std::int64_t v) {
  V3 r{0, 0, 0};
  for (int a = 0; a < c.dim; ++a) r[a] = c.vertices[v * c.dim + a];
  return r;
}

/// A 3D cell's volume and centroid from its mesh faces, as check_invariants
/// integrates them in doubles (a fan from each face's first vertex, read
/// from the generator gp), but in __float128, and the bound `tol` on how far
/// the rounding of the mesh's vertices alone may move the volume: 8u times
/// their largest coordinate times the cell's surface area. For cells whose
/// double sums cancel: a column 5e7 long and 0.07 wide (points far off a
/// slanted plane) has terms of ~1e14 summing to ~1e5.
inline void mesh_measure_quad(const tessera::Cells& c, std::size_t k, const V3& gp, double& vol, V3& cen,
                              double& tol) {
  using Q = __float128;
  Q v = 0, m[3] = {0, 0, 0};
  double area = 0, xmax = 0;
  for (auto f = c.cell_face_offsets[k]; f < c.cell_face_offsets[k + 1]; ++f) {
    const auto vb = c.face_vertex_offsets[f], ve = c.face_vertex_offsets[f + 1];
    auto rel = [&](std::int64_t t, Q* out) {
      const V3 x = mesh_vertex(c, c.face_vertices[static_cast<std::size_t>(t)]);
      for (int q = 0; q < 3; ++q) {
        out[q] = Q(x[q]) - Q(gp[q]);
        xmax = std::max(xmax, std::abs(x[q]));
      }
    };
    Q o[3], a[3], b[3];
    rel(vb, o);
    for (auto t = vb + 1; t + 1 < ve; ++t) {
      rel(t, a);
      rel(t + 1, b);
      const Q cr[3] = {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
      const Q tv = (o[0] * cr[0] + o[1] * cr[1] + o[2] * cr[2]) / 6;
      v += tv;
      for (int q = 0; q < 3; ++q) m[q] += tv * (o[q] + a[q] + b[q]) / 4;
      const Q e[3] = {(a[1] - o[1]) * (b[2] - o[2]) - (a[2] - o[2]) * (b[1] - o[1]),
                      (a[2] - o[2]) * (b[0] - o[0]) - (a[0] - o[0]) * (b[2] - o[2]),
                      (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0])};
      area += 0.5 * std::sqrt(double(e[0] * e[0] + e[1] * e[1] + e[2] * e[2]));
    }
  }
  vol = double(v);
  for (int q = 0; q < 3; ++q) cen[q] = double(Q(gp[q]) * v + m[q]);  // check_invariants divides by vol
  tol = 8 * 0x1p-53 * xmax * area;
}

inline V3 input_point(const std::vector<double>& pts, int dim, std::int64_t i) {
  V3 r{0, 0, 0};
  for (int a = 0; a < dim; ++a) r[a] = pts[i * dim + a];
  return r;
}

/// Area (3D) or length (2D) of face f of the mesh.
inline double mesh_face_measure(const tessera::Cells& c, std::int64_t f) {
  const auto b = c.face_vertex_offsets[f], e = c.face_vertex_offsets[f + 1];
  if (c.dim == 2) {
    if (e - b != 2) return -1;
    return norm(sub(mesh_vertex(c, c.face_vertices[b]), mesh_vertex(c, c.face_vertices[b + 1])));
  }
  V3 o = mesh_vertex(c, c.face_vertices[b]);
  V3 s{0, 0, 0};
  for (auto k = b + 1; k + 1 < e; ++k) {
    V3 t = cross(sub(mesh_vertex(c, c.face_vertices[k]), o), sub(mesh_vertex(c, c.face_vertices[k + 1]), o));
    for (int a = 0; a < 3; ++a) s[a] += t[a];
  }
  return 0.5 * norm(s);
}

/// Per cell: face measure for every spoke (neighbour id or negative box plane),
/// summed over faces with the same spoke.
inline std::map<int, double> mesh_face_measures(const tessera::Cells& c, std::size_t cell) {
  std::map<int, double> m;
  for (auto f = c.cell_face_offsets[cell]; f < c.cell_face_offsets[cell + 1]; ++f)
    m[c.face_neighbor[f]] += mesh_face_measure(c, f);
  return m;
}

// ---------------------------------------------------------------- invariants

struct InvariantOptions {
  bool all_inside = true;        ///< every non-duplicate point owns a cell: volume sums to domain
  double volume_sum_tol = 1e-12; ///< relative
  bool check_validate = true;    ///< also require tessera::validate(...).ok
};

/// Collects failures (printing the first few) so a broken invariant on a big
/// input produces a readable report instead of thousands of lines.
class Failures {
 public:
  explicit Failures(std::string what) : what_(std::move(what)) {}
  template <class... T>
  void add(const T&... parts) {
    ++count_;
    if (count_ <= 12) {
      std::ostringstream os;
      (os << ... << parts);
      ADD_FAILURE() << what_ << ": " << os.str();
    }
  }
  std::size_t count() const { return count_; }
  ~Failures() {
    if (count_ > 12) ADD_FAILURE() << what_ << ": ... " << count_ << " failures in total";
  }

 private:
  std::string what_;
  std::size_t count_ = 0;
};

/// Expects two results to be the same bit for bit: every per-cell, per-generator
/// and mesh array and the diagnostics' lists (not the counters, which say how
/// the cells were found). `why`: how they were computed apart.
inline void expect_same_cells(const tessera::Cells& a, const tessera::Cells& b, const std::string& why) {
  EXPECT_EQ(a.dim, b.dim);
  EXPECT_EQ(a.n_points, b.n_points);
  EXPECT_EQ(a.bounds.lo, b.bounds.lo);
  EXPECT_EQ(a.bounds.hi, b.bounds.hi);
#define SAME(f) EXPECT_TRUE(a.f == b.f) << #f " differs: " << why
  SAME(generator);
  SAME(region);
  SAME(volume);
  SAME(centroid);
  SAME(num_faces);
  SAME(neighbor_offsets);
  SAME(neighbors);
  SAME(cell_of);
  SAME(vertices);
  SAME(vertex_keys);
  SAME(cell_face_offsets);
  SAME(face_vertex_offsets);
  SAME(face_vertices);
  SAME(face_neighbor);
  SAME(face_class);
  SAME(duplicates);
  SAME(ignored_outside_bounds);
#undef SAME
}

/// Checks every structural and geometric invariant of a result computed from
/// `pts` (row-major, dim) and `labels`. What each block proves is stated inline.
inline void check_invariants(const tessera::Cells& c, const std::vector<double>& pts,
                             const std::vector<std::int32_t>& labels, const std::string& what,
                             InvariantOptions opt = {}) {
  const int dim = c.dim;
  const std::size_t n = pts.size() / dim;
  const std::size_t nc = c.n_cells();
  const double L = box_size(c.bounds, dim);
  Failures fail(what);

  // -- shapes: every per-cell array has n_cells entries, per-generator n_points.
  ASSERT_EQ(c.n_points, n) << what;
  ASSERT_EQ(c.region.size(), nc) << what;
  ASSERT_EQ(c.volume.size(), nc) << what;
  ASSERT_EQ(c.centroid.size(), nc * dim) << what;
  ASSERT_EQ(c.num_faces.size(), nc) << what;
  ASSERT_EQ(c.neighbor_offsets.size(), nc + 1) << what;
  ASSERT_EQ(c.cell_of.size(), n) << what;
  ASSERT_GT(nc, 0u) << what;

  // -- generator/cell_of are inverse maps; cells in ascending generator order;
  //    region is the label; outside points (label < 0) own no cell.
  for (std::size_t k = 0; k < nc; ++k) {
    const auto g = c.generator[k];
    if (g < 0 || std::size_t(g) >= n) { fail.add("cell ", k, " has generator ", g); continue; }
    if (k > 0 && g <= c.generator[k - 1]) fail.add("generators not ascending at cell ", k);
    if (c.cell_of[g] != std::int32_t(k)) fail.add("cell_of[", g, "] = ", c.cell_of[g], " != ", k);
    const int want_region = labels.empty() ? 0 : labels[g];
    if (c.region[k] != want_region) fail.add("cell ", k, " region ", c.region[k], " != label ", want_region);
  }
  std::size_t with_cell = 0;
  for (std::size_t i = 0; i < n; ++i) {
    if (c.cell_of[i] >= 0) {
      ++with_cell;
      if (!labels.empty() && labels[i] < 0) fail.add("outside point ", i, " owns a cell");
    }
  }
  if (with_cell != nc) fail.add("cell_of has ", with_cell, " entries >= 0 but there are ", nc, " cells");

  // -- duplicates are (dup, owner) with owner < dup, coincident, owner has a cell, dup none.
  for (auto [d, o] : c.duplicates) {
    if (!(o < d)) fail.add("duplicate pair (", d, ",", o, "): owner is not the lowest id");
    if (c.cell_of[d] != -1) fail.add("duplicate ", d, " has a cell");
    if (o >= 0 && c.cell_of[o] < 0 && (labels.empty() || labels[o] >= 0))
      fail.add("duplicate owner ", o, " has no cell");
    for (int a = 0; a < dim; ++a)
      if (pts[d * dim + a] != pts[o * dim + a]) fail.add("duplicate pair (", d, ",", o, ") not coincident");
  }

  // -- volumes are positive and sum to the domain volume (partition of the box).
  const double domain = box_volume(c.bounds, dim);
  double sum = 0;
  for (std::size_t k = 0; k < nc; ++k) {
    if (!(c.volume[k] > 0)) fail.add("cell ", k, " volume ", c.volume[k]);
    sum += c.volume[k];
  }
  if (opt.all_inside) {
    if (!(std::abs(sum - domain) <= opt.volume_sum_tol * domain))
      fail.add("volume sum ", sum, " != domain ", domain, " (rel ", (sum - domain) / domain, ")");
  } else if (!(sum < domain * (1 + 1e-12))) {
    fail.add("inside volume sum ", sum, " exceeds the domain ", domain);
  }

  // -- centroids lie inside the box.
  for (std::size_t k = 0; k < nc; ++k)
    for (int a = 0; a < dim; ++a) {
      const double x = c.centroid[k * dim + a];
      if (!(x >= c.bounds.lo[a] - 1e-12 * L && x <= c.bounds.hi[a] + 1e-12 * L))
        fail.add("cell ", k, " centroid outside the box");
    }

  // -- neighbour CSR: ascending, no self, valid ids; every listed neighbour
  //    either owns a cell or is an outside point; adjacency is symmetric
  //    between cells.
  if (c.neighbor_offsets[0] != 0 || std::size_t(c.neighbor_offsets[nc]) != c.neighbors.size())
    fail.add("neighbor_offsets do not span neighbors");
  std::set<std::pair<int, int>> adj;
  for (std::size_t k = 0; k < nc; ++k) {
    const auto g = c.generator[k];
    auto nb = neighbours_of(c, k);
    for (std::size_t t = 0; t < nb.size(); ++t) {
      const auto j = nb[t];
      if (j < 0 || std::size_t(j) >= n) { fail.add("cell ", k, " lists bad neighbour ", j); continue; }
      if (t > 0 && j <= nb[t - 1]) fail.add("cell ", k, " neighbours not strictly ascending");
      if (j == g) fail.add("cell ", k, " lists itself");
      if (c.cell_of[j] < 0 && (labels.empty() || labels[j] >= 0))
        fail.add("generator ", g, " lists ", j, " which has no cell and is not outside");
      adj.insert({g, j});
    }
  }
  for (auto [a, b] : adj)
    if (c.cell_of[b] >= 0 && !adj.count({b, a})) fail.add("asymmetric adjacency: ", a, " lists ", b, " but not back");

  // ---------------- mesh ----------------
  if (c.vertex_keys.empty()) {
    fail.add("no mesh (build_mesh is on by default)");
    return;
  }
  const std::size_t nv = c.n_vertices();
  ASSERT_EQ(c.vertices.size(), nv * dim) << what;
  ASSERT_EQ(c.cell_face_offsets.size(), nc + 1) << what;
  const std::size_t nf = c.cell_face_offsets[nc];
  ASSERT_EQ(c.face_vertex_offsets.size(), nf + 1) << what;
  ASSERT_EQ(c.face_neighbor.size(), nf) << what;
  ASSERT_EQ(c.face_class.size(), nf) << what;
  ASSERT_EQ(std::size_t(c.face_vertex_offsets[nf]), c.face_vertices.size()) << what;

  // -- vertex keys: dim+1 strictly ascending ids, box planes in [-2dim,-1],
  //    generators valid; one vertex per key (keys unique).
  std::set<std::vector<std::int32_t>> keys;
  for (std::size_t v = 0; v < nv; ++v) {
    std::vector<std::int32_t> key(c.vertex_keys.begin() + v * (dim + 1), c.vertex_keys.begin() + (v + 1) * (dim + 1));
    for (int t = 0; t <= dim; ++t) {
      if (t > 0 && key[t] <= key[t - 1]) fail.add("vertex ", v, " key not strictly ascending");
      if (key[t] < -2 * dim || key[t] >= std::int32_t(n)) fail.add("vertex ", v, " key id ", key[t], " out of range");
    }
    if (!keys.insert(key).second) fail.add("vertex ", v, " key is not unique");
    // Geometry of the key: equidistant from its generators, on its box planes.
    std::vector<double> d2;
    const V3 x = mesh_vertex(c, v);
    for (auto id : key) {
      if (id >= 0 && std::size_t(id) < n) {
        d2.push_back(norm(sub(x, input_point(pts, dim, id))));
      } else if (id < 0 && id >= -2 * dim) {
        const int axis = (-1 - id) / 2;
        const double plane = ((-1 - id) % 2 == 0) ? c.bounds.lo[axis] : c.bounds.hi[axis];
        if (!(std::abs(x[axis] - plane) <= 1e-12 * L)) fail.add("vertex ", v, " not on its box plane ", id);
      }
    }
    for (std::size_t t = 1; t < d2.size(); ++t)
      if (!(std::abs(d2[t] - d2[0]) <= 1e-9 * L)) fail.add("vertex ", v, " not equidistant from its key generators");
    for (int a = 0; a < dim; ++a)
      if (!(x[a] >= c.bounds.lo[a] - 1e-12 * L && x[a] <= c.bounds.hi[a] + 1e-12 * L)) fail.add("vertex ", v, " outside the box");
  }

  // -- per cell faces: count = num_faces; spokes are generators or box planes;
  //    spoke classes agree with labels; the generator spokes are exactly the
  //    neighbour list; every vertex of a face carries the cell's generator and
  //    the spoke in its key; the face loop is closed and consistently oriented
  //    (3D: every directed edge's reverse appears exactly once; Euler V-E+F=2;
  //    2D: the edge chain is one closed cycle); the volume and centroid
  //    integrated from the mesh equal the reported ones.
  std::vector<std::set<std::int32_t>> users(nv);  // cells using each vertex
  for (std::size_t k = 0; k < nc; ++k) {
    const auto g = c.generator[k];
    const auto fb = c.cell_face_offsets[k], fe = c.cell_face_offsets[k + 1];
    if (c.num_faces[k] != fe - fb) fail.add("cell ", k, " num_faces ", c.num_faces[k], " but mesh has ", fe - fb);
    std::set<std::int32_t> spokes;
    std::set<std::int32_t> cell_vertices;
    std::map<std::pair<std::int32_t, std::int32_t>, int> directed;
    const V3 gp = input_point(pts, dim, g);
    double vol = 0;
    V3 cen{0, 0, 0};
    std::vector<std::pair<std::int32_t, std::int32_t>> edges2d;
    for (auto f = fb; f < fe; ++f) {
      const auto s = c.face_neighbor[f];
      // spoke class
      tessera::SpokeClass want;
      if (s < 0) want = tessera::SpokeClass::domain_boundary;
      else if (!labels.empty() && labels[s] < 0) want = tessera::SpokeClass::outside;
      else if (!labels.empty() && labels[s] != labels[g]) want = tessera::SpokeClass::region_boundary;
      else want = tessera::SpokeClass::same_region;
      if (c.face_class[f] != want) fail.add("cell ", k, " face ", f, " spoke ", s, " has class ", int(c.face_class[f]), " expected ", int(want));
      if (s >= 0) spokes.insert(s);
      if (s < -2 * dim || s >= std::int32_t(n) || s == g) fail.add("cell ", k, " face spoke ", s, " invalid");
      const auto vb = c.face_vertex_offsets[f], ve = c.face_vertex_offsets[f + 1];
      std::vector<std::int32_t> fv(c.face_vertices.begin() + vb, c.face_vertices.begin() + ve);
      if (dim == 2 && fv.size() != 2) { fail.add("2D face with ", fv.size(), " vertices"); continue; }
      if (dim == 3 && fv.size() < 3) { fail.add("3D face with ", fv.size(), " vertices"); continue; }
      bool ok = true;
      for (auto v : fv) if (v < 0 || std::size_t(v) >= nv) ok = false;
      if (!ok) { fail.add("cell ", k, " face vertex out of range"); continue; }
      for (auto v : fv) {
        cell_vertices.insert(v);
        const auto* key = &c.vertex_keys[std::size_t(v) * (dim + 1)];
        const bool has_g = std::find(key, key + dim + 1, g) != key + dim + 1;
        const bool has_s = std::find(key, key + dim + 1, s) != key + dim + 1;
        if (!has_g || !has_s) fail.add("cell ", k, " (gen ", g, ") face spoke ", s, " uses vertex ", v, " whose key lacks them");
      }
      if (dim == 2) {
        edges2d.push_back({fv[0], fv[1]});
        const V3 a = sub(mesh_vertex(c, fv[0]), gp), b = sub(mesh_vertex(c, fv[1]), gp);
        const double t = 0.5 * (a[0] * b[1] - a[1] * b[0]);
        vol += t;
        // triangle (g, a, b): centroid g + (a + b) / 3
        for (int q = 0; q < 2; ++q) cen[q] += t * (gp[q] + (a[q] + b[q]) / 3.0);
      } else {
        for (std::size_t t = 0; t < fv.size(); ++t) {
          const auto a = fv[t], b = fv[(t + 1) % fv.size()];
          if (a == b) fail.add("cell ", k, " face with repeated vertex");
          directed[{a, b}]++;
        }
        const V3 o = sub(mesh_vertex(c, fv[0]), gp);
        for (std::size_t t = 1; t + 1 < fv.size(); ++t) {
          const V3 a = sub(mesh_vertex(c, fv[t]), gp), b = sub(mesh_vertex(c, fv[t + 1]), gp);
          const double tv = dot(o, cross(a, b)) / 6.0;  // > 0 when CCW from outside
          vol += tv;
          for (int q = 0; q < 3; ++q) cen[q] += tv * (gp[q] + (o[q] + a[q] + b[q]) / 4.0);
        }
      }
    }
    for (auto v : cell_vertices) users[v].insert(std::int32_t(k));
    auto nb = neighbours_of(c, k);
    if (std::set<std::int32_t>(nb.begin(), nb.end()) != spokes)
      fail.add("cell ", k, " (gen ", g, ") neighbour list differs from its generator spokes");
    if (dim == 3) {
      std::size_t undirected = 0;
      for (auto& [e, cnt] : directed) {
        if (cnt != 1) fail.add("cell ", k, " directed edge used ", cnt, " times");
        auto r = directed.find({e.second, e.first});
        if (r == directed.end()) fail.add("cell ", k, " edge ", e.first, "-", e.second, " has no reverse (surface not closed/oriented)");
        if (e.first < e.second) ++undirected;
      }
      const long V = long(cell_vertices.size()), E = long(undirected), F = long(fe - fb);
      if (V - E + F != 2) fail.add("cell ", k, " (gen ", g, ") Euler V-E+F = ", V, "-", E, "+", F, " = ", V - E + F);
    } else {
      // The polygon: edge t's second vertex is edge t+1's first vertex, cyclically.
      for (std::size_t t = 0; t < edges2d.size(); ++t)
        if (edges2d[t].second != edges2d[(t + 1) % edges2d.size()].first)
          fail.add("cell ", k, " 2D edges do not form a closed chain at edge ", t);
    }
    // Where the doubles may have cancelled, the integral again in
    // __float128, allowed what the mesh vertices' own rounding moves it by
    // (mesh_measure_quad). The centroid weighs each error by its lever, up
    // to the cell's reach, and the library's vertices err by more than the
    // mesh's rounding (up to 64u cond |y|, filter::vertex_eps): the columns
    // of points far off a slanted plane (FromNeighbours) differ by up to 40
    // times the volume's slack times reach / volume; 128 is allowed.
    double volume_slack = 0, centroid_slack = 0;
    auto volume_agrees = [&] { return std::abs(vol - c.volume[k]) <= 1e-9 * c.volume[k] + volume_slack; };
    auto centroid_agrees = [&](int q) {
      return std::abs(cen[q] / vol - c.centroid[k * dim + q]) <= 1e-9 * L + centroid_slack;
    };
    auto all_agree = [&] {
      bool agree = volume_agrees();
      for (int q = 0; q < dim; ++q) agree = agree && centroid_agrees(q);
      return agree;
    };
    if (dim == 3 && !all_agree()) {
      mesh_measure_quad(c, k, gp, vol, cen, volume_slack);
      double reach = 0;
      for (auto v : cell_vertices) reach = std::max(reach, std::sqrt(norm(sub(mesh_vertex(c, v), gp))));
      centroid_slack = 128 * volume_slack / std::abs(vol) * reach;
    }
    if (!volume_agrees())
      fail.add("cell ", k, " (gen ", g, ") mesh volume ", vol, " != volume ", c.volume[k], " (negative = wrong orientation)");
    for (int q = 0; q < dim; ++q)
      if (!centroid_agrees(q)) fail.add("cell ", k, " mesh centroid differs on axis ", q);
  }

  // -- each merged vertex is used by exactly the cells of its non-negative key
  //    ids (those that own a cell: outside points own none).
  for (std::size_t v = 0; v < nv; ++v) {
    std::set<std::int32_t> want;
    for (int t = 0; t <= dim; ++t) {
      const auto id = c.vertex_keys[v * (dim + 1) + t];
      if (id >= 0 && std::size_t(id) < n && c.cell_of[id] >= 0) want.insert(c.cell_of[id]);
    }
    if (users[v] != want) {
      std::ostringstream os;
      os << "key {";
      for (int t = 0; t <= dim; ++t) os << c.vertex_keys[v * (dim + 1) + t] << (t < dim ? "," : "}");
      os << " used by " << users[v].size() << " cells, expected " << want.size();
      fail.add("vertex ", v, " ", os.str());
    }
  }

  if (opt.check_validate) {
    // With the points: also the exact check of sampled cells' measures.
    auto rep = tessera::validate(c, labels, pts);
    if (!rep.ok) {
      std::string m;
      for (auto& s : rep.messages) m += s + "; ";
      fail.add("tessera::validate not ok: ", m);
    }
  }
}

}  // namespace cells_test

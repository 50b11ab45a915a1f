// Measures of a finished cell: volume (area), centroid, faces with their
// vertex loops. One adapter per cell kernel so compositors stay dimension-free.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <vector>

#include "tessera/kernels/hull.hpp"
#include "tessera/kernels/tile.hpp"

namespace tessera::front {

/// Topological coordinate of a vertex: the generator and the ids of its
/// planes, ascending (box planes negative, so they come first).
template <int D>
using Key = std::array<std::int32_t, D + 1>;

/// Where a float measure keeps fewer than ~20 correct bits: its terms cancel
/// to less than 2^-20 of their magnitudes (or to a non-positive sum). That
/// happens for slivers thinner than the rounding of their own vertices (points
/// a few ulps apart), whose float volume can come out zero or negative; such
/// cells are measured exactly instead (exact_cell_measure). Ordinary cells
/// keep a sum within a small factor of the magnitudes.
inline bool measure_cancelled(double sum, double magnitude) { return !(sum > 0x1p-20 * magnitude); }

/// The exact fallback: the cell's vertices by their planes and the same
/// terms as the float measure, in rationals.
template <class Cell>
void measure_exactly(const Cell& cell, const std::vector<kernels::MeasureTerm>& terms, double& volume,
                     double* centroid) {
  constexpr int D = Cell::dim;
  thread_local std::vector<std::int32_t> vertex_planes;
  vertex_planes.clear();
  for (const auto& v : cell.vertices())
    for (int k = 0; k < D; ++k) vertex_planes.push_back(cell.planes()[v.p[k]].id);
  volume = kernels::exact_cell_measure(*cell.exact_context(), cell.generator(), vertex_planes, terms, centroid);
}

/// Volume and centroid (relative to the generator) of a finished cell.
/// Returns the volume's binary exponent: the volume is `volume` times
/// 2^(D x the result), which is 0 unless the cell's sums left double's
/// range (measure_shift; its volume alone may then over- or underflow).
///
/// 3D, without walking the faces: the cell is the union of the tetrahedra
/// (generator, c_f, y_a, y_b) over every edge a -> b of every face f's loop
/// (counter-clockwise from outside), c_f being the foot of the perpendicular
/// from the generator to f's plane: q/2 for a bisector, n d for a box plane.
/// Each tetrahedron's signed volume is det(c_f, y_a, y_b) / 6, and those of
/// one face sum to its cone's volume whatever the polygon's shape. Where
/// those terms may cancel (a cell far longer than wide), each face is
/// fanned from one of its vertices instead (hull_sums, Fan). The edge
/// leaving triangle t within face p[k+1] is t's edge k, whose twin triangle is
/// across(t, k) (hull.hpp), so every term comes straight from a triangle and
/// its edge table: no face walk, no chain of dependent loads.
/// 2D: the shoelace formula over the polygon's edges, bounded edge by edge
/// where a strip far longer than wide may lose bits (tile_sums).
/// Either falls back to exact arithmetic where the terms cancel (above) or
/// where those bounds allow an error past 2^-30 of the measure.
namespace detail {
/// The k of a power of two 2^-k that brings the cell's largest |vertex
/// coordinate| near 1: the measure of a cell whose sums overflowed or came
/// near underflow (vertices beyond ~1e77 or below ~1e-150 in 3D, met only in
/// input that no single frame fits, front/pass.cpp) is taken on vertices
/// scaled by it, exactly.
template <class Cell>
std::int32_t measure_shift(const Cell& cell) {
  double m = 0;
  for (const auto& v : cell.vertices())
    for (int d = 0; d < Cell::dim; ++d) m = std::max(m, std::fabs(v.y[d]));
  return m > 0 && m <= std::numeric_limits<double>::max() ? kernels::filter::binary_exponent(m) + 1 : 0;
}
inline bool out_of_range(double mag, const double* c, int n) {
  double t = mag;
  for (int i = 0; i < n; ++i) t += std::fabs(c[i]);
  return !(t <= std::numeric_limits<double>::max()) || mag < 0x1p-600;  // inf or NaN, or tiny terms
}

// A bound on how far vertex y (unscaled) lies off plane pl: its computed
// residual n.y - d plus that residual's rounding, over |n| >= |n|_1 / sqrt D
// (a factor 1.75 in 3D, 1.5 in 2D). (A scaled bisector's n and d carry the
// same power of two: the ratio holds.)
template <class Plane, int D = static_cast<int>(sizeof(Plane::n) / sizeof(double))>
inline double off_plane(const Plane& pl, const double* y) {
  double dot = -pl.d, terms = std::fabs(pl.d);
  for (int a = 0; a < D; ++a) {
    dot += pl.n[a] * y[a];
    terms += std::fabs(pl.n[a] * y[a]);
  }
  return (D == 3 ? 1.75 : 1.5) * (std::fabs(dot) + 4 * kernels::filter::u * terms) / pl.n1;
}

// n / |n|, computed without under- or overflow (0 for n = 0).
inline void unit_normal(const double* n, double* out) {
  const double m = std::max({std::fabs(n[0]), std::fabs(n[1]), std::fabs(n[2])});
  if (!(m > 0)) {
    out[0] = out[1] = out[2] = 0;
    return;
  }
  const double t[3] = {n[0] / m, n[1] / m, n[2] / m};
  const double l = std::sqrt(t[0] * t[0] + t[1] * t[1] + t[2] * t[2]);
  for (int i = 0; i < 3; ++i) out[i] = t[i] / l;
}

// The 3D measure's sums (below), of the vertices and feet scaled by `sc`
// (a power of two; Scaled false: 1, without the multiplications), and
// emax, the largest Vertex::e (unscaled), for sums_uncertain.
// ScaledPlanes: some bisector's foot is not n / 2: it is stored scaled
// (Hull::has_scaled_planes, also set by a wall), or the cell is a power cell (Hull::weighted),
// whose bisectors' feet are n d / |n|^2 (power.hpp); otherwise every
// bisector's foot is n / 2 without reading Plane::scale.
//
// Fan false: each term is det(c_f, a, b), the cone over the triangle
// (c_f, a, b), c_f the foot of f's plane. Its rounding error is up to
// ~u |c_f| |a| |b| (sums_uncertain bounds it by the cell's radius): small
// for a cell about its generator, but a face far off and small, or far
// beside its plane's foot, cancels. A column cell 5e7 long and 0.07 wide
// (points far off a slanted plane), whose end on a box plane lies 3e5
// beside that plane's foot 1e6 away, had terms worth 1e5 with errors of
// ~1e7, and until stop 63 its volume came out wrong by up to 100%.
// Fan true: each face is fanned from one of its own vertices r (the last
// triangle to name its plane: `face_vertex`), each term det(r, a, b) =
// det(c_f, a - r, b - r), whose error is u |c_f| times the face's diameter
// squared. An extra pass and six subtractions a term, so only for the
// cells that need it (measure()). It also bounds, into `blur`, how far the
// vertices' own errors, and the terms' rounding, may move the volume (Fan
// false leaves it alone). The sum is (1/3) sum_f c_f . A_f, A_f the area
// vector of f's loop, so a vertex moved along c_f (off f's plane) leaves
// it; what moves it is a vertex sliding within f across one of its edges:
// c_f . dA_f = 1/2 sum_edges (d_a + d_b) . ((b - a) x c_f), per edge |b - a|
// |c_f| times the ends' moves within f perpendicular to the edge. The edge
// lies on f and its other plane g, and a move m that way shows in the
// residuals only as m sin(theta) off g (theta the angle between f and g),
// so m <= (off_g + cos(theta) off_f) / sin(theta) (off_plane bounds each
// residual); and m <= sqrt(3) e, the vertex's own bound: the smaller
// counts. Until stop 74 the bound was each fan triangle's area times the
// residuals alone: between nearly parallel faces (a dense cluster's cell
// reaching 1e4 away to two far points' nearly parallel bisectors, theta
// ~2e-5) a vertex 1e-12 off its planes slid 1e-7 along them, and a volume
// passed with an error of 1.2e-8 where the bound said 1e-14.
template <bool Scaled, bool ScaledPlanes, bool Fan>
void hull_sums(const kernels::Hull& hull, double sc, double& vol, double& mag, double* c, double& blur, double& emax) {
  const auto& verts = hull.vertices();
  const auto& planes = hull.planes();
  const std::uint32_t* face_vertex = nullptr;
  const std::array<double, 3>* unit = nullptr;  // each plane's unit normal
  if constexpr (Fan) {
    thread_local std::vector<std::uint32_t> table;
    thread_local std::vector<std::array<double, 3>> units;
    table.resize(planes.size());  // every entry read below is written first
    units.resize(planes.size());
    for (std::size_t t = 0; t < verts.size(); ++t)
      for (int k = 0; k < 3; ++k) table[verts[t].p[k]] = static_cast<std::uint32_t>(t);
    for (std::size_t q = 0; q < planes.size(); ++q) unit_normal(planes[q].n, units[q].data());
    face_vertex = table.data();
    unit = units.data();
  }
  vol = 0, mag = 0, c[0] = c[1] = c[2] = 0, emax = 0;
  if constexpr (Fan) blur = 0;
  const bool weighted = ScaledPlanes && hull.weighted();
  for (std::size_t t = 0; t < verts.size(); ++t) {
    const auto& v = verts[t];
    emax = std::max(emax, v.e);
    double as[3];
    if constexpr (Scaled)
      for (int i = 0; i < 3; ++i) as[i] = v.y[i] * sc;
    const double* a = Scaled ? as : v.y;
    for (int k = 0; k < 3; ++k) {
      const auto face = v.p[(k + 1) % 3];
      const auto& pl = planes[face];
      // The foot n d / |n|^2: d = |n|^2 / 2 on a bisector (2^scale times
      // that on a scaled one), |n| = 1 on a box plane; a wall's (a cell
      // with one has_scaled_planes) is computed.
      double w = pl.id < 0 ? pl.d : 0.5;
      if constexpr (ScaledPlanes) {
        if (pl.id >= 0 && (weighted || pl.scale != 0))
          w = weighted ? pl.d / (pl.n[0] * pl.n[0] + pl.n[1] * pl.n[1] + pl.n[2] * pl.n[2])  // scale-free
                       : std::ldexp(0.5, pl.scale);
        else if (kernels::is_wall_plane(pl.id))
          w = pl.d / (pl.n[0] * pl.n[0] + pl.n[1] * pl.n[1] + pl.n[2] * pl.n[2]);
      }
      if constexpr (Scaled) w *= sc;
      const double f[3] = {pl.n[0] * w, pl.n[1] * w, pl.n[2] * w};
      double bs[3];
      const double* by = verts[hull.across(t, k)].y;
      if constexpr (Scaled)
        for (int i = 0; i < 3; ++i) bs[i] = by[i] * sc;
      const double* b = Scaled ? bs : by;
      // The term's tetrahedron is (generator, o, a, b): o the foot, or the
      // fan's vertex.
      double s, rs[3];
      const double* o = f;
      if constexpr (Fan) {
        const double* ry = verts[face_vertex[face]].y;
        if constexpr (Scaled)
          for (int i = 0; i < 3; ++i) rs[i] = ry[i] * sc;
        const double* r = Scaled ? rs : ry;
        const double ar[3] = {a[0] - r[0], a[1] - r[1], a[2] - r[2]};
        const double br[3] = {b[0] - r[0], b[1] - r[1], b[2] - r[2]};
        const double n[3] = {ar[1] * br[2] - ar[2] * br[1], ar[2] * br[0] - ar[0] * br[2],
                             ar[0] * br[1] - ar[1] * br[0]};
        s = f[0] * n[0] + f[1] * n[1] + f[2] * n[2];
        const auto& pg = planes[v.p[k]];  // the edge's other plane (Hull::across: planes p[k], p[k+1])
        const double* uf = unit[face].data();
        const double* ug = unit[v.p[k]].data();
        const double x[3] = {uf[1] * ug[2] - uf[2] * ug[1], uf[2] * ug[0] - uf[0] * ug[2], uf[0] * ug[1] - uf[1] * ug[0]};
        // sin and cos of the angle, the sine shaded down for its rounding.
        const double sin_fg = std::sqrt(x[0] * x[0] + x[1] * x[1] + x[2] * x[2]) * (1 - 0x1p-40) - 8 * kernels::filter::u;
        const double cos_fg = std::fabs(uf[0] * ug[0] + uf[1] * ug[1] + uf[2] * ug[2]);
        // A vertex's own bound (Vertex::e per coordinate) bounds its slide
        // too; the tighter of the two counts.
        auto slide = [&](const auto& vx) {
          const double by_residuals = sin_fg > 0 ? (off_plane(pg, vx.y) + cos_fg * off_plane(pl, vx.y)) / sin_fg
                                                 : std::numeric_limits<double>::infinity();
          const double by_bound = 1.7320508075688774 * vx.e;  // sqrt(3) e
          return (by_residuals < by_bound ? by_residuals : by_bound) * sc;  // NaN residuals: the bound
        };
        const double ab[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]};
        // (In the sums' frame, where they stay in double's range; a square
        // that overflows makes the bound infinite, and the cell exact.)
        const double edge = std::sqrt(ab[0] * ab[0] + ab[1] * ab[1] + ab[2] * ab[2]);
        const double foot = std::sqrt(f[0] * f[0] + f[1] * f[1] + f[2] * f[2]);
        const double moved = edge * foot * (slide(v) + slide(verts[hull.across(t, k)]));
        // The term's rounding, by its products' magnitudes (a long edge
        // times a short one, where a column's faces are long).
        const double rounding =
            8 * kernels::filter::u *
            (std::fabs(f[0]) * (std::fabs(ar[1] * br[2]) + std::fabs(ar[2] * br[1])) +
             std::fabs(f[1]) * (std::fabs(ar[2] * br[0]) + std::fabs(ar[0] * br[2])) +
             std::fabs(f[2]) * (std::fabs(ar[0] * br[1]) + std::fabs(ar[1] * br[0])));
        blur += (moved + rounding) / 6;  // in the volume's units (the sums are six times it)
        o = r;
      } else {
        s = f[0] * (a[1] * b[2] - a[2] * b[1]) + f[1] * (a[2] * b[0] - a[0] * b[2]) +
            f[2] * (a[0] * b[1] - a[1] * b[0]);
      }
      vol += s;
      mag += std::fabs(s);
      for (int i = 0; i < 3; ++i) c[i] += s * (o[i] + a[i] + b[i]);
    }
  }
}

// Whether the foot's sums (Fan false) may have lost more than ~20 bits:
// each of the 3 nv terms errs by at most ~21u R^3 (the three vectors within
// R, the cell's radius, of the generator: a determinant's absolute terms sum
// to at most (sqrt(3) R)^3, and four roundings each), bounded by 32u R^3.
// An ordinary cell's volume is a fair fraction of R^3 (uniform points:
// ~0.3), far above the bound; a column 5e7 long and 0.07 wide is 1e-11 of it.
// Or whether the vertices' own errors may move the volume by 2^-30 of it:
// each vertex lies within sqrt(3) e of its exact place (e, the largest
// Vertex::e, bounds its error per coordinate). A move d of an edge's end
// across the edge moves the sums (six times the volume) by |edge| |c_f| d
// on each of the edge's two faces (hull_sums, Fan), each edge at most 2R
// long and each foot within R: over the 3 nv / 2 edges, 12 sqrt(3) nv e R^2.
// (Until stop 74 this was e times the surface, 4 pi R^2, sqrt(3) and six:
// 131 e R^2; a vertex's slide along nearly parallel faces moves the volume
// more than its surface says.) Until stop 65 the gate had
// only the first test (the 2D gate has had both since stop 64): a cell of
// nearly collinear points, with vertices of condition ~1e5 (e ~1e-11 of the
// cell's size), kept a volume 7.9e-9 off (Oracle.VertexErrorsBoundTheVolume;
// found by validate's exact check). Such a cell is now summed again by
// faces (Fan), whose bound on the vertices' errors (blur, from the residuals)
// is far tighter, and measured exactly if that bound passes 2^-30.
inline bool sums_uncertain(double vol, std::size_t nv, double radius, double emax) {
  const double bound = 32 * kernels::filter::u * static_cast<double>(3 * nv) * radius * radius * radius;
  const double moved = 21 * static_cast<double>(nv) * emax * radius * radius;  // 12 sqrt(3) = 20.8
  return !(std::fabs(vol) > 0x1p20 * bound && std::fabs(vol) > 0x1p30 * moved);  // NaN and inf too
}

// The 2D measure's sums (the shoelace formula), of the vertices scaled by
// `sc` (a power of two; Scaled false: 1): s (twice the area), mag (the sum
// of the terms' magnitudes), c (the centroid's sums), and emax, the largest
// Vertex::e (unscaled), for tile_sums_uncertain.
//
// Bounded true: they also bound, into `err`, how far the computed s may lie
// from twice the area of the exact cell. Two sources, each to first order:
// * the terms' rounding: a cross product a0 b1 - a1 b0 errs by up to
//   3u (|a0 b1| + |a1 b0|), and the sum of m terms by (m - 1)u times their
//   magnitudes. In a strip 5e11 long and 0.07 wide, slanted (points on a
//   slanted row and one 1e12 off it), each cross of two vertices along it
//   cancels from products of ~1e23 to ~1e10: 1e-5 of the area was lost.
//   Taking the terms about one of the strip's own vertices (the 3D fan's
//   remedy) leaves the same products: only exact arithmetic helps there.
// * the vertices' own errors: moving vertex v by delta changes the area by
//   half delta x (next - prev); a delta along one of v's edges leaves v on
//   that edge's line and moves it off the other's by the same cross, so each
//   edge's length times how far its ends may lie off its line (off_plane),
//   summed, bounds what all of them move it (twice that in s).
// An extra pass over the edges, so only for the cells that need it (measure()).
struct TileSums {
  double s = 0, mag = 0, c[2] = {0, 0}, emax = 0;
  double err = 0;  // Bounded only
};
template <bool Scaled, bool Bounded>
TileSums tile_sums(const kernels::Tile& tile, double sc) {
  const auto& v = tile.vertices();
  const auto& planes = tile.planes();
  const std::size_t m = v.size();
  TileSums r;
  double& s = r.s;
  double& mag = r.mag;
  double* c = r.c;
  double rounding = 0, moved = 0;
  for (std::size_t k = 0; k < m; ++k) {
    r.emax = std::max(r.emax, v[k].e);
    const double* ay = v[k].y;
    const double* by = v[k + 1 == m ? 0 : k + 1].y;
    double as[2], bs[2];
    if constexpr (Scaled)
      for (int i = 0; i < 2; ++i) as[i] = ay[i] * sc, bs[i] = by[i] * sc;
    const double* a = Scaled ? as : ay;
    const double* b = Scaled ? bs : by;
    const double cr = a[0] * b[1] - a[1] * b[0];
    s += cr;
    mag += std::fabs(cr);
    c[0] += (a[0] + b[0]) * cr;
    c[1] += (a[1] + b[1]) * cr;
    if constexpr (Bounded) {
      rounding += std::fabs(a[0] * b[1]) + std::fabs(a[1] * b[0]);
      const auto& line = planes[v[k].p[1]];  // edge k's (Tile: vertex k's leaving plane)
      moved += std::hypot(b[0] - a[0], b[1] - a[1]) * std::max(off_plane(line, ay), off_plane(line, by)) * sc;
    }
  }
  if constexpr (Bounded)
    r.err = 3 * kernels::filter::u * rounding + static_cast<double>(m) * kernels::filter::u * mag + 2 * moved;
  return r;
}

// Whether the 2D sums (Bounded false) may fall short of ~30 correct bits,
// from bounds alone, without a pass over the edges: R, the cell's radius,
// bounds every vertex's distance from the generator, so each cross's
// rounding is at most 3u R^2 and the sum's (m - 1)u m R^2; and e, the
// largest Vertex::e, bounds each vertex's error, so the area moves by at
// most e sqrt 2 times the perimeter, itself at most 2 pi R. An ordinary
// cell's area is a fair fraction of R^2, far above both; a strip far longer
// than wide, or a cell with an ill-conditioned vertex kept, may not be, and
// its edges are then bounded one by one (tile_sums, Bounded).
inline bool tile_sums_uncertain(double s, std::size_t m, double radius, double emax) {
  const double md = static_cast<double>(m);
  const double bound = kernels::filter::u * md * (md + 2) * radius * radius + 18 * emax * radius;  // in s
  return !(std::fabs(s) > 0x1p30 * bound);  // NaN and inf too
}
}  // namespace detail

inline std::int32_t measure(const kernels::Hull& hull, double& volume, std::array<double, 3>& centroid) {
  const auto& verts = hull.vertices();
  const auto& planes = hull.planes();
  double vol, mag, c[3], blur = 0, emax = 0;
  const bool scaled_planes = hull.has_scaled_planes() || hull.weighted();
  if (scaled_planes) [[unlikely]]
    detail::hull_sums<false, true, false>(hull, 1.0, vol, mag, c, blur, emax);
  else
    detail::hull_sums<false, false, false>(hull, 1.0, vol, mag, c, blur, emax);
  std::int32_t shift = 0;  // the sums are of coordinates scaled by 2^-shift
  if (detail::out_of_range(mag, c, 3)) [[unlikely]] {
    shift = detail::measure_shift(hull);
    if (shift != 0) detail::hull_sums<true, true, false>(hull, kernels::filter::pow2(-shift), vol, mag, c, blur, emax);
  }
  bool exact = measure_cancelled(vol, mag);
  // The cell's radius, an upper bound (half the security radius), in the
  // sums' scale.
  const double sc = kernels::filter::pow2(-shift);
  if (!exact && detail::sums_uncertain(vol, verts.size(), 0.5 * std::sqrt(hull.security_radius2()) * sc, emax * sc))
      [[unlikely]] {
    if (shift == 0) detail::hull_sums<false, true, true>(hull, 1.0, vol, mag, c, blur, emax);
    else detail::hull_sums<true, true, true>(hull, sc, vol, mag, c, blur, emax);
    // Where the vertices' errors may move the volume by 2^-30 of it, it is
    // measured exactly from their planes: a column 5e7 long and 0.07 wide,
    // slanted (points 1e8 off a slanted plane), has vertices ~1e-8 off its
    // walls, and its volume blurred by ~1e-7 (at 1e12 off, 1e-3).
    // Axis-aligned, the walls' residuals leave out the long coordinate, and
    // such columns keep their float measure. (A bound by 64u |y|max, the
    // vertices' isotropic error, sent those too, and a thin band's cells,
    // to the exact measure: 3,000 points between two 1e9 off a plane 0.17 ->
    // 4.8 s; by the vertices' own bounds, Vertex::e, wide where kept
    // ill-conditioned, 100,000 band points took 2.2 times as long.)
    exact = measure_cancelled(vol, mag) || !(blur <= 0x1p-30 * std::fabs(vol / 6));  // NaN too
  }
  if (exact && hull.exact_context() != nullptr && !verts.empty()) [[unlikely]] {
    thread_local std::vector<kernels::MeasureTerm> terms;
    terms.clear();
    for (std::size_t t = 0; t < verts.size(); ++t)
      for (int k = 0; k < 3; ++k)
        terms.push_back({planes[verts[t].p[(k + 1) % 3]].id, static_cast<std::uint32_t>(t), hull.across(t, k)});
    measure_exactly(hull, terms, volume, centroid.data());
    return 0;
  }
  volume = vol / 6.0;
  for (int i = 0; i < 3; ++i) {
    const double ci = vol != 0 ? c[i] / (4.0 * vol) : 0.0;
    centroid[static_cast<std::size_t>(i)] = shift == 0 ? ci : std::ldexp(ci, shift);
  }
  return shift;
}

inline std::int32_t measure(const kernels::Tile& tile, double& area, std::array<double, 2>& centroid) {
  const std::size_t m = tile.vertices().size();
  detail::TileSums t = detail::tile_sums<false, false>(tile, 1.0);
  std::int32_t shift = 0;
  if (detail::out_of_range(t.mag, t.c, 2)) [[unlikely]] {
    shift = detail::measure_shift(tile);
    if (shift != 0) t = detail::tile_sums<true, false>(tile, kernels::filter::pow2(-shift));
  }
  bool exact = measure_cancelled(t.s, t.mag);
  const double sc = kernels::filter::pow2(-shift);
  if (!exact && detail::tile_sums_uncertain(t.s, m, 0.5 * std::sqrt(tile.security_radius2()) * sc, t.emax * sc))
      [[unlikely]] {
    // Where the terms' rounding or the vertices' errors may move the area by
    // 2^-30 of it, it is measured exactly from their lines (stop 64: strips
    // of points on a slanted row at random gaps, one point 1e12 off it, had
    // areas off by up to 14%; an axis-aligned strip keeps its float measure).
    t = shift == 0 ? detail::tile_sums<false, true>(tile, 1.0) : detail::tile_sums<true, true>(tile, sc);
    exact = measure_cancelled(t.s, t.mag) || !(t.err <= 0x1p-30 * std::fabs(t.s));  // NaN too
  }
  if (exact && tile.exact_context() != nullptr && m != 0) [[unlikely]] {
    thread_local std::vector<kernels::MeasureTerm> terms;
    terms.clear();
    for (std::size_t k = 0; k < m; ++k)
      terms.push_back({0, static_cast<std::uint32_t>(k), static_cast<std::uint32_t>(k + 1 == m ? 0 : k + 1)});
    measure_exactly(tile, terms, area, centroid.data());
    return 0;
  }
  area = 0.5 * t.s;
  for (int i = 0; i < 2; ++i) {
    const double ci = t.s != 0 ? t.c[i] / (3 * t.s) : 0.0;
    centroid[static_cast<std::size_t>(i)] = shift == 0 ? ci : std::ldexp(ci, shift);
  }
  return shift;
}

/// Sort a key's ids ascending by a sorting network (branch-free min/max;
/// std::sort's call and branches cost more on 3 or 4 ids).
template <std::size_t N>
[[gnu::always_inline]] inline void sort_key(std::array<std::int32_t, N>& k) {
  auto order = [&](std::size_t a, std::size_t b) {
    const std::int32_t lo = std::min(k[a], k[b]), hi = std::max(k[a], k[b]);
    k[a] = lo;
    k[b] = hi;
  };
  if constexpr (N == 4) {
    order(0, 1); order(2, 3); order(0, 2); order(1, 3); order(1, 2);
  } else {
    static_assert(N == 3);
    order(0, 1); order(1, 2); order(0, 1);
  }
}

inline Key<3> vertex_key(const kernels::Hull& hull, std::size_t t) {
  const auto& v = hull.vertices()[t];
  const auto& pl = hull.planes();
  Key<3> k{hull.generator(), pl[v.p[0]].id, pl[v.p[1]].id, pl[v.p[2]].id};
  sort_key(k);
  return k;
}

inline Key<2> vertex_key(const kernels::Tile& tile, std::size_t t) {
  const auto& v = tile.vertices()[t];
  const auto& pl = tile.planes();
  Key<2> k{tile.generator(), pl[v.p[0]].id, pl[v.p[1]].id};
  sort_key(k);
  return k;
}

/// Visit each face once as f(local plane index, neighbour id) (box planes
/// negative), in the order the mesh numbers a cell's faces: 3D by plane
/// index, 2D counter-clockwise (the edge leaving vertex k is face k).
template <class F>
void for_each_face_plane(kernels::Hull& hull, F&& f) {
  const auto& pl = hull.planes();
  hull.for_each_face_plane([&](kernels::Hull::Index p) { f(p, pl[p].id); });
}

template <class F>
void for_each_face_plane(kernels::Tile& tile, F&& f) {
  const auto& v = tile.vertices();
  const auto& pl = tile.planes();
  for (std::size_t k = 0; k < v.size(); ++k) f(v[k].p[1], pl[v[k].p[1]].id);
}

/// Visit each face's neighbour id once, f(id), without the vertex loops:
/// what a cell's spokes need.
template <class CellT, class F>
void for_each_spoke(CellT& cell, F&& f) {
  for_each_face_plane(cell, [&](auto, std::int32_t id) { f(id); });
}

}  // namespace tessera::front

// Walls: half-spaces n.x <= d that cut a finished cell (Hull/Tile::
// clip_wall), so that the domain is the box cut down to a convex polytope.
//
// A cell is built in the box as ever (its neighbours, its security radius),
// then cut by each wall in turn: the cell inside the walls is the box cell's
// part inside them, since a wall does not depend on the other points. The
// only question a wall asks is a vertex's side of it, decided by the float
// filter below and else exactly (exact_wall_sign), as a function of the
// vertex's planes alone: every cell holding a vertex takes the same decision,
// and the cut cells stay conformal. The new vertices lie on the wall (plane
// id wall_plane_id(k)), each the meeting point of its planes as any other.
#pragma once

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <vector>

#include "tessera/kernels/exact_predicates.hpp"
#include "tessera/kernels/filter.hpp"

namespace tessera::kernels::walls {

/// A wall relative to a generator p: n.y <= d for y = x - p, with |n|_1 = n1
/// and d_err bounding the rounding of d = d_wall - n.p.
template <int D>
struct RelativeWall {
  double n[D];
  double d;
  double n1;
  double d_err;
};

template <int D>
RelativeWall<D> relative(const Wall& w, const double* p) {
  RelativeWall<D> r;
  double d = w.d, mag = std::fabs(w.d);
  r.n1 = 0;
  for (int k = 0; k < D; ++k) {
    r.n[k] = w.n[k];
    r.n1 += std::fabs(w.n[k]);
    const double t = w.n[k] * p[k];
    d -= t;
    mag += std::fabs(t);
  }
  r.d = d;
  // D products and D differences, each rounded once: within gamma_{2D} of
  // the magnitudes' sum (itself rounded; doubled for margin).
  r.d_err = 4 * D * filter::u * mag + filter::abs_eps;
  return r;
}

/// `relative`'s wall with its offset computed exactly and rounded
/// (exact_wall_offset), so that it is as accurate as a clipping plane's
/// must be (within plane_eps |d|: the vertices solved on it then keep their
/// bounds): for a wall that may cut the cell (a few cells of many).
template <int D>
void refine(RelativeWall<D>& r, const Wall& w, const double* p) {
  r.d = exact_wall_offset(w, p, D);
  r.d_err = 4 * filter::u * std::fabs(r.d) + filter::abs_eps;
}

/// A ball holding a cell's vertices, exact ones included: centre c
/// relative to the generator, radius r. Where a cell is long and thin (the
/// cell of a point on a sphere, cut by its hull: a needle from the point to
/// the centre), it lies far tighter than the ball of the vertices' reach
/// around the generator.
template <int D>
struct Ball {
  double c[D];
  double r;
};

/// The ball around the vertices' bounding box's centre through the farthest
/// vertex, widened by the vertices' error bounds (e, along each axis) and
/// by 1e-12 for its own rounding. Squares that would under- or overflow
/// take the farthest coordinate difference times sqrt(D) instead; a vertex
/// not finite makes it infinite (no wall is missed).
template <int D, class Vertex>
Ball<D> vertex_ball(const Vertex* verts, std::size_t nv) {
  Ball<D> b;
  double lo[D], hi[D], e = 0;
  bool finite = true;
  for (int a = 0; a < D; ++a) lo[a] = hi[a] = nv > 0 ? verts[0].y[a] : 0;
  for (std::size_t t = 0; t < nv; ++t) {
    for (int a = 0; a < D; ++a) {  // (a NaN or an infinity clears `finite`: then no comparison matters)
      const double y = verts[t].y[a];
      lo[a] = y < lo[a] ? y : lo[a];
      hi[a] = y > hi[a] ? y : hi[a];
      finite &= std::isfinite(y);
    }
    e = verts[t].e > e ? verts[t].e : e;
    finite &= std::isfinite(verts[t].e);
  }
  for (int a = 0; a < D; ++a) b.c[a] = 0.5 * lo[a] + 0.5 * hi[a];
  double r2 = 0, far = 0;
  for (std::size_t t = 0; t < nv; ++t) {
    double s = 0;
    for (int a = 0; a < D; ++a) {
      const double g = verts[t].y[a] - b.c[a];
      s += g * g;
      far = std::fabs(g) > far ? std::fabs(g) : far;
    }
    r2 = s > r2 ? s : r2;
  }
  const double r = r2 > 1e-280 && r2 < 1e280 ? std::sqrt(r2) : far * std::sqrt(static_cast<double>(D));
  b.r = finite ? (r + e * std::sqrt(static_cast<double>(D))) * (1 + 1e-12) : std::numeric_limits<double>::infinity();
  return b;
}

/// Whether wall `w` (of norm at most `norm`: Wall::norm) surely cuts nothing
/// of a cell within ball `b`: n.y <= n.c + |n| r < d for every vertex, with
/// room for d's rounding and n.c's. Most cells of a many-sided domain lie
/// far inside most walls.
template <int D>
bool misses(const RelativeWall<D>& w, double norm, const Ball<D>& b) {
  double dot = 0, mag = std::fabs(w.d);
  for (int a = 0; a < D; ++a) {
    dot += w.n[a] * b.c[a];
    mag += std::fabs(w.n[a] * b.c[a]);
  }
  return w.d - dot - w.d_err - 4 * D * filter::u * mag > norm * b.r * (1 + 1e-12);
}

/// Wall `wall` relative to a cell's generator `site`, refined, into `w`;
/// false where it surely cuts nothing of the cell (vertices within ball
/// `b`, `verts[0..nv)`): by `misses`, else by `all_inside`. The first steps
/// of Hull::clip_wall and Tile::clip_wall alike.
template <int D, class Vertex>
bool may_cut(const Wall& wall, const double* site, const Ball<D>& b, const Vertex* verts, std::size_t nv,
             RelativeWall<D>& w);

/// Whether every vertex lies surely inside wall `w` by the float filter of
/// `signs` below, before `refine`: its bound holds with the unrefined
/// offset's larger d_err too. A cell whose reach crosses a wall's plane
/// mostly lies inside it all the same (a boundary cell of a convex hull's
/// thousands of walls meets dozens that way): this spares each such wall
/// the exact offset (exact_wall_offset: 5% of a 100k-point hull run).
template <int D, class Vertex>
bool all_inside(const Vertex* verts, std::size_t nv, const RelativeWall<D>& w) {
  const double de = filter::plane_eps * std::fabs(w.d) + w.d_err;
  for (std::size_t t = 0; t < nv; ++t) {
    const Vertex& v = verts[t];
    double dot = w.n[0] * v.y[0];
    for (int c = 1; c < D; ++c) dot += w.n[c] * v.y[c];
    if (!(w.d - dot > w.n1 * v.e + de)) return false;  // (NaN: not surely)
  }
  return true;
}

template <int D, class Vertex>
bool may_cut(const Wall& wall, const double* site, const Ball<D>& b, const Vertex* verts, std::size_t nv,
             RelativeWall<D>& w) {
  w = relative<D>(wall, site);
  if (misses(w, wall.norm, b) || all_inside<D>(verts, nv, w)) return false;
  refine(w, wall, site);
  return true;
}

/// Each vertex's side of wall k (relative: `w`, refined) into `sign`: +1
/// keep (inside or on it), -1 remove; returns the number removed. A vertex
/// is decided by the float filter where P = d - n.y clears its bound (the
/// vertex's own bound e, the plane's rounding as a clip's, and d's), else
/// exactly. A vertex on an earlier wall is decided alike: that wall's
/// offset was refined, so the vertex's bound holds as a clip's does.
template <int D, class Vertex, class Plane>
std::size_t signs(const Vertex* verts, std::size_t nv, const Plane* planes, const RelativeWall<D>& w, int k,
                  const ExactContext& ctx, std::int32_t gen, std::vector<filter::Sign>& sign) {
  const double de = filter::plane_eps * std::fabs(w.d) + w.d_err;
  std::size_t removed = 0;
  for (std::size_t t = 0; t < nv; ++t) {
    const Vertex& v = verts[t];
    double dot = w.n[0] * v.y[0];
    for (int c = 1; c < D; ++c) dot += w.n[c] * v.y[c];
    const double P = w.d - dot, e = w.n1 * v.e + de;
    int s = P - P == 0 ? (P > e) - (P < -e) : 0;  // (undecided where n.y overflowed)
    if (s == 0) {
      std::int32_t ids[D];
      for (int c = 0; c < D; ++c) ids[c] = planes[v.p[c]].id;
      s = exact_wall_sign(ctx, gen, ids, k);
    }
    sign[t] = static_cast<filter::Sign>(s);
    removed += s < 0;
  }
  return removed;
}

}  // namespace tessera::kernels::walls

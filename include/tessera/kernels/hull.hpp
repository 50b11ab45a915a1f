// The 3D cell builder: a convex polyhedron clipped by half-spaces.
//
// Representation (dual, after Lévy's ConvexCell and Ray et al., "Meshless
// Voronoi on the GPU", 2018): the cell is a list of planes (its faces: box
// planes first, then one bisector per clipping neighbour) and a list of
// vertices, each the meeting point of three planes stored as a triangle
// (a, b, c) of local plane indices, ordered counter-clockwise seen from
// outside (det(n_a, n_b, n_c) > 0). The triangles form a closed, consistently
// oriented surface: vertex adjacency is the table `edge_tri` that maps a
// directed plane pair (a -> b) to the triangle holding that edge.
//
// Every vertex's topological coordinate is {generator, ids of its 3 planes}.
// Clip decisions go through the float filter, then the exact predicate, so the
// combinatorics are those of the exactly computed, symbolically perturbed
// diagram: every vertex is simple and every cell agrees with its neighbours.
#pragma once

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstdint>
#include <limits>
#include <stdexcept>
#include <tuple>
#include <utility>
#include <vector>

#include "tessera/buffer.hpp"  // DefaultInitAllocator
#include "tessera/kernels/assembly.hpp"
#include "tessera/kernels/dual_faces.hpp"
#include "tessera/kernels/exact_predicates.hpp"
#include "tessera/kernels/walls.hpp"  // walls::Ball
#include "tessera/kernels/filter.hpp"
#include "tessera/kernels/lane_blocks.hpp"
#include "tessera/kernels/power.hpp"
#include "tessera/kernels/prepared_signs.hpp"

namespace tessera::kernels {

enum class ClipResult { unchanged, clipped, emptied };

class Hull {
 public:
  static constexpr int dim = 3;
  /// A local plane's index (vertices hold three). 32 bits since stop 59: a
  /// cell may have any number of faces (16 bits stopped the centre of 70,000
  /// points on a sphere with an error).
  using Index = std::uint32_t;
  /// The domain box's planes are always the cell's first local planes.
  static constexpr Index box_planes = 6;
  /// The most bisectors assemble() takes (more: the cell is clipped), below
  /// the local plane limit with the box's six and a far plane. Beyond
  /// dense_planes the edge map is the hash, so memory follows the
  /// triangles (until stop 55 the limit was 500: the dense table of a hull
  /// point of a terrain's samples, thousands of neighbours, took gigabytes,
  /// and the centre of 40,000 points on a sphere was clipped instead, in
  /// time quadratic in its faces: 6 s).
  static constexpr std::size_t max_assembled_planes = 0xFFFFFFF0;
  /// A cell's local planes stay below this (Index's range; clip() throws
  /// beyond, which no input of fewer than 2^32 points reaches).
  static constexpr std::size_t max_planes = 0xFFFFFFFF;
  struct Plane {
    double n[3];
    double d;
    double n1;           // |n|_1, for the error bound
    std::int32_t id;     // generator id, or box-plane id < 0
    std::int32_t scale;  // a bisector: n = q 2^-scale; 0 unless |q| is huge or tiny (filter::Bisector)
  };
  struct Vertex {
    double y[3];         // position relative to the generator
    double e;            // err + plane_eps * |y|_inf, err bounding |y - exact|_inf (filter.hpp)
    double r2;           // upper bound on the exact |y|^2
    Index p[3];              // local plane indices, counter-clockwise from outside
    std::uint32_t deferred;  // 1: its exact solve waits for solve_deferred
  };
  static_assert(sizeof(Vertex) == 56, "three 32-bit plane indices and the deferral flag");

  /// Start the cell of generator `gen` at p as the domain box [lo, hi].
  void reset(std::int32_t gen, const double* p, const double* lo, const double* hi,
             const ExactContext* exact) {
    start(gen, p, lo, hi, exact);
    ensure_table(64);
    resize_vertices(8);
    for (int c = 0; c < 8; ++c) {
      const int sx = c & 1, sy = (c >> 1) & 1, sz = (c >> 2) & 1;
      Vertex& v = verts_[static_cast<std::size_t>(c)];
      v.y[0] = sx ? planes_[1].d : -planes_[0].d;
      v.y[1] = sy ? planes_[3].d : -planes_[2].d;
      v.y[2] = sz ? planes_[5].d : -planes_[4].d;
      double ymax = std::max({std::fabs(v.y[0]), std::fabs(v.y[1]), std::fabs(v.y[2])});
      double err = filter::u * ymax;  // each coordinate rounded once
      v.e = err + filter::plane_eps * ymax;
      set_radius(v, err);
      v.deferred = 0;
      const Index a = static_cast<Index>(sx), b = static_cast<Index>(2 + sy), cc = static_cast<Index>(4 + sz);
      // det(±e_x, ±e_y, ±e_z) = product of the signs; swap to make it positive.
      const bool positive = ((sx + sy + sz) % 2) == 1;  // signs: upper=+, lower=-
      v.p[0] = a;
      v.p[1] = positive ? b : cc;
      v.p[2] = positive ? cc : b;
      settle(static_cast<std::uint32_t>(c));
    }
    update_radius();
  }

  /// Clip by the bisector with generator j, q = p_j - p_i (computed in double).
  ClipResult clip(std::int32_t j, const double* q) {
    if (deferred_asks_ >= filter::deferred_ask_limit) [[unlikely]] {
      deferred_asks_ = 0;
      solve_deferred();
    }
    filter::Bisector<3> b(q);
    if (weighted_) [[unlikely]] weigh(b, *exact_, gen_, j);  // a power diagram's plane (power.hpp)
    const std::size_t nv = verts_.size();
    auto exact = [&](std::size_t t) { return exact_sign(t, j); };
    std::size_t removed;
    if (other_pass_) [[unlikely]]
      removed = other_sign_pass(b, j);
    else
      removed = filter::classify<3>(lanes_, b.n, b.d, b.n1, b.d_unscaled, sign_, exact);
    if (removed == 0) return ClipResult::unchanged;
    if (removed == nv) {
      resize_vertices(0);
      security2_ = 0;
      return ClipResult::emptied;
    }

    const Index pn = static_cast<Index>(planes_.size());
    if (planes_.size() + 1 >= max_planes) [[unlikely]]
      throw std::length_error("a cell has more than 4294967294 faces (one point with that many neighbours)");
    Plane& pl = planes_.emplace_back();  // written in place (see reset)
    pl.n[0] = b.n[0]; pl.n[1] = b.n[1]; pl.n[2] = b.n[2];
    pl.d = b.d;
    pl.n1 = b.n1;
    pl.id = j;
    pl.scale = b.scale;
    scaled_planes_ |= b.scale != 0;
    if (planes_.size() > cap_) [[unlikely]] grow_table();
    if (hashed_) [[unlikely]]
      cut_huge(pn, nv, removed);
    else
      cut<false>(pn, nv, removed);
    return ClipResult::clipped;
  }

  /// Cut the finished cell by wall k of the exact context (walls.hpp): after
  /// every clip by a neighbour, the walls in any order (engine::clip_walls
  /// takes those through the generator first where the cell is long). `b`:
  /// a ball holding every vertex
  /// (vertex_ball(); a cut only shrinks the cell, so an older ball stays
  /// true). Emptied only where the whole cell lies outside (a power cell;
  /// the front end refuses generators outside a wall).
  ClipResult clip_wall(int k, const walls::Ball<3>& b);  // (kernels/clip_walls.cpp)
  walls::Ball<3> vertex_ball() const { return walls::vertex_ball<3>(verts_.data(), verts_.size()); }


 private:
  // Replace the vertices sign_ marks removed (-1; `removed` of the nv)
  // by the new face on local plane pn: a clip's work after its sign pass.
  // Hashed: the edge map is the hash (grow_table), in a huge cell only; the
  // ordinary instantiation has no test of it, nor of blocked_ (a blocked
  // cell is hashed).
  template <bool Hashed>
  [[gnu::always_inline]] void cut(Index pn, std::size_t nv, std::size_t removed) {
    // The removed slots, ascending: holes_[0, nh) (never shrunk, so growing
    // it value-initializes nothing per clip). A blocked pass listed them.
    std::size_t nh = 0;
    if (Hashed && blocked_) {
      nh = removed;
    } else {
      if (holes_.size() < nv) holes_.resize(nv);
      for (std::size_t t = 0; t < nv; ++t) {
        holes_[nh] = static_cast<std::uint32_t>(t);
        nh += sign_[t] < 0;
      }
    }
    // Boundary of the removed region: edges (a -> b) of removed triangles whose
    // twin (b -> a) lies in a kept triangle. Each gets a new triangle (a, b, pn).
    // The edges are collected first, branch-free (whether a twin was kept is
    // a coin flip the branch predictor loses), then solved in a plain loop.
    if (border_.size() < 3 * nh) border_.resize(3 * nh);
    std::size_t nb = 0;
    if constexpr (!Hashed) {
      Edge* const edges = border_.data();
      const std::uint32_t* const table = edge_tri_.data();
      const filter::Sign* const sign = sign_.data();
      const std::size_t cap = cap_;
      for (std::size_t h = 0; h < nh; ++h) {
        const Vertex& v = verts_[holes_[h]];
        for (int k = 0; k < 3; ++k) {
          const Index a = v.p[k], b = v.p[k == 2 ? 0 : k + 1];
          edges[nb] = {a, b};
          nb += sign[table[static_cast<std::size_t>(b) * cap + a]] >= 0;
        }
      }
    } else {
      nb = border_hashed(nh);
    }
    // The new triangles go straight into the removed slots (the border is
    // collected, so those may be overwritten), the rest after the last slot;
    // when fewer were made than removed, the remaining holes are filled from
    // the tail.
    if (nb > nh) resize_vertices(nv + nb - nh);
    for (std::size_t k = 0; k < nb; ++k) {
      const std::uint32_t t = k < nh ? holes_[k] : static_cast<std::uint32_t>(nv + k - nh);
      Vertex& v = verts_[t];  // built in place (see reset)
      v.p[0] = border_[k].a; v.p[1] = border_[k].b; v.p[2] = pn;
      solve(v, filter::SolveMode::deferrable);
      if (Hashed && blocked_ && v.deferred != 0) deferred_slots_.push_back(t);
      if (k < nh) sign_[t] = 1;  // kept from now on
      settle<Hashed>(t);
    }
    if (nb < nh) {
      std::size_t end = nv;
      for (std::size_t k = nb; k < nh; ++k) {
        const std::uint32_t t = holes_[k];
        while (end > t && sign_[end - 1] < 0) --end;  // drop trailing holes
        if (end <= t) break;                          // this hole and the rest lie beyond
        place<Hashed>(t, verts_[end - 1]);
        --end;
      }
      resize_vertices(end);
      if (Hashed && blocked_) {
        blocks_.touch_range(end, nv);
        keep_signs(end, nv);  // the holes dropped at the tail
      }
    }
    update_radius<Hashed>();
  }

 public:
  /// Start the cell of generator `gen` at p as the polyhedron known whole in
  /// advance (its Delaunay star: CellBuilder::build_from_star), without
  /// clipping: its faces lie on the bisectors with the m points q (relative
  /// to p, q[3k..3k+3)) of generator ids `ids`, and its nt vertices are the
  /// triangles `corners` (three indices into those m each, counter-clockwise
  /// from outside: det(q_a, q_b, q_c) > 0). Each vertex is solved as a clip
  /// would solve it. Where vertices lie outside the domain box [lo, hi], the
  /// box planes then cut the cell (clip_to_box). Returns false when that
  /// cannot be decided in floating point (a vertex within rounding of a box
  /// plane), when more vertices are too ill-conditioned for their float
  /// solve (flat simplices, whose circumcentres lie far out: surface
  /// samples) than assembly::exact_solves_paid lets it solve exactly, when
  /// the star has more than max_assembled_planes neighbours, or on extreme input
  /// (may_underflow): the cell is then unfinished, and must be built again
  /// (reset and clipped), which never solves vertices the box cuts away.
  ///
  /// `open`: the generator lies on the convex hull, and the triangles form
  /// a disk (its star's link), whose boundary edges (a -> b) are its hull
  /// facets. The cell is unbounded; each facet adds a vertex where its ray
  /// crosses a far plane (assembly::far_plane), the triangle (b, a, far),
  /// and the box cuts them all away. False too where the triangles are not
  /// such a disk or the far plane cannot be placed.
  bool assemble(std::int32_t gen, const double* p, const double* lo, const double* hi, const ExactContext* exact,
                const std::int32_t* ids, const double* q, std::size_t m, const Index* corners,
                std::size_t nt, bool open = false) {
    start(gen, p, lo, hi, exact);
    // A power cell's star comes from the regular triangulation, its planes weighed.
    if (may_underflow_ || m > max_assembled_planes ||
        !assembly::star_planes<3>(planes_, box_planes, ids, q, m, weighted_ ? exact_ : nullptr, gen))
      return false;
    // Room for the far plane too: dense up to dense_planes, else the hash.
    const std::size_t need = planes_.size() + 1;
    if (need <= dense_planes) {
      if (need > cap_ || edge_tri_.empty()) ensure_table(std::min(2 * need, dense_planes));
    } else {
      enter_hash(nt);  // (rehash() grows it if the far plane and the box add more)
    }
    resize_vertices(nt);
    auto set_planes = [&](Vertex& v, std::size_t t) {
      const Index* c = corners + 3 * t;
      v.p[0] = static_cast<Index>(box_planes + c[0]);
      v.p[1] = static_cast<Index>(box_planes + c[1]);
      v.p[2] = static_cast<Index>(box_planes + c[2]);
    };
    // A hull point: its link's boundary and the far plane's direction come
    // from the triangles alone, so a large star that cannot be closed gives
    // up before its vertices are solved, some thousands exactly (the end of
    // a thin band holds 160,000 neighbours; until stop 60 its far vertices'
    // conditions were checked here too, when one past the float bound was
    // refused). A small one is checked after them, as before: checked
    // first, the extra pass cost points on a sphere 2.5%.
    const bool boundary_first = open && nt >= boundary_first_from;
    if (boundary_first) {
      for (std::size_t t = 0; t < nt; ++t) {
        set_planes(verts_[t], t);
        link_any(static_cast<std::uint32_t>(t));
      }
      if (!link_boundary(q, m)) return false;
    }
    refused_.clear();
    const std::size_t may_refuse = assembly::exact_solves_paid(m, nt);
    for (std::size_t t = 0; t < nt; ++t) {
      Vertex& v = verts_[t];
      set_planes(v, t);
      solve(v, filter::SolveMode::float_only);
      if (!(v.e <= std::numeric_limits<double>::max())) {  // would need the exact solve
        if (refused_.size() == may_refuse) return false;          // clip instead
        refused_.push_back(static_cast<std::uint32_t>(t));
        continue;
      }
      settle_any(static_cast<std::uint32_t>(t));
    }
    for (const std::uint32_t t : refused_) {  // few enough to pay for their exact solves
      solve(verts_[t], filter::SolveMode::exact_now);
      settle_any(t);
    }
    if (open && !((boundary_first || link_boundary(q, m)) && close_far())) return false;
    update_radius();
    return clip_to_box() && (!open || assembly::drop_far_plane<3>(planes_, verts_));
  }

  /// Upper bound on (2R)^2, R = the largest distance from the generator to a
  /// vertex: a neighbour farther than 2R cannot clip (security radius).
  double security_radius2() const { return security2_; }
  /// An upper bound on every vertex's distance from the generator (half the
  /// security radius); a cut by a wall never raises it.
  double vertex_reach() const { return 0.5 * std::sqrt(security2_); }
  /// power_slack (power.hpp) of a power cell, in every vertex's r2; 0 without radii.
  double power_slack() const { return slack_; }

  std::int32_t generator() const { return gen_; }
  /// Whether some plane is a scaled bisector (Plane::scale != 0: only in
  /// input no frame fits) or a wall; the measure reads every plane's scale
  /// and kind only then.
  bool has_scaled_planes() const { return scaled_planes_; }
  /// Whether this is a power cell (ExactContext::radii; power.hpp).
  bool weighted() const { return weighted_; }
  /// The generator's coordinates: vertices are relative to them.
  const double* site() const { return site_; }
  std::size_t num_vertices() const { return verts_.size(); }
  /// Slots are default-initialized (written in place by every path that
  /// adds one): zeroing them cost the clip's growth ~1.5%.
  using VertexList = std::vector<Vertex, DefaultInitAllocator<Vertex>>;
  const VertexList& vertices() const { return verts_; }
  const std::vector<Plane>& planes() const { return planes_; }
  std::uint64_t exact_calls() const { return signs_.calls(); }
  std::uint64_t off_grid_exact_calls() const { return signs_.off_grid_calls(); }
  /// The exact stages' gates open again (PreparedSigns::reset_gates).
  void reset_stage_gates() { signs_.reset_gates(); }
  /// Vertices of this cell solved exactly (too ill-conditioned for the float solve).
  std::uint64_t exact_solves() const { return exact_solves_; }
  /// Whether this cell's sign passes go by blocks of slots (blocked_from
  /// vertices reached: LaneBlocks): for tests.
  bool blocked() const { return blocked_; }

  /// The cell's last step once no clip is to come: the vertices whose exact
  /// solve a clip or the assembly deferred (filter::deferred_vertex_
  /// condition), and that are still there, are solved exactly now, so every vertex of a built
  /// cell is as accurate as if they had been solved at once (the same
  /// doubles: the clips' decisions are exact either way). CellBuilder calls
  /// it for every cell it returns, and clip() sooner, once the deferred
  /// vertices were asked filter::deferred_ask_limit exact questions.
  void solve_deferred() {
    if (deferred_ == 0) return;
    if (blocked_) [[unlikely]] {
      solve_deferred_slots();
    } else {
      for (std::size_t t = 0; t < verts_.size(); ++t)
        if (verts_[t].deferred != 0) solve_now(t);
    }
    update_radius<true>();  // (this cell may be blocked)
  }
  /// The input's exact context (null in bare kernel tests).
  const ExactContext* exact_context() const { return exact_; }
  /// The triangle (vertex) sharing edge k of triangle t, i.e. the directed
  /// plane pair (p[k] -> p[k+1]) seen from the other side.
  std::uint32_t across(std::size_t t, int k) const {
    const Vertex& v = verts_[t];
    return edge(v.p[(k + 1) % 3], v.p[k]);
  }

  /// Visit each face's plane index once, ascending: the planes that still
  /// carry a vertex (a later clip may have cut a face away whole).
  template <class F>
  void for_each_face_plane(F&& f) {
    seen_.assign(planes_.size(), 0);
    std::uint8_t* const seen = seen_.data();
    for (const Vertex& v : verts_) seen[v.p[0]] = seen[v.p[1]] = seen[v.p[2]] = 1;
    for (std::size_t p = 0; p < planes_.size(); ++p)
      if (seen[p]) f(static_cast<Index>(p));
  }

  /// Visit each face once, by ascending plane index: f(plane index, vertex
  /// indices counter-clockwise from outside as pointer + count), by the
  /// walk of a cell's dual form (dual_faces.hpp). The walk's buffers are
  /// members, reused.
  template <class F>
  void for_each_face(F&& f) {
    const Vertex* const verts = verts_.data();
    for_each_face_loop(
        verts_.size(), planes_.size(), [verts](std::size_t t, int k) { return verts[t].p[k]; }, walk_,
        std::forward<F>(f));
  }

 private:
  // The assembled cell cut by the domain box's planes, each decided by the
  // float filter alone (the clip's test with the box plane's d): false,
  // leaving the cell unfinished, where a vertex lies within its error bound
  // of a box plane. Otherwise every decision is certain, so the cell is the
  // one the exact clips build from the box: a vertex exactly on a box plane
  // is the only case whose answer the perturbation would choose.
  //
  // A float bound may straddle a box plane that the exact vertex does not
  // touch (first-order bounds are wide: 1e-9 at a condition of 1e5, more
  // for a deferred vertex): those vertices are solved exactly, and the
  // plane is tried again. Only a vertex within rounding of the plane is
  // left to the clips. (The apex of a cone over 80,000 circle points: its
  // cell's edges pass within 1e-9 of the default box's edges, and it was
  // clipped by all 80,000 neighbours: 61 s.)
  bool clip_to_box() {
    for (Index k = 0; k < box_planes; ++k) {
      const std::size_t nv = verts_.size();
      const std::size_t removed = assembly::box_cut_signs<3>(verts_.data(), nv, static_cast<int>(k), planes_.data(),
                                                             sign_, exact_, gen_, [&] { solve_near(k); });
      if (removed == assembly::undecided || removed == nv) return false;
      if (removed == 0) continue;
      if (hashed_) cut_hashed(k, nv, removed);  // a star of more than dense_planes neighbours
      else cut<false>(k, nv, removed);
    }
    return true;
  }

  // Vertex t solved exactly now (solve_deferred's step, and solve_near's).
  void solve_now(std::size_t t) {
    Vertex& v = verts_[t];
    if (v.deferred != 0) --deferred_;
    v.deferred = 0;
    const double ymax = solve_exactly(v);
    const double err = 4 * filter::u * ymax;
    v.e = err + filter::plane_eps * ymax;
    set_radius(v, err);
    lanes_.set(static_cast<std::uint32_t>(t), v);
    if (blocked_) blocks_.touch(t);
  }

  // The vertices box plane k cannot place, solved exactly
  // (assembly::solve_near_box_plane), and the radius updated if any were.
  void solve_near(Index k) {
    const bool solved = assembly::solve_near_box_plane<3>(verts_.data(), verts_.size(), static_cast<int>(k),
                                                          planes_[k].d, [this](std::size_t t) { solve_now(t); });
    if (solved) update_radius();
  }

  // assemble() of a hull point, before its vertices are solved: the link's
  // nt = verts_.size() triangles are linked (their planes written). Find
  // its boundary edges (a -> b: no triangle holds b -> a) into border_ as
  // (b, a), check that a cone over them closes the disk into a sphere, and
  // find the far plane's direction (far_n_) from the hull facets' outward
  // normals (dirs_). q: the bisectors' points, as assemble's.
  bool link_boundary(const double* q, std::size_t m) {
    const std::size_t nt = verts_.size();
    border_.clear();
    for (std::size_t t = 0; t < nt; ++t) {
      const Vertex& v = verts_[t];
      for (int k = 0; k < 3; ++k) {
        const Index a = v.p[k], b = v.p[k == 2 ? 0 : k + 1];
        // The table is not cleared between cells: an entry is this cell's
        // only if its triangle holds the edge.
        const std::uint32_t u = edge(b, a);
        if (u < nt && holds(verts_[u], b, a)) continue;
        border_.push_back({b, a});
      }
    }
    const std::size_t nb = border_.size();
    // A disk closed by a cone over its boundary is a sphere: its triangles
    // number twice its vertices (the m bisectors and the far plane) less 4.
    if (nt + nb != 2 * (m + 1) - 4) return false;
    // Facet (p, a, b) of the hull, with the link triangle (a, b, c): c lies
    // inside, det(q_a, q_b, q_c) > 0, so the outward normal, the ray's
    // direction, is q_b x q_a.
    dirs_.resize(3 * nb);
    margins_.resize(nb);
    axis_errors_.resize(3 * nb);
    double hint[3] = {0, 0, 0};  // the point less its hull neighbours' mean (far_direction)
    for (std::size_t k = 0; k < nb; ++k) {
      const double* qb = q + 3 * (border_[k].a - box_planes);
      const double* qa = q + 3 * (border_[k].b - box_planes);
      for (int a = 0; a < 3; ++a) hint[a] -= qb[a];  // each hull neighbour once, as an edge's start
      double* d = dirs_.data() + 3 * k;
      cross(qb, qa, d);
      const double len = std::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
      // Any thinness will do (assembly::facet_tilt), but not none: q_a and
      // q_b parallel in floats give no direction.
      const double na = std::sqrt(qa[0] * qa[0] + qa[1] * qa[1] + qa[2] * qa[2]);
      const double nbl = std::sqrt(qb[0] * qb[0] + qb[1] * qb[1] + qb[2] * qb[2]);
      if (!(len > 0)) return false;
      for (int a = 0; a < 3; ++a) d[a] /= len;
      const double scale = 6 * assembly::facet_tilt / len;
      margins_[k] = scale * (na * nbl);
      // Component a of the cross product (q_b,i q_a,j - q_b,j q_a,i) errs
      // by ~4u (|q_b,i q_a,j| + |q_b,j q_a,i|): 2u from q's rounding, 2u
      // from its own; facet_tilt (~7u) and the factor 6 as for the margin.
      for (int a = 0; a < 3; ++a) {
        const int i = a == 2 ? 0 : a + 1, j = a == 0 ? 2 : a - 1;
        axis_errors_[3 * k + static_cast<std::size_t>(a)] =
            scale * (std::fabs(qb[i] * qa[j]) + std::fabs(qb[j] * qa[i]));
      }
    }
    if (assembly::far_direction<3>(dirs_.data(), nb, far_n_, hint, margins_.data(), axis_errors_.data()))
      return true;
    // The float rays admit no far plane; the exact ones may. A point far off
    // a plane of points at a slant (1e8 off 3,000): its rays lie 1e-8 from
    // the plane, while their float directions, cross products of nearly
    // parallel differences each rounded by 1e-8 of their length, are known
    // to 1e-4 only (on an axis-aligned plane the errors stay off the normal,
    // which ray_axis_errors sees). Its star went to the clips: 3,000
    // near-parallel bisectors, 8.9M exact evaluations, 14 s. The hint, the
    // point less its hull neighbours' mean (p_i - x, x inside the hull),
    // crosses every exact ray outwards unless x lies on a facet's plane;
    // each ray is tested exactly (exact_ray_side). No margin is needed
    // then: each far vertex is solved as its condition allows (exactly
    // beyond far_vertex_condition), and the box cut decides as for any.
    if (exact_ == nullptr) return false;
    for (int a = 0; a < 3; ++a) far_n_[a] = hint[a];
    assembly::scale_to_unit<3>(far_n_);
    for (std::size_t k = 0; k < nb; ++k)
      if (exact_ray_side(*exact_, gen_, planes_[border_[k].a].id, planes_[border_[k].b].id, far_n_) <= 0)
        return false;
    return true;
  }

  // link_boundary's second half, once the link's vertices are solved and
  // settled: the far plane (its offset beyond them and the box) and the
  // triangles (b, a, far) over the boundary; false unless the surface is
  // then closed.
  bool close_far() {
    const std::size_t nt = verts_.size(), nb = border_.size();
    const Index far = static_cast<Index>(planes_.size());
    Plane& pf = planes_.emplace_back();
    if (!assembly::far_offset<3>(far_n_, planes_.data(), verts_.data(), nt, pf)) return false;
    resize_vertices(nt + nb);
    for (std::size_t k = 0; k < nb; ++k) {
      Vertex& v = verts_[nt + k];
      v.p[0] = border_[k].a;
      v.p[1] = border_[k].b;
      v.p[2] = far;
      solve(v, filter::SolveMode::float_only);  // never exact: on the far plane
      if (!(v.e <= std::numeric_limits<double>::max())) return false;
      settle_any(static_cast<std::uint32_t>(nt + k));
    }
    // Closed and consistently oriented: every directed edge is held by one
    // triangle only, and its twin by another. (The disk's edges were
    // checked above, but a vertex with two boundary edges leaving it would
    // give the far plane's triangles a repeated edge.)
    for (std::size_t t = 0; t < nt + nb; ++t) {
      const Vertex& v = verts_[t];
      for (int k = 0; k < 3; ++k) {
        const Index a = v.p[k], b = v.p[k == 2 ? 0 : k + 1];
        const std::uint32_t u = edge(b, a);
        if (edge(a, b) != t || !(u < nt + nb && holds(verts_[u], b, a))) return false;
      }
    }
    return true;
  }

  // Whether triangle v holds the directed edge (a -> b).
  static bool holds(const Vertex& v, Index a, Index b) {
    return (v.p[0] == a && v.p[1] == b) || (v.p[1] == a && v.p[2] == b) || (v.p[2] == a && v.p[0] == b);
  }

  // The cell's generator and the domain box's planes (always its first
  // local planes), with no vertices yet.
  void start(std::int32_t gen, const double* p, const double* lo, const double* hi, const ExactContext* exact) {
    gen_ = gen;
    for (int a = 0; a < 3; ++a) site_[a] = p[a];
    exact_ = exact;
    may_underflow_ = exact != nullptr && exact->may_underflow;
    weighted_ = exact != nullptr && exact->radii != nullptr;
    slack_ = weighted_ ? kernels::power_slack(exact->max_radius, exact->radii[gen]) : 0.0;
    scaled_planes_ = false;
    if (hashed_) [[unlikely]] leave_hash();
    blocked_ = false;
    other_pass_ = may_underflow_;
    signs_.start_cell();
    exact_solves_ = 0;
    deferred_ = 0;
    deferred_asks_ = 0;
    // Planes and corners are written in place: a local struct copied in
    // would be read back wider than it was written (a store-forwarding stall).
    planes_.resize(box_planes);
    for (int k = 0; k < static_cast<int>(box_planes); ++k) {
      const int axis = k / 2;
      const bool upper = k & 1;
      Plane& pl = planes_[static_cast<std::size_t>(k)];
      for (int a = 0; a < 3; ++a) pl.n[a] = 0.0;
      pl.n[axis] = upper ? 1.0 : -1.0;
      pl.d = upper ? hi[axis] - p[axis] : p[axis] - lo[axis];
      pl.n1 = 1.0;
      pl.id = box_plane_id(axis, upper);
      pl.scale = 0;
    }
    resize_vertices(0);  // nothing stale for ensure_table to link
  }

  // The exact sign of vertex slot t against j (prepared_signs.hpp).
  int exact_sign(std::size_t t, std::int32_t j) {
    const Vertex& v = verts_[t];
    deferred_asks_ += v.deferred;
    const std::int32_t ids[3] = {planes_[v.p[0]].id, planes_[v.p[1]].id, planes_[v.p[2]].id};
    return signs_.sign(*exact_, gen_, t, v.p, ids, j);
  }

  // Every change to the vertex list goes through these, which keep the sign
  // pass's mirror (lanes_) and the edge table in step with verts_.
  template <bool Hashed = false>
  void place(std::uint32_t t, const Vertex& v) {  // into an existing slot, kept from now on
    verts_[t] = v;
    if (Hashed && blocked_ && v.deferred != 0) deferred_slots_.push_back(t);
    sign_[t] = 1;
    settle<Hashed>(t);
  }
  /// Keep the first n vertices, or make room for slots to be written in place
  /// and then settled.
  void resize_vertices(std::size_t n) {
    verts_.resize(n);
    lanes_.resize(n);
  }
  template <bool Hashed = false>
  void settle(std::uint32_t t) {  // slot t was written in place
    lanes_.set(t, verts_[t]);
    if (Hashed && blocked_) blocks_.touch(t);
    link<Hashed>(t);
  }

  // settle() and link() in whichever mode the edge map is (assembly: decided per cell).
  void settle_any(std::uint32_t t) {
    if (hashed_) settle<true>(t);
    else settle<false>(t);
  }
  void link_any(std::uint32_t t) {
    if (hashed_) link<true>(t);
    else link<false>(t);
  }

  template <bool Hashed = false>
  void link(std::uint32_t t) {
    const Vertex& v = verts_[t];
    if constexpr (Hashed) {
      for (int k = 0; k < 3; ++k) hash_link(v.p[k], v.p[(k + 1) % 3], t);
    } else {
      for (int k = 0; k < 3; ++k)
        edge_tri_[static_cast<std::size_t>(v.p[k]) * cap_ + v.p[(k + 1) % 3]] = t;
    }
  }

  // The edge map: directed plane pair (a -> b) -> the triangle holding it.
  // Entries of triangles since removed stay (the dense table is not cleared
  // between cells either); a lookup only asks for an edge of a current
  // triangle, which was linked last. While the cell has at most dense_planes
  // planes (every ordinary cell) it is a dense cap x cap table, a lookup one
  // load. Beyond, it is an open-addressing hash of the pairs linked, so
  // memory follows the triangles, not the square of the planes: one point
  // inside a shell of 20,000 points made a 4.3 GB table (5.3 GB peak for 20k
  // points), and 70,000 one of 17 GB before its face limit stopped it.
  static constexpr std::size_t dense_planes = 1024;  // a 4 MB table
  // assemble(): a hull point's star of this many triangles or more is
  // checked for closing before its vertices are solved (link_boundary).
  static constexpr std::size_t boundary_first_from = 4096;

  std::uint32_t edge(Index a, Index b) const {
    if (!hashed_) [[likely]] return edge_tri_[static_cast<std::size_t>(a) * cap_ + b];
    return hash_find(a, b);
  }

  void ensure_table(std::size_t cap) {
    if (cap <= cap_ && !edge_tri_.empty()) return;
    cap_ = std::max<std::size_t>(cap, 64);
    edge_tri_.assign(cap_ * cap_, 0);
    for (std::size_t t = 0; t < verts_.size(); ++t) link(static_cast<std::uint32_t>(t));
  }

  // More planes than the dense table holds: double it, or past dense_planes
  // switch to the hash (kept until the next cell starts).
  [[gnu::noinline, gnu::cold]] void grow_table() {
    if (hashed_) return;
    if (2 * cap_ <= dense_planes) {
      ensure_table(2 * cap_);
      return;
    }
    enter_hash(verts_.size());
    for (std::size_t t = 0; t < verts_.size(); ++t) link<true>(static_cast<std::uint32_t>(t));
  }

  // The hash as the edge map, empty, sized for about `triangles` (three
  // edges each, at most half full; it grows by rehash()).
  void enter_hash(std::size_t triangles) {
    hashed_ = true;
    hash_.assign(std::max<std::size_t>(1024, std::bit_ceil(8 * triangles)), HashSlot{});
    hash_used_ = 0;
  }

  // A new cell: back to the dense table (its size kept), the hash dropped.
  void leave_hash() {
    hashed_ = false;
    std::vector<HashSlot>().swap(hash_);
    hash_used_ = 0;
  }

  // A hash slot: the directed edge (a -> b) and the triangle holding it;
  // a = no_plane: empty. 12 bytes (a huge cell's map holds millions).
  static constexpr Index no_plane = std::numeric_limits<Index>::max();
  struct HashSlot {
    Index a = no_plane, b = 0;
    std::uint32_t tri = 0;
  };
  std::size_t hash_slot(Index a, Index b) const {  // Fibonacci hashing: the product's top bits
    const std::uint64_t key = (static_cast<std::uint64_t>(a) << 32) | b;
    return static_cast<std::size_t>((key * 0x9E3779B97F4A7C15ull) >> (64 - std::countr_zero(hash_.size())));
  }
  std::uint32_t hash_find(Index a, Index b) const {
    for (std::size_t s = hash_slot(a, b);; s = (s + 1) & (hash_.size() - 1)) {
      const HashSlot& e = hash_[s];
      if (e.a == a && e.b == b) return e.tri;
      if (e.a == no_plane) return 0;  // never linked (not asked for by a consistent cell)
    }
  }
  void hash_link(Index a, Index b, std::uint32_t t) {
    if (2 * (hash_used_ + 1) > hash_.size()) rehash();
    for (std::size_t s = hash_slot(a, b);; s = (s + 1) & (hash_.size() - 1)) {
      HashSlot& e = hash_[s];
      if (e.a == no_plane) ++hash_used_;
      if (e.a == no_plane || (e.a == a && e.b == b)) {
        e = {a, b, t};
        return;
      }
    }
  }
  void rehash() {
    std::vector<HashSlot> old(2 * hash_.size());
    old.swap(hash_);
    hash_used_ = 0;
    for (const HashSlot& e : old)
      if (e.a != no_plane) hash_link(e.a, e.b, e.tri);
  }

  [[gnu::noinline, gnu::cold]] void cut_hashed(Index pn, std::size_t nv, std::size_t removed) {
    cut<true>(pn, nv, removed);
  }
  // A clip's cut in a huge cell (the edge map hashed), which from
  // blocked_from vertices on takes its sign passes by blocks. (The box cut
  // of an assembled star never does: it is one pass per box plane.)
  [[gnu::noinline, gnu::cold]] void cut_huge(Index pn, std::size_t nv, std::size_t removed) {
    cut<true>(pn, nv, removed);
    if (!blocked_ && verts_.size() >= blocked_from && !may_underflow_) enter_blocks();
  }

  // A cell of this many vertices or more (thousands of faces: hashed)
  // takes its sign passes by blocks of slots (LaneBlocks), the rest of
  // its life: on points on a line and one off it, the off point's cell
  // grows by a face per clip, and each clip's pass read every vertex.
  static constexpr std::size_t blocked_from = 4096;

  // The sign pass of a cell that is not an ordinary one: where no frame fits
  // (may_underflow), n.y may overflow (filter::classify<3, true>); a huge
  // cell's by blocks, which lists the removed slots in holes_ for cut().
  // Either gives classify's signs. One test of other_pass_ in the clip.
  [[gnu::noinline]] std::size_t other_sign_pass(const filter::Bisector<3>& b, std::int32_t j) {
    auto exact = [&](std::size_t t) { return exact_sign(t, j); };
    if (may_underflow_) return filter::classify_unbounded<3>(lanes_, b, sign_, exact);
    return blocks_.classify(lanes_, b.n, b.d, b.n1, b.d_unscaled, sign_, holes_, exact);
  }

  // From now on this cell's passes go by blocks. A blocked pass writes the
  // signs of the slots it evaluates only, and cut() reads the sign of any
  // slot (a removed triangle's twin, wherever it lies), so between clips no
  // entry of sign_ may be -1 (a slot appended later reads the entry it
  // finds): set here for all, and a clip's removed slots are each refilled
  // (+1) or dropped from the tail (keep_signs).
  [[gnu::noinline, gnu::cold]] void enter_blocks() {
    blocked_ = true;
    other_pass_ = true;
    blocks_.start(verts_.size());
    keep_signs(0, std::max(sign_.size(), lanes_.padded()));
    deferred_slots_.clear();
    for (std::size_t t = 0; t < verts_.size(); ++t)
      if (verts_[t].deferred != 0) deferred_slots_.push_back(static_cast<std::uint32_t>(t));
  }
  // solve_deferred() of a blocked cell: the slots noted since the last
  // (those a deferred vertex was written to; a slot since reused or cut
  // away is passed over) instead of every slot, as the long search of a
  // cell whose deferred vertices are asked often calls it every few clips.
  // Each vertex is solved alone, so the order changes nothing.
  void solve_deferred_slots() {
    for (const std::uint32_t t : deferred_slots_)
      if (t < verts_.size() && verts_[t].deferred != 0) solve_now(t);
    deferred_slots_.clear();
  }
  void keep_signs(std::size_t a, std::size_t e) {
    if (sign_.size() < e) sign_.resize(e);
    std::fill(sign_.begin() + static_cast<std::ptrdiff_t>(a), sign_.begin() + static_cast<std::ptrdiff_t>(e),
              filter::Sign{1});
  }

  // cut()'s border collection in hashed mode (see there). A copy with the
  // hash lookup, not one loop with both: that loop (the lookup chosen by
  // `if constexpr` in a lambda) cost the ordinary clip 2.5% (100k uniform 3D
  // cells on one thread, four alternated rounds).
  [[gnu::noinline]] std::size_t border_hashed(std::size_t nh) {
    std::size_t nb = 0;
    for (std::size_t h = 0; h < nh; ++h) {
      const Vertex& v = verts_[holes_[h]];
      for (int k = 0; k < 3; ++k) {
        const Index a = v.p[k], b = v.p[k == 2 ? 0 : k + 1];
        border_[nb] = {a, b};
        nb += sign_[hash_find(b, a)] >= 0;
      }
    }
    return nb;
  }

  // The vertex where planes p[0], p[1], p[2] meet (Cramer's rule) and its
  // error bound. A vertex too ill-conditioned for that bound is solved
  // exactly, or as `mode` allows (filter::SolveMode, ill_conditioned): it
  // may keep its float position with a wider bound until solve_deferred,
  // or (float_only: assemble) get NaN for its bound, which sends its cell
  // back to the clips.
  // Inlined in both callers: out of line (it has two), the clip's calls
  // cost the search 4%.
  [[gnu::always_inline]] void solve(Vertex& v, filter::SolveMode mode) const {
    const Plane& A = planes_[v.p[0]];
    const Plane& B = planes_[v.p[1]];
    const Plane& C = planes_[v.p[2]];
    double c1[3], c2[3], c3[3];
    cross(B.n, C.n, c1);
    cross(C.n, A.n, c2);
    cross(A.n, B.n, c3);
    double det = A.n[0] * c1[0] + A.n[1] * c1[1] + A.n[2] * c1[2];
    double inv = 1.0 / det;
    for (int k = 0; k < 3; ++k) v.y[k] = (A.d * c1[k] + B.d * c2[k] + C.d * c3[k]) * inv;
    double ymax = std::max({std::fabs(v.y[0]), std::fabs(v.y[1]), std::fabs(v.y[2])});
    v.deferred = 0;  // ill_conditioned may defer it
    // |a x b|_1 <= |a|_1 |b|_1, so the adjugate's entries sum to at most s.
    double s = B.n1 * C.n1 + C.n1 * A.n1 + A.n1 * B.n1;
    double inv_norm = s * std::fabs(inv);             // >= |A^-1|_inf
    double amax = std::max({A.n1, B.n1, C.n1});
    double bmax = std::max({std::fabs(A.d), std::fabs(B.d), std::fabs(C.d)});
    double cond = inv_norm * amax;
    // Extreme input only (front/pass.cpp): products that may have underflowed.
    const double slack = may_underflow_ ? filter::underflow_slack(inv, amax, bmax, s, ymax) : 0.0;
    double err;
    if (cond < filter::exact_vertex_condition && std::isfinite(ymax))
      err = filter::vertex_eps * inv_norm * (amax * ymax + bmax) + slack;
    else
      std::tie(err, ymax) = ill_conditioned(v, inv, ymax, slack, mode);
    v.e = err + filter::plane_eps * ymax;
    set_radius(v, err);
  }

  // solve() for a vertex whose plain bound failed (cond >= 1e6, or not
  // finite); returns err and ymax, and may replace y. First the same bound,
  // plus solve()'s underflow `slack`, on the equilibrated system: each row (plane) scaled by a power of two
  // that brings |n|_1 into [1, 2). Those scalings are exact, so Cramer's rule
  // on the scaled rows computes the same y bit for bit, and the bound for
  // that computation holds for this one; but its condition ignores the rows'
  // magnitudes, which differ by orders when the points are spaced
  // anisotropically (a slab of voxel centres 1e-8 apart across and 1 along:
  // unscaled, every vertex there went to the exact solve). Failing that, the
  // vertex is too ill-conditioned for a trustworthy float position (it
  // exists: the exact predicates created it) and is solved exactly, unless
  // its condition is below deferred_vertex_condition and `mode` is not
  // exact_now: then the bound stands, and solve_deferred solves it if it is
  // still there when the cell is built. Out of line: inline, the extra code
  // cost ordinary input 2%.
  [[gnu::noinline, gnu::cold]] std::pair<double, double> ill_conditioned(Vertex& v, double inv, double ymax, double slack, filter::SolveMode mode) const {
    const Plane& A = planes_[v.p[0]];
    const Plane& B = planes_[v.p[1]];
    const Plane& C = planes_[v.p[2]];
    const std::int32_t ea = filter::binary_exponent(A.n1), eb = filter::binary_exponent(B.n1),
                       ec = filter::binary_exponent(C.n1);
    const double sa = filter::pow2(-ea), sb = filter::pow2(-eb), sc = filter::pow2(-ec);
    const double na = A.n1 * sa, nb = B.n1 * sb, nc = C.n1 * sc;
    const double inv_norm =
        (nb * nc + nc * na + na * nb) * (std::fabs(inv) * filter::pow2(ea) * filter::pow2(eb) * filter::pow2(ec));
    const double amax = std::max({na, nb, nc});
    const double bmax = std::max({std::fabs(A.d) * sa, std::fabs(B.d) * sb, std::fabs(C.d) * sc});
    const double cond = inv_norm * amax;
    const double err = filter::vertex_eps * inv_norm * (amax * ymax + bmax) + slack;
    if (cond < filter::exact_vertex_condition && std::isfinite(ymax))  // false on NaN
      return {err, ymax};
    return assembly::settle_ill_conditioned<3>(
        mode, cond, err, ymax, v, planes_.data(),
        [&] {
          v.deferred = 1;
          ++deferred_;
        },
        [&] { return solve_exactly(v); });
  }

  // v's position solved exactly and rounded (exact_vertex); returns |y|_inf.
  double solve_exactly(Vertex& v) const {
    assembly::exact_solve<3>(*exact_, gen_, planes_.data(), v.p, v.y);
    ++exact_solves_;
    return std::max({std::fabs(v.y[0]), std::fabs(v.y[1]), std::fabs(v.y[2])});
  }

  // |y_exact| <= |y| + sqrt(3) err, so |y_exact|^2 <= |y|^2 + 4 err |y|_1 + 4 err^2
  // (|y| <= |y|_1), with a relative margin for the rounding of this sum.
  // With radii it bounds |y|^2 + slack_ (power.hpp); slack_ 0 adds nothing.
  void set_radius(Vertex& v, double err) const {
    double a = v.y[0] * v.y[0] + v.y[1] * v.y[1] + v.y[2] * v.y[2];
    double l1 = std::fabs(v.y[0]) + std::fabs(v.y[1]) + std::fabs(v.y[2]);
    v.r2 = (a + 4.0 * err * (l1 + err) + slack_) * (1.0 + 1e-12) + filter::radius_abs_eps;
    if (!(v.r2 < std::numeric_limits<double>::infinity())) v.r2 = std::numeric_limits<double>::infinity();  // NaN too
  }

  static void cross(const double* a, const double* b, double* out) {
    out[0] = a[1] * b[2] - a[2] * b[1];
    out[1] = a[2] * b[0] - a[0] * b[2];
    out[2] = a[0] * b[1] - a[1] * b[0];
  }

  // Blocked: the maximum from the blocks' (the same value).
  template <bool MayBeBlocked = false>
  void update_radius() {
    const double m = MayBeBlocked && blocked_ ? blocks_.max_r2(lanes_) : lanes_.max_r2();
    security2_ = 4.0 * m * (1 + 1e-12);
  }

  std::int32_t gen_ = -1;
  double site_[3] = {};  // the generator's coordinates
  const ExactContext* exact_ = nullptr;
  bool may_underflow_ = false;  // exact_->may_underflow: solve() adds filter::underflow_slack
  bool blocked_ = false;        // the sign passes go by blocks_ (blocked_from)
  bool other_pass_ = false;     // may_underflow_ or blocked_: other_sign_pass
  bool weighted_ = false;       // exact_->radii: a power cell (power.hpp)
  double slack_ = 0;            // power_slack of this cell (0 without radii), in every r2
  bool scaled_planes_ = false;  // has_scaled_planes()
  mutable std::uint64_t exact_solves_ = 0;  // exact_solves(); counted by the const solve
  mutable std::size_t deferred_ = 0;  // vertices deferred (Vertex::deferred) since the cell started
  // Exact evaluations asked of deferred vertices since the cell started or
  // they were last solved (filter::deferred_ask_limit).
  std::uint32_t deferred_asks_ = 0;
  std::vector<Plane> planes_;
  VertexList verts_;
  filter::FilterLanes<3> lanes_;  // verts_' filter data, for the sign pass
  LaneBlocks<3> blocks_;          // a huge cell's summaries of lanes_ (blocked_)
  std::vector<std::uint32_t> deferred_slots_;  // blocked_: slots given a deferred vertex (solve_deferred_slots)
  struct Edge { Index a, b; };
  std::vector<Edge> border_;   // a clip's boundary edges (its first slots)
  std::vector<std::uint32_t> holes_;
  std::vector<filter::Sign> sign_;
  std::vector<std::uint32_t> edge_tri_;  // cap_ x cap_: directed plane pair -> triangle (edge())
  std::size_t cap_ = 0;
  bool hashed_ = false;                  // the edge map is hash_ (grow_table)
  std::vector<HashSlot> hash_;
  std::size_t hash_used_ = 0;
  double security2_ = 0;
  std::vector<std::uint8_t> seen_;
  FaceLoopScratch walk_;  // for_each_face's
  std::vector<double> dirs_;         // link_boundary: the rays' unit directions
  std::vector<double> margins_;      // and their own margins (assembly::facet_tilt)
  std::vector<double> axis_errors_;  // and the bounds on their components (far_direction)
  double far_n_[3] = {};             // link_boundary: the far plane's normal
  std::vector<std::uint32_t> refused_;  // assemble: the vertices refused the exact solve
  PreparedSigns<3, Index> signs_;  // the exact stages, prepared per vertex slot
};

}  // namespace tessera::kernels

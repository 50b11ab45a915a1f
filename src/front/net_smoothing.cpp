// Smoothing of surface nets: vertex classification from topological
// coordinates, stencils from polygon edges (CSR), and a constrained Laplacian
// iterated Jacobi-style (two buffers), so the result is the same for any
// thread count. Conventions and defaults: include/tessera/surface_nets.hpp.
#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <cstdio>
#include <cstdint>
#include <limits>
#include <numeric>
#include <stdexcept>
#include <string>
#include <vector>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "net_crossings.hpp"
#include "net_smoothing.hpp"
#include "pass.hpp"
#include "tessera/buffer.hpp"
#include "tessera/surface_nets.hpp"

namespace tessera {
namespace front {

namespace {
std::string num(double v) {
  char b[32];
  std::snprintf(b, sizeof b, "%g", v);
  return b;
}
}  // namespace

void check_smoothing_options(const SmoothingOptions& o) {
  if (o.iterations < 0)
    throw InputError("smoothing: iterations must be >= 0 (0 = no smoothing), got " + std::to_string(o.iterations));
  if (!(o.relaxation > 0 && o.relaxation <= 1))
    throw InputError("smoothing: relaxation factor must be in (0, 1], got " + num(o.relaxation));
  if (!(o.constraint >= 0) || !std::isfinite(o.constraint))
    throw InputError("smoothing: constraint must be a finite number >= 0, got " + num(o.constraint));
}

namespace {

constexpr std::int64_t kNoRegion = std::numeric_limits<std::int64_t>::min();

/// |d| (dn = 2 or 3 components) from d2, its sum of squares as computed:
/// sqrt(d2) where no square under- or overflowed, else std::hypot, which
/// scales. The net's frame (net_frame_shift) keeps squares in range unless
/// no frame fits the input (1e-300 beside 1e300), where an infinite d2
/// would let a vertex move without its constraint.
double length(const double* d, std::size_t dn, double d2) {
  if (d2 >= 0x1p-900 && d2 <= 0x1p900) return std::sqrt(d2);
  return std::hypot(d[0], d[1], dn == 3 ? d[2] : 0.0);
}

/// The region of a generator id of a topological coordinate: a point's label,
/// or, for a domain-box plane (negative id), a code of its own that no label
/// can take (labels are int32).
struct RegionOf {
  std::span<const std::int32_t> labels;
  std::int64_t operator()(std::int32_t id) const {
    if (id < 0) return (std::int64_t{1} << 40) - id;  // one region per box plane
    return labels.empty() ? 0 : labels[static_cast<std::size_t>(id)];
  }
};

/// Number of distinct values among the first n of r (n <= 4).
int distinct(const std::int64_t* r, int n) {
  int k = 0;
  for (int a = 0; a < n; ++a) {
    bool seen = false;
    for (int b = 0; b < a; ++b) seen = seen || r[b] == r[a];
    k += seen ? 0 : 1;
  }
  return k;
}

/// The step of a vertex on walls (a key id -7-k), projected onto the walls'
/// planes and the box planes it is pinned to: the vertex slides within
/// them, as a box-plane vertex slides within its plane. Orthonormal
/// constraint directions per such vertex (the walls' normals and the
/// pinned axes, by Gram-Schmidt; none left free: the vertex stays).
class WallSlide {
 public:
  WallSlide(const FaceSet& mesh, const std::vector<std::uint8_t>& pinned, const std::vector<std::uint8_t>& on_wall)
      : dn_(static_cast<std::size_t>(mesh.dim)) {
    if (on_wall.empty()) return;
    const std::size_t kn = dn_ + 1, nv = on_wall.size();
    first_.assign(nv + 1, 0);
    for (std::size_t v = 0; v < nv; ++v) {
      first_[v + 1] = first_[v];
      if (!on_wall[v]) continue;
      std::vector<std::array<double, 3>> normals;
      for (std::size_t a = 0; a < dn_; ++a)
        if ((pinned[v] >> a) & 1u) {
          std::array<double, 3> e{0, 0, 0};
          e[a] = 1;
          normals.push_back(e);
        }
      for (std::size_t a = 0; a < kn; ++a) {
        const std::int32_t id = mesh.vertex_keys[v * kn + a];
        if (!is_wall_spoke(id)) continue;
        const Wall& w = mesh.walls[static_cast<std::size_t>(-7 - id)];
        normals.push_back({w.normal[0], w.normal[1], dn_ == 3 ? w.normal[2] : 0.0});
      }
      for (auto q : normals) {  // Gram-Schmidt, twice for accuracy
        for (int pass = 0; pass < 2; ++pass)
          for (std::size_t b = first_[v]; b < first_[v + 1]; ++b) {
            const double* u = &basis_[3 * b];
            const double t = q[0] * u[0] + q[1] * u[1] + q[2] * u[2];
            for (int c = 0; c < 3; ++c) q[c] -= t * u[c];
          }
        const double len = std::sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2]);
        if (!(len > 1e-9)) continue;  // dependent on the earlier ones
        for (int c = 0; c < 3; ++c) basis_.push_back(q[c] / len);
        ++first_[v + 1];
      }
    }
  }
  /// d (dn components) less its components along v's constraint directions.
  void operator()(std::size_t v, double* d) const {
    if (first_[v + 1] - first_[v] >= dn_) {  // no direction left free
      for (std::size_t a = 0; a < dn_; ++a) d[a] = 0;
      return;
    }
    for (std::size_t b = first_[v]; b < first_[v + 1]; ++b) {
      const double* u = &basis_[3 * b];
      double t = 0;
      for (std::size_t a = 0; a < dn_; ++a) t += d[a] * u[a];
      for (std::size_t a = 0; a < dn_; ++a) d[a] -= t * u[a];
    }
  }

 private:
  std::size_t dn_;
  std::vector<std::size_t> first_;  // per vertex: its directions are basis_[3 first_[v], 3 first_[v + 1])
  std::vector<double> basis_;
};

template <class Body>
void parallel_range(std::size_t n, std::size_t grain, Body&& body) {
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n, grain), [&](const tbb::blocked_range<std::size_t>& r) {
    for (std::size_t i = r.begin(); i != r.end(); ++i) body(i);
  });
}

}  // namespace

/// Is (u, w) a junction edge: do the D generators the two keys share span
/// three distinct regions? (3D only; 2D has no junction vertices.)
bool is_junction_edge(const FaceSet& mesh, std::span<const std::int32_t> labels, std::size_t u, std::size_t w) {
  const std::size_t kn = static_cast<std::size_t>(mesh.dim) + 1;
  if (kn != 4) return false;
  const RegionOf region{labels};
  const std::int32_t* a = &mesh.vertex_keys[u * kn];
  const std::int32_t* b = &mesh.vertex_keys[w * kn];
  std::int64_t r[4];
  int n = 0;
  std::size_t i = 0, j = 0;
  while (i < kn && j < kn) {  // keys are ascending
    if (a[i] < b[j]) ++i;
    else if (b[j] < a[i]) ++j;
    else {
      r[n++] = region(a[i]);
      ++i;
      ++j;
    }
  }
  return n >= 3 && distinct(r, n) >= 3;
}

std::vector<double> petal_radii(const FaceSet& mesh, std::span<const double> positions, std::span<const double> points,
                                int k) {
  const std::size_t dn = static_cast<std::size_t>(mesh.dim), kn = dn + 1;
  const bool periodic = mesh.is_periodic();
  const auto lattice = net_lattice(mesh, k);
  std::vector<double> petal(mesh.n_vertices(), 0.0);
  parallel_range(petal.size(), 4096, [&](std::size_t v) {
    const std::int32_t* key = &mesh.vertex_keys[v * kn];
    std::size_t a = 0;
    while (a < kn && key[a] < 0) ++a;  // box planes come first; a vertex has a generator
    if (a == kn) return;
    const double* p = &points[static_cast<std::size_t>(key[a]) * dn];
    double g[3] = {0, 0, 0};
    if (periodic)  // the image the key names
      periodic_image(lattice, mesh.dim, p, &mesh.vertex_key_shifts[(v * kn + a) * dn], g);
    else
      std::copy_n(p, dn, g);
    double d[3] = {0, 0, 0}, d2 = 0;
    for (std::size_t c = 0; c < dn; ++c) {
      d[c] = positions[v * dn + c] - g[c];
      d2 += d[c] * d[c];
    }
    petal[v] = length(d, dn, d2);
  });
  return petal;
}

std::array<std::array<double, 3>, 3> net_lattice(const FaceSet& mesh, int k) {
  auto lattice = mesh.lattice;
  for (auto& row : lattice)
    for (double& x : row) x = std::ldexp(x, k);
  return lattice;
}

int net_frame_shift(std::span<const double> vertices, std::span<const double> points, int dim) {
  const auto dn = static_cast<std::size_t>(dim);
  Bounds extent;  // the vertices' (the box corners among them), zeros when there are none
  for (std::size_t i = 0; i < vertices.size(); ++i) {
    double& lo = extent.lo[i % dn];
    double& hi = extent.hi[i % dn];
    lo = i < dn ? vertices[i] : std::min(lo, vertices[i]);
    hi = i < dn ? vertices[i] : std::max(hi, vertices[i]);
  }
  return choose_scaling(points, extent, dim).k;
}

NetStencils build_stencils(const FaceSet& mesh, std::span<const std::int32_t> labels) {
  const int D = mesh.dim;
  const std::size_t kn = static_cast<std::size_t>(D) + 1;
  const std::size_t nv = mesh.n_vertices(), nf = mesh.n_faces();
  const RegionOf region{labels};
  NetStencils s;
  s.kind.resize(nv);

  // Classification: distinct regions among the D+1 generators.
  parallel_range(nv, 4096, [&](std::size_t v) {
    std::int64_t r[4] = {kNoRegion, kNoRegion, kNoRegion, kNoRegion};
    for (std::size_t a = 0; a < kn; ++a) r[a] = region(mesh.vertex_keys[v * kn + a]);
    const int k = distinct(r, static_cast<int>(kn));
    NetVertexKind kind = NetVertexKind::surface;
    if (k >= static_cast<int>(kn)) kind = NetVertexKind::corner;
    else if (k == 3) kind = NetVertexKind::junction;  // 3D only: in 2D k == 3 is a corner
    s.kind[v] = kind;
  });

  // Incidence vertex -> (face corner), counting sort in face order (deterministic).
  std::vector<std::int64_t> inc_off(nv + 1, 0);
  for (std::int32_t v : mesh.face_vertices) ++inc_off[static_cast<std::size_t>(v) + 1];
  std::partial_sum(inc_off.begin(), inc_off.end(), inc_off.begin());
  std::vector<std::int64_t> inc(mesh.face_vertices.size());
  {
    std::vector<std::int64_t> fill(inc_off.begin(), inc_off.end() - 1);
    for (std::size_t q = 0; q < mesh.face_vertices.size(); ++q)
      inc[static_cast<std::size_t>(fill[static_cast<std::size_t>(mesh.face_vertices[q])]++)] =
          static_cast<std::int64_t>(q);
  }
  // Face of each corner: the corner positions are the CSR of faces.
  std::vector<std::int32_t> face_of(mesh.face_vertices.size());
  parallel_range(nf, 1024, [&](std::size_t f) {
    for (auto q = mesh.face_offsets[f]; q < mesh.face_offsets[f + 1]; ++q)
      face_of[static_cast<std::size_t>(q)] = static_cast<std::int32_t>(f);
  });

  auto junction_edge = [&](std::size_t u, std::size_t w) { return is_junction_edge(mesh, labels, u, w); };

  // The stencil of v: its neighbours along polygon edges (previous and next
  // corner of every incident face), filtered by v's kind, ascending, unique.
  auto gather = [&](std::size_t v, std::vector<std::int32_t>& out) {
    out.clear();
    const NetVertexKind kind = s.kind[v];
    if (kind == NetVertexKind::corner) return;
    for (auto t = inc_off[v]; t < inc_off[v + 1]; ++t) {
      const auto q = inc[static_cast<std::size_t>(t)];
      const auto f = static_cast<std::size_t>(face_of[static_cast<std::size_t>(q)]);
      const auto b = mesh.face_offsets[f], e = mesh.face_offsets[f + 1];
      const auto prev = q == b ? e - 1 : q - 1, next = q + 1 == e ? b : q + 1;
      for (auto p : {prev, next}) {
        const std::int32_t w = mesh.face_vertices[static_cast<std::size_t>(p)];
        if (static_cast<std::size_t>(w) == v) continue;
        if (kind == NetVertexKind::junction && !junction_edge(v, static_cast<std::size_t>(w))) continue;
        out.push_back(w);
      }
    }
    std::sort(out.begin(), out.end());
    out.erase(std::unique(out.begin(), out.end()), out.end());
  };

  s.offsets.assign(nv + 1, 0);
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, nv, 2048), [&](const tbb::blocked_range<std::size_t>& r) {
    std::vector<std::int32_t> tmp;
    for (std::size_t v = r.begin(); v != r.end(); ++v) {
      gather(v, tmp);
      s.offsets[v + 1] = static_cast<std::int64_t>(tmp.size());
    }
  });
  std::partial_sum(s.offsets.begin(), s.offsets.end(), s.offsets.begin());
  s.neighbors.resize(static_cast<std::size_t>(s.offsets[nv]));
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, nv, 2048), [&](const tbb::blocked_range<std::size_t>& r) {
    std::vector<std::int32_t> tmp;
    for (std::size_t v = r.begin(); v != r.end(); ++v) {
      gather(v, tmp);
      std::copy(tmp.begin(), tmp.end(), s.neighbors.begin() + s.offsets[v]);
    }
  });
  return s;
}

}  // namespace front

std::vector<NetVertexKind> smooth_surface_net(FaceSet& mesh, std::span<const double> points,
                                              std::span<const std::int32_t> labels, const SmoothingOptions& given,
                                              double& moved) {
  SmoothingOptions options = given;  // an absolute constraint is scaled into the frame below
  front::check_smoothing_options(options);
  moved = 0;
  const int D = mesh.dim;
  if (D != 2 && D != 3) throw std::invalid_argument("smooth_surface_net: dim must be 2 or 3");
  const std::size_t dn = static_cast<std::size_t>(D), kn = dn + 1;
  const std::size_t nv = mesh.n_vertices();
  if (mesh.vertex_keys.size() != nv * kn || mesh.vertices.size() != nv * dn)
    throw std::invalid_argument("smooth_surface_net: vertex arrays have inconsistent sizes");
  if (points.size() % dn != 0) throw std::invalid_argument("smooth_surface_net: bad point array");
  const std::size_t n_points = points.size() / dn;
  if (!labels.empty() && labels.size() != n_points)
    throw InputError("labels: " + std::to_string(labels.size()) + " values for " + std::to_string(n_points) +
                     " points");
  for (std::int32_t id : mesh.vertex_keys)
    if (id >= 0 && static_cast<std::size_t>(id) >= n_points)
      throw std::invalid_argument("smooth_surface_net: a vertex key names a point beyond the point array");
  for (std::int32_t v : mesh.face_vertices)
    if (v < 0 || static_cast<std::size_t>(v) >= nv)
      throw std::invalid_argument("smooth_surface_net: face vertex out of range");

  const front::NetStencils st = front::build_stencils(mesh, labels);
  if (options.iterations == 0 || nv == 0) return st.kind;

  // In the net's frame (front::net_frame_shift), undone at the end.
  const int k = front::net_frame_shift(mesh.vertices, points, D);
  std::vector<double> scaled_points;
  if (k != 0) {
    scaled_points.assign(points.begin(), points.end());
    front::scale_pow2(scaled_points, k);
    points = scaled_points;
    front::scale_pow2(mesh.vertices, k);
    if (options.constraint_is_absolute) options.constraint = std::ldexp(options.constraint, k);
  }

  // Per vertex: the constraint radius and the axes pinned to a box plane.
  const std::vector<double> x0 = mesh.vertices;
  const std::vector<double> petal = front::petal_radii(mesh, x0, points, k);
  std::vector<double> radius(nv);
  std::vector<std::uint8_t> pinned(nv, 0);
  std::vector<std::uint8_t> on_wall(mesh.walls.empty() ? 0 : nv, 0);
  front::parallel_range(nv, 4096, [&](std::size_t v) {
    const std::int32_t* key = &mesh.vertex_keys[v * kn];
    std::uint8_t pin = 0;
    for (std::size_t a = 0; a < kn; ++a) {
      if (key[a] >= 0) continue;
      if (is_wall_spoke(key[a])) on_wall[v] = 1;
      else pin |= static_cast<std::uint8_t>(1u << ((-key[a] - 1) / 2));
    }
    pinned[v] = pin;
    radius[v] = options.constraint_is_absolute ? options.constraint : options.constraint * petal[v];
  });
  // A vertex on walls moves within them: its step loses its components
  // along the walls' normals and the pinned axes (wall_slide).
  const front::WallSlide slide(mesh, pinned, on_wall);

  // The Jacobi step moves groups of copies of one vertex (a periodic face
  // set's; every vertex alone otherwise: vertex_copies, faces.hpp), each by
  // its first copy's constraint, over the union of its copies' stencils
  // brought into its frame; its copies then follow by their translations,
  // so the surface stays closed across the box's faces.
  const VertexCopies copies = vertex_copies(mesh);
  const bool periodic = copies.periodic();
  const std::size_t ng = copies.n_groups();
  const auto lattice = front::net_lattice(mesh, k);
  const double origin[3] = {0, 0, 0};
  auto translation = [&](const std::int32_t* shift, double* out) { periodic_image(lattice, D, origin, shift, out); };
  // Group stencils: (group, translation from this group's first copy to the
  // neighbour copy's group's first copy's frame), unique.
  std::vector<std::int64_t> g_off;
  std::vector<std::int32_t> g_nbr;
  std::vector<double> g_rel;  // periodic only: dn per entry, added to the neighbour group's position
  // Periodic only: the copies of each group as CSR (a counting sort by
  // group: ascending vertex ids within a group).
  std::vector<std::int64_t> member_off;
  std::vector<std::int32_t> members;
  if (periodic) {
    member_off.assign(ng + 1, 0);
    for (std::size_t v = 0; v < nv; ++v) ++member_off[static_cast<std::size_t>(copies.group[v]) + 1];
    std::partial_sum(member_off.begin(), member_off.end(), member_off.begin());
    members.resize(nv);
    {
      std::vector<std::int64_t> fill(member_off.begin(), member_off.end() - 1);
      for (std::size_t v = 0; v < nv; ++v)
        members[static_cast<std::size_t>(fill[static_cast<std::size_t>(copies.group[v])]++)] = static_cast<std::int32_t>(v);
    }
    // A group's entries (neighbour group, relative shift), sorted and unique:
    // w's position is its group's plus shift_w; seen from v's frame, moved
    // back by shift_v, the relative shift is shift_w - shift_v.
    using Entry = std::array<std::int32_t, 4>;
    auto gather = [&](std::size_t g, std::vector<Entry>& e) {
      e.clear();
      for (auto m = member_off[g]; m < member_off[g + 1]; ++m) {
        const auto vu = static_cast<std::size_t>(members[static_cast<std::size_t>(m)]);
        for (auto t = st.offsets[vu]; t < st.offsets[vu + 1]; ++t) {
          const auto w = static_cast<std::size_t>(st.neighbors[static_cast<std::size_t>(t)]);
          Entry x{copies.group[w], 0, 0, 0};
          for (std::size_t a = 0; a < dn; ++a) x[a + 1] = copies.shift[w * dn + a] - copies.shift[vu * dn + a];
          e.push_back(x);
        }
      }
      std::sort(e.begin(), e.end());
      e.erase(std::unique(e.begin(), e.end()), e.end());
    };
    // Two passes, as build_stencils: counts, then the entries in place.
    g_off.assign(ng + 1, 0);
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, ng, 2048), [&](const tbb::blocked_range<std::size_t>& r) {
      std::vector<Entry> e;
      for (std::size_t g = r.begin(); g != r.end(); ++g) {
        gather(g, e);
        g_off[g + 1] = static_cast<std::int64_t>(e.size());
      }
    });
    std::partial_sum(g_off.begin(), g_off.end(), g_off.begin());
    g_nbr.resize(static_cast<std::size_t>(g_off[ng]));
    g_rel.resize(g_nbr.size() * dn);
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, ng, 2048), [&](const tbb::blocked_range<std::size_t>& r) {
      std::vector<Entry> e;
      for (std::size_t g = r.begin(); g != r.end(); ++g) {
        gather(g, e);
        auto o = static_cast<std::size_t>(g_off[g]);
        for (const Entry& x : e) {
          g_nbr[o] = x[0];
          translation(&x[1], &g_rel[o * dn]);
          ++o;
        }
      }
    });
  }
  // Without a box the groups' stencils are the vertices' own.
  const std::span<const std::int64_t> stencil_off = periodic ? std::span<const std::int64_t>(g_off) : st.offsets;
  const std::span<const std::int32_t> stencil = periodic ? std::span<const std::int32_t>(g_nbr) : st.neighbors;
  // A copy's position from its group's: the group's plus its translation.
  std::vector<double> offset;  // periodic only: dn per vertex
  if (periodic) {
    offset.resize(nv * dn);
    front::parallel_range(nv, 4096, [&](std::size_t v) { translation(&copies.shift[v * dn], &offset[v * dn]); });
  }
  auto place = [&](std::span<const double> group_pos, std::span<double> out) {
    front::parallel_range(nv, 4096, [&](std::size_t v) {
      const double* x = &group_pos[static_cast<std::size_t>(copies.group[v]) * dn];
      for (std::size_t a = 0; a < dn; ++a) out[v * dn + a] = x[a] + offset[v * dn + a];
    });
  };

  // The guard: after each Jacobi step every polygon must still have a ladder
  // triangulation whose triangles all face the polygon's original normal (2D:
  // every segment keeps its direction). Where a polygon has none, its
  // vertices keep their current positions for this step; this is decided in
  // rounds that each read the previous round's frozen set, so the outcome
  // does not depend on the schedule, and freezing everything is the
  // current, valid state, so the rounds end. A frozen copy freezes its group.
  const std::size_t nf = mesh.n_faces();
  std::vector<double> ref(nf * dn);
  std::vector<std::uint32_t> rotation(nf, 0);  // last valid ladder rotation
  front::parallel_range(nf, 1024, [&](std::size_t f) {
    const auto b = static_cast<std::size_t>(mesh.face_offsets[f]), e = static_cast<std::size_t>(mesh.face_offsets[f + 1]);
    front::reference_orientation(D, x0.data(), petal.data(), &mesh.face_vertices[b], e - b, &ref[dn * f]);
  });

  // The polygons at each vertex (CSR, 3D): the untangling rounds below pin
  // the ring of polygons around crossing ones.
  std::vector<std::int64_t> around_off;
  std::vector<std::int32_t> around;
  if (D == 3) {
    around_off.assign(nv + 1, 0);
    for (const std::int32_t v : mesh.face_vertices) ++around_off[static_cast<std::size_t>(v) + 1];
    std::partial_sum(around_off.begin(), around_off.end(), around_off.begin());
    around.resize(mesh.face_vertices.size());
    std::vector<std::int64_t> fill(around_off.begin(), around_off.end() - 1);
    for (std::size_t f = 0; f < nf; ++f)
      for (auto q = mesh.face_offsets[f]; q < mesh.face_offsets[f + 1]; ++q) {
        auto& slot = fill[static_cast<std::size_t>(mesh.face_vertices[static_cast<std::size_t>(q)])];
        around[static_cast<std::size_t>(slot++)] = static_cast<std::int32_t>(f);
      }
  }
  // The smoothing with `pinned` as it stands; every copy's final position.
  // Without a zone every group runs from the start (x0). With one (groups,
  // ascending), the zone's groups run from the start and the others stay
  // where `held` (every copy's position) has them: a rerun of the places the
  // untangling rounds below pin, whose cost is the zone's, not the net's.
  // The result goes to `out`. The arrays are kept from run to run (a fresh
  // page costs ~10 us to fault in on the VMs measured: design.md, "Large
  // arrays on transparent huge pages").
  Buffer<double> gcur, gnxt, cur_copies, nxt_copies;
  std::vector<std::uint8_t> frozen, freeze, newly, group_frozen;
  auto smooth = [&](const std::vector<std::int32_t>* zone, const std::vector<double>* held, std::vector<double>& out) {
    const std::size_t nz = zone ? zone->size() : ng;
    auto zone_group = [&](std::size_t i) { return zone ? static_cast<std::size_t>((*zone)[i]) : i; };
    // Group positions (gcur, gnxt) and, for periodic sets, every copy's (cur,
    // nxt); groups outside the zone are never written, so both buffers keep them.
    gcur.resize(ng * dn);
    const std::vector<double>& start = held ? *held : x0;
    front::parallel_range(ng, 4096, [&](std::size_t g) {
      std::copy_n(&start[static_cast<std::size_t>(copies.first[g]) * dn], dn, &gcur[g * dn]);
    });
    if (zone)
      front::parallel_range(nz, 4096, [&](std::size_t i) {
        const std::size_t g = zone_group(i);
        std::copy_n(&x0[static_cast<std::size_t>(copies.first[g]) * dn], dn, &gcur[g * dn]);
      });
    gnxt.assign(gcur.begin(), gcur.end());
    // The polygons the guard evaluates: those with a corner in the zone (the
    // others keep every corner, so their verdict stands).
    std::vector<std::int32_t> zone_faces;
    if (zone) {
      std::vector<std::uint8_t> in_zone(ng, 0), face_in(nf, 0);
      for (const std::int32_t g : *zone) in_zone[static_cast<std::size_t>(g)] = 1;
      front::parallel_range(nf, 1024, [&](std::size_t f) {
        for (auto q = mesh.face_offsets[f]; q < mesh.face_offsets[f + 1]; ++q)
          face_in[f] |= in_zone[static_cast<std::size_t>(
              copies.group[static_cast<std::size_t>(mesh.face_vertices[static_cast<std::size_t>(q)])])];
      });
      for (std::size_t f = 0; f < nf; ++f)
        if (face_in[f]) zone_faces.push_back(static_cast<std::int32_t>(f));
    }
    const std::size_t nzf = zone ? zone_faces.size() : nf;
    auto zone_face = [&](std::size_t i) { return zone ? static_cast<std::size_t>(zone_faces[i]) : i; };
    if (periodic) {
      cur_copies.resize(nv * dn);
      nxt_copies.resize(nv * dn);
      place(gcur, cur_copies);
    }
    frozen.assign(nv, 0);
    freeze.assign(nv, 0);
    newly.assign(nv, 0);
    group_frozen.assign(periodic ? ng : 0, 0);
    const double lambda = options.relaxation;
    for (int it = 0; it < options.iterations; ++it) {
      front::parallel_range(nz, 2048, [&](std::size_t i) {
        const std::size_t g = zone_group(i);
        const auto v = static_cast<std::size_t>(copies.first[g]);
        double* out = &gnxt[g * dn];
        const double* x = &gcur[g * dn];
        const auto b = stencil_off[g], e = stencil_off[g + 1];
        if (b == e) {
          std::copy_n(x, dn, out);
          return;
        }
        double mean[3] = {0, 0, 0};
        for (auto t = b; t < e; ++t) {
          const auto tu = static_cast<std::size_t>(t);
          const double* y = &gcur[static_cast<std::size_t>(stencil[tu]) * dn];
          if (periodic)
            for (std::size_t a = 0; a < dn; ++a) mean[a] += y[a] + g_rel[tu * dn + a];
          else
            for (std::size_t a = 0; a < dn; ++a) mean[a] += y[a];
        }
        const double inv = 1.0 / static_cast<double>(e - b);
        double d[3] = {0, 0, 0}, d2 = 0;
        for (std::size_t a = 0; a < dn; ++a) d[a] = x[a] + lambda * (mean[a] * inv - x[a]) - x0[v * dn + a];
        if (!on_wall.empty() && on_wall[v]) [[unlikely]] slide(v, d);
        for (std::size_t a = 0; a < dn; ++a) d2 += d[a] * d[a];
        const double r = radius[v], r2 = r * r;
        double scale = 1.0;
        if (d2 >= 0x1p-900 && d2 <= 0x1p900 && r2 >= 0x1p-900 && r2 <= 0x1p900) {
          if (d2 > r2) scale = r / std::sqrt(d2);
        } else if (const double dl = front::length(d, dn, d2); dl > r) {
          scale = r / dl;  // squares out of range (length)
        }
        for (std::size_t a = 0; a < dn; ++a)
          out[a] = (pinned[v] >> a) & 1u ? x0[v * dn + a] : x0[v * dn + a] + scale * d[a];
      });
      if (periodic) place(gnxt, nxt_copies);
      const Buffer<double>& cur = periodic ? cur_copies : gcur;
      const Buffer<double>& nxt = periodic ? nxt_copies : gnxt;

      std::fill(frozen.begin(), frozen.end(), 0);
      for (bool grew = true, first = true; grew; first = false) {
        // After the first round a polygon none of whose corners froze in the
        // last round sees the positions it passed with then: only those with
        // a newly frozen corner are evaluated again (same outcome, same
        // rotations; `freeze` holds the round before's set here).
        if (!first) front::parallel_range(nv, 4096, [&](std::size_t v) { newly[v] = frozen[v] & ~freeze[v]; });
        std::copy(frozen.begin(), frozen.end(), freeze.begin());
        front::parallel_range(nzf, 1024, [&](std::size_t i) {
          const std::size_t f = zone_face(i);
          const auto b = static_cast<std::size_t>(mesh.face_offsets[f]);
          const auto n = static_cast<std::size_t>(mesh.face_offsets[f + 1]) - b;
          const std::int32_t* loop = &mesh.face_vertices[b];
          auto newly_frozen = [&](std::int32_t v) { return newly[static_cast<std::size_t>(v)] != 0; };
          if (!first && std::none_of(loop, loop + n, newly_frozen))
            return;
          auto at = [&](std::int32_t v) {
            const auto u = static_cast<std::size_t>(v);
            return frozen[u] ? &cur[u * dn] : &nxt[u * dn];
          };
          bool ok = false;
          if (D == 2) {
            const double* p = at(loop[0]);
            const double* q = at(loop[1]);
            ok = (q[0] - p[0]) * ref[2 * f] + (q[1] - p[1]) * ref[2 * f + 1] > 0 ||
                 (ref[2 * f] == 0 && ref[2 * f + 1] == 0);
          } else {
            ok = front::ladder_score(at, x0.data(), loop, n, rotation[f], &ref[3 * f]) > 0;
            for (std::size_t start = 0; start < n && !ok; ++start)
              if (start != rotation[f] && front::ladder_score(at, x0.data(), loop, n, start, &ref[3 * f]) > 0) {
                rotation[f] = static_cast<std::uint32_t>(start);
                ok = true;
              }
          }
          if (ok) return;
          for (std::size_t q = 0; q < n; ++q)
            std::atomic_ref<std::uint8_t>(freeze[static_cast<std::size_t>(loop[q])])
                .store(1, std::memory_order_relaxed);
        });
        if (periodic) {  // a frozen copy freezes every copy of its vertex
          front::parallel_range(ng, 4096, [&](std::size_t g) {
            std::uint8_t any = 0;
            for (auto m = member_off[g]; m < member_off[g + 1]; ++m)
              any |= freeze[static_cast<std::size_t>(members[static_cast<std::size_t>(m)])];
            group_frozen[g] = any;
          });
          front::parallel_range(nv, 4096, [&](std::size_t v) {
            freeze[v] = group_frozen[static_cast<std::size_t>(copies.group[v])];
          });
        }
        grew = freeze != frozen;
        frozen.swap(freeze);
      }
      // Frozen groups keep their positions (a group is frozen iff its first copy is).
      front::parallel_range(nz, 4096, [&](std::size_t i) {
        const std::size_t g = zone_group(i);
        if (frozen[static_cast<std::size_t>(copies.first[g])]) std::copy_n(&gcur[g * dn], dn, &gnxt[g * dn]);
      });
      gcur.swap(gnxt);
      if (periodic) place(gcur, cur_copies);
    }
    const Buffer<double>& result = periodic ? cur_copies : gcur;
    out.assign(result.begin(), result.end());
  };

  // Untangling rounds (3D): the guard keeps each polygon from turning over,
  // not faces from passing through each other, which a Laplacian step does
  // where faces meet at a junction curve of a voxel label map with three or
  // more labels (a constraint of 0.43 voxel lets neighbours a voxel apart
  // pass each other): 82 crossing pairs of 80,000 triangles with 8 labels at
  // 64^3, 1,005 of 405,000 with 40. Where the triangles that will be output
  // (each polygon's best ladder, as triangulate_ladder takes it) cross
  // (front::crossing_triangles, exact), the polygons around both polygons'
  // corners are pinned where they started (from the second round, the ring
  // around that ring too) and the smoothing runs again from the start around
  // them (zone_around), the rest of the net held where the last round left
  // it; pinning less (the two polygons alone) took more rounds, as their
  // neighbours then folded against them, and so did two rings at once. Pairs
  // that cross at the start already (rounding artefacts) are not counted, so
  // pinning converges (4-5 rounds on those images); past 16 rounds every
  // vertex keeps its start.
  std::vector<double> cur, before_round;  // the positions now, and those the last check saw
  smooth(nullptr, nullptr, cur);
  // Polygon f's n - 2 triangles start at triangle face_offsets[f] - 2 f.
  const std::size_t nt = D == 3 ? mesh.face_vertices.size() - 2 * nf : 0;
  std::vector<std::int32_t> corners(3 * nt);
  std::vector<std::size_t> polygon_of(nt);
  auto moved_since = [&](std::size_t v) {  // (3D)
    return cur[3 * v] != before_round[3 * v] || cur[3 * v + 1] != before_round[3 * v + 1] ||
           cur[3 * v + 2] != before_round[3 * v + 2];
  };
  // The groups a rerun smooths again: those within zone_steps steps (across
  // polygons) of the newly pinned ones, ascending. A Laplacian step carries
  // a change one step, and over the iterations it spreads as a diffusion of
  // variance relaxation * iterations (in steps squared): within twice its
  // deviation a rerun of the whole net would change positions, beyond it
  // hardly. The whole net's rerun (the first version) cost a full smoothing
  // per round and made every triangle one to check again. On a 128^3 map of
  // 12 labels the zone's result differs from the whole rerun's by more than
  // 0.01 voxel at 1.6% of the vertices (where one pinned and the other did
  // not), and pins 2.3% more vertices (docs/design.md, "Untangling").
  const int zone_steps = static_cast<int>(std::ceil(2 * std::sqrt(options.iterations * options.relaxation)));
  auto zone_around = [&](const std::vector<std::int32_t>& seeds) {
    std::vector<std::uint8_t> in(ng, 0);
    std::vector<std::int32_t> zone, frontier, next;
    for (const std::int32_t g : seeds)
      if (!in[static_cast<std::size_t>(g)]) {
        in[static_cast<std::size_t>(g)] = 1;
        frontier.push_back(g);
      }
    zone = frontier;
    auto copies_of = [&](std::int32_t g, auto&& body) {
      if (!periodic) return body(static_cast<std::size_t>(g));
      for (auto m = member_off[static_cast<std::size_t>(g)]; m < member_off[static_cast<std::size_t>(g) + 1]; ++m)
        body(static_cast<std::size_t>(members[static_cast<std::size_t>(m)]));
    };
    for (int step = 0; step < zone_steps && !frontier.empty(); ++step) {
      next.clear();
      for (const std::int32_t g : frontier)
        copies_of(g, [&](std::size_t v) {
          for (auto e = around_off[v]; e < around_off[v + 1]; ++e) {
            const auto f = static_cast<std::size_t>(around[static_cast<std::size_t>(e)]);
            for (auto q = mesh.face_offsets[f]; q < mesh.face_offsets[f + 1]; ++q) {
              const std::int32_t w = copies.group[static_cast<std::size_t>(mesh.face_vertices[static_cast<std::size_t>(q)])];
              if (!in[static_cast<std::size_t>(w)]) {
                in[static_cast<std::size_t>(w)] = 1;
                next.push_back(w);
              }
            }
          }
        });
      zone.insert(zone.end(), next.begin(), next.end());
      frontier.swap(next);
    }
    std::sort(zone.begin(), zone.end());
    return zone;
  };
  front::CrossingCheck check;
  // Zone reruns while each round leaves fewer crossings than the last; once
  // one does not, the whole net runs again every round (the zones' held
  // borders can keep making crossings: 606, 149, 47, 67, 49, 67 ... for
  // 16 rounds on a 48^3 map of 40 labels with 60 iterations of relaxation 1,
  // constraint 0.9, which then kept every vertex where it started; so it
  // ends in seven).
  bool whole = false;
  std::size_t last_count = std::numeric_limits<std::size_t>::max();
  for (int round = 0; D == 3 && round < 16; ++round) {
    // The output triangles; after the first round only those of polygons
    // with a moved corner can differ, and only pairs with one of those can
    // cross (the others were checked apart before). All of such a polygon's
    // triangles count as changed: another ladder may make one of corners
    // that did not move.
    std::vector<std::uint8_t> changed(round > 0 ? nt : 0);
    front::parallel_range(nf, 1024, [&](std::size_t f) {
      const auto b = static_cast<std::size_t>(mesh.face_offsets[f]);
      const auto n = static_cast<std::size_t>(mesh.face_offsets[f + 1]) - b;
      const std::int32_t* loop = &mesh.face_vertices[b];
      auto has_moved = [&](std::int32_t v) { return moved_since(static_cast<std::size_t>(v)); };
      if (round > 0 && std::none_of(loop, loop + n, has_moved))
        return;
      std::size_t t = b - 2 * f;
      front::ladder(n, front::output_ladder_rotation(cur.data(), x0.data(), loop, n, &ref[3 * f]),
                    [&](std::size_t i, std::size_t j, std::size_t q) {
                      corners[3 * t] = loop[i], corners[3 * t + 1] = loop[j], corners[3 * t + 2] = loop[q];
                      if (round > 0) changed[t] = 1;
                      polygon_of[t++] = f;
                    });
    });
    // Rounding can set vertices that should coincide ulps apart, so that the
    // unsmoothed net itself overlaps by ulps (far from the origin, with
    // anisotropic voxels: hundreds of pairs). Pinning cannot undo those (a
    // first version pinned all of a 2-label box), so a pair that crosses
    // where it started is left alone while it stays that small: unless it
    // still crosses with each triangle shrunk by 1e-6 of its size (an ulp
    // sliver that smoothing opened into a fold does). A pair whose corners
    // are all where they started is left alone in any case (not tested: it
    // is as good as it gets, and the rounds end).
    auto corner = [&](const std::vector<double>& at, std::size_t t, std::size_t k) {
      return &at[3 * static_cast<std::size_t>(corners[3 * t + k])];
    };
    auto crosses_at = [&](const std::vector<double>& at, std::size_t s, std::size_t t) {
      const double* a[3] = {corner(at, s, 0), corner(at, s, 1), corner(at, s, 2)};
      const double* b[3] = {corner(at, t, 0), corner(at, t, 1), corner(at, t, 2)};
      return front::triangle_pair_crosses(a, &corners[3 * s], b, &corners[3 * t]);
    };
    auto crosses_shrunk = [&](std::size_t s, std::size_t t) {
      double pts[2][3][3];
      for (int side = 0; side < 2; ++side) {
        const std::size_t u = side == 0 ? s : t;
        for (std::size_t d = 0; d < 3; ++d) {
          const double c = (corner(cur, u, 0)[d] + corner(cur, u, 1)[d] + corner(cur, u, 2)[d]) / 3;
          for (std::size_t k = 0; k < 3; ++k) pts[side][k][d] = c + (1 - 1e-6) * (corner(cur, u, k)[d] - c);
        }
      }
      const double* a[3] = {pts[0][0], pts[0][1], pts[0][2]};
      const double* b[3] = {pts[1][0], pts[1][1], pts[1][2]};
      const std::int32_t ids[6] = {-1, -2, -3, -4, -5, -6};  // apart: no corner shared
      return front::triangle_pair_crosses(a, ids, b, ids + 3);
    };
    std::vector<std::uint8_t> at_start(nt);
    front::parallel_range(nt, 4096, [&](std::size_t t) {
      bool same = true;
      for (std::size_t k = 0; k < 3; ++k) same = same && std::equal(corner(cur, t, k), corner(cur, t, k) + 3, corner(x0, t, k));
      at_start[t] = same;
    });
    auto crossings = check(cur, corners, changed, at_start);
    std::erase_if(crossings, [&](const auto& st) {
      const auto [s, t] = st;
      return crosses_at(x0, s, t) && !crosses_shrunk(s, t);
    });
    if (crossings.empty()) break;
    std::vector<std::int32_t> newly_pinned;  // groups
    auto pin_polygon = [&](std::size_t f) {
      for (auto q = mesh.face_offsets[f]; q < mesh.face_offsets[f + 1]; ++q) {
        const auto v = static_cast<std::size_t>(mesh.face_vertices[static_cast<std::size_t>(q)]);
        const std::int32_t g = copies.group[v];
        const auto first = static_cast<std::size_t>(copies.first[static_cast<std::size_t>(g)]);
        if (pinned[first] != 7) newly_pinned.push_back(g);
        pinned[first] = 7;  // every axis: the group stays where it started
      }
    };
    // The ring of polygons around both polygons' corners; from the second
    // round on, the ring around that ring too (crossings left after a round
    // sit beside the places pinned, and a wider ring ends the rounds sooner).
    std::vector<std::size_t> ring;
    for (const auto& [s, t] : crossings) ring.insert(ring.end(), {polygon_of[s], polygon_of[t]});
    for (int width = 0; width < (round == 0 ? 1 : 2); ++width) {
      std::vector<std::size_t> wider;
      for (const std::size_t f : ring)
        for (auto q = mesh.face_offsets[f]; q < mesh.face_offsets[f + 1]; ++q) {
          const auto v = static_cast<std::size_t>(mesh.face_vertices[static_cast<std::size_t>(q)]);
          for (auto e = around_off[v]; e < around_off[v + 1]; ++e)
            wider.push_back(static_cast<std::size_t>(around[static_cast<std::size_t>(e)]));
        }
      std::sort(wider.begin(), wider.end());
      wider.erase(std::unique(wider.begin(), wider.end()), wider.end());
      ring = std::move(wider);
    }
    for (const std::size_t f : ring) pin_polygon(f);
    if (newly_pinned.empty()) {  // (cannot happen: crossings need a moved corner)
      cur = x0;
      break;
    }
    whole = whole || crossings.size() >= last_count;
    last_count = crossings.size();
    before_round.swap(cur);
    if (round + 1 == 16) cur = x0;
    else if (whole) smooth(nullptr, nullptr, cur);
    else {
      const std::vector<std::int32_t> zone = zone_around(newly_pinned);
      smooth(&zone, &before_round, cur);
    }
  }

  moved = 0;
  for (std::size_t v = 0; v < nv; ++v) {
    double d[3] = {0, 0, 0}, d2 = 0;
    for (std::size_t a = 0; a < dn; ++a) {
      d[a] = cur[v * dn + a] - x0[v * dn + a];
      d2 += d[a] * d[a];
    }
    moved = std::max(moved, front::length(d, dn, d2));
  }
  mesh.vertices = std::move(cur);
  if (k != 0) {
    front::scale_pow2(mesh.vertices, -k);
    moved = std::ldexp(moved, -k);
  }
  return st.kind;
}

}  // namespace tessera

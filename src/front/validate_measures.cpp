// validate()'s exact check of sampled cells' volumes and centroids.
//
// The check does not reuse the cell kernels' sums. It takes each sampled
// cell from the merged mesh: its vertices by their keys (the generators and
// box planes that meet there), and its faces' corner loops. It solves those
// vertices exactly from the input points and sums the cell's cones exactly
// (kernels::exact_cell_measure, the measure's own fallback, given terms
// built here from the mesh). So a wrong float measure, or a cell whose
// recorded measure belongs to different faces, shows up. The merged
// vertices' coordinates are compared with those exact positions too. The
// per-cell cost is ~0.1 ms in fixed point, more where it falls back to
// rationals, so only a sample is measured: the cells most likely to be wrong (the smallest,
// and the most elongated, whose float terms cancel: stop 63's columns,
// stop 64's strips) and a spread over the rest.
#include "validate_measures.hpp"
#include "walls.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <map>
#include <optional>
#include <sstream>
#include <stdexcept>
#include <unordered_map>
#include <vector>

#include <tbb/parallel_for.h>

#include "tessera/kernels/exact_predicates.hpp"

namespace tessera::front {
namespace {

constexpr std::size_t sample_smallest = 32;  // by volume
constexpr std::size_t sample_longest = 32;   // by radius^dim / volume
constexpr std::size_t sample_spread = 64;    // evenly spaced in output order
// A cell of more face corners than this is left out of the sample (the
// centre of thousands of points on a sphere: its exact measure alone would
// take seconds); the sample is measured in order of priority, each cell
// only while the corners measured in all stay within the second.
constexpr std::size_t max_cell_corners = 20000;
constexpr std::size_t max_total_corners = 400000;
// Where the exact check reports failures by name, the first few.
constexpr std::size_t named_failures = 3;

std::string number(double x) {
  std::ostringstream s;
  s.precision(17);
  s << x;
  return s.str();
}

// One sampled cell against its exact measure.
struct Outcome {
  bool keyed = false;  // false: a face too short, or a corner whose key lacks the generator
  bool solvable = true;  // false: a corner's key names dependent planes (no such vertex exists)
  double exact = 0, rel = 0;                 // the exact volume; the reported one's relative error
  double off = 0, off_tolerance = 0, radius = 0;  // the centroid's error, its tolerance; the cell's radius
  // The corner farthest from its exact position (by its key), and how far
  // (|.|_inf); its tolerance is off_tolerance's.
  double vertex_off = 0;
  std::int32_t vertex_worst = -1;
};

/// The points a periodic cell's planes name: its generator and the images in
/// its keys and faces, numbered locally (the generator 0, each (point,
/// shift) from 1 in order of appearance) and placed at their images. Those
/// sums are exact (the periodic box's grid, periodic_image), so the exact
/// measure reads them as any input points; it decides no ties, so the local
/// numbering does not matter.
class LocalImages {
 public:
  /// `radii`: power cells' (input ids), else null; each image has its point's.
  LocalImages(const Cells& c, std::int32_t g, const double* radii)
      : c_(c), du_(static_cast<std::size_t>(c.dim)), lattice_(c.lattice()), given_radii_(radii) {
    const std::int8_t zero[3] = {0, 0, 0};
    (void)id_of(g, zero);
  }
  /// The local id of point `id` moved by `shift` (dim int8); box planes
  /// (negative ids) stay as they are.
  std::int32_t id_of(std::int32_t id, const std::int8_t* shift) {
    if (id < 0) return id;
    std::array<std::int32_t, 4> key{id, 0, 0, 0};
    for (std::size_t a = 0; a < du_; ++a) key[a + 1] = shift[a];
    const auto [it, fresh] = ids_.try_emplace(key, static_cast<std::int32_t>(ids_.size()));
    if (fresh) {
      double x[3];
      periodic_image(lattice_, c_.dim, &c_.periodic_points[static_cast<std::size_t>(id) * du_], shift, x);
      points_.insert(points_.end(), x, x + du_);
      if (given_radii_ != nullptr) radii_.push_back(given_radii_[id]);
    }
    return it->second;
  }
  const std::vector<double>& points() const { return points_; }
  const std::vector<double>& radii() const { return radii_; }  ///< per local id (power cells)

 private:
  const Cells& c_;
  std::size_t du_;
  std::array<std::array<double, 3>, 3> lattice_;
  std::map<std::array<std::int32_t, 4>, std::int32_t> ids_;
  std::vector<double> points_;
  const double* given_radii_;
  std::vector<double> radii_;
};

Outcome measure_cell(const Cells& c, const kernels::ExactContext& ctx, std::span<const double> points,
                     const std::vector<double>& radius2, std::size_t k) {
  const auto Du = static_cast<std::size_t>(c.dim);
  const std::size_t nv = c.n_vertices();
  // In a periodic box the cell's planes are named by (point, shift), and its
  // generator is local point 0 (LocalImages).
  const bool periodic = c.is_periodic();
  std::optional<LocalImages> images;
  if (periodic) images.emplace(c, c.generator[k], ctx.radii);
  const std::int32_t g = periodic ? 0 : c.generator[k];
  std::unordered_map<std::int32_t, std::uint32_t> local;  // merged vertex -> its index in the cell
  std::vector<std::int32_t> merged;                        // the inverse
  std::vector<std::int32_t> vertex_planes;
  std::vector<kernels::MeasureTerm> terms;
  Outcome o;
  o.keyed = true;
  auto index_of = [&](std::int32_t v) {
    const auto [it, fresh] = local.try_emplace(v, static_cast<std::uint32_t>(local.size()));
    if (fresh) {
      merged.push_back(v);
      // The vertex's planes: its key without the generator (ascending,
      // box planes negative, as exact_cell_measure takes them).
      const std::size_t e0 = static_cast<std::size_t>(v) * (Du + 1);
      const std::int32_t* key = c.vertex_keys.data() + e0;
      std::size_t own = 0;
      for (std::size_t d = 0; d <= Du; ++d) {
        const std::int32_t id = periodic ? images->id_of(key[d], &c.vertex_key_shifts[(e0 + d) * Du]) : key[d];
        if (id == g) ++own;
        else vertex_planes.push_back(id);
      }
      o.keyed &= own == 1;
    }
    return it->second;
  };
  for (auto f = c.cell_face_offsets[k]; f < c.cell_face_offsets[k + 1] && o.keyed; ++f) {
    const auto q0 = static_cast<std::size_t>(c.face_vertex_offsets[static_cast<std::size_t>(f)]);
    const auto q1 = static_cast<std::size_t>(c.face_vertex_offsets[static_cast<std::size_t>(f) + 1]);
    o.keyed &= q1 >= q0 + (c.dim == 3 ? 3 : 2);  // a polygon; in 2D an edge
    for (std::size_t q = q0; q < q1 && o.keyed; ++q)
      o.keyed &= c.face_vertices[q] >= 0 && static_cast<std::size_t>(c.face_vertices[q]) < nv;
    if (!o.keyed) return o;
    // 3D: the cone over each edge a -> b of the face's loop
    // (counter-clockwise from outside) from the foot of its plane. 2D: a
    // face is an edge, its two vertices counter-clockwise (the shoelace term).
    const auto fu = static_cast<std::size_t>(f);
    const std::int32_t plane = c.dim != 3 ? 0
                               : periodic ? images->id_of(c.face_neighbor[fu], &c.face_shift[fu * Du])
                                          : c.face_neighbor[fu];
    const std::size_t m = q1 - q0;
    for (std::size_t t = 0; t < (c.dim == 3 ? m : 1); ++t) {
      const std::uint32_t a = index_of(c.face_vertices[q0 + t]);
      const std::uint32_t b = index_of(c.face_vertices[q0 + (t + 1) % m]);
      terms.push_back({plane, a, b});
    }
  }
  if (!o.keyed) return o;
  kernels::ExactContext local_ctx = ctx;
  if (periodic) {
    local_ctx.points = images->points().data();
    if (ctx.radii != nullptr) local_ctx.radii = images->radii().data();
    points = images->points();
  }
  double centroid[3] = {0, 0, 0};
  try {
    o.exact = kernels::exact_cell_measure(local_ctx, g, vertex_planes, terms, centroid);
  } catch (const std::logic_error&) {  // exact_vertex: the key's planes meet in no point
    o.solvable = false;
    return o;
  }
  o.rel = o.exact > 0 ? std::fabs(c.volume[k] - o.exact) / o.exact : std::numeric_limits<double>::infinity();
  const double* p = points.data() + static_cast<std::size_t>(g) * Du;
  o.radius = std::sqrt(radius2[k]);
  double pmax = 0;
  for (std::size_t d = 0; d < Du; ++d) {
    o.off = std::max(o.off, std::fabs(c.centroid[k * Du + d] - (p[d] + centroid[d])));
    pmax = std::max(pmax, std::fabs(p[d]));
  }
  // Both centroids add the generator's coordinates to one relative to it,
  // each rounding once.
  o.off_tolerance = measure_tolerance * o.radius + 8 * 0x1p-53 * (pmax + o.radius);
  // The corners where the mesh puts them against their exact positions.
  // A merged vertex was solved in its owner's frame (the lowest generator
  // of its key), but it lies as far from every generator of its key, so its
  // float error scales with |y| <= this cell's radius as here: below 1e-10
  // of it for the float solves (condition under filter::exact_vertex_condition),
  // the last bits for exact ones; the tolerance allows 2^-28.
  for (std::size_t l = 0; l < merged.size(); ++l) {
    double y[3] = {0, 0, 0};
    kernels::exact_vertex(local_ctx, g, vertex_planes.data() + l * Du, y);  // solvable: the measure solved it
    const double* v = c.vertices.data() + static_cast<std::size_t>(merged[l]) * Du;
    double off = 0;
    for (std::size_t d = 0; d < Du; ++d) off = std::max(off, std::fabs(v[d] - (p[d] + y[d])));
    if (!(off <= o.vertex_off) || o.vertex_worst < 0) {  // NaN: the worst
      o.vertex_off = off;
      o.vertex_worst = merged[l];
    }
  }
  return o;
}

}  // namespace

void check_measures(const Cells& c, std::span<const double> points, std::span<const double> radii,
                    const std::vector<double>& radius2, ValidationReport& r) {
  const int D = c.dim;
  const std::size_t nc = c.n_cells();
  if (nc == 0 || c.vertex_keys.empty()) return;
  // Each cell's face corners: the exact measure's terms in 3D (twice them in 2D).
  auto corners = [&](std::size_t k) {
    return static_cast<std::size_t>(c.face_vertex_offsets[static_cast<std::size_t>(c.cell_face_offsets[k + 1])] -
                                    c.face_vertex_offsets[static_cast<std::size_t>(c.cell_face_offsets[k])]);
  };

  // The sample. Cells of subnormal or zero volume carry too few bits for a
  // relative comparison (zero ones are counted by validate()).
  std::vector<std::uint32_t> eligible;
  for (std::size_t k = 0; k < nc; ++k)
    if (c.volume[k] > 0x1p-960 && std::isfinite(c.volume[k]) && corners(k) > 0 && corners(k) <= max_cell_corners)
      eligible.push_back(static_cast<std::uint32_t>(k));
  if (eligible.empty()) return;
  std::vector<std::uint32_t> pick;
  auto take_first = [&](std::vector<std::uint32_t> order, std::size_t count, auto&& before) {
    count = std::min(count, order.size());
    std::partial_sort(order.begin(), order.begin() + static_cast<std::ptrdiff_t>(count), order.end(), before);
    pick.insert(pick.end(), order.begin(), order.begin() + static_cast<std::ptrdiff_t>(count));
  };
  take_first(eligible, sample_smallest, [&](std::uint32_t a, std::uint32_t b) {
    return c.volume[a] != c.volume[b] ? c.volume[a] < c.volume[b] : a < b;
  });
  // Elongation radius^D / volume, compared in logarithms: the ratio itself
  // may overflow (a radius of 1e120 over a volume of 1e-100).
  std::vector<double> elongation(nc, 0.0);
  for (const std::uint32_t k : eligible)
    elongation[k] = 0.5 * static_cast<double>(D) * std::log(radius2[k]) - std::log(c.volume[k]);
  take_first(eligible, sample_longest, [&](std::uint32_t a, std::uint32_t b) {
    return elongation[a] != elongation[b] ? elongation[a] > elongation[b] : a < b;
  });
  const std::size_t spread = std::min(sample_spread, eligible.size());
  for (std::size_t s = 0; s < spread; ++s) pick.push_back(eligible[s * eligible.size() / spread]);
  // Each cell once, in that order of priority (the corner budget below may
  // leave the last ones out).
  std::vector<std::uint32_t> sample;
  for (const std::uint32_t k : pick)
    if (std::find(sample.begin(), sample.end(), k) == sample.end()) sample.push_back(k);

  // The cells measured: the sample in order of priority, within the corner budget.
  std::vector<std::uint32_t> measured;
  std::size_t measured_corners = 0;
  for (const std::uint32_t k : sample)
    if (measured_corners + corners(k) <= max_total_corners) {
      measured_corners += corners(k);
      measured.push_back(k);
    }

  // Their exact measures, in parallel (each is independent; validate runs
  // in the cells' arena), then reported in the order above.
  kernels::ExactContext ctx;
  ctx.points = points.data();
  ctx.dim = D;
  ctx.lo = c.bounds.lo;
  ctx.hi = c.bounds.hi;
  if (!radii.empty()) ctx.radii = radii.data();
  const std::vector<kernels::Wall> walls = kernel_walls(c.walls, D, 0);  // the user's frame, as the points
  ctx.walls = walls.data();
  ctx.num_walls = static_cast<int>(walls.size());
  std::vector<Outcome> outcomes(measured.size());
  tbb::parallel_for(std::size_t{0}, measured.size(),
                    [&](std::size_t s) { outcomes[s] = measure_cell(c, ctx, points, radius2, measured[s]); });
  std::size_t failed = 0;
  for (std::size_t s = 0; s < measured.size(); ++s) {
    const Outcome& o = outcomes[s];
    const std::int32_t g = c.generator[measured[s]];
    if (!o.keyed || !o.solvable) {
      r.messages.push_back("cell of point " + std::to_string(g) +
                           (o.keyed ? ": a corner's key names planes that meet in no point"
                                    : ": a face too short, or a corner whose key does not name the generator"));
      r.ok = false;
      continue;
    }
    ++r.measures_checked;
    if (r.measure_worst < 0 || o.rel > r.measure_rel_error) {
      r.measure_rel_error = o.rel;
      r.measure_worst = g;
    }
    const double vertex_rel = o.radius > 0 ? o.vertex_off / o.radius : std::numeric_limits<double>::infinity();
    if (r.vertex_worst < 0 || !(vertex_rel <= r.vertex_rel_error)) {
      r.vertex_rel_error = vertex_rel;
      r.vertex_worst = o.vertex_worst;
    }
    const bool volume_bad = !(o.rel <= measure_tolerance), centroid_bad = !(o.off <= o.off_tolerance),
               vertex_bad = !(o.vertex_off <= o.off_tolerance);
    if (!volume_bad && !centroid_bad && !vertex_bad) continue;
    r.ok = false;
    if (++failed > named_failures) continue;
    const char* what = D == 3 ? "volume " : "area ";
    if (volume_bad)
      r.messages.push_back("cell of point " + std::to_string(g) + ": " + what + number(c.volume[measured[s]]) +
                           ", exactly " + number(o.exact) + " (relative error " + number(o.rel) + ")");
    else if (centroid_bad)
      r.messages.push_back("cell of point " + std::to_string(g) + ": centroid " + number(o.off) +
                           " off its exact value (cell radius " + number(o.radius) + ")");
    else
      r.messages.push_back("cell of point " + std::to_string(g) + ": merged vertex " + std::to_string(o.vertex_worst) +
                           " " + number(o.vertex_off) + " off its exact position (cell radius " +
                           number(o.radius) + ")");
  }
  if (failed > named_failures)
    r.messages.push_back(std::to_string(failed) + " of " + std::to_string(r.measures_checked) +
                         " sampled cells differ from their exact measures or corners");
}

}  // namespace tessera::front

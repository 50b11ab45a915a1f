// validate()'s exact check of sampled cells' volumes and centroids.
//
// The check does not reuse the cell kernels' sums. It takes each sampled
// cell from the merged mesh: its vertices by their keys (the generators and
// box planes that meet there), and its faces' corner loops. It solves those
// vertices exactly from the input points and sums the cell's cones exactly
// (kernels::exact_cell_measure, the measure's own fallback, given terms
// built here from the mesh). So a wrong float measure, or a cell whose
// recorded measure belongs to different faces, shows up. The per-cell cost
// is ~0.1 ms in fixed point, more where it falls back to rationals, so only
// a sample is measured: the cells most likely to be wrong (the smallest,
// and the most elongated, whose float terms cancel: stop 63's columns,
// stop 64's strips) and a spread over the rest.
#include "validate_measures.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <sstream>
#include <unordered_map>
#include <vector>

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

}  // namespace

void check_measures(const Cells& c, std::span<const double> points, const std::vector<double>& radius2,
                    ValidationReport& r) {
  const int D = c.dim;
  const auto Du = static_cast<std::size_t>(D);
  const std::size_t nc = c.n_cells();
  if (nc == 0 || c.vertex_keys.empty()) return;
  const std::size_t nv = c.n_vertices();
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

  kernels::ExactContext ctx;
  ctx.points = points.data();
  ctx.dim = D;
  ctx.lo = c.bounds.lo;
  ctx.hi = c.bounds.hi;
  std::unordered_map<std::int32_t, std::uint32_t> local;  // merged vertex -> its index in the cell
  std::vector<std::int32_t> vertex_planes;
  std::vector<kernels::MeasureTerm> terms;
  std::size_t measured_corners = 0, failed = 0;
  for (const std::uint32_t k : sample) {
    if (measured_corners + corners(k) > max_total_corners) continue;
    measured_corners += corners(k);
    const std::int32_t g = c.generator[k];
    local.clear();
    vertex_planes.clear();
    terms.clear();
    bool keyed = true;
    auto index_of = [&](std::int32_t v) {
      const auto [it, fresh] = local.try_emplace(v, static_cast<std::uint32_t>(local.size()));
      if (fresh) {
        // The vertex's planes: its key without the generator (ascending,
        // box planes negative, as exact_cell_measure takes them).
        const std::int32_t* key = c.vertex_keys.data() + static_cast<std::size_t>(v) * (Du + 1);
        std::size_t own = 0;
        for (std::size_t d = 0; d <= Du; ++d) {
          if (key[d] == g) ++own;
          else vertex_planes.push_back(key[d]);
        }
        keyed &= own == 1;
      }
      return it->second;
    };
    for (auto f = c.cell_face_offsets[k]; f < c.cell_face_offsets[k + 1] && keyed; ++f) {
      const auto q0 = static_cast<std::size_t>(c.face_vertex_offsets[static_cast<std::size_t>(f)]);
      const auto q1 = static_cast<std::size_t>(c.face_vertex_offsets[static_cast<std::size_t>(f) + 1]);
      keyed &= q1 >= q0 + (D == 3 ? 3 : 2);  // a polygon; in 2D an edge
      for (std::size_t q = q0; q < q1 && keyed; ++q)
        keyed &= c.face_vertices[q] >= 0 && static_cast<std::size_t>(c.face_vertices[q]) < nv;
      if (!keyed) break;
      // 3D: the cone over each edge a -> b of the face's loop
      // (counter-clockwise from outside) from the foot of its plane. 2D: a
      // face is an edge, its two vertices counter-clockwise (the shoelace term).
      const std::int32_t plane = D == 3 ? c.face_neighbor[static_cast<std::size_t>(f)] : 0;
      const std::size_t m = q1 - q0;
      for (std::size_t t = 0; t < (D == 3 ? m : 1); ++t) {
        const std::uint32_t a = index_of(c.face_vertices[q0 + t]);
        const std::uint32_t b = index_of(c.face_vertices[q0 + (t + 1) % m]);
        terms.push_back({plane, a, b});
      }
    }
    if (!keyed) {
      r.messages.push_back("cell of point " + std::to_string(g) +
                           ": a face too short, or a corner whose key does not name the generator");
      r.ok = false;
      continue;
    }
    double centroid[3] = {0, 0, 0};
    const double exact = kernels::exact_cell_measure(ctx, g, vertex_planes, terms, centroid);
    ++r.measures_checked;
    const double v = c.volume[k];
    const double rel = exact > 0 ? std::fabs(v - exact) / exact : std::numeric_limits<double>::infinity();
    const double* p = points.data() + static_cast<std::size_t>(g) * Du;
    const double radius = std::sqrt(radius2[k]);
    double off = 0, pmax = 0;
    for (std::size_t d = 0; d < Du; ++d) {
      off = std::max(off, std::fabs(c.centroid[k * Du + d] - (p[d] + centroid[d])));
      pmax = std::max(pmax, std::fabs(p[d]));
    }
    // Both centroids add the generator's coordinates to one relative to it,
    // each rounding once.
    const double off_tolerance = measure_tolerance * radius + 8 * 0x1p-53 * (pmax + radius);
    if (r.measure_worst < 0 || rel > r.measure_rel_error) {
      r.measure_rel_error = rel;
      r.measure_worst = g;
    }
    const bool volume_bad = !(rel <= measure_tolerance), centroid_bad = !(off <= off_tolerance);
    if (!volume_bad && !centroid_bad) continue;
    r.ok = false;
    if (++failed > named_failures) continue;
    const char* what = D == 3 ? "volume " : "area ";
    if (volume_bad)
      r.messages.push_back("cell of point " + std::to_string(g) + ": " + what + number(v) + ", exactly " +
                           number(exact) + " (relative error " + number(rel) + ")");
    else
      r.messages.push_back("cell of point " + std::to_string(g) + ": centroid " + number(off) +
                           " off its exact value (cell radius " + number(radius) + ")");
  }
  if (failed > named_failures)
    r.messages.push_back(std::to_string(failed) + " of " + std::to_string(r.measures_checked) +
                         " sampled cells differ from their exact measures");
}

}  // namespace tessera::front

// Periodic boxes: the input's wrapping and rounding, the images, and the
// cells mapped back (see periodic.hpp).
#include "periodic.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <string>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "tessera/engine/classifier.hpp"
#include "tessera/engine/thread_arena.hpp"
#include "tessera/finite_points.hpp"
#include "tessera/kernels/filter.hpp"
#include "tessera/kernels/power.hpp"
#include "../message_text.hpp"

namespace tessera::front {
namespace {


std::string num(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.17g", v);
  return buf;
}

std::string short_num(double v) {  // (an estimate, to 3 digits)
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.3g", v);
  return buf;
}

/// x rounded to the nearest multiple of g (a power of two), ties to even.
double snap(double x, double g) { return std::nearbyint(x / g) * g; }

/// The power of two that brings the box's largest length or tilt near 1.
/// Its volumes, areas and squared lengths are taken in that frame: in
/// doubles they underflow or overflow far before the lengths do (a box
/// 1e-191 wide has a volume of 1e-573, which is 0, and a squared length of
/// 0; one 1e120 wide a volume of infinity). Scaling by a power of two is
/// exact, so the results are the same doubles wherever nothing overflowed.
int geometry_exponent(const PeriodicInput& in) {
  double m = 0;
  for (int a = 0; a < in.dim; ++a) m = std::max(m, in.length[static_cast<std::size_t>(a)]);
  for (double t : in.tilt) m = std::max(m, std::fabs(t));
  return kernels::filter::binary_exponent(m);  // the lengths are finite and positive (checked)
}

/// Tilts (xy, xz, yz) of more than a box length, reduced by whole box lengths
/// to within half of one: b - k a for xy, then c - k b for yz (which moves xz
/// by k times the reduced xy, where it may end within a length and stay),
/// then c - k a for xz. Nothing changes where k is 0 (not even -0.0's sign). The same lattice, so the
/// same cells, in a box whose heights are near its lengths. A tilt of many
/// lengths makes the parallelepiped thin across its faces, and the layer of
/// images, counted in lattice vectors of the given basis, passed the int8
/// shifts: one point at tilts of 10.3 was refused ("some cell reaches past
/// 127 box lengths"), 1,000 points at an xy of 640. Tilts within a length
/// are kept as given (LAMMPS keeps its own within half by flipping the box).
/// The tilts used are what Cells::tilt reports, and the shifts count the
/// vectors of that basis.
std::array<double, 3> reduced_tilts(std::array<double, 3> t, const std::array<double, 3>& length) {
  auto whole_lengths = [](double v, double l) { return std::fabs(v) > l ? std::nearbyint(v / l) : 0.0; };
  if (const double k = whole_lengths(t[0], length[0]); k != 0) t[0] -= k * length[0];
  if (const double k = whole_lengths(t[2], length[1]); k != 0) {
    t[2] -= k * length[1];
    t[1] -= k * t[0];
  }
  if (const double k = whole_lengths(t[1], length[0]); k != 0) t[1] -= k * length[0];
  return t;
}

}  // namespace

PeriodicInput periodic_input(std::span<const double> points, int dim, std::span<const std::int32_t> labels,
                             const VoronoiOptions& options) {
  if (dim != 2 && dim != 3) throw InputError("dimension must be 2 or 3, got " + std::to_string(dim));
  const auto du = static_cast<std::size_t>(dim);
  if (points.empty()) throw InputError("no input points");
  if (points.size() % du != 0)
    throw InputError("point array length " + std::to_string(points.size()) + " is not a multiple of dimension " +
                     std::to_string(dim));
  PeriodicInput in;
  in.dim = dim;
  in.n = points.size() / du;
  if (in.n > static_cast<std::size_t>(INT32_MAX - 1)) throw InputError("too many points (ids are 32-bit)");
  if (!labels.empty() && labels.size() != in.n)
    throw InputError("labels: " + std::to_string(labels.size()) + " values for " + std::to_string(in.n) + " points");
  for (int a = dim; a < 3; ++a)
    if (options.periodic[static_cast<std::size_t>(a)])
      throw InputError(std::string("periodic axis ") + detail::axis_name(a) + " of " + std::to_string(dim) + "D points");
  if (!options.bounds) throw InputError("a periodic box needs its bounds (the box that repeats)");
  in.periodic = options.periodic;
  in.box = *options.bounds;
  for (int a = 0; a < dim; ++a) {
    const auto au = static_cast<std::size_t>(a);
    if (!std::isfinite(in.box.lo[au]) || !std::isfinite(in.box.hi[au]) || !(in.box.lo[au] < in.box.hi[au]))
      throw InputError(std::string("bounds along ") + detail::axis_name(a) + " must be finite with lo < hi, not [" +
                       num(in.box.lo[au]) + ", " + num(in.box.hi[au]) + "]");
    in.length[au] = in.box.hi[au] - in.box.lo[au];
    if (!std::isfinite(in.length[au])) throw InputError("the periodic box's extent overflows double");
  }
  // Tilts: tilt t (xy, xz, yz) is lattice[hi][lo], a shear of axis lo by axis hi.
  static constexpr int tilt_lo[3] = {0, 0, 1}, tilt_hi[3] = {1, 2, 2};
  static constexpr const char* tilt_name[3] = {"xy", "xz", "yz"};
  for (std::size_t t = 0; t < 3; ++t) {
    const double v = options.tilt[t];
    if (v == 0) continue;
    const auto lo = static_cast<std::size_t>(tilt_lo[t]), hi = static_cast<std::size_t>(tilt_hi[t]);
    if (!std::isfinite(v)) throw InputError(std::string("tilt ") + tilt_name[t] + " must be finite, not " + num(v));
    if (static_cast<int>(hi) >= dim) throw InputError(std::string("tilt ") + tilt_name[t] + " of 2D points (only xy)");
    if (!in.periodic[lo] || !in.periodic[hi])
      throw InputError(std::string("tilt ") + tilt_name[t] + " needs " + detail::axis_name(tilt_lo[t]) + " and " +
                       detail::axis_name(tilt_hi[t]) + " periodic (a tilted wall is not supported)");
    // The fractional coordinates' rounding stays far below fraction_slack.
    if (!(std::fabs(v) <= 0x1p10 * in.length[lo]))
      throw InputError(std::string("tilt ") + tilt_name[t] + " " + num(v) + " is over 1024 box lengths along " +
                       detail::axis_name(tilt_lo[t]) + "; reduce it by whole box lengths (the same lattice)");
  }
  const std::array<double, 3> tilt = reduced_tilts(options.tilt, in.length);
  in.sheared = tilt[0] != 0 || tilt[1] != 0 || tilt[2] != 0;
  // The extreme radii of power cells (0 without radii): r_max^2 - r_min^2
  // bounds their slack (below, in the geometry's frame).
  double rmin = 0, rmax = 0;
  if (!options.radii.empty() && options.radii.size() == in.n) {
    const auto [lo_r, hi_r] = std::minmax_element(options.radii.begin(), options.radii.end());
    rmin = *lo_r;
    rmax = *hi_r;
  }

  // The grid along each periodic axis, with the box and tilts rounded to it.
  // Multiples of g below 2^(e+1) are doubles; every image's coordinate
  // (a point of the box plus at most max_shift lattice vectors, each term a
  // multiple of g) and every step of the wrap stay below that, so all are
  // exact. max_shift follows the cap, which follows the rounded box: rounded
  // again on a coarser grid until the grid suffices (twice at most, but for
  // boxes of a few grid steps).
  std::array<double, 3> grid{0, 0, 0};
  const Bounds given = in.box;
  for (int attempt = 0;; ++attempt) {
    in.box = given;
    in.tilt = tilt;
    for (std::size_t a = 0; a < du; ++a) {
      if (grid[a] == 0) continue;
      in.box.lo[a] = snap(given.lo[a], grid[a]);
      in.box.hi[a] = snap(given.hi[a], grid[a]);
      if (!(in.box.lo[a] < in.box.hi[a])) throw InputError("the periodic box is too thin for its coordinates");
    }
    for (std::size_t t = 0; t < 3; ++t)
      if (grid[static_cast<std::size_t>(tilt_lo[t])] != 0)
        in.tilt[t] = snap(in.tilt[t], grid[static_cast<std::size_t>(tilt_lo[t])]);
    for (std::size_t a = 0; a < du; ++a) in.length[a] = in.box.hi[a] - in.box.lo[a];  // exact on the grid
    for (std::size_t a = 0; a < 3; ++a) {
      in.lattice[a] = {0, 0, 0};
      in.lattice[a][a] = a < du ? in.length[a] : 1.0;
    }
    for (std::size_t t = 0; t < 3; ++t)
      in.lattice[static_cast<std::size_t>(tilt_hi[t])][static_cast<std::size_t>(tilt_lo[t])] = in.tilt[t];
    // The box's geometry in the frame scaled by `to` (geometry_exponent):
    // lattice vectors v and lengths l there, results scaled back by `back`.
    const int e = geometry_exponent(in);
    const double to = std::ldexp(1.0, -e), back = std::ldexp(1.0, e);
    std::array<std::array<double, 3>, 3> v{};
    std::array<double, 3> l{};
    for (std::size_t i = 0; i < 3; ++i) {
      for (std::size_t a = 0; a < 3; ++a) v[i][a] = i < du ? in.lattice[i][a] * to : in.lattice[i][a];
      l[i] = i < du ? in.length[i] * to : 1.0;
    }
    if (in.sheared) {
      const double volume = l[0] * l[1] * v[2][2];
      for (std::size_t i = 0; i < 3; ++i) {
        const auto& p = v[(i + 1) % 3];
        const auto& q = v[(i + 2) % 3];
        const double area = std::hypot(p[1] * q[2] - p[2] * q[1], p[2] * q[0] - p[0] * q[2], p[0] * q[1] - p[1] * q[0]);
        in.height[i] = volume / area * back;
      }
    } else {
      in.height = in.length;
    }
    // A cell lies within the half-spaces |y.v| <= |v|^2 / 2 of its point's
    // images one lattice vector v away (y relative to the point) and within
    // the walls along the others. Along periodic axes, lower triangular
    // lattice vectors bound |y_a| by forward substitution (the box about the
    // point, L_a / 2, when orthogonal); along walls by the box's extent. The
    // security sphere (twice the farthest vertex) reaches at most `cap`.
    // (In the scaled frame: bound and r2 as the text says, times `to`.)
    std::array<double, 3> bound{0, 0, 0};
    double r2 = 0;
    for (std::size_t a = 0; a < du; ++a) {
      if (!in.periodic[a]) {
        bound[a] = l[a];
      } else if (!in.sheared) {
        bound[a] = 0.5 * l[a];
      } else {
        const auto& va = v[a];
        double s = 0.5 * (va[0] * va[0] + va[1] * va[1] + va[2] * va[2]);
        for (std::size_t b = 0; b < a; ++b) s += std::fabs(va[b]) * bound[b];
        bound[a] = s / l[a] * (1 + 0x1p-40);
      }
      r2 += bound[a] * bound[a];
    }
    // Power cells (radii): a vertex's petal reaches sqrt(|y|^2 + slack)
    // beyond it (kernels/power.hpp), slack at most r_max^2 - r_min^2; the
    // bound on |y| holds as it is (a point's own images have its radius, so
    // their planes are the bisectors). Without radii, twice sqrt(r2) exactly.
    const double radii_spread = kernels::power_slack(rmax * to, rmin * to);
    const double cap = (std::sqrt(r2) + std::sqrt(r2 + radii_spread)) * (1 + 0x1p-20) * back;
    // An image within the cap of a point of the box lies within cap / h
    // lattice vectors along each (one more for a triclinic box's rounded
    // fractional coordinates).
    const int extra = in.sheared ? 1 : 0;
    for (std::size_t a = 0; a < du; ++a) {
      if (!in.periodic[a]) continue;
      // Shifts are int8 (Cells::neighbor_shifts). A box whose walls are more
      // than ~60 periods long may ask for more than 127 only where its cells
      // are that long (a few points): the driver then reports it.
      const double k = std::min(std::ceil(cap / in.height[a]) + extra, double{max_periodic_shift});
      in.max_shift[a] = static_cast<int>(k);
      in.reach_cap[a] = std::min(cap, (k - extra) * in.height[a]);
      in.reach_clamped[a] = in.reach_cap[a] < cap;
    }
    // The grid each periodic axis needs: the box's range along it (the
    // parallelepiped's, triclinic) plus max_shift of each lattice vector's
    // component there; the margin covers the box's own rounding (g / 2 of
    // m's 2^-52) and the wrap's steps (within one lattice vector of the box).
    bool enough = true;
    for (std::size_t a = 0; a < du; ++a) {
      if (!in.periodic[a]) continue;
      double lo = in.box.lo[a], hi = in.box.hi[a], shifts = 0;
      for (std::size_t i = a + 1; i < du; ++i) {
        lo += std::min(0.0, in.lattice[i][a]);
        hi += std::max(0.0, in.lattice[i][a]);
      }
      for (std::size_t i = 0; i < du; ++i)
        if (in.periodic[i]) shifts += in.max_shift[i] * std::fabs(in.lattice[i][a]);
      const double m = (std::max(std::fabs(lo), std::fabs(hi)) + shifts) * (1 + 0x1p-40);
      if (!std::isfinite(m)) throw InputError("the periodic box's images overflow double; scale the input down");
      const double g = std::ldexp(1.0, std::max(std::ilogb(m) - 52, -1074));
      if (g > grid[a]) {
        grid[a] = g;
        enough = false;
      }
    }
    if (enough) break;
    if (attempt == 8) throw InputError("the periodic box is too thin for its coordinates");
  }
  in.grid = grid;

  in.points.assign(points.begin(), points.end());
  in.takes_part.assign(in.n, 1);
  for (std::size_t i = 0; i < in.n; ++i) {
    double* p = in.points.data() + i * du;
    if (!finite_point(in.points, i, dim)) {
      if (!options.ignore_outside_points)
        throw InputError("point " + std::to_string(i) +
                         " has a NaN or infinite coordinate (ignore_outside sets such points aside)");
      in.takes_part[i] = 0;
      in.ignored.push_back(static_cast<std::int32_t>(i));
      continue;
    }
    for (std::size_t a = 0; a < du && in.takes_part[i]; ++a) {
      if (!in.periodic[a] && (p[a] < in.box.lo[a] || p[a] > in.box.hi[a])) {
        if (!options.ignore_outside_points) {
          const std::string axis = detail::axis_name(static_cast<int>(a));
          throw InputError("point " + std::to_string(i) + " lies outside the bounds: " + axis + " = " +
                           detail::number_text(p[a]) + " is not in [" + detail::number_text(in.box.lo[a]) + ", " +
                           detail::number_text(in.box.hi[a]) + "], and " + axis +
                           " is not periodic (use --ignore-outside to drop such points)");
        }
        in.takes_part[i] = 0;
        in.ignored.push_back(static_cast<std::int32_t>(i));
      }
    }
    if (!in.takes_part[i]) continue;
    // Wrapped into the box, last axis first: the lattice vector along axis a
    // moves the axes below it too (by the tilts), which are wrapped after.
    // Along an axis the box starts at lo + sum of f_b times the tilts of the
    // axes b above (their fractional coordinates, now final): exactly lo
    // when orthogonal, else up to rounding (the layer's slack covers it).
    for (std::size_t a = du; a-- > 0;) {
      if (!in.periodic[a]) continue;
      const double len = in.length[a];
      double start = in.box.lo[a];
      if (in.sheared) {
        double f[3];
        fractional(in, p, f);
        for (std::size_t b = a + 1; b < du; ++b) start += f[b] * in.lattice[b][a];
      }
      auto step = [&](double k) {  // p -= k lattice[a] (exact on axis a once on the grid)
        p[a] -= k * len;
        for (std::size_t b = 0; b < a; ++b) p[b] -= k * in.lattice[a][b];
      };
      // Nearly, in floating point, where it lies a period or more out; then
      // rounded to the grid, where the last steps of a period are exact.
      double off = p[a] - start;
      if (off < -len || off >= 2 * len) {
        // fmod is exact: the error is only that of the offset, the point's
        // own imprecision at that distance.
        if (!std::isfinite(off))
          throw InputError("point " + std::to_string(i) + " lies too far from the periodic box to be wrapped into it");
        double r = std::fmod(off, len);
        if (r < 0) r += len;
        const double k = std::nearbyint((off - r) / len);
        for (std::size_t b = 0; b < a; ++b) p[b] -= k * in.lattice[a][b];
        p[a] = start + r;
      }
      p[a] = snap(p[a], in.grid[a]);
      while (p[a] - start >= len) step(1);
      while (p[a] - start < 0) step(-1);
      for (std::size_t b = 0; b < a; ++b)
        if (!std::isfinite(p[b]))
          throw InputError("point " + std::to_string(i) + " lies too far from the periodic box to be wrapped into it");
    }
  }
  if (in.ignored.size() == in.n) throw InputError("all points lie outside the bounds");
  std::sort(in.ignored.begin(), in.ignored.end());
  in.ignored.erase(std::unique(in.ignored.begin(), in.ignored.end()), in.ignored.end());
  return in;
}

void fractional(const PeriodicInput& in, const double* p, double f[3]) {
  const auto du = static_cast<std::size_t>(in.dim);
  f[0] = f[1] = f[2] = 0;
  for (std::size_t a = du; a-- > 0;) {
    double x = p[a] - in.box.lo[a];
    for (std::size_t b = a + 1; b < du; ++b) x -= f[b] * in.lattice[b][a];
    f[a] = x / in.length[a];
  }
}

PeriodicImages periodic_images(const PeriodicInput& in, std::span<const std::int32_t> labels,
                               const std::array<double, 3>& width, int threads) {
  const int dim = in.dim;
  const auto du = static_cast<std::size_t>(dim);
  PeriodicImages im;
  im.domain = in.box;
  std::array<int, 3> k{0, 0, 0};  // the largest shift per axis
  std::array<double, 3> lo_f{0, 0, 0}, hi_f{1, 1, 1};  // triclinic: the layer in fractional coordinates
  const int extra = in.sheared ? 1 : 0;                // (PeriodicInput::max_shift)
  for (std::size_t a = 0; a < du; ++a) {
    if (!in.periodic[a]) continue;
    const double w = std::min(width[a], in.reach_cap[a]);
    im.width[a] = w;
    im.domain.lo[a] = in.box.lo[a] - w;
    im.domain.hi[a] = in.box.hi[a] + w;
    k[a] = std::min(in.max_shift[a], static_cast<int>(std::ceil(w / in.height[a])) + extra);
    lo_f[a] = -w / in.height[a] - fraction_slack;
    hi_f[a] = 1 + w / in.height[a] + fraction_slack;
  }
  if (in.sheared) {
    // The bounding box of the parallelepiped's layer (with the slack twice
    // and a margin for the rounding): every image lies in it. The offsets
    // from the corner are summed apart from it, and the margin counts the
    // corner's own rounding too: far from the origin (a box 0.2 wide at
    // 1e14, where an ulp is 0.016) the sum with the corner rounded by more
    // than the offsets' margin, an image fell outside, and the pass
    // reported "point 24890 lies outside the bounds" (a hostile-input fuzz).
    for (std::size_t a = 0; a < du; ++a) {
      if (!in.periodic[a]) continue;
      double lo = 0, hi = 0, size = 0;
      for (std::size_t i = 0; i < du; ++i) {
        const double v = in.lattice[i][a];
        const double f0 = lo_f[i] - fraction_slack, f1 = hi_f[i] + fraction_slack;
        lo += std::min(f0 * v, f1 * v);
        hi += std::max(f0 * v, f1 * v);
        size += (f1 - f0) * std::fabs(v);
      }
      const double corner = in.box.lo[a];
      const double margin = 0x1p-30 * size + 4 * std::numeric_limits<double>::epsilon() *
                                                 (std::fabs(corner) + std::fabs(lo) + std::fabs(hi));
      im.domain.lo[a] = corner + lo - margin;
      im.domain.hi[a] = corner + hi + margin;
    }
  }
  // The images a layer may hold: 64 per point, and 2^20 more for boxes of
  // a few points (ten points in a cube hold ~100 each; 1M uniform points
  // ~1.1). A box whose heights are tiny next to its cells takes up to 127
  // lattice vectors along each axis: a slab a millionth as thick as wide,
  // sheared so that its third vector lies nearly in the slab's plane, has
  // every height tiny, and its 300 points asked for ~5e9 images (51 GB)
  // before the allocation failed. Refused before the shifts are walked, by
  // the count the walk would reach, and after it, by the count itself.
  // (2^24 let 30 points in a box 2e16 long and 3 wide take ~6e6 images,
  // whose cells, each reaching across them all, ran for minutes; and tilts
  // of 1000 box lengths took 3 GB before the reach was refused: a fuzz of
  // the Python module.)
  const std::size_t taking = in.n - in.ignored.size();
  const double image_budget = 64.0 * static_cast<double>(taking) + 0x1p20;
  // The message names the cells' reach in box heights and the three ways to
  // get there: a cubic box whose points fill a thousandth of it (a blob in
  // a void) was said to be "far thinner than wide".
  double reach = 0;
  for (std::size_t a = 0; a < du; ++a)
    if (in.periodic[a]) reach = std::max(reach, im.width[a] / in.height[a]);
  auto refuse_images = [&](double count) {
    throw InputError("the periodic box would need ~" + num(count) + " images of its " + std::to_string(taking) +
                     " points: its cells reach ~" + short_num(reach) +
                     " box heights (distances between opposite faces) across it (points gathered in a small part of "
                     "the box, whose outer cells span it; a box far thinner than wide; or one sheared nearly flat); "
                     "spread the points over the box, or give a thicker or less sheared box of the same lattice");
  };
  double walked = static_cast<double>(taking);
  for (std::size_t a = 0; a < du; ++a) walked *= 2.0 * k[a] + 1;
  if (walked > 8 * image_budget) refuse_images(walked);
  // Shifts in lexicographic order (x, then y, then z), shift 0 among them
  // (periodic.hpp: the perturbation's order).
  std::vector<std::array<int, 3>> shifts;
  for (int s0 = -k[0]; s0 <= k[0]; ++s0)
    for (int s1 = -k[1]; s1 <= k[1]; ++s1)
      for (int s2 = -k[2]; s2 <= k[2]; ++s2) shifts.push_back({s0, s1, s2});
  // Point i's images in the layer, in shift order: f(shift, image).
  auto for_each_image = [&](std::size_t i, auto&& f) {
    if (!in.takes_part[i]) return;
    const double* p = in.points.data() + i * du;
    if (!in.sheared) {
      for (const auto& s : shifts) {
        double y[3] = {0, 0, 0};
        bool inside = true;
        for (std::size_t a = 0; a < du && inside; ++a) {
          y[a] = p[a] + s[a] * in.length[a];  // exact (PeriodicInput's grid)
          inside = y[a] >= im.domain.lo[a] && y[a] <= im.domain.hi[a];
        }
        if (inside) f(s, y);
      }
      return;
    }
    // The test is one per axis in fractional coordinates: the shifts in
    // the layer are a box, walked in the same lexicographic order.
    double fp[3];
    fractional(in, p, fp);
    std::array<int, 3> first{0, 0, 0}, last{0, 0, 0};
    for (std::size_t a = 0; a < du; ++a) {
      if (!in.periodic[a]) continue;
      first[a] = -k[a];
      last[a] = k[a];
      while (first[a] <= last[a] && !(fp[a] + first[a] >= lo_f[a])) ++first[a];
      while (last[a] >= first[a] && !(fp[a] + last[a] <= hi_f[a])) --last[a];
    }
    std::array<int, 3> s{};
    for (s[0] = first[0]; s[0] <= last[0]; ++s[0])
      for (s[1] = first[1]; s[1] <= last[1]; ++s[1])
        for (s[2] = first[2]; s[2] <= last[2]; ++s[2]) {
          double y[3] = {0, 0, 0};
          periodic_image(in.lattice, dim, p, s, y);  // exact: every term on the grid, within its range
          f(s, y);
        }
  };
  // Counted, then written at their offsets, one block of points per task:
  // the same array for any thread count.
  std::vector<std::size_t> first(in.n + 1, 0);
  engine::ThreadArena arena(threads);
  arena.execute([&] {
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, in.n, 4096), [&](const tbb::blocked_range<std::size_t>& r) {
      for (std::size_t i = r.begin(); i != r.end(); ++i)
        for_each_image(i, [&](const std::array<int, 3>&, const double*) { ++first[i + 1]; });
    });
  });
  std::partial_sum(first.begin(), first.end(), first.begin());
  const std::size_t m = first.back();
  if (static_cast<double>(m) > image_budget) refuse_images(static_cast<double>(m));
  if (m > static_cast<std::size_t>(INT32_MAX - 1))
    throw InputError("too many points with their periodic images (ids are 32-bit)");
  im.original.assign(in.n, -1);
  im.base.resize(m);
  im.points.resize(m * du);
  im.shift.resize(m * du);
  im.labels.resize(m);
  im.images = m - (in.n - in.ignored.size());
  arena.execute([&] {
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, in.n, 4096), [&](const tbb::blocked_range<std::size_t>& r) {
      for (std::size_t i = r.begin(); i != r.end(); ++i) {
        std::size_t at = first[i];
        for_each_image(i, [&](const std::array<int, 3>& s, const double* y) {
          const bool zero = s[0] == 0 && s[1] == 0 && s[2] == 0;
          if (zero) im.original[i] = static_cast<std::int32_t>(at);
          im.base[at] = static_cast<std::int32_t>(i);
          for (std::size_t a = 0; a < du; ++a) {
            im.points[at * du + a] = y[a];
            im.shift[at * du + a] = static_cast<std::int8_t>(s[a]);
          }
          im.labels[at] = zero ? (labels.empty() ? 0 : labels[i]) : -1;
          ++at;
        });
      }
    });
  });
  return im;
}

std::array<double, 3> initial_image_reach(const PeriodicInput& in) {
  // The volume in the frame of geometry_exponent (a box 1e-191 wide has
  // none in doubles, one 1e120 wide an infinite one).
  const int e = geometry_exponent(in);
  double volume = 1;
  for (int a = 0; a < in.dim; ++a) volume *= std::ldexp(in.length[static_cast<std::size_t>(a)], -e);
  const double taking = static_cast<double>(in.n - in.ignored.size());
  const double spacing = std::ldexp(std::pow(volume / taking, 1.0 / in.dim), e);
  // Four spacings: uniform points (20k, 200k and 1M, 2D and 3D) needed no
  // wider layer; at 3.5 one 2D cell of 20k asked for 4.0.
  const double w = 4.0 * spacing;
  std::array<double, 3> width{0, 0, 0};
  for (std::size_t a = 0; a < 3; ++a)
    if (in.periodic[a]) width[a] = std::isfinite(w) ? std::min(w, in.reach_cap[a]) : in.reach_cap[a];
  return width;
}

std::array<double, 3> needed_image_reach(const PeriodicInput& in, const PeriodicImages& im,
                                         std::span<const double> reach) {
  const auto du = static_cast<std::size_t>(in.dim);
  std::array<double, 3> need{0, 0, 0};
  for (std::size_t g = 0; g < reach.size(); ++g) {
    const double r = reach[g];
    if (r == 0) continue;  // no cell (an image, a duplicate); NaN (unbounded) goes on
    const double* p = im.points.data() + g * du;
    double f[3] = {0, 0, 0};
    if (in.sheared) fractional(in, p, f);
    for (std::size_t a = 0; a < du; ++a) {
      if (!in.periodic[a]) continue;
      // How far the security sphere reaches past the box's faces along a:
      // across the parallelepiped's, triclinic, plus the layer's slack
      // (which its test took on the other side: periodic.hpp).
      const double beyond =
          in.sheared ? std::max(-f[a], f[a] - 1) * in.height[a] + r + 2 * fraction_slack * in.height[a]
                     : std::max(in.box.lo[a] - (p[a] - r), (p[a] + r) - in.box.hi[a]);
      need[a] = beyond <= need[a] ? need[a] : beyond;  // NaN too: unbounded, below
    }
  }
  for (double& n : need) n = n >= 0 ? n : std::numeric_limits<double>::infinity();  // NaN: unbounded
  return need;
}

void to_points(const PeriodicImages& im, int dim, std::span<std::int32_t> ids, std::span<std::int8_t> shifts,
               int threads) {
  const auto du = static_cast<std::size_t>(dim);
  engine::ThreadArena(threads).execute([&] {
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, ids.size(), 16384), [&](const tbb::blocked_range<std::size_t>& r) {
      for (std::size_t e = r.begin(); e != r.end(); ++e) {
        const auto j = static_cast<std::size_t>(ids[e]);
        ids[e] = im.base[j];
        for (std::size_t a = 0; a < du; ++a) shifts[e * du + a] = im.shift[j * du + a];
      }
    });
  });
}

std::vector<std::pair<std::int32_t, std::int32_t>> duplicates_as_points(
    const PeriodicImages& im, std::span<const std::pair<std::int32_t, std::int32_t>> duplicates) {
  std::vector<std::pair<std::int32_t, std::int32_t>> out;
  out.reserve(duplicates.size());
  for (const auto& [d, owner] : duplicates)
    out.emplace_back(im.base[static_cast<std::size_t>(d)], im.base[static_cast<std::size_t>(owner)]);
  std::sort(out.begin(), out.end());
  return out;
}

Cells periodic_cells(Cells&& aug, const PeriodicInput& in, const PeriodicImages& im,
                     std::span<const std::int32_t> labels, int threads) {
  const int dim = in.dim;
  const auto du = static_cast<std::size_t>(dim);
  Cells out;
  describe_box(in, out);
  out.periodic_images = im.images;
  out.image_reach = im.width;
  auto base = [&](std::int32_t id) { return id < 0 ? id : im.base[static_cast<std::size_t>(id)]; };
  const std::size_t nc = aug.n_cells();
  // Element-wise maps over the outputs, in blocks on the caller's threads.
  engine::ThreadArena arena(threads);
  auto each = [&](std::size_t n, auto&& f) {
    arena.execute([&] {
      tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n, 16384), [&](const tbb::blocked_range<std::size_t>& r) {
        for (std::size_t k = r.begin(); k != r.end(); ++k) f(k);
      });
    });
  };

  // Per cell: every cell is a point's own (images own none), in the order
  // of the points, as the augmented ids keep it.
  out.generator = std::move(aug.generator);
  each(nc, [&](std::size_t c) { out.generator[c] = base(out.generator[c]); });
  out.region = std::move(aug.region);
  out.volume = std::move(aug.volume);
  out.centroid = std::move(aug.centroid);
  out.num_faces = std::move(aug.num_faces);
  out.cell_of.assign(in.n, -1);
  for (std::size_t c = 0; c < nc; ++c) out.cell_of[static_cast<std::size_t>(out.generator[c])] = static_cast<std::int32_t>(c);

  // Neighbours: (point, shift), ascending.
  out.neighbor_offsets = std::move(aug.neighbor_offsets);
  out.neighbors = std::move(aug.neighbors);
  out.neighbor_shifts.resize(out.neighbors.size() * du);
  to_points(im, dim, out.neighbors, out.neighbor_shifts, threads);  // ascending by (point, shift)

  // The mesh: keys and faces by the points' ids; classes by their labels.
  if (!aug.vertex_keys.empty() || !aug.cell_face_offsets.empty()) {
    out.vertices = std::move(aug.vertices);
    out.vertex_keys = std::move(aug.vertex_keys);
    out.vertex_key_shifts.resize(out.vertex_keys.size() * du);
    each(out.vertex_keys.size() / (du + 1), [&](std::size_t v) {
      // (id, shift) per entry, ascending; a box plane (a wall) has shift 0.
      std::int32_t* key = out.vertex_keys.data() + v * (du + 1);
      std::int8_t* key_shift = out.vertex_key_shifts.data() + v * (du + 1) * du;
      std::array<std::pair<std::int32_t, std::array<std::int8_t, 3>>, 4> e{};
      for (std::size_t d = 0; d <= du; ++d) {
        e[d].first = base(key[d]);
        if (key[d] >= 0)
          for (std::size_t a = 0; a < du; ++a) e[d].second[a] = im.shift[static_cast<std::size_t>(key[d]) * du + a];
      }
      std::sort(e.begin(), e.begin() + static_cast<std::ptrdiff_t>(du) + 1);
      for (std::size_t d = 0; d <= du; ++d) {
        key[d] = e[d].first;
        for (std::size_t a = 0; a < du; ++a) key_shift[d * du + a] = e[d].second[a];
      }
    });
    out.cell_face_offsets = std::move(aug.cell_face_offsets);
    out.face_vertex_offsets = std::move(aug.face_vertex_offsets);
    out.face_vertices = std::move(aug.face_vertices);
    out.face_neighbor = std::move(aug.face_neighbor);
    out.face_class = std::move(aug.face_class);
    out.face_shift.resize(out.face_neighbor.size() * du);
    const engine::RegionClassifier classify(labels);
    each(nc, [&](std::size_t c) {
      for (auto f = out.cell_face_offsets[c]; f < out.cell_face_offsets[c + 1]; ++f) {
        const auto fu = static_cast<std::size_t>(f);
        const std::int32_t j = out.face_neighbor[fu];
        for (std::size_t a = 0; a < du; ++a)
          out.face_shift[fu * du + a] = j < 0 ? std::int8_t{0} : im.shift[static_cast<std::size_t>(j) * du + a];
        out.face_neighbor[fu] = base(j);
        out.face_class[fu] = classify(out.generator[c], out.face_neighbor[fu]);
      }
    });
  }

  out.duplicates = duplicates_as_points(im, aug.duplicates);
  out.power = aug.power;
  for (const std::int32_t e : aug.empty_cells) out.empty_cells.push_back(base(e));
  std::sort(out.empty_cells.begin(), out.empty_cells.end());
  out.exact_predicate_calls = aug.exact_predicate_calls;
  out.far_points = aug.far_points;
  out.threads_used = aug.threads_used;
  out.from_insertion = aug.from_insertion;
  out.assembled_from_stars = aug.assembled_from_stars;
  out.cells_from_pilot = aug.cells_from_pilot;
  return out;
}

}  // namespace tessera::front

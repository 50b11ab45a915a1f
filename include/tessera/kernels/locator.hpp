// Static uniform bin grid over the domain box (VTK's static point locator).
//
// Points are sorted by bin (counting sort, stable in point id), with CSR
// offsets per bin and a copy of the coordinates in bin order so the neighbour
// search streams through memory. Bins are near-cubic: one target edge length,
// rounded per axis to divide the grid's box exactly.
//
// The grid's box is the domain box, except along an axis where a few far
// outliers stretch the box to more than four times the bulk of the points
// (grid_box): there the grid spans the bulk alone, and its first and last
// bins reach on to the box's faces. One stray point at x = 1000 beside a
// million in the unit cube would otherwise leave the cube in one or two
// bins, every cell scanning them. Edge bins are unbounded outward in every
// bound below (bin_distance2, shell_lower_bound, the shells' gap tables):
// a point in one may lie anywhere beyond its nominal face.
#pragma once

#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <functional>
#include <limits>
#include <span>
#include <utility>
#include <vector>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_reduce.h>
#include <tbb/task_arena.h>

#include "tessera/buffer.hpp"

namespace tessera::kernels {

template <int D>
class BinLocator {
 public:
  using Point = std::array<double, D>;

  /// Bin the points of `coords` (n*D, row-major) whose `use[id]` is true (all
  /// when `use` is empty) inside the box [lo, hi]; points must lie in the box.
  /// `points_per_bin` sets the mean occupancy the bin size aims for.
  BinLocator(std::span<const double> coords, std::span<const std::uint8_t> use, const Point& lo,
             const Point& hi, double points_per_bin) {
    const std::size_t n = coords.size() / D;
    std::size_t used = use.empty() ? n : static_cast<std::size_t>(std::count(use.begin(), use.end(), 1));
    const double target_bins = std::max(1.0, static_cast<double>(used) / std::max(points_per_bin, 0.05));
    Point glo = lo, ghi = hi;  // the grid's box
    grid_box(coords, use, glo, ghi);
    // Cubic bins of the size that gives target_bins over the box. An axis
    // thinner than half that size gets one division, and the size is chosen
    // again over the other axes: a slab 1e-8 thick would otherwise get bins
    // sized for a volume density, hundreds across its wide axes per point,
    // and every cell would walk thousands of empty bins.
    std::array<bool, D> thin{};
    double h = 0;
    for (int round = 0; round < D; ++round) {
      double vol = 1;
      int wide = 0;
      for (int d = 0; d < D; ++d)
        if (!thin[d]) {
          vol *= ghi[d] - glo[d];
          ++wide;
        }
      if (wide == 0) break;
      h = std::pow(vol / target_bins, 1.0 / wide);
      if (!(vol >= std::numeric_limits<double>::min() && vol <= std::numeric_limits<double>::max())) {
        // The product left double's range: a grid spanning the bulk of
        // points whose outliers lie 1e200 away is scaled (front/pass.cpp)
        // so that the bulk's volume underflows, and a zero h made
        // 16k^3 bins. The same size by logarithms.
        double log_vol = 0;
        for (int d = 0; d < D; ++d)
          if (!thin[d]) log_vol += std::log(ghi[d] - glo[d]);
        h = std::exp((log_vol - std::log(target_bins)) / wide);
      }
      bool again = false;
      for (int d = 0; d < D; ++d)
        if (!thin[d] && std::round((ghi[d] - glo[d]) / h) < 1) thin[d] = again = true;
      if (!again) break;
    }
    std::size_t total = 1;
    for (int d = 0; d < D; ++d) {
      lo_[d] = glo[d];
      hi_[d] = ghi[d];
      double extent = ghi[d] - glo[d];
      // Cap each axis so the grid stays proportionate to the point count.
      double divs = thin[d] ? 1.0 : std::clamp(std::round(extent / h), 1.0, 1.0 + 4.0 * static_cast<double>(used));
      divs_[d] = static_cast<std::int32_t>(std::min(divs, 1e6));
      size_[d] = extent / divs_[d];
      inv_size_[d] = 1.0 / size_[d];
      total *= static_cast<std::size_t>(divs_[d]);
    }
    min_size_ = *std::min_element(size_.begin(), size_.end());
    for (int d = 0; d < D; ++d) slack_ = std::max({slack_, std::fabs(glo[d]), std::fabs(ghi[d])});
    slack_ *= 8 * std::numeric_limits<double>::epsilon();
    // Counting sort by bin, stable in id, so the order is deterministic and
    // independent of the thread count. In parallel, in the caller's arena:
    // the ids are cut into contiguous chunks, each chunk counts its bins,
    // and chunk c's points of bin b go after those of bin b in chunks < c.
    // Each used point's bin, and (where the grid spans a bulk) how many lie
    // beyond it, in the same parallel sweep.
    const bool any_core = std::any_of(core_.begin(), core_.end(), [](bool c) { return c; });
    Buffer<std::uint32_t> bin_of(n);  // not zeroed first: every used id's bin is written
    outside_core_ = tbb::parallel_reduce(
        tbb::blocked_range<std::size_t>(0, n, std::size_t{1} << 14), std::size_t{0},
        [&](const tbb::blocked_range<std::size_t>& r, std::size_t beyond) {
          for (std::size_t id = r.begin(); id != r.end(); ++id)
            if (use.empty() || use[id]) {
              bin_of[id] = static_cast<std::uint32_t>(bin_index(bin_coords(&coords[id * D])));
              beyond += any_core && beyond_core(&coords[id * D]);
            }
          return beyond;
        },
        std::plus<>());
    const std::size_t chunks = std::clamp<std::size_t>(
        static_cast<std::size_t>(tbb::this_task_arena::max_concurrency()), 1, std::max<std::size_t>(1, n >> 16));
    std::vector<Buffer<std::uint32_t>> count(chunks);
    auto chunk_range = [&](std::size_t c) { return std::pair{n * c / chunks, n * (c + 1) / chunks}; };
    tbb::parallel_for(std::size_t{0}, chunks, [&](std::size_t c) {
      auto [first, last] = chunk_range(c);
      count[c].assign(total, 0);
      for (std::size_t id = first; id < last; ++id)
        if (use.empty() || use[id]) ++count[c][bin_of[id]];
    });
    // count[c][b] becomes chunk c's first slot in bin b.
    offsets_.assign(total + 1, 0);
    std::uint32_t run = 0;
    for (std::size_t b = 0; b < total; ++b) {
      offsets_[b] = run;
      for (std::size_t c = 0; c < chunks; ++c) {
        const std::uint32_t k = count[c][b];
        count[c][b] = run;
        run += k;
      }
    }
    offsets_[total] = run;
    ids_.resize(used);
    sorted_.resize(used);
    tbb::parallel_for(std::size_t{0}, chunks, [&](std::size_t c) {
      auto [first, last] = chunk_range(c);
      std::uint32_t* fill = count[c].data();
      for (std::size_t id = first; id < last; ++id) {
        if (!use.empty() && !use[id]) continue;
        std::uint32_t k = fill[bin_of[id]]++;
        ids_[k] = static_cast<std::int32_t>(id);
        for (int d = 0; d < D; ++d) sorted_[k][d] = coords[id * D + d];
      }
    });
  }

  /// Whether x lies beyond the grid's box along an axis where that box is
  /// the bulk of the points, not the domain box (see grid_box): an outlier,
  /// held by an edge bin that reaches out to it.
  bool beyond_core(const double* x) const {
    for (int d = 0; d < D; ++d)
      if (core_[d] && !(x[d] >= lo_[d] && x[d] <= core_hi_[d])) return true;
    return false;
  }
  /// The grid's box: the domain box, or along an axis where a few points lie
  /// far out, the bulk of the points (grid_box).
  Point grid_lo() const { return lo_; }
  Point grid_hi() const { return hi_; }
  /// How many located points lie beyond the grid's box (beyond_core).
  std::size_t outside_core() const { return outside_core_; }
  /// Whether the grid spans the bulk of the points, not the domain box,
  /// along some axis (grid_box): the box reaches far beyond the bulk, set
  /// by far points or by explicit bounds.
  bool spans_bulk() const {
    for (const bool c : core_)
      if (c) return true;
    return false;
  }

  std::array<std::int32_t, D> bin_coords(const double* x) const {
    std::array<std::int32_t, D> b;
    for (int d = 0; d < D; ++d) {
      double f = std::floor((x[d] - lo_[d]) * inv_size_[d]);
      b[d] = static_cast<std::int32_t>(std::clamp(f, 0.0, static_cast<double>(divs_[d] - 1)));
    }
    if constexpr (D == 2) {
      // One 8-byte store, not two of 4: GCC reads the pair back as one
      // 8-byte vector (max_shell, vectorized), and a load spanning two
      // narrower stores cannot be forwarded from them: a stall of ~7% of a
      // 2D run on an Intel Xeon (stop 50).
      const std::uint64_t packed =
          static_cast<std::uint32_t>(b[0]) | static_cast<std::uint64_t>(static_cast<std::uint32_t>(b[1])) << 32;
      std::memcpy(b.data(), &packed, sizeof packed);
    }
    return b;
  }
  /// Per axis, the bin coordinates that can hold a point whose coordinate
  /// lies in [lo[d], hi[d]]: [first[d], last[d]]. Exact: binning rounds
  /// monotonically, so a point at or above lo[d] falls in no lower bin.
  void bin_range(const double* lo, const double* hi, std::array<std::int32_t, D>& first,
                 std::array<std::int32_t, D>& last) const {
    first = bin_coords(lo);
    last = bin_coords(hi);
  }
  /// The slots of the bins [first, last] (per axis, inclusive) as one run
  /// per row of bins (rows are contiguous along x): f(begin slot, end slot).
  template <class F>
  void for_each_row_run(const std::array<std::int32_t, D>& first, const std::array<std::int32_t, D>& last,
                        F&& f) const {
    std::array<std::int32_t, D> a = first, e = first;
    e[0] = last[0];
    auto row = [&] { f(offsets_[bin_index(a)], offsets_[bin_index(e) + 1]); };
    if constexpr (D == 2) {
      for (a[1] = e[1] = first[1]; a[1] <= last[1]; e[1] = ++a[1]) row();
    } else {
      for (a[2] = first[2]; a[2] <= last[2]; ++a[2])
        for (a[1] = first[1]; a[1] <= last[1]; ++a[1]) {
          e[1] = a[1];
          e[2] = a[2];
          row();
        }
    }
  }
  /// The number of points in the bins [first, last] (per axis, inclusive):
  /// one subtraction per row of bins.
  std::size_t count_in(const std::array<std::int32_t, D>& first, const std::array<std::int32_t, D>& last) const {
    std::size_t n = 0;
    for_each_row_run(first, last, [&](std::uint32_t a, std::uint32_t e) { n += e - a; });
    return n;
  }
  std::size_t bin_index(const std::array<std::int32_t, D>& b) const {
    std::size_t idx = static_cast<std::size_t>(b[D - 1]);
    for (int d = D - 2; d >= 0; --d) idx = idx * static_cast<std::size_t>(divs_[d]) + static_cast<std::size_t>(b[d]);
    return idx;
  }
  /// Squared distance from x to the box of bin b (0 inside).
  /// Never larger than the true value: bin faces are computed in floating
  /// point while points were binned by a rounded product, so each gap is
  /// shrunk by a few ulp of the box's coordinates.
  /// Edge bins reach outward without bound (the file comment).
  double bin_distance2(const double* x, const std::array<std::int32_t, D>& b) const {
    double s = 0;
    for (int d = 0; d < D; ++d) {
      const auto [blo, bhi] = faces(d, b[d]);
      double g = std::max({0.0, blo - x[d] - slack_, x[d] - bhi - slack_});
      s += g * g;
    }
    return s;
  }
  /// Lower bound on the distance from x (in bin b) to any point in the shell of
  /// Chebyshev radius s >= 1 around b. A bin of the shell differs from b by s
  /// along some axis d, on a side where the grid has a bin s away: it lies
  /// past b's face on that side, with s-1 whole bins of axis d between. So
  /// the bound is the least, over such axes and sides, of the gap from x to
  /// that face plus s-1 bin sizes of that axis. (An edge bin's outer face
  /// has no bin beyond, and x, held there, may lie beyond it.) Per axis, not
  /// with the smallest bin size of all: where one axis is a single bin wide
  /// (a plane of points and one far off it), that size bounded nothing along
  /// the long axis, and every cell walked the column of bins to its end.
  double shell_lower_bound(const double* x, const std::array<std::int32_t, D>& b, int s) const {
    double bound = INFINITY;
    for (int d = 0; d < D; ++d) {
      const double blo = lo_[d] + b[d] * size_[d];
      const double across = std::max(0.0, (s - 1) * size_[d] * (1 - 1e-12));
      if (b[d] - s >= 0) bound = std::min(bound, std::max(0.0, x[d] - blo - slack_) + across);
      if (b[d] + s <= divs_[d] - 1) bound = std::min(bound, std::max(0.0, blo + size_[d] - x[d] - slack_) + across);
    }
    return bound;
  }
  /// The largest shell radius that still touches the grid from bin b.
  int max_shell(const std::array<std::int32_t, D>& b) const {
    int m = 0;
    for (int d = 0; d < D; ++d) m = std::max({m, b[d], divs_[d] - 1 - b[d]});
    return m;
  }

  /// Visit the bins of the shell of Chebyshev radius s around b (clipped to the
  /// grid): f(bin coords, bin index).
  template <class F>
  void for_each_shell_bin(const std::array<std::int32_t, D>& b, int s, F&& f) const {
    auto keep = [](const auto&...) { return true; };
    walk_rows(b, s, keep, keep, [&](std::array<std::int32_t, D> c, int xa, int xb) {
      for (c[0] = xa; c[0] <= xb; ++c[0]) f(c, bin_index(c));
    });
  }

  /// The points of the bins of shell s around b, in the order of
  /// for_each_shell_bin, as runs of consecutive slots: f(first slot, end slot)
  /// (see for_each_shell_run_near).
  template <class F>
  void for_each_shell_run(const std::array<std::int32_t, D>& b, int s, F&& f) const {
    auto keep = [](const auto&...) { return true; };
    walk_rows(b, s, keep, keep, [&](std::array<std::int32_t, D> c, int xa, int xb) { emit_run(c, xa, xb, f); });
  }

  /// The points of the bins of shell s around b whose box lies within squared
  /// distance r2max of x (bins with bin_distance2(x, c) > r2max are skipped),
  /// in the order of for_each_shell_bin, as runs of consecutive slots:
  /// f(first slot, end slot), one call per run of neighbouring bins along x
  /// (bins are numbered x fastest, so their slots are contiguous). Shell 0 is
  /// the bin itself, always visited.
  ///
  /// The per-axis gaps are computed once per shell; a slab or row whose
  /// partial sum already exceeds r2max is skipped whole, which is exact:
  /// rounding is monotone, so the full sum, added in bin_distance2's axis
  /// order, can only be larger. Along a row the gap grows away from x on both
  /// sides, so the near bins form one interval, found from its two ends.
  /// `gaps` is the caller's scratch (one per thread): the locator stays
  /// read-only.
  ///
  /// `range`, when given, also limits the walk to the bins with coordinates
  /// range[0][d] <= c[d] <= range[1][d] (see bin_range): their gaps count as
  /// infinite.
  template <class F>
  void for_each_shell_run_near(const double* x, const std::array<std::int32_t, D>& b, int s, double r2max,
                               std::vector<double>& gaps, F&& f,
                               const std::array<std::int32_t, D>* range = nullptr) const {
    if (s == 0) return for_each_shell_run(b, 0, f);
    const std::size_t w = static_cast<std::size_t>(2 * s + 1);
    gaps.resize(D * w);
    for (int d = 0; d < D; ++d) {
      // Offsets outside the grid are never read (walk_rows clips to it).
      const int olo = std::max(-s, -b[d]), ohi = std::min(s, divs_[d] - 1 - b[d]);
      for (int o = olo; o <= ohi; ++o) {
        const auto [blo, bhi] = faces(d, b[d] + o);
        const double g = std::max(std::max(0.0, blo - x[d] - slack_), x[d] - bhi - slack_);
        const bool out = range != nullptr && (b[d] + o < range[0][d] || b[d] + o > range[1][d]);
        gaps[static_cast<std::size_t>(d) * w + static_cast<std::size_t>(o + s)] =
            out ? std::numeric_limits<double>::infinity() : g * g;
      }
    }
    auto gap2 = [&](int d, int o) { return gaps[static_cast<std::size_t>(d) * w + static_cast<std::size_t>(o + s)]; };
    walk_rows(
        b, s, [&](int o_outer) { return gap2(D - 1, o_outer) <= r2max; },
        [&](int oy, int oz) { return gap2(1, oy) + gap2(2, oz) <= r2max; },
        [&](std::array<std::int32_t, D> c, int xa, int xb) {
          auto near = [&](int cx) {
            double sum = gap2(0, cx - b[0]);
            for (int d = 1; d < D; ++d) sum += gap2(d, c[d] - b[d]);
            return sum <= r2max;
          };
          while (xa <= xb && !near(xa)) ++xa;
          while (xb >= xa && !near(xb)) --xb;
          if (xa <= xb) emit_run(c, xa, xb, f);
        });
  }

  /// Whether two located points coincide exactly (coincident_in_bin over
  /// the bins in parallel, stopping once any thread found a pair). ~2-5 ms
  /// for 1M uniform points on two threads.
  bool has_coincident(std::uint32_t crowded = 32) const {
    std::atomic<bool> found{false};
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, num_bins(), 1 << 12), [&](const tbb::blocked_range<std::size_t>& r) {
      std::vector<std::uint32_t> crowd;
      for (std::size_t k = r.begin(); k != r.end() && !found.load(std::memory_order_relaxed); ++k)
        if (!coincident_in_bin(k, crowded, crowd, [](std::uint32_t, std::uint32_t) { return false; }))
          found.store(true, std::memory_order_relaxed);
    });
    return found.load();
  }

  /// Per slot, the lowest id among the located points at exactly its
  /// coordinates when that is another point's, else -1: each group of
  /// coincident points maps to its first member (coincident_in_bin, bins in
  /// parallel).
  std::vector<std::int32_t> lowest_coincident(std::uint32_t crowded = 32) const {
    std::vector<std::int32_t> lowest(ids_.size(), -1);
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, num_bins(), 1 << 10), [&](const tbb::blocked_range<std::size_t>& r) {
      std::vector<std::uint32_t> crowd;
      for (std::size_t k = r.begin(); k != r.end(); ++k)
        coincident_in_bin(k, crowded, crowd, [&](std::uint32_t slot, std::uint32_t first) {
          lowest[slot] = ids_[first];
          return true;
        });
    });
    return lowest;
  }

  std::size_t num_bins() const { return offsets_.size() - 1; }
  double min_bin_size() const { return min_size_; }
  /// The bins' edge along axis d (edge bins: their nominal extent).
  double bin_size(int d) const { return size_[d]; }
  std::size_t size() const { return ids_.size(); }
  /// Points of bin k are slots offsets()[k] .. offsets()[k+1]).
  const Buffer<std::uint32_t>& offsets() const { return offsets_; }
  std::int32_t id(std::size_t slot) const { return ids_[slot]; }
  const Point& point(std::size_t slot) const { return sorted_[slot]; }
  const std::array<std::int32_t, D>& divisions() const { return divs_; }

 private:
  // Bin k's slots that coincide with an earlier slot (coincident points
  // share a bin): f(slot, the group's first slot, which holds its lowest id,
  // as a bin's slots keep id order), which returns false to stop; returns
  // false when f stopped. A bin of up to `crowded` points is compared
  // pairwise, a fuller one sorted by coordinates, then slot (`crowd`: its
  // scratch).
  template <class F>
  bool coincident_in_bin(std::size_t k, std::uint32_t crowded, std::vector<std::uint32_t>& crowd, F&& f) const {
    const std::uint32_t a = offsets_[k], e = offsets_[k + 1];
    if (e - a <= crowded) {
      for (std::uint32_t i = a + 1; i < e; ++i)
        for (std::uint32_t j = a; j < i; ++j)
          if (sorted_[j] == sorted_[i]) {
            if (!f(i, j)) return false;
            break;
          }
      return true;
    }
    crowd.resize(e - a);
    for (std::uint32_t i = a; i < e; ++i) crowd[i - a] = i;
    std::sort(crowd.begin(), crowd.end(), [&](std::uint32_t x, std::uint32_t y) {
      return sorted_[x] != sorted_[y] ? sorted_[x] < sorted_[y] : x < y;
    });
    std::uint32_t first = crowd[0];
    for (std::size_t m = 1; m < crowd.size(); ++m) {
      if (sorted_[crowd[m]] != sorted_[crowd[m - 1]]) {
        first = crowd[m];
        continue;
      }
      if (!f(crowd[m], first)) return false;
    }
    return true;
  }

  // Bin c's faces along axis d: nominal inside the grid, unbounded outward
  // at its edges (the file comment).
  std::pair<double, double> faces(int d, std::int32_t c) const {
    const double blo = lo_[d] + c * size_[d], bhi = blo + size_[d];
    return {c <= 0 ? -std::numeric_limits<double>::infinity() : blo,
            c >= divs_[d] - 1 ? std::numeric_limits<double>::infinity() : bhi};
  }

  // The grid's box, [glo, ghi] on entry the domain box (see the file
  // comment). Per axis, the bulk of the points is the range from the k-th
  // smallest to the k-th largest coordinate of a sample (every stride-th
  // point, at most 2^13 of them; k = a 256th of the sample), widened by a
  // quarter on each side. It replaces the box's range where it still spans
  // less than a quarter of it: a few points far away, whose cells the k-d
  // tree serves (CellBuilder::searches_tree). Uniform and Gaussian points
  // never qualify (their box spans at most about twice their bulk), and
  // heavy tails rarely reach the cells' search at all (the pass's pilot sends
  // them to insertion). The sample is taken by id, so the grid does not
  // depend on the thread count; any grid gives the same cells.
  void grid_box(std::span<const double> coords, std::span<const std::uint8_t> use, Point& glo, Point& ghi) {
    const std::size_t n = coords.size() / D;
    // At most 2^13 samples (64 KiB): a sample above glibc's mmap threshold
    // (128 KiB) is mmap'd, and freeing it raises that threshold for the
    // rest of the process, so the later passes' mid-sized vectors came from
    // the heap instead: insertion's phases ran 20% slower on clustered 100k.
    const std::size_t stride = std::max<std::size_t>(1, (n + 8191) >> 13);
    std::vector<double> x;
    x.reserve(n / stride + 1);
    for (int d = 0; d < D; ++d) {
      x.clear();
      for (std::size_t id = 0; id < n; id += stride)
        if (use.empty() || use[id]) x.push_back(coords[id * D + static_cast<std::size_t>(d)]);
      if (x.size() < 256) continue;  // too few to tell a bulk from outliers
      const std::size_t k = x.size() / 256;
      std::nth_element(x.begin(), x.begin() + static_cast<std::ptrdiff_t>(k), x.end());
      const double a = x[k];
      const auto top = x.end() - 1 - static_cast<std::ptrdiff_t>(k);
      std::nth_element(x.begin(), top, x.end());
      const double w = *top - a;
      const double clo = std::max(glo[d], a - 0.25 * w), chi = std::min(ghi[d], *top + 0.25 * w);
      if (!(w > 0) || !(chi - clo < 0.25 * (ghi[d] - glo[d]))) continue;
      glo[d] = clo;  // becomes lo_
      ghi[d] = core_hi_[d] = chi;
      core_[d] = true;
    }
  }

  // The slots of bins xa..xb of the row of c: contiguous, as bins are numbered x fastest.
  template <class F>
  void emit_run(std::array<std::int32_t, D> c, int xa, int xb, F&& f) const {
    c[0] = xa;
    const std::size_t k = bin_index(c);
    f(offsets_[k], offsets_[k + static_cast<std::size_t>(xb - xa) + 1]);
  }

  // The one shell walk behind the visitors: the shell's surface row by row
  // (z, then y), each row as intervals of x bin coordinates: the whole row
  // (clipped to the grid) on the shell's z and y faces, else its two x-face
  // bins one at a time. f(bin coords with y, z set, first x, last x).
  // near_outer(offset along the last axis) and near_row (y and z offsets, 3D
  // only) may skip a slab or a row.
  template <class Outer, class Row, class F>
  void walk_rows(const std::array<std::int32_t, D>& b, int s, Outer&& near_outer, Row&& near_row, F&& f) const {
    if (s == 0) { f(b, b[0], b[0]); return; }
    std::array<std::int32_t, D> c = b;
    auto walk_x = [&](bool surface) {
      if (surface) {
        const int xa = std::max(b[0] - s, 0), xb = std::min(b[0] + s, divs_[0] - 1);
        if (xa <= xb) f(c, xa, xb);
        return;
      }
      if (b[0] - s >= 0) f(c, b[0] - s, b[0] - s);
      if (b[0] + s < divs_[0]) f(c, b[0] + s, b[0] + s);
    };
    // The offsets along z and y run over the grid only: a shell far wider
    // than a thin axis of the grid (a column of bins, one wide across) then
    // costs its bins, not s^2 empty rows. A plane of 741 points and one 1e6
    // above it: every cell's security radius reaches ~185 shells up such a
    // column; the search took 13 s, 0.75 s with this clipping alone, and
    // 0.32 s with shell_lower_bound's per-axis bound too.
    const int outer = D - 1;
    const int oo_lo = std::max(-s, -b[outer]), oo_hi = std::min(s, divs_[outer] - 1 - b[outer]);
    for (int oo = oo_lo; oo <= oo_hi; ++oo) {
      c[outer] = b[outer] + oo;
      if (!near_outer(oo)) continue;
      const bool outer_face = oo == -s || oo == s;
      if constexpr (D == 2) {
        walk_x(outer_face);
      } else {
        const int oy_lo = std::max(-s, -b[1]), oy_hi = std::min(s, divs_[1] - 1 - b[1]);
        for (int oy = oy_lo; oy <= oy_hi; ++oy) {
          c[1] = b[1] + oy;
          if (!near_row(oy, oo)) continue;
          walk_x(outer_face || oy == -s || oy == s);
        }
      }
    }
  }

  Point lo_{}, hi_{}, size_{}, inv_size_{};  // the grid's box, and its bins' size
  std::array<bool, D> core_{};         // per axis: the grid spans the bulk, not the box
  Point core_hi_{};                    // the bulk's upper end where core_ (its lower end is lo_)
  std::size_t outside_core_ = 0;
  double min_size_ = 0;
  double slack_ = 0;  // a few ulp of the box coordinates
  std::array<std::int32_t, D> divs_{};
  Buffer<std::uint32_t> offsets_;
  Buffer<std::int32_t> ids_;        // point id per slot (bin order)
  Buffer<Point> sorted_;            // coordinates per slot
};

}  // namespace tessera::kernels

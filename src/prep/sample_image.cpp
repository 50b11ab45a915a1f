// The labelled-image point sampler (see include/tessera/prep/sample_image.hpp).
//
// Boundary distance: boundary voxels (a face neighbour with another label,
// one of the two selected) get 0, the others +inf; then one 1D pass per axis
// computes d(v) = min over voxels w of (d(w) + |v_a - w_a|) along that axis
// (a forward and a backward sweep of min(d, previous + 1)). For the city-block
// metric the distance transform is a min-plus convolution with a separable
// kernel, so the three passes give the exact L1 distance to the nearest
// boundary voxel. VTK's sampler also sweeps per axis but marks boundaries
// inside each pass, so a boundary found along y never propagates along x.
//
// Parallel model: every pass is a parallel loop over independent lines (x),
// or strips of up to 256 consecutive x (y and z sweeps, cache friendly). The
// sampling is two passes over fixed voxel blocks (count, prefix sum, fill);
// every random draw is a function of (seed, voxel index), so the result is
// the same for any thread count.
#include "tessera/prep/sample_image.hpp"

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <string>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_reduce.h>

#include "../progress_chunks.hpp"
#include "random.hpp"
#include "tessera/cells.hpp"
#include "tessera/engine/thread_arena.hpp"

namespace tessera {
namespace {

constexpr std::int32_t kInf = std::numeric_limits<std::int32_t>::max();
constexpr std::int64_t kStrip = 256;       // x extent of a y / z sweep task
constexpr std::size_t kBlock = 1 << 15;    // voxels per sampling block

inline std::int32_t step_up(std::int32_t d) { return d >= kInf - 1 ? kInf : d + 1; }

void check_image(const LabelImage& image) {
  const ImageGeometry& g = image.geometry;
  if (g.dim != 2 && g.dim != 3) throw InputError("label image: dim must be 2 or 3, got " + std::to_string(g.dim));
  for (int a = 0; a < 3; ++a)
    if (g.size[static_cast<std::size_t>(a)] < 1) throw InputError("label image is empty (a size is < 1)");
  if (g.dim == 2 && g.size[2] != 1) throw InputError("label image: a 2D image has size[2] = 1");
  if (image.labels.size() != g.n_voxels())
    throw InputError("label image has " + std::to_string(image.labels.size()) + " labels for " +
                     std::to_string(g.n_voxels()) + " voxels (mismatched sizes)");
  for (int a = 0; a < g.dim; ++a) {
    const double s = g.spacing[static_cast<std::size_t>(a)], o = g.origin[static_cast<std::size_t>(a)];
    if (!(s > 0) || !std::isfinite(s)) throw InputError("label image: spacing must be finite and > 0");
    if (!std::isfinite(o)) throw InputError("label image: origin must be finite");
  }
}

/// Per-voxel "selected" flags and, per label of `select` (sorted, unique),
/// whether some voxel carries it.
struct Selection {
  std::vector<std::int32_t> labels;  // sorted unique; empty = every label >= 0
  std::vector<std::uint8_t> voxel;   // 1 = selected
  std::vector<std::uint8_t> found;   // per entry of `labels`
  bool any = false;

  bool is_selected(std::int32_t l) const {
    return labels.empty() ? l >= 0 : std::binary_search(labels.begin(), labels.end(), l);
  }
};

Selection make_selection(const LabelImage& image, const std::vector<std::int32_t>& select) {
  Selection s;
  s.labels = select;
  std::sort(s.labels.begin(), s.labels.end());
  s.labels.erase(std::unique(s.labels.begin(), s.labels.end()), s.labels.end());
  const std::size_t n = image.labels.size();
  s.voxel.resize(n);
  const std::size_t k = s.labels.size();
  using Found = std::vector<std::uint8_t>;
  Found found = tbb::parallel_reduce(
      tbb::blocked_range<std::size_t>(0, n, kBlock), Found(k + 1, 0),
      [&](const tbb::blocked_range<std::size_t>& r, Found f) {
        const std::int32_t* lab = image.labels.data();
        std::uint8_t* out = s.voxel.data();
        std::uint8_t any = 0;
        if (k == 0) {
          for (std::size_t v = r.begin(); v != r.end(); ++v) {
            const std::uint8_t x = lab[v] >= 0;
            out[v] = x;
            any |= x;
          }
        } else {
          const std::int32_t* first = s.labels.data();
          const std::int32_t* last = first + k;
          for (std::size_t v = r.begin(); v != r.end(); ++v) {
            const std::int32_t* it = std::lower_bound(first, last, lab[v]);
            const bool hit = it != last && *it == lab[v];
            out[v] = hit;
            if (hit) {
              f[static_cast<std::size_t>(it - first)] = 1;
              any = 1;
            }
          }
        }
        f[k] |= any;
        return f;
      },
      [](Found a, const Found& b) {
        for (std::size_t i = 0; i < a.size(); ++i) a[i] |= b[i];
        return a;
      });
  s.any = found[k] != 0;
  found.pop_back();
  s.found = std::move(found);
  return s;
}

/// The distance field (1 + L1 distance; kInf without boundaries). Runs in
/// the caller's arena. `progress` (may be empty) is called between its
/// passes over the image, with fractions up to `upto` of the whole run.
std::vector<std::int32_t> distance_field(const LabelImage& image, const Selection& sel,
                                         const std::function<void(double)>& progress = {}, double upto = 1.0) {
  auto passed = [&](int k) {
    if (progress) progress(upto * k / 4.0);
  };
  const ImageGeometry& g = image.geometry;
  const std::int64_t nx = g.size[0], ny = g.size[1], nz = g.size[2];
  const std::size_t n = g.n_voxels();
  const std::int32_t* lab = image.labels.data();
  const std::uint8_t* sv = sel.voxel.data();
  std::vector<std::int32_t> dist(n);
  std::int32_t* d = dist.data();

  // Boundary voxels, and the x pass on the same rows.
  tbb::parallel_for(tbb::blocked_range<std::int64_t>(0, ny * nz), [&](const tbb::blocked_range<std::int64_t>& r) {
    for (std::int64_t row = r.begin(); row != r.end(); ++row) {
      const std::int64_t j = row % ny, k = row / ny;
      const std::size_t base = static_cast<std::size_t>(row * nx);
      for (std::int64_t i = 0; i < nx; ++i) {
        const std::size_t v = base + static_cast<std::size_t>(i);
        const std::int32_t l = lab[v];
        const bool s = sv[v] != 0;
        auto differs = [&](std::size_t w) { return lab[w] != l && (s || sv[w] != 0); };
        bool b = (i > 0 && differs(v - 1)) || (i + 1 < nx && differs(v + 1));
        const std::size_t sy = static_cast<std::size_t>(nx), sz = static_cast<std::size_t>(nx * ny);
        b = b || (j > 0 && differs(v - sy)) || (j + 1 < ny && differs(v + sy));
        b = b || (k > 0 && differs(v - sz)) || (k + 1 < nz && differs(v + sz));
        d[v] = b ? 0 : kInf;
      }
      std::int32_t* line = d + base;
      for (std::int64_t i = 1; i < nx; ++i) line[i] = std::min(line[i], step_up(line[i - 1]));
      for (std::int64_t i = nx - 2; i >= 0; --i) line[i] = std::min(line[i], step_up(line[i + 1]));
    }
  });
  passed(1);

  // A sweep along an axis of stride `stride` (elements) and length `len`,
  // over strips [x0, x1) of rows starting at `start`.
  auto sweep = [d](std::size_t start, std::size_t stride, std::int64_t len, std::int64_t width) {
    for (std::int64_t t = 1; t < len; ++t) {
      std::int32_t* cur = d + start + static_cast<std::size_t>(t) * stride;
      const std::int32_t* prev = cur - stride;
      for (std::int64_t x = 0; x < width; ++x) cur[x] = std::min(cur[x], step_up(prev[x]));
    }
    for (std::int64_t t = len - 2; t >= 0; --t) {
      std::int32_t* cur = d + start + static_cast<std::size_t>(t) * stride;
      const std::int32_t* next = cur + stride;
      for (std::int64_t x = 0; x < width; ++x) cur[x] = std::min(cur[x], step_up(next[x]));
    }
  };
  const std::int64_t strips = (nx + kStrip - 1) / kStrip;
  // y pass: per z slice and x strip.
  if (ny > 1)
    tbb::parallel_for(tbb::blocked_range<std::int64_t>(0, nz * strips), [&](const tbb::blocked_range<std::int64_t>& r) {
      for (std::int64_t t = r.begin(); t != r.end(); ++t) {
        const std::int64_t k = t / strips, x0 = (t % strips) * kStrip;
        sweep(static_cast<std::size_t>(k * nx * ny + x0), static_cast<std::size_t>(nx), ny, std::min(kStrip, nx - x0));
      }
    });
  passed(2);
  // z pass: per y row and x strip.
  if (nz > 1)
    tbb::parallel_for(tbb::blocked_range<std::int64_t>(0, ny * strips), [&](const tbb::blocked_range<std::int64_t>& r) {
      for (std::int64_t t = r.begin(); t != r.end(); ++t) {
        const std::int64_t j = t / strips, x0 = (t % strips) * kStrip;
        sweep(static_cast<std::size_t>(j * nx + x0), static_cast<std::size_t>(nx * ny), nz, std::min(kStrip, nx - x0));
      }
    });
  passed(3);
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n, kBlock), [&](const tbb::blocked_range<std::size_t>& r) {
    for (std::size_t v = r.begin(); v != r.end(); ++v) d[v] = d[v] == kInf ? kInf : d[v] + 1;
  });
  return dist;
}

/// d is a power of n (n^0 = 1 included); exact integer arithmetic.
inline bool is_power(std::int32_t d, std::int32_t n) {
  if (d < 1) return false;
  while (d % n == 0) d /= n;
  return d == 1;
}

}  // namespace

std::vector<std::int32_t> boundary_distance(const LabelImage& image, const std::vector<std::int32_t>& select) {
  check_image(image);
  engine::ThreadArena arena(resolve_threads(0));
  std::vector<std::int32_t> out;
  arena.execute([&] {
    const Selection sel = make_selection(image, select);
    if (!sel.any)
      throw InputError(select.empty() ? "empty selection: no voxel has a label >= 0"
                                      : "empty selection: no voxel has any of the selected labels");
    out = distance_field(image, sel);
  });
  return out;
}

LabelledPoints sample_image(const LabelImage& image, const SampleImageOptions& o) {
  check_image(image);
  if (o.schedule == SampleSchedule::exponential && o.step < 2)
    throw InputError("step must be >= 2 for the exponential schedule, got " + std::to_string(o.step));
  if (o.schedule == SampleSchedule::linear && o.step < 1)
    throw InputError("step must be >= 1 for the linear schedule, got " + std::to_string(o.step));
  if (o.schedule != SampleSchedule::exponential && o.schedule != SampleSchedule::linear)
    throw InputError("unknown schedule");
  const double lo = o.probability_range[0], hi = o.probability_range[1];
  if (!(lo >= 0 && lo <= hi && hi <= 1))
    throw InputError("probability range must satisfy 0 <= lo <= hi <= 1, got " + std::to_string(lo) + "," +
                     std::to_string(hi));
  if (o.background_label && *o.background_label >= 0)
    throw InputError("background label must be < 0 (an outside label), got " + std::to_string(*o.background_label));
  if (!(o.joggle >= 0) || !std::isfinite(o.joggle))
    throw InputError("joggle must be a finite number >= 0");
  if (o.output != SampleOutput::all && o.output != SampleOutput::labelled && o.output != SampleOutput::background)
    throw InputError("unknown output mode");

  const ImageGeometry& g = image.geometry;
  const int dim = g.dim;
  const std::int64_t nx = g.size[0], ny = g.size[1];
  double min_spacing = g.spacing[0];
  for (int a = 1; a < dim; ++a) min_spacing = std::min(min_spacing, g.spacing[static_cast<std::size_t>(a)]);
  const double jog = std::min(o.joggle, 0.5) * min_spacing;
  const std::size_t n = g.n_voxels();

  LabelledPoints out;
  out.dim = dim;
  engine::ThreadArena arena(resolve_threads(o.threads));
  arena.execute([&] {
    const Selection sel = make_selection(image, o.select);
    for (std::size_t i = 0; i < sel.labels.size(); ++i)
      if (!sel.found[i]) throw InputError("unknown label " + std::to_string(sel.labels[i]) + " in the selection: no voxel has it");
    if (!sel.any) throw InputError("empty selection: no voxel has a label >= 0");
    if (o.progress) o.progress(0.0);
    const std::vector<std::int32_t> dist = distance_field(image, sel, o.progress, 0.5);

    const std::int32_t step = o.step;
    auto scheduled = [&](std::int32_t d) {
      return o.schedule == SampleSchedule::exponential ? is_power(d, step) : (d == 1 || d % step == 0);
    };
    // Distances are at most nx + ny + nz - 2 (or kInf): a lookup table of the
    // scheduled ones spares a division loop per voxel.
    const std::int64_t max_d = g.size[0] + g.size[1] + g.size[2];
    std::vector<std::uint8_t> table;
    if (max_d < (std::int64_t(1) << 24)) {
      table.resize(static_cast<std::size_t>(max_d) + 1);
      for (std::int64_t d = 1; d <= max_d; ++d) table[static_cast<std::size_t>(d)] = scheduled(static_cast<std::int32_t>(d));
    }
    const bool far_scheduled = scheduled(kInf);
    auto keep = [&](std::size_t v) {
      const bool s = sel.voxel[v] != 0;
      if ((o.output == SampleOutput::labelled && !s) || (o.output == SampleOutput::background && s)) return false;
      const std::int32_t d = dist[v];
      const bool candidate = d == kInf                                      ? far_scheduled
                             : static_cast<std::size_t>(d) < table.size() ? table[static_cast<std::size_t>(d)] != 0
                                                                          : scheduled(d);
      if (!candidate) return false;
      if (!o.randomize) return true;
      const double p = std::clamp(1.0 / static_cast<double>(d), lo, hi);
      detail::RandomStream r(o.seed, v, detail::kStreamSamplerKeep);
      return r.uniform() < p;
    };

    // The two passes over the voxels, by blocks, in chunks of blocks for
    // the progress callback (the second half of the run).
    const std::size_t blocks = (n + kBlock - 1) / kBlock;
    auto halfway = [&](double from) -> std::function<void(double)> {
      if (!o.progress) return {};
      return [&, from](double f) { o.progress(from + 0.25 * f); };
    };
    const std::size_t chunk = std::max<std::size_t>(1, detail::kProgressChunk * 16 / kBlock);
    std::vector<std::size_t> offset(blocks + 1, 0);
    detail::in_progress_chunks(blocks, halfway(0.5), [&](std::size_t b0, std::size_t b1) {
      tbb::parallel_for(b0, b1, [&](std::size_t b) {
        std::size_t c = 0;
        const std::size_t end = std::min(n, (b + 1) * kBlock);
        for (std::size_t v = b * kBlock; v < end; ++v) c += keep(v);
        offset[b + 1] = c;
      });
    }, chunk);
    for (std::size_t b = 0; b < blocks; ++b) offset[b + 1] += offset[b];
    const std::size_t total = offset[blocks];
    out.coords.resize(total * static_cast<std::size_t>(dim));
    out.labels.resize(total);
    detail::in_progress_chunks(blocks, halfway(0.75), [&](std::size_t b0, std::size_t b1) {
      tbb::parallel_for(b0, b1, [&](std::size_t b) {
        std::size_t k = offset[b];
        const std::size_t end = std::min(n, (b + 1) * kBlock);
        for (std::size_t v = b * kBlock; v < end; ++v) {
          if (!keep(v)) continue;
          const std::int64_t iv = static_cast<std::int64_t>(v);
          const std::int64_t idx[3] = {iv % nx, (iv / nx) % ny, iv / (nx * ny)};
          double* c = out.coords.data() + k * static_cast<std::size_t>(dim);
          for (int a = 0; a < dim; ++a)
            c[a] = g.origin[static_cast<std::size_t>(a)] +
                   static_cast<double>(idx[a]) * g.spacing[static_cast<std::size_t>(a)];
          if (jog > 0) {
            double off[3];
            detail::RandomStream r(o.seed, v, detail::kStreamSamplerJoggle);
            r.in_unit_ball(dim, off);
            for (int a = 0; a < dim; ++a) c[a] += jog * off[a];
          }
          out.labels[k] = (sel.voxel[v] == 0 && o.background_label) ? *o.background_label : image.labels[v];
          ++k;
        }
      });
    }, chunk);
  });
  return out;
}

}  // namespace tessera

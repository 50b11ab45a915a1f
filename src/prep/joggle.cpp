// Joggle (include/tessera/prep/joggle.hpp): each moving point i gets the
// displacement radius * u, u uniform in the unit ball / disk drawn from the
// random stream of (seed, i) — so the result is the same for any thread count
// and for any mask. Points the mask leaves alone are copied through bit for
// bit (VTK's vtkJogglePoints leaves them uninitialised, notes §6.7).
#include "tessera/prep/joggle.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <string>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "random.hpp"
#include "tessera/cells.hpp"
#include "tessera/engine/thread_arena.hpp"
#include "tessera/finite_points.hpp"
#include "../message_text.hpp"
#include "../progress_chunks.hpp"

namespace tessera {
namespace {

constexpr std::size_t kGrain = 4096;


/// `r` times the length of the diagonal of the bounding box of the finite
/// points (every point, unless keep_non_finite let others in); 0 when none is.
double times_diagonal(double r, std::span<const double> coords, int dim) {
  const std::size_t n = coords.size() / static_cast<std::size_t>(dim);
  double lo[3] = {0, 0, 0}, hi[3] = {0, 0, 0};
  bool any = false;
  for (std::size_t i = 0; i < n; ++i) {
    if (!finite_point(coords, i, dim)) continue;
    for (int d = 0; d < dim; ++d) {
      const double v = coords[i * static_cast<std::size_t>(dim) + static_cast<std::size_t>(d)];
      lo[d] = any ? std::min(lo[d], v) : v;
      hi[d] = any ? std::max(hi[d], v) : v;
    }
    any = true;
  }
  if (!any) return 0;
  double s = 0;
  for (int d = 0; d < dim; ++d) s += (hi[d] - lo[d]) * (hi[d] - lo[d]);
  if (std::isfinite(s) && s > 1e-290) return r * std::sqrt(s);
  // Extents past ~1e154 overflow the sum of squares (and past ~1e308 the
  // extents themselves), below ~1e-154 they underflow it: std::hypot of the
  // half extents does neither.
  double half[3] = {0, 0, 0};
  for (int d = 0; d < dim; ++d) half[d] = 0.5 * hi[d] - 0.5 * lo[d];
  return (2 * r) * std::hypot(half[0], half[1], half[2]);  // may overflow: joggle() reports it
}

}  // namespace

std::vector<double> joggle(std::span<const double> coords, int dim, const JoggleOptions& options,
                           std::span<const std::uint8_t> mask) {
  if (dim != 2 && dim != 3) throw InputError("joggle: dimension must be 2 or 3, not " + std::to_string(dim));
  if (coords.size() % static_cast<std::size_t>(dim) != 0)
    throw InputError("joggle: " + std::to_string(coords.size()) + " coordinates are not a whole number of " +
                     std::to_string(dim) + "D points");
  const std::size_t n = coords.size() / static_cast<std::size_t>(dim);
  if (!(options.radius >= 0) || !std::isfinite(options.radius))
    throw InputError("joggle: radius must be a finite number >= 0, not " + detail::number_text(options.radius));
  if (options.mode != JoggleMode::ball && dim != 3)
    throw InputError("joggle: plane modes (xy, xz, yz) need 3D points; 2D points joggle in their plane (ball)");
  if (static_cast<unsigned>(options.mode) > static_cast<unsigned>(JoggleMode::yz))
    throw InputError("joggle: unknown mode");
  if (!mask.empty() && mask.size() != n)
    throw InputError("joggle: mask has " + std::to_string(mask.size()) + " values for " + std::to_string(n) +
                     " points");
  for (std::size_t k = 0; k < coords.size() && !options.keep_non_finite; ++k)
    if (!std::isfinite(coords[k]))
      throw InputError("joggle: non-finite coordinate " + detail::number_text(coords[k]) + " in point " +
                       std::to_string(k / static_cast<std::size_t>(dim)) +
                       " (keep_non_finite copies such points through unmoved)");

  std::vector<double> out(coords.begin(), coords.end());
  if (n == 0) return out;
  const double radius = options.absolute ? options.radius : times_diagonal(options.radius, coords, dim);
  if (radius == 0) return out;
  if (!std::isfinite(radius))
    throw InputError("joggle: the displacement radius (" + detail::number_text(options.radius) +
                     " of the bounding box's diagonal) overflows double; give a smaller radius");

  // The axes that move: all of them (ball), or the two of the plane.
  int axes[3] = {0, 1, 2};
  int moving = dim;
  if (options.mode != JoggleMode::ball) {
    moving = 2;
    axes[0] = options.mode == JoggleMode::yz ? 1 : 0;
    axes[1] = options.mode == JoggleMode::xy ? 1 : 2;
  }
  const std::size_t stride = static_cast<std::size_t>(dim);
  auto body = [&](const tbb::blocked_range<std::size_t>& r) {
    double u[3];
    for (std::size_t i = r.begin(); i != r.end(); ++i) {
      if (!mask.empty() && mask[i] == 0) continue;
      if (options.keep_non_finite && !finite_point(coords, i, dim)) continue;  // copied through
      detail::RandomStream rng(options.seed, i, detail::kStreamJoggle);
      rng.in_unit_ball(moving, u);
      for (int k = 0; k < moving; ++k) out[i * stride + static_cast<std::size_t>(axes[k])] += radius * u[k];
    }
  };
  detail::parallel_in_progress_chunks(resolve_threads(options.threads), n, kGrain, options.progress, body);
  for (std::size_t k = 0; k < out.size(); ++k)
    if (!std::isfinite(out[k]) && std::isfinite(coords[k]))
      throw InputError("joggle: point " + std::to_string(k / stride) + " moved past double's range (radius " +
                       detail::number_text(radius) + "); give a smaller radius");
  return out;
}

}  // namespace tessera

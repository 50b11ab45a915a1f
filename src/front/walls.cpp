// Walls in the kernels' form, and points against them (walls.hpp).
#include "compensated_sum.hpp"
#include "walls.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <string>

#include <tbb/blocked_range.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include "../message_text.hpp"
#include "cell_geometry.hpp"
#include "tessera/engine/tessellate.hpp"  // clip_walls
#include "tessera/engine/thread_arena.hpp"
#include "tessera/kernels/filter.hpp"
#include "tessera/kernels/hull.hpp"
#include "tessera/kernels/tile.hpp"

namespace tessera::front {

std::vector<kernels::Wall> kernel_walls(const std::vector<Wall>& given, int dim, int k) {
  if (given.size() > static_cast<std::size_t>(kernels::max_walls))
    throw InputError(std::to_string(given.size()) + " walls: at most " + std::to_string(kernels::max_walls));
  std::vector<kernels::Wall> out;
  out.reserve(given.size());
  for (std::size_t w = 0; w < given.size(); ++w) {
    const Wall& g = given[w];
    const std::string name = "wall " + std::to_string(w);
    double top = 0;
    for (int a = 0; a < 3; ++a) {
      const double x = g.normal[static_cast<std::size_t>(a)];
      if (!std::isfinite(x)) throw InputError(name + ": its normal is not finite");
      if (a >= dim && x != 0)
        throw InputError(name + ": a 2D wall's normal has two components (its third must be 0)");
      top = std::max(top, std::fabs(x));
    }
    if (top == 0) throw InputError(name + ": its normal is zero");
    if (!std::isfinite(g.offset)) throw InputError(name + ": its offset is not finite");
    // Scale by 2^-e so that the largest component lies in [1, 2): exact for
    // the normal (its largest component is normal), and for the offset
    // unless it leaves double's range, which is refused.
    const int e = std::ilogb(top);
    kernels::Wall kw{};
    for (int a = 0; a < dim; ++a) {
      kw.n[a] = std::ldexp(g.normal[static_cast<std::size_t>(a)], -e);
      if (std::ldexp(kw.n[a], e) != g.normal[static_cast<std::size_t>(a)])
        throw InputError(name + ": its normal's components differ by more than a double's range");
    }
    kw.d = std::ldexp(g.offset, k - e);
    // |n|_2 rounded up: each square and sum within u, the root within u.
    double nn = 0;
    for (int a = 0; a < dim; ++a) nn += kw.n[a] * kw.n[a];
    kw.norm = std::sqrt(nn) * (1 + 8 * kernels::filter::u);
    if (!std::isfinite(kw.d) || std::ldexp(kw.d, e - k) != g.offset)
      throw InputError(name + ": its offset " + tessera::detail::number_text(g.offset) +
                       " is out of range beside its normal (the two differ by more than a double's range)");
    out.push_back(kw);
  }
  return out;
}

WallTest::WallTest(std::span<const kernels::Wall> walls, int dim, double largest, const kernels::walls::Index* index)
    : walls_(walls), dim_(dim), error_(walls.size()), index_(index) {
  // d - n.p in D products and D differences, each rounded once: within
  // gamma_{2D} of |d| + |n|_1 max|p| (doubled for margin and the bound's own
  // rounding), plus what products in the subnormal range lose.
  for (std::size_t k = 0; k < walls.size(); ++k) {
    double n1 = 0;
    for (int a = 0; a < dim; ++a) n1 += std::fabs(walls[k].n[a]);
    error_[k] = 4 * dim * kernels::filter::u * (std::fabs(walls[k].d) + n1 * largest) + kernels::filter::abs_eps;
  }
}

int WallTest::side(std::size_t k, const double* p) const {
  const kernels::Wall& w = walls_[k];
  double s = w.d;
  for (int a = 0; a < dim_; ++a) s -= w.n[a] * p[a];
  return s > error_[k] ? 1 : s < -error_[k] ? -1 : kernels::exact_wall_point_side(w, p, dim_);
}

int WallTest::outside(const double* p) const {
  if (index_ != nullptr) {  // the first wall p lies outside of, among those that p may
    int first = -1;
    index_->visit(p, 0.0, [&](std::int32_t k) {
      if ((first < 0 || k < first) && side(static_cast<std::size_t>(k), p) < 0) first = k;
      return true;
    });
    return first;
  }
  for (std::size_t k = 0; k < walls_.size(); ++k)
    if (side(k, p) < 0) return static_cast<int>(k);
  return -1;
}

std::unique_ptr<const kernels::walls::Index> make_wall_index(std::span<const kernels::Wall> walls, int dim,
                                                             const Bounds& box) {
  if (walls.size() < 16) return nullptr;
  double centre[3] = {0, 0, 0};
  for (int a = 0; a < dim; ++a)
    centre[a] = box.lo[static_cast<std::size_t>(a)] / 2 + box.hi[static_cast<std::size_t>(a)] / 2;
  return std::make_unique<const kernels::walls::Index>(walls, dim, centre);
}

double largest_magnitude(std::span<const double> values) {
  double m = 0;
  for (const double x : values) m = std::max(m, std::fabs(x));
  return m;
}

namespace {
// The measure of the cell of generator c (the box's centre) in the box
// [lo, hi] cut by the context's walls (engine::clip_walls: every wall, or
// with the context's index those it finds).
template <class CellT>
double cut_box_measure(kernels::ExactContext& ctx, const double* c, const double* lo, const double* hi, CellT& cell,
                       engine::WallScratch& scratch) {
  constexpr int D = CellT::dim;
  for (int a = 0; a < D; ++a) ctx.lo[static_cast<std::size_t>(a)] = lo[a], ctx.hi[static_cast<std::size_t>(a)] = hi[a];
  ctx.points = c;
  cell.reset(0, c, lo, hi, &ctx);
  kernels::BuildStatus st;
  st.has_cell = true;
  engine::clip_walls(cell, st, ctx, c, scratch);
  if (!st.has_cell) return 0;
  double volume;
  std::array<double, D> centroid;
  const std::int32_t shift = measure(cell, volume, centroid);
  return std::ldexp(volume, D * shift);
}

template <class CellT>
double polytope_measure(const Bounds& box, const std::vector<Wall>& given, int threads) {
  constexpr int D = CellT::dim;
  const std::vector<kernels::Wall> walls = kernel_walls(given, D, 0);
  kernels::ExactContext ctx;
  ctx.dim = D;
  ctx.walls = walls.data();
  ctx.num_walls = static_cast<int>(walls.size());
  double centre[3] = {0, 0, 0};
  for (int a = 0; a < D; ++a) centre[a] = box.lo[static_cast<std::size_t>(a)] / 2 + box.hi[static_cast<std::size_t>(a)] / 2;
  // Few walls: the box's centre as the one generator, its cell the box, cut
  // by every wall.
  if (walls.size() <= 256) {
    CellT cell;
    engine::WallScratch scratch;
    return cut_box_measure<CellT>(ctx, centre, box.lo.data(), box.hi.data(), cell, scratch);
  }
  // Many (a hull's: two per point on a sphere): one cell cut by every wall
  // tests each cut's every vertex, O(walls^2) (40k walls 13 s). The box is
  // split into g^D sub-boxes, about 8 walls each, each cut as a cell is by
  // the walls the index finds near it (engine::clip_walls), in parallel.
  // The sub-boxes share their faces' coordinates, so they partition the
  // box; their measures are summed in their order with compensation
  // (Neumaier): the same sum on any number of threads.
  const kernels::walls::Index index(walls, D, centre);
  ctx.wall_index = &index;
  const int g = std::min(D == 3 ? 64 : 512, static_cast<int>(std::ceil(std::pow(static_cast<double>(walls.size()) / 8, 1.0 / D))));
  auto at = [&](int a, int i) {
    const double lo = box.lo[static_cast<std::size_t>(a)], hi = box.hi[static_cast<std::size_t>(a)];
    return i == g ? hi : lo + (hi - lo) * (static_cast<double>(i) / g);
  };
  const std::size_t cells = static_cast<std::size_t>(std::lround(std::pow(g, D)));
  std::vector<double> part(cells);
  struct Local {  // per thread: the context (its box and generator change with each sub-box), the cell, lists
    kernels::ExactContext ctx;
    CellT cell;
    engine::WallScratch scratch;
  };
  tbb::enumerable_thread_specific<Local> locals([&] { return Local{ctx, CellT{}, {}}; });
  engine::ThreadArena(resolve_threads(threads)).execute([&] {
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, cells, 64), [&](const tbb::blocked_range<std::size_t>& r) {
      Local& local = locals.local();
      for (std::size_t cellno = r.begin(); cellno != r.end(); ++cellno) {
        std::size_t rest = cellno;
        double lo[3], hi[3], c[3];
        for (int a = 0; a < D; ++a) {
          const int i = static_cast<int>(rest % static_cast<std::size_t>(g));
          rest /= static_cast<std::size_t>(g);
          lo[a] = at(a, i);
          hi[a] = at(a, i + 1);
          c[a] = lo[a] / 2 + hi[a] / 2;
        }
        part[cellno] = cut_box_measure<CellT>(local.ctx, c, lo, hi, local.cell, local.scratch);
      }
    });
  });
  front::CompensatedSum total;
  for (const double v : part) total.add(v);
  return total.value();
}
}  // namespace

double domain_volume(const Bounds& box, const std::vector<Wall>& walls, int dim, int threads) {
  if (walls.empty()) return box.volume(dim);
  return dim == 3 ? polytope_measure<kernels::Hull>(box, walls, threads)
                  : polytope_measure<kernels::Tile>(box, walls, threads);
}

}  // namespace tessera::front

namespace tessera {
double domain_volume(const Bounds& box, const std::vector<Wall>& walls, int dim, int threads) {
  return front::domain_volume(box, walls, dim, threads);
}
}  // namespace tessera

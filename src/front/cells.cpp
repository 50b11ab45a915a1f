// tessera::voronoi: one cells pass with the cells compositor, for 2D tiles or
// 3D hulls. The shared set-up (checks, domain, rescaling, locator) is pass.cpp.
#include "tessera/cells.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdlib>
#include <functional>
#include <limits>
#include <optional>
#include <string>

#include <tbb/info.h>

#include "cells_compositor.hpp"
#include "delaunay_stars.hpp"
#include "pass.hpp"
#include "periodic.hpp"
#include "pilot.hpp"
#include "spoke_class_marker.hpp"
#include "tessera/engine/tessellate.hpp"
#include "tessera/kernels/hull.hpp"
#include "tessera/kernels/tile.hpp"

namespace tessera {

double Bounds::volume(int dim) const {
  double v = 1;
  for (int d = 0; d < dim; ++d) v *= hi[static_cast<std::size_t>(d)] - lo[static_cast<std::size_t>(d)];
  return v;
}

int resolve_threads(int requested) {
  if (requested > max_threads)
    throw InputError("threads must be at most " + std::to_string(max_threads) + ", got " + std::to_string(requested));
  if (requested > 0) return requested;
  if (const char* env = std::getenv("TESSERA_NUM_THREADS")) {
    char* end = nullptr;
    long v = std::strtol(env, &end, 10);
    if (end != env && *end == '\0' && v > 0 && v <= max_threads) return static_cast<int>(v);
    throw InputError(std::string("TESSERA_NUM_THREADS must be an integer from 1 to ") + std::to_string(max_threads) +
                     ", got '" + env + "'");
  }
  return std::max(1, tbb::info::default_concurrency());
}

namespace {

/// From this pilot ratio on (front/pilot.hpp: the cells' search work per
/// Delaunay simplex they find, relative to uniform input), cells are
/// taken from the Delaunay triangulation (CellMethod::insertion). The same
/// for every thread count: the two methods' cells differ in the last bits of
/// their volumes and centroids (the clip order differs), and the output must
/// not depend on the thread count.
///
/// 3D: 1.75 (stop 68). On uniform points the search then took 0.64 of the
/// insertion's time (100k, two threads). Measured on two threads (docs/
/// design.md, "The cells' choice on sampled label images and outside
/// points"): sampled label images at ratios 1.84-2.2 (118k-324k points) and a
/// cube with a far outlier at 1.84 run 10-85% faster by insertion. Since
/// stop 69 ("The store of simplices: sized once, on huge pages") the
/// insertion's cells cost 1.09-1.21 times the search's on uniform points, and
/// graded densities, thin slabs and sampled images at 1.56-1.69 run 5-27%
/// faster by insertion; but inputs near ties do not follow the ratio: a
/// lattice jittered by 1e-9 (1.56), a dyadic voxel grid (1.42) and a
/// rectilinear grid (1.63) run 7-29% slower by insertion, whose in-sphere
/// tests meet those ties, and the ratio of one input varies by ~0.1 from
/// sample to sample. So 3D stays at 1.75 (stop 68 had it at 2 before).
///
/// 2D: 1.3 (stop 69; 2 since stop 35). Since stop 69 the insertion's cells
/// take 1.04 times the search's time on 1M uniform points on two threads and
/// 0.88 on one. From ratios 1.33-1.86 (blobs over a uniform background, a
/// density gradient, thin strips, a rotated lattice, a 100k grid) they run
/// level to 25% faster on two threads and 6-47% faster on one; a gradient at
/// 1.22 stays 11% faster by the search on two threads. Lattices, exact or
/// jittered by 1e-9, measure 0.53-0.73.
///
/// With outside points the threshold grows with the located points per
/// generator (run(), below).
template <int D>
inline constexpr double neighbours_ratio = D == 3 ? 1.75 : 1.3;
/// 3D, where the domain box reaches far beyond the bulk of the points (a few
/// far points, or explicit bounds many times the points' extent:
/// BinLocator::spans_bulk), the insertion is taken from a ratio of 1.2
/// (stop 70). The pilot's sample of cells cannot see what such input costs
/// the search: the far points' own cells (bisectors with the bulk nearly
/// parallel) and the bulk's hull cells, long cones out to the box, are a few
/// cells among many. Their sampled neighbours measure 1.2-1.75 (uniform
/// bulks), and on every such input measured the insertion ran level (within
/// 2%) to 2.7 times faster on two threads (docs/design.md, "Far boxes: the
/// cells' choice (stop 70)"). Not where the pilot met ties (far_box_tie_limit):
/// a lattice or a voxel grid with one point 1e3 away measures 1.42-1.50 and
/// runs 2-8% faster by the search, whose ties are cheap. Not in 2D, where
/// such cells are cheap: uniform squares with far points run level by either
/// method.
inline constexpr double far_box_ratio = 1.2;
/// Exact evaluations per pilot cell from which the input counts as tied
/// (lattices ~53, sampled label images ~30; uniform points below 0.2).
inline constexpr double far_box_tie_limit = 10;
/// The pilot's work units (~15-18 ns each) per exact evaluation that a small
/// grid or the box-corner pattern served (a lattice's or a voxel grid's ties,
/// ~53 per cell; ~30 on a sampled label image): 24-26 ns each measured on
/// the 50^3 lattice and on voxel centres, 55 ns on a sampled label image,
/// whose ties reach the narrow vertex stage more often. Until stop 68 they
/// weighed nothing here, and a sampled image's search looked ~12% cheaper
/// than it was. (tessera::delaunay's choice leaves them out: its insertion
/// pays for the same ties.)
inline constexpr std::uint64_t tie_weight = 2;
/// The share of the generators the pilot may build: on small inputs too.
inline constexpr double pilot_share = 0.5;

/// VoronoiOptions::only_with_faces: the cells with such faces alone are
/// built where at most this share of them has some (only_with_faces_up_to
/// 0). The first pass over every cell without the mesh costs about half of
/// what the mesh pass of every cell does (1M uniform points, as the whole
/// `faces --kind boundary` with 3% (3D) and 0.1% (2D) of the cells built:
/// 3D 0.43 of it on one thread, 0.50 on two; 2D 0.41 and 0.49), so building
/// a share f of the cells after it costs about 0.5 + f of the whole mesh
/// pass: more from f ~ 0.5. The cells of the surface nets' sampled label
/// volume (bench/surface_nets, 256^3 and 12 labels, capped: 67% of them
/// with faces of the net) took 28% longer so (docs/design.md, "Face sets of
/// some cells").
inline constexpr double with_faces_share = 0.5;
/// The cells sampled to estimate that share: spread over the generators
/// (every k-th in bin order), ~0.2% of the first pass on 1M points; an
/// estimate within ~0.01 of the share (its standard error at one half).
inline constexpr std::size_t with_faces_sample = 2048;

/// InputError unless every id of VoronoiOptions::only is one of the n
/// points' (after the input's own checks: an empty input says so first).
void check_only(std::span<const std::int32_t> only, std::size_t n) {
  for (const std::int32_t g : only)
    if (g < 0 || static_cast<std::size_t>(g) >= n)
      throw InputError("only: point " + std::to_string(g) + " does not exist (there are " + std::to_string(n) +
                       " points)");
}

/// `reach`, when given (sized for every point, zeros): each built cell's
/// security radius, in the input's units, at its generator's index.
template <class CellT>
Cells run(std::span<const double> input, std::span<const std::int32_t> labels, const VoronoiOptions& opt,
          std::vector<double>* reach = nullptr) {
  constexpr int D = CellT::dim;
  front::Pass<D> pass(input, labels, opt);
  Cells out;
  out.dim = D;
  out.n_points = input.size() / D;
  out.bounds = pass.bounds;
  out.walls = opt.walls;
  out.ignored_outside_bounds = pass.ignored_outside;
  out.threads_used = pass.engine_options.threads;
  out.far_points = pass.locator->outside_core();
  out.power = !pass.radii.empty();
  out.generators = pass.order.size();

  front::report_duplicates(pass, labels, out.duplicates);
  // Cells whose search would cost far more than on uniform points (points
  // nearly on a sphere, surface samples, dense clusters; in 2D points on a
  // circle, along curves, in blobs) come from the Delaunay triangulation
  // instead, assembled from their stars or clipped by their Delaunay
  // neighbours: the same cells (docs/design.md, "Cells from Delaunay
  // neighbours", "Cells assembled from their stars").
  std::optional<engine::DelaunayStars> stars;
  front::CellsCompositor<CellT> comp(out, labels, opt.build_mesh, pass.k, pass.bounds);
  comp.record_reach(reach);
  front::PilotKeep<front::CellsCompositor<CellT>> kept{comp, {}, 0};  // the pilot's whole cells
  {
    bool insert = opt.cell_method == CellMethod::insertion;
    // Input no frame fits (a far outlier beyond ~1e154, points spread
    // log-uniformly over 1e-300..1e300: ExactContext::may_underflow) goes to
    // the insertion without a pilot. The insertion serves it since stop 52
    // (long double orientations, the Morton order over the grid's box),
    // while the search's cells at the bulk's edge reach the far points
    // (200k 3D beside one at 1e200: 49 s by search, 2.2 s by insertion). The
    // pilot chose the insertion on each of the ten such inputs measured
    // (docs/design.md, "Delaunay beyond the frame"), where its own sample of
    // searched cells cost up to 0.4 s (2,003 log-uniform points: 0.6 s, 0.17 s
    // without it).
    if (opt.cell_method == CellMethod::automatic) {
      if (pass.exact.may_underflow) {
        insert = true;
      } else {
        // The insertion triangulates every located point, outside points
        // (label < 0) too, and the search builds the generators' cells only:
        // the threshold grows with the located points per generator (as the
        // labelled Delaunay pass weighs its ratio, delaunay.cpp), but only
        // where the pilot measured the cells' cost (front::pilot_measured:
        // none abandoned at its cap, none much larger than a uniform cell).
        const double located = static_cast<double>(pass.locator->size());
        const double generators = static_cast<double>(pass.order.size());
        const double per_generator = generators > 0 ? std::max(1.0, located / generators)
                                                    : std::numeric_limits<double>::infinity();
        const front::PilotEstimate e = front::pilot_estimate<CellT>(
            pass, neighbours_ratio<D> * per_generator, pilot_share, tie_weight, neighbours_ratio<D>, &kept);
        const bool far_box = D == 3 && pass.locator->spans_bulk() && e.exact_per_cell < far_box_tie_limit;
        const double from = far_box ? far_box_ratio : neighbours_ratio<D>;
        insert = generators > 0 && e.ratio >= (e.measured ? from * per_generator : from);
      }
    }
    if (insert) {
      // The progress bar gives the insertion its first half, the cells the
      // second (about their shares of the time on 1M clustered points).
      std::function<void(double)> half;
      if (opt.progress) half = [&opt](double f) { opt.progress(0.5 * f); };
      stars = front::delaunay_stars(pass, half);
    }
    if (stars) {
      pass.gens.stars = &*stars;
      out.from_insertion = true;
      if (opt.progress) pass.engine_options.progress = [&opt](double f) { opt.progress(0.5 + 0.5 * f); };
    }
  }
  // VoronoiOptions::only: the cells asked for, then with their neighbours
  // (below). The pilot's cells are left (the same cells, built again).
  std::vector<std::uint64_t> only;
  if (!opt.only.empty()) {
    kept.batches.clear();
    kept.exact_calls = 0;
    only.assign((out.n_points + 63) / 64, 0);
    for (const std::int32_t g : opt.only)  // (< 0: a periodic pass's point that takes no part)
      if (g >= 0) only[static_cast<std::size_t>(g) >> 6] |= std::uint64_t{1} << (g & 63);
  }
  // VoronoiOptions::only_with_faces: the cells found by a first pass over
  // all (below); same_region asks for every cell. The pilot's cells are
  // left here too: its kept batches are the mesh compositor's, with owners
  // decided before the cells to build were known.
  const SpokeClassSet with_faces = opt.only_with_faces;
  bool find_with_faces = with_faces != 0 && (with_faces & spoke_class_bit(SpokeClass::same_region)) == 0;
  if (find_with_faces && pass.order.size() > with_faces_sample) {
    // Where most cells have such faces, all are built: a sample of them,
    // spread over the generators (every k-th in bin order), says which.
    const double up_to = opt.only_with_faces_up_to > 0 ? opt.only_with_faces_up_to : with_faces_share;
    std::vector<std::int32_t> sample_order;
    std::vector<std::uint32_t> sample_slots;
    const std::size_t step = pass.order.size() / with_faces_sample;
    for (std::size_t q = step / 2; q < pass.order.size(); q += step) {
      sample_order.push_back(pass.order[q]);
      sample_slots.push_back(pass.slots[q]);
    }
    pass.gens.order = sample_order;
    pass.gens.slots = sample_slots;
    front::SpokeClassMarker<CellT> sample(labels, with_faces, out.n_points);
    engine::EngineOptions quiet = pass.engine_options;
    quiet.progress = nullptr;
    out.exact_predicate_calls += engine::tessellate<CellT>(pass.gens, sample, quiet);
    pass.gens.order = pass.order;
    pass.gens.slots = pass.slots;
    const std::size_t cells = sample_order.size() - sample.empty_cells().size();
    find_with_faces = static_cast<double>(sample.count()) <= up_to * static_cast<double>(cells);
  }
  if (find_with_faces) {
    kept.batches.clear();
    kept.exact_calls = 0;
  }
  // The search's pass leaves out the cells its pilot built whole.
  std::vector<std::uint64_t> built;
  if (stars || kept.batches.empty()) {
    kept.batches.clear();
    kept.exact_calls = 0;
  } else {
    built.assign((out.n_points + 63) / 64, 0);
    for (const auto& b : kept.batches) {
      for (const std::int32_t g : b.gen) built[static_cast<std::size_t>(g) >> 6] |= std::uint64_t{1} << (g & 63);
      out.cells_from_pilot += b.gen.size();
    }
    pass.gens.skip = built;
  }
  // The generators of a set (bit g of `set`), in bin order as the pass
  // lists them (its order and slots, restricted).
  std::vector<std::int32_t> only_order;
  std::vector<std::uint32_t> only_slots;
  auto restrict_order = [&](std::span<const std::uint64_t> set) {
    only_order.clear();
    only_slots.clear();
    for (std::size_t q = 0; q < pass.order.size(); ++q) {
      const std::int32_t g = pass.order[q];
      if ((set[static_cast<std::size_t>(g) >> 6] >> (g & 63) & 1) == 0) continue;
      only_order.push_back(g);
      only_slots.push_back(pass.slots[q]);
    }
    pass.gens.order = only_order;
    pass.gens.slots = only_slots;
  };
  if (!only.empty()) {
    // First the cells asked for, for their neighbours (a few cells, no
    // mesh); then those with their neighbours, whose cells own the merged
    // vertices the cells asked for share with them.
    restrict_order(only);
    Cells first;
    first.dim = D;
    first.n_points = out.n_points;
    front::CellsCompositor<CellT> scout(first, labels, false, pass.k, pass.bounds);
    engine::EngineOptions quiet = pass.engine_options;
    quiet.progress = nullptr;
    out.exact_predicate_calls += engine::tessellate<CellT>(pass.gens, scout, quiet);
    for (const std::int32_t j : first.neighbors) only[static_cast<std::size_t>(j) >> 6] |= std::uint64_t{1} << (j & 63);
    restrict_order(only);
    out.partial = only_order.size() < pass.order.size();
    comp.build_only(only);
  }
  std::vector<std::uint64_t> found;  // only_with_faces: the cells to build
  if (find_with_faces) {
    // Every cell without the mesh, for its spokes' classes (no measures,
    // no neighbour lists kept: a bit per generator); then the cells marked,
    // with the mesh (VoronoiOptions::only_with_faces says why they suffice).
    // The progress bar gives the first pass the first half of what is left
    // after the insertion, the cells marked the second.
    front::SpokeClassMarker<CellT> marker(labels, with_faces, out.n_points);
    const double from = stars ? 0.5 : 0.0, share = 0.5 * (1 - from);
    engine::EngineOptions first = pass.engine_options;
    first.progress = nullptr;
    if (opt.progress) first.progress = [&opt, from, share](double f) { opt.progress(from + share * f); };
    out.exact_predicate_calls += engine::tessellate<CellT>(pass.gens, marker, first);
    if (opt.progress)
      pass.engine_options.progress = [&opt, from, share](double f) { opt.progress(from + share * (1 + f)); };
    found = std::move(marker.marked());
    out.empty_cells = std::move(marker.empty_cells());  // every generator's (the compositor adds none of its own)
    restrict_order(found);
    if (marker.count() + out.empty_cells.size() < pass.order.size()) {
      out.partial = true;
      out.with_faces_of = with_faces;
    }
    comp.build_only(found);
  }
  out.exact_predicate_calls +=
      engine::tessellate<CellT>(pass.gens, comp, pass.engine_options, std::move(kept.batches)) + kept.exact_calls;
  std::sort(out.duplicates.begin(), out.duplicates.end());
  if (pass.k != 0) {
    // (volumes: already in the input's units, CellsCompositor)
    for (double& c : out.centroid) c = pass.unscale(c);
    for (double& c : out.vertices) c = pass.unscale(c);
  }
  if (reach != nullptr)
    for (double& r : *reach) r = pass.unscale(std::sqrt(r));
  out.bounds = pass.user_bounds;
  return out;
}

/// The cells of a periodic box (front/periodic.hpp): the points among their
/// images in a layer around the box, widened once where some cell's
/// security sphere reaches past it (then to what the cells asked for, which
/// suffices: with more images no cell grows).
template <class CellT>
Cells run_periodic(std::span<const double> input, int dim, std::span<const std::int32_t> labels,
                   const VoronoiOptions& opt) {
  const front::PeriodicInput in = front::periodic_input(input, dim, labels, opt);
  check_only(opt.only, in.n);
  const int threads = resolve_threads(opt.threads);
  VoronoiOptions o = opt;
  o.periodic = {false, false, false};
  o.tilt = {0, 0, 0};
  o.ignore_outside_points = false;  // set aside already; every image lies in the layer
  o.only_with_faces = 0;            // every cell (VoronoiOptions::only_with_faces)
  std::vector<double> radii;  // power cells: each image has its point's radius
  auto [aug, im] = front::run_in_final_layer(in, labels, threads, [&](const front::PeriodicImages& images,
                                                                      std::vector<double>& reach) {
    o.bounds = images.domain;
    if (!opt.radii.empty()) {
      radii.resize(images.base.size());
      for (std::size_t k = 0; k < radii.size(); ++k) radii[k] = opt.radii[static_cast<std::size_t>(images.base[k])];
      o.radii = radii;
    }
    // VoronoiOptions::only names points: here their augmented ids (at shift 0).
    std::vector<std::int32_t> only;
    for (const std::int32_t g : opt.only)
      if (const std::int32_t a = images.original[static_cast<std::size_t>(g)]; a >= 0) only.push_back(a);
    if (!opt.only.empty() && only.empty()) only.push_back(-1);  // none takes part: build none (run)
    o.only = only;
    return run<CellT>(images.points, images.labels, o, &reach);
  });
  const std::size_t generators = aug.generators;
  const bool partial = aug.partial;  // (only)
  Cells out = front::periodic_cells(std::move(aug), in, im, labels, threads);
  out.generators = generators;
  out.partial = partial;
  return out;
}

}  // namespace

Cells voronoi(std::span<const double> input, int dim, std::span<const std::int32_t> labels,
              const VoronoiOptions& options) {
  if (!options.radii.empty() && (dim == 2 || dim == 3))
    front::check_radii(options.radii, input.size() / static_cast<std::size_t>(dim));
  if (!options.only.empty() && options.only_with_faces != 0)
    throw InputError("only and only_with_faces cannot be combined: give the cells wanted by one of them");
  if (options.periodic_box()) {
    if (!options.periodic[0] && !options.periodic[1] && !options.periodic[2])
      throw InputError("a tilt (triclinic box) needs periodic axes");
    if (!options.walls.empty()) throw InputError("walls cut a box with walls: not a periodic one");
    return dim == 3 ? run_periodic<kernels::Hull>(input, dim, labels, options)
                    : run_periodic<kernels::Tile>(input, dim, labels, options);
  }
  const front::CheckedInput<VoronoiOptions> in(input, dim, labels, options);
  check_only(options.only, in.points.size() / static_cast<std::size_t>(dim));
  return dim == 3 ? run<kernels::Hull>(in.points, labels, in.options)
                  : run<kernels::Tile>(in.points, labels, in.options);
}

}  // namespace tessera

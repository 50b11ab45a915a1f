// Front end: the Voronoi cells of a point set, over flat arrays.
//
// This is the compiled, non-templated layer (DESIGN §2.3): the CLI, the Python
// module and the tests call only this. Everything it returns is ordered by
// generator id and is byte-identical for any thread count.
#pragma once

#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <optional>
#include <span>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include "tessera/buffer.hpp"

namespace tessera {

/// Axis-aligned domain box. In 2D only the first two axes are used.
struct Bounds {
  std::array<double, 3> lo{0, 0, 0};
  std::array<double, 3> hi{0, 0, 0};
  double volume(int dim) const;  ///< area in 2D
};

/// `message` as one printable line of valid UTF-8: line breaks and tabs
/// become spaces, other control bytes (NUL included) and bytes that are not
/// UTF-8 become '?'. Error messages quote file contents (a header's keys,
/// a field's text), which may be any bytes: raw, they reached the terminal
/// as such, and Python could not decode them (an empty message).
std::string one_printable_line(std::string_view message);

/// Invalid input (shape, NaN, bounds, labels...). The message is one line
/// naming the problem (one_printable_line); the CLI prints it and exits
/// non-zero.
struct InputError : std::runtime_error {
  // Out of line (input_error.cpp): a throw site stays one call, as
  // runtime_error's own constructors are, and the hot code around the
  // library's checks is compiled as before.
  explicit InputError(std::string_view message);
  explicit InputError(const std::string& message);
  explicit InputError(const char* message);
};

/// Raised from a progress callback to cancel a run (e.g. Ctrl-C in Python).
struct Cancelled : std::runtime_error {
  Cancelled() : std::runtime_error("cancelled") {}
};

/// A periodic box's lattice vectors: row a is the shift by one along axis a,
/// (Lx, 0, 0), (xy, Ly, 0), (xz, yz, Lz) for tilts {xy, xz, yz} (the first
/// dim entries count).
inline std::array<std::array<double, 3>, 3> periodic_lattice(const Bounds& box, const std::array<double, 3>& tilt) {
  return {{{box.hi[0] - box.lo[0], 0, 0}, {tilt[0], box.hi[1] - box.lo[1], 0}, {tilt[1], tilt[2], box.hi[2] - box.lo[2]}}};
}

/// out = p + sum_b shift[b] lattice[b] (dim coordinates): p's image moved by
/// `shift` lattice vectors. Exact for a periodic computation's points and
/// shifts (its grid makes every term and partial sum a double).
template <class Shift>
inline void periodic_image(const std::array<std::array<double, 3>, 3>& lattice, int dim, const double* p,
                           const Shift& shift, double* out) {
  for (int a = 0; a < dim; ++a) {
    double x = p[a];
    for (int b = a; b < dim; ++b) x += shift[b] * lattice[static_cast<std::size_t>(b)][static_cast<std::size_t>(a)];
    out[a] = x;
  }
}

/// A wall: the half-space normal . x <= offset, which cuts the domain box
/// down to a convex polytope (VoronoiOptions::walls). In 2D normal[2] must be 0.
struct Wall {
  std::array<double, 3> normal{0, 0, 0};
  double offset = 0;
};

/// Spoke classes (DESIGN §2, the classifier): the kind of each cell face.
enum class SpokeClass : std::uint8_t {
  same_region = 0,     ///< neighbour is an inside point with the same label
  region_boundary = 1, ///< neighbour is an inside point with another label
  domain_boundary = 2, ///< face lies on the domain box or a wall
  outside = 3,         ///< neighbour is an outside point (label < 0)
};

/// The spoke id of wall k (VoronoiOptions::walls) in neighbour lists,
/// faces and vertex keys: -7 - k, below the box planes' -1..-6 in 2D and 3D.
constexpr std::int32_t wall_spoke(int k) { return -7 - k; }
/// Whether a negative spoke id is a wall's (else a box plane's).
constexpr bool is_wall_spoke(std::int32_t id) { return id <= -7; }

/// A set of spoke classes: bit 1 << c for each SpokeClass c in it.
using SpokeClassSet = std::uint8_t;
constexpr SpokeClassSet spoke_class_bit(SpokeClass c) {
  return static_cast<SpokeClassSet>(1u << static_cast<unsigned>(c));
}

/// How a cell finds the points that clip it (tessera::voronoi).
enum class CellMethod {
  /// The search, unless a pilot of a few hundred cells finds them far
  /// costlier than uniform input's (points nearly on a sphere or circle,
  /// surface samples, dense clusters, 2D curves): then insertion. The
  /// choice does not depend on the thread count.
  automatic,
  search,     ///< each cell searches the bins around it (the meshless method)
  /// The neighbours from the Delaunay triangulation by incremental
  /// insertion; each cell is the box clipped by them alone. The same cells
  /// as the search's (volumes and centroids to the last bits: the clip order
  /// differs). Points all on one plane (3D) or line (2D) have no
  /// triangulation: the search serves them.
  insertion,
};

struct VoronoiOptions {
  /// 2 or 3: read by surface_nets(); voronoi() and delaunay() take their
  /// `dim` argument instead (and ignore this one).
  int dim = 3;
  std::optional<Bounds> bounds;         ///< explicit domain; default: padded bbox
  double padding = 0.01;                ///< relative margin of the default domain (fraction of the largest extent)
  /// With explicit bounds: drop points outside instead of failing. Also,
  /// with or without bounds, points with a NaN or infinite coordinate (the
  /// default domain then comes from the others). Ids stay the input's; the
  /// dropped points are listed in Cells::ignored_outside_bounds.
  bool ignore_outside_points = false;
  /// 0 (or negative): TESSERA_NUM_THREADS, else all cores; at most max_threads.
  int threads = 0;
  double points_per_bin = 0;            ///< locator bin occupancy; 0 = automatic
  bool build_mesh = true;               ///< merged vertices + per-cell faces (needed for VTK output)
  CellMethod cell_method = CellMethod::automatic;  ///< tessera::voronoi only (Delaunay has its own)
  /// Periodic axes (tessera::voronoi only): the domain, `bounds`, which must
  /// be given, repeats along them (a simulation's or a crystal's unit cell),
  /// and each point's cell is its cell among all the images of all points.
  /// Along a periodic axis the box has no walls; points outside it are
  /// wrapped in, and the box and the coordinates along it are rounded to the
  /// spacing of doubles at a few box lengths from the origin, so that every
  /// image is exact (for a unit box 2^-51: each moves by at most 2^-52).
  /// Cells straddle the box's faces where their points lie near them.
  /// Cells::neighbor_shifts says which image each neighbour is. The
  /// adjacency graph, face sets, flowers and surface nets take periodic
  /// cells (faces.hpp: a face across the box names its side's image), and
  /// delaunay() takes periodic input where every axis is periodic.
  std::array<bool, 3> periodic{false, false, false};
  /// Tilt factors of a triclinic (sheared) periodic box, as lengths in
  /// LAMMPS's and Voro++'s convention: {xy, xz, yz}. The box repeats by the
  /// lattice vectors a = (Lx, 0, 0), b = (xy, Ly, 0), c = (xz, yz, Lz), with
  /// L the extents of `bounds`; it is the parallelepiped spanned by them
  /// from bounds' lower corner (2D: a = (Lx, 0), b = (xy, Ly); xz and yz
  /// must be 0). A tilt needs both of its axes periodic (xy: x and y).
  /// A tilt of more than one box length (|xy| or |xz| > Lx, |yz| > Ly) is
  /// reduced by whole lengths first (xy by Lx; yz by Ly, which moves xz by
  /// as many xy; then xz by Lx): the same lattice, in a box that is not thin
  /// (Cells::tilt reports the tilts used). Points are wrapped into the
  /// parallelepiped of the tilts used, rounded to the same grid as the
  /// coordinates, and Cells::neighbor_shifts count its lattice vectors.
  /// All zero: an orthogonal box.
  std::array<double, 3> tilt{0, 0, 0};
  /// Radii of spheres at the points (one per point, finite, >= 0; viewed,
  /// not copied: it must outlive the call), or empty. With them each cell is
  /// its point's power cell (radical or Laguerre cell: where the point's
  /// power |x - p|^2 - r^2 is the least; Voro++'s container_poly): the
  /// face with a neighbour lies on their spheres' radical plane. A point
  /// may then own no cell (Cells::empty_cells), or lie outside its own;
  /// of exactly coincident points the largest radius owns the cell (ties:
  /// the lowest id). All radii equal give the ordinary cells. In a periodic
  /// box every image has its point's radius. Either cell method builds
  /// them (the insertion from the regular triangulation's stars), and
  /// delaunay() takes them for the regular triangulation. Not for input
  /// that no power-of-two frame fits (coordinates spanning more than
  /// ~1e-150..1e150 of each other: InputError).
  std::span<const double> radii;
  /// Build only some cells (empty: all): those of these point ids (any
  /// order, repeats allowed; each in [0, n), InputError otherwise) and of
  /// the generators across their faces, whose cells place the merged
  /// vertices they share (the mesh takes a vertex from the cell of its
  /// lowest generator). Nothing else changes: every point takes part as
  /// without it (it sets the default domain, is located and clips, is
  /// checked; of duplicates the same one owns the cell; labels and radii
  /// count), and the cell method is chosen as for all the cells (the pilot
  /// samples them all; where it picks the insertion, all points are
  /// triangulated), so each cell built is bit for bit the cell of the whole
  /// computation, its merged vertices placed as there. In a periodic box
  /// the layer of images is the one the built cells need, which is
  /// narrower than all cells' where some other cell widened it
  /// (Cells::periodic_images): the same cells, whose vertices may then come
  /// in another order and differ in the last bits (the search meets the
  /// points in another order). The mesh numbers the merged vertices of the cells
  /// built only (each cell's vertices keep their relative order);
  /// Cells::generators counts every generator. A point asked for that owns
  /// no cell (outside label, duplicate, set aside) is left out. Viewed, not
  /// copied. For flowers of a few cells (flower.hpp), at a few cells' cost;
  /// not for validate(), which checks a whole tessellation (the volumes
  /// sum to the domain's, every vertex has all its cells) and refuses
  /// such cells (Cells::partial).
  std::span<const std::int32_t> only;
  /// Build only the cells that have a face of one of these spoke classes
  /// (0: every cell), where at most half the cells have one (else every
  /// cell, which is then faster: only_with_faces_up_to): the cells whose
  /// faces a face set of such faces reads
  /// (face_set_classes, faces.hpp: a boundary's are on the box or against
  /// outside points, a surface net's between regions). A first pass builds
  /// every cell without the mesh and finds them by their spokes; the pass
  /// set-up is shared as with `only` (the pilot and, where it picks the
  /// insertion, the triangulation, once), and each cell built is bit for
  /// bit the cell of the whole computation. Built alone, not with their
  /// neighbours: the merged vertices of their faces of these classes keep
  /// their owners, and so their positions and relative order. Such a
  /// vertex's key holds the D + 1 points (or box planes) around it, which
  /// pairwise share a face (also where exact ties are settled by the
  /// symbolic perturbation); each cell of the key faces the box plane or
  /// the outside point in it, or, the key holding two cells of different
  /// regions, faces a cell of another region: every cell of the key is
  /// built, and the lowest (the owner, CellsCompositor) is the whole
  /// computation's. So extract_faces of these cells gives the face set of
  /// all cells, byte for byte (docs/design.md, "Face sets of some cells").
  /// Cells::partial says whether some cell was left out, and then
  /// Cells::empty_cells lists every generator's empty power cell (the
  /// first pass saw them all). A set with same_region builds every cell:
  /// faces inside a region have no such closure (a cell of another region
  /// around their vertex may have none), and the face set that needs them,
  /// the complex, has faces in every cell. Not with `only` (InputError).
  /// In a periodic box every cell is built (some cells' images may differ
  /// in the last bits, see `only`).
  SpokeClassSet only_with_faces = 0;
  /// With only_with_faces: the largest share of the cells with such faces
  /// at which those alone are built; where more have them, every cell is
  /// built (Cells::partial false), which is then faster: the first pass
  /// costs about half of what the mesh of every cell does (docs/design.md,
  /// "Face sets of some cells"). The share is estimated from a sample of
  /// about 2,000 cells spread over the generators (up to 2,048 generators
  /// go straight to the first pass, and then their cells with such faces
  /// alone are built). 0: automatic (one half); 1: always some.
  double only_with_faces_up_to = 0;
  /// Walls (tessera::voronoi only): half-spaces that cut the domain box
  /// down to a convex polytope, the box's part inside every wall (a convex
  /// polygon in 2D: one wall per edge). Each cell is its box cell's part
  /// inside the walls, cut with the same exact predicates, so the cells
  /// stay conformal and their volumes sum to the polytope's; a wall's faces
  /// have spoke id wall_spoke(k) = -7 - k (below the box planes', -1..-6)
  /// and class domain_boundary. Every point must lie inside or on every
  /// wall (InputError, or set aside with ignore_outside_points, listed in
  /// Cells::ignored_outside_bounds). A normal must be finite and non-zero,
  /// an offset finite; both are scaled by one power of two, exactly, so
  /// that the largest normal component is in [1, 2). Not with a periodic
  /// box, nor for delaunay() (InputError). At most 2^20 walls.
  std::vector<Wall> walls;
  /// Some axis periodic, or a tilt given (which needs periodic axes).
  bool periodic_box() const {
    return periodic[0] || periodic[1] || periodic[2] || tilt[0] != 0 || tilt[1] != 0 || tilt[2] != 0;
  }
  /// Called from the calling thread with the fraction done, in [0,1]; may throw
  /// Cancelled to stop the run (the engine stops between batches).
  std::function<void(double)> progress;
};

/// The Voronoi tessellation of the inside points, clipped to the domain box.
///
/// Generators: the n input points. A generator "has a cell" when it is inside
/// (label >= 0 or no labels), within the domain, and not an exact duplicate of
/// a point that owns the cell. Cells are listed in generator-id order; `cell_of`
/// maps a generator to its cell index (-1 when it has none).
struct Cells {
  int dim = 3;
  std::size_t n_points = 0;
  Bounds bounds;
  /// VoronoiOptions::walls as given: the domain is `bounds` inside them.
  std::vector<Wall> walls;

  // ---- per cell (size n_cells, in generator-id order) ----
  Buffer<std::int32_t> generator;   ///< generator id of each cell
  Buffer<std::int32_t> region;      ///< its label (0 when no labels were given)
  Buffer<double> volume;            ///< area in 2D
  Buffer<double> centroid;          ///< n_cells * dim
  Buffer<std::int32_t> num_faces;   ///< faces (3D) / edges (2D), box faces included
  /// Face neighbours of each cell as CSR: the generator ids across its faces,
  /// ascending; box and wall faces are not listed (they are counted in num_faces).
  /// Exact ties keep the faces of zero area the symbolic perturbation makes
  /// (a cubic lattice's cell lists its 6 face neighbours and up to 8 more
  /// across faces of area 0): the topology is a valid one, exactly. The
  /// adjacency graph's prune_tolerance drops them (graph.hpp).
  Buffer<std::int64_t> neighbor_offsets;  ///< n_cells + 1
  Buffer<std::int32_t> neighbors;
  /// Periodic boxes only (VoronoiOptions::periodic), else empty: for each
  /// entry of `neighbors`, dim shifts: the face is shared with the image of
  /// that point moved by shift[a] box lengths along axis a (0 on axes that
  /// are not periodic); in a triclinic box by shift[0] a + shift[1] b +
  /// shift[2] c (the lattice vectors of Cells::tilt, the tilts used). A point may be listed more than once (several of
  /// its images, in a box only a few cells wide), even as its own
  /// neighbour; entries are ascending by id, then by shift.
  Buffer<std::int8_t> neighbor_shifts;

  // ---- per generator (size n_points) ----
  std::vector<std::int32_t> cell_of;     ///< cell index or -1

  // ---- the conformal mesh (only with build_mesh) ----
  /// Merged vertices: one per topological coordinate.
  Buffer<double> vertices;          ///< n_vertices * dim
  /// Topological coordinate of each vertex: dim+1 ids, ascending; domain-box
  /// planes are negative (-1-axis*2 for lo, -2-axis*2 for hi: x0=-1, x1=-2, y0=-3, ...),
  /// walls below them (wall k: wall_spoke(k) = -7-k).
  /// In a periodic box the ids are those of the points whose images meet
  /// there, without the shifts: a vertex shared by cells on opposite sides
  /// of the box is listed once beside each, and keys need not be unique.
  Buffer<std::int32_t> vertex_keys; ///< n_vertices * (dim+1)
  /// Periodic boxes only, else empty: per key entry, dim shifts of that
  /// point's image (n_vertices * (dim+1) * dim); a key is then ascending by
  /// (id, shift), and two keys that differ by a common shift are the same
  /// Delaunay simplex seen from different cells.
  Buffer<std::int8_t> vertex_key_shifts;
  /// 3D: faces of each cell: cell_face_offsets (n_cells+1) into faces; each face
  /// has face_vertex_offsets (n_faces_total+1) into face_vertices (global vertex
  /// ids, counter-clockwise seen from outside the cell) and face_neighbor (the
  /// spoke: generator id, or the negative box-plane id, or a wall's wall_spoke).
  /// 2D: one face per edge; face_vertices holds the edge's two vertices (the
  /// polygon's vertices, counter-clockwise, are the first vertex of each edge in order).
  Buffer<std::int64_t> cell_face_offsets;
  Buffer<std::int64_t> face_vertex_offsets;
  Buffer<std::int32_t> face_vertices;
  Buffer<std::int32_t> face_neighbor;
  Buffer<SpokeClass> face_class;
  /// Periodic boxes only, else empty: per face, dim shifts of its neighbour's
  /// image (as neighbor_shifts; 0 for a wall).
  Buffer<std::int8_t> face_shift;

  // ---- diagnostics ----
  /// Pairs (duplicate id, owner id): exactly coincident inputs; the lowest id owns the cell
  /// (with VoronoiOptions::radii the largest radius, then the lowest id).
  std::vector<std::pair<std::int32_t, std::int32_t>> duplicates;
  std::vector<std::int32_t> ignored_outside_bounds;  ///< with ignore_outside_points
  /// Power cells only (VoronoiOptions::radii): generators whose cell is
  /// empty (their sphere's power is nowhere the least), ascending; they have
  /// no cell (cell_of -1) and nobody lists them as a neighbour.
  std::vector<std::int32_t> empty_cells;
  /// Whether the cells are power cells (VoronoiOptions::radii, not all equal).
  bool power = false;
  std::uint64_t exact_predicate_calls = 0;          ///< filter failures resolved exactly
  /// Points far beyond the bulk of the input along some axis (a few points
  /// that stretch the default domain to over four times the bulk's extent:
  /// likely outliers). The search grid spans the bulk, and their cells come
  /// from a k-d tree; reported so that a user can spot them.
  std::size_t far_points = 0;
  /// The generators of the whole computation: the points that take part
  /// with a label >= 0 (or no labels) and are no duplicate. n_cells() but
  /// for power cells found empty, and with VoronoiOptions::only or
  /// only_with_faces, which build some of their cells.
  std::size_t generators = 0;
  /// Some cells only, not a whole tessellation: VoronoiOptions::only or
  /// only_with_faces left some generator's cell out. validate() and
  /// adjacency_graph() refuse such cells (std::invalid_argument), and
  /// extract_faces() takes them only where with_faces_of covers its face
  /// set; flowers() takes them.
  bool partial = false;
  /// VoronoiOptions::only_with_faces where it left cells out (else 0):
  /// every cell with a face of one of these classes is here.
  SpokeClassSet with_faces_of = 0;
  int threads_used = 1;
  /// The cells came from the Delaunay triangulation by insertion (CellMethod).
  bool from_insertion = false;
  /// Of those, the cells assembled from their Delaunay stars with no clip
  /// (points on the hull too); the rest (cells with a vertex within
  /// rounding of the box, or one too ill-conditioned for the float solve
  /// and far out, or stars of over 500 neighbours in 3D) were clipped by
  /// their stars' vertices.
  std::size_t assembled_from_stars = 0;
  /// Generators whose cells the automatic method's pilot built whole while
  /// it sampled what the search costs, kept where the search was chosen
  /// instead of being built again (the same cells).
  std::size_t cells_from_pilot = 0;
  /// Periodic boxes: the periodic axes (VoronoiOptions::periodic; `bounds`
  /// is then the box as rounded), the images of points that took part, and
  /// how far beyond the box they reached along each periodic axis.
  std::array<bool, 3> periodic{false, false, false};
  /// A triclinic box's tilts {xy, xz, yz} as used: VoronoiOptions::tilt
  /// rounded, and reduced by whole box lengths where one was more than a
  /// length. The shifts count the lattice vectors of these (lattice()).
  std::array<double, 3> tilt{0, 0, 0};
  /// Periodic boxes only, else empty: the points as the cells took them,
  /// n_points * dim, wrapped into the box and rounded to its grid (rows of
  /// points set aside as given). Neighbour shifts are relative to these.
  std::vector<double> periodic_points;
  std::size_t periodic_images = 0;
  std::array<double, 3> image_reach{0, 0, 0};

  bool is_periodic() const { return periodic[0] || periodic[1] || periodic[2]; }
  /// A periodic box's lattice vectors (periodic_lattice).
  std::array<std::array<double, 3>, 3> lattice() const { return periodic_lattice(bounds, tilt); }
  std::size_t n_cells() const { return generator.size(); }
  std::size_t n_vertices() const { return vertex_keys.size() / (dim + 1); }
};

/// Compute the cells. `points` holds n*dim doubles (row-major). `labels` is
/// empty or n ints (label < 0: outside, clips neighbours, owns no cell).
/// Throws InputError on bad input.
Cells voronoi(std::span<const double> points, int dim, std::span<const std::int32_t> labels,
              const VoronoiOptions& options);

/// The domain's volume (area in 2D): `box` inside `walls` (VoronoiOptions::
/// walls), 0 where they leave nothing; the box's volume without walls.
/// Computed in double precision by the cell kernels; past 256 walls on
/// `threads` threads (0: TESSERA_NUM_THREADS or all cores), the same result
/// on any number. Throws InputError for walls voronoi() refuses.
double domain_volume(const Bounds& box, const std::vector<Wall>& walls, int dim, int threads = 0);

/// The convex hull of `points` (n x dim, row-major; dim 2 or 3) as walls,
/// for VoronoiOptions::walls: cells bounded by the hull instead of a box. One
/// wall per hull facet (an edge in 2D), facets in one plane merged; each
/// wall's normal points outwards (not unit length) and its offset is such
/// that every point lies inside it exactly, the wall passing within ~1e-14
/// of the coordinates' magnitude of the facet's plane (exactly on it where
/// the arithmetic is exact, as on lattices), pushed out by `dilation` (a
/// distance >= 0 along the normal). From the Delaunay triangulation of the points that
/// may be hull vertices (threads as VoronoiOptions::threads). Throws
/// InputError for fewer than dim + 1 points, a non-finite coordinate, points
/// that span no area (volume), or coordinates whose normals or offsets over-
/// or underflow.
std::vector<Wall> hull_walls(std::span<const double> points, int dim, double dilation = 0, int threads = 0);

/// Invariant checks on a result (the CLI's --validate).
struct ValidationReport {
  bool ok = true;
  double volume_sum = 0, domain_volume = 0, volume_rel_error = 0;
  /// False when the volumes are outside double's range at this scale (the
  /// domain's volume, or a cell's share of it, overflows or underflows, as
  /// with coordinates near 1e-120 or 1e120): the volume checks are skipped.
  /// The cells were computed in a rescaled frame; only their volumes in the
  /// input's units cannot be represented.
  bool volumes_checked = true;
  std::size_t asymmetric_spokes = 0;      ///< i lists j but j does not list i (both inside)
  std::size_t bad_vertex_degree = 0;      ///< merged vertices not shared by exactly the cells of their key
  std::size_t bad_euler = 0;              ///< cells with V - E + F != 2 (3D)
  /// Cells whose exact volume is below the smallest double, reported as 0
  /// (points within ~1e-160 of each other): not a failure.
  std::size_t underflowed_volumes = 0;
  /// Cells whose volume and centroid were compared with their exact values
  /// (exact arithmetic from the input points and the merged vertices'
  /// keys): a sample, the smallest, the most elongated and some spread over
  /// the output (see validate). 0 where no points were given, without the
  /// mesh, or where volumes are not checked.
  std::size_t measures_checked = 0;
  double measure_rel_error = 0;           ///< the largest relative volume error among them
  std::int32_t measure_worst = -1;        ///< the generator of that cell (-1: none checked)
  /// The largest distance (max norm) of a corner of those cells from its
  /// exact position (solved from its key), relative to its cell's radius,
  /// and that merged vertex (-1: none checked).
  double vertex_rel_error = 0;
  std::int32_t vertex_worst = -1;
  std::vector<std::string> messages;      ///< one line each
};
/// The sampled exact check fails a cell whose volume errs by more than this,
/// relatively (four times the 2^-30 the measure keeps: docs/design.md,
/// "Strip areas"), or whose centroid errs by more than this times the
/// cell's radius (plus the rounding of adding the generator's coordinates),
/// or one of whose corners lies farther than that from its exact position.
inline constexpr double measure_tolerance = 0x1p-28;
/// `labels`: those the cells were computed with (empty: none), which say
/// whether outside points carve the domain (then the volumes are not summed
/// against it); std::invalid_argument where not empty and not n_points long.
/// `points` (n_points x dim, the coordinates the cells were computed from)
/// enables the exact check of sampled cells' measures; an empty span skips
/// it. std::invalid_argument where its size is not n_points x dim. Cells of
/// a periodic box: neighbour entries must pair up with opposite shifts, a
/// merged vertex is used by the cells of its key's points at shift 0
/// (Cells::vertex_key_shifts), and the exact-measure check is left out.
/// Power cells (Cells::power) measure exactly with their `radii`, which
/// must then come with the points (std::invalid_argument otherwise).
/// Cells that are some only (Cells::partial) are refused
/// (std::invalid_argument): the checks are of a whole tessellation.
ValidationReport validate(const Cells& cells, std::span<const std::int32_t> labels,
                          std::span<const double> points = {}, std::span<const double> radii = {});

/// Whether the cell volumes of a domain of volume `domain_volume` cut into
/// `cells` cells are normal doubles (the rule behind volumes_checked): the
/// domain's at most 1e300, so their sum cannot overflow, and the mean
/// cell's at least 1e-290, above the subnormals by a factor that leaves room
/// for cells far smaller than the mean.
inline bool volumes_representable(double domain_volume, std::size_t cells) {
  return std::isnormal(domain_volume) && domain_volume <= 1e300 &&
         domain_volume / static_cast<double>(cells > 0 ? cells : 1) >= 1e-290;
}

/// The most threads a call may ask for: more than cores runs oversubscribed
/// (engine::ThreadArena), and each thread costs a stack and a workspace.
inline constexpr int max_threads = 4096;

/// Resolved thread count for an option value (0 -> TESSERA_NUM_THREADS or
/// hardware). InputError above max_threads, or for a malformed variable.
int resolve_threads(int requested);

}  // namespace tessera

// Front end: face sets of a tessellation — the domain boundary, the
// polygonal complex and surface nets.
//
// A face set is a list of Voronoi faces (3D: convex polygons; 2D: line
// segments) over the topologically merged vertices of Cells, each face listed
// once, with the two sides it separates.
//
// Sides and orientation. Every face separates side 0, a cell, from side 1, a
// cell, an outside point or a domain-box plane. Side 0 is
//   * the cell, when the other side is not a cell (box or outside point);
//   * otherwise the cell with the smaller (region label, generator id):
//     across a region interface the lower label, inside a region the lower id.
// Faces are oriented from side 0 towards side 1: in 3D the polygon is
// counter-clockwise seen from side 1 (its right-hand normal points into side
// 1, so boundary faces face outward); in 2D the segment runs with side 0 on
// its left (counter-clockwise around side 0's tile), so its right-hand normal
// (dy, -dx) points into side 1.
//
// Periodic boxes (cells computed with VoronoiOptions::periodic). Side 1 of a
// face between cells is an image of its point (FaceSet::side_shifts), and
// side 0's cell sits at shift 0: a face's vertices are those of side 0's cell
// as computed (Cells: one copy of a vertex per frame it is seen from), so a
// face set is a set of pieces that fit together across the box's faces by
// lattice translations. Side 0 is chosen by (region label, generator id) as
// above; a face between a cell and an image of itself is taken from the side
// whose shift towards the other is lexicographically positive.
//
// BoundaryLabels (two per face) are the labels of side 0 and side 1. Side 0
// always holds a cell's label (>= 0). Side 1 holds the neighbour's label: a
// cell's region, an outside point's own (negative) label, or
// FaceSetOptions::background_label for a domain-box plane. Without labels
// every cell's label is 0.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <optional>
#include <span>
#include <string_view>
#include <vector>

#include "tessera/cells.hpp"

namespace tessera {

enum class FaceSetKind : std::uint8_t {
  /// Faces on the domain box or against outside points: the boundary of the
  /// union of all cells, outward.
  boundary = 0,
  /// Every Voronoi face exactly once: between cells (same region or not), on
  /// the box and against outside points.
  complex = 1,
  /// Faces between cells of different regions; with capping also the
  /// boundary faces, so that every region is enclosed.
  surface_net = 2,
};

/// "boundary", "complex", "surface-net" (also "surface_net").
std::optional<FaceSetKind> parse_face_set_kind(std::string_view name);
const char* face_set_kind_name(FaceSetKind kind);

struct FaceSetOptions {
  FaceSetKind kind = FaceSetKind::boundary;
  bool capping = false;              ///< surface_net: add the boundary faces
  std::int32_t background_label = -1;  ///< BoundaryLabels value of a domain-box side (must be < 0)
  /// As VoronoiOptions::progress: called between chunks of cells (once per
  /// pass over them), it may throw Cancelled to stop.
  std::function<void(double)> progress;
};

struct FaceSet {
  int dim = 3;
  FaceSetKind kind = FaceSetKind::boundary;
  /// The merged vertices of Cells that the faces use, in ascending order of
  /// their Cells vertex id, and their topological coordinates.
  std::vector<double> vertices;            ///< n_vertices * dim
  std::vector<std::int32_t> vertex_keys;   ///< n_vertices * (dim + 1)
  /// Faces as CSR into face_vertices (ids into `vertices`); 2D faces have two.
  std::vector<std::int64_t> face_offsets;  ///< n_faces + 1
  std::vector<std::int32_t> face_vertices;
  /// Per face: side 0's generator, then side 1's generator or negative
  /// box-plane id (x0=-1, x1=-2, y0=-3, ...).
  std::vector<std::int32_t> sides;            ///< n_faces * 2
  std::vector<std::int32_t> boundary_labels;  ///< n_faces * 2, see the header comment
  std::vector<SpokeClass> face_class;         ///< the spoke from side 0 to side 1
  /// Periodic cells only, else empty: per face, dim shifts of side 1's image
  /// (Cells::face_shift of side 0's face: box lengths along each axis, or
  /// lattice vectors in a triclinic box; zeros for a box plane).
  std::vector<std::int8_t> side_shifts;       ///< n_faces * dim
  /// Periodic cells only, else empty: per key entry, dim shifts of that
  /// point's image (Cells::vertex_key_shifts). Two vertices whose keys agree
  /// up to a common shift t are copies of one vertex, t lattice vectors apart.
  std::vector<std::int8_t> vertex_key_shifts;  ///< n_vertices * (dim + 1) * dim
  /// The periodic axes and the lattice vectors (Cells::periodic, lattice()).
  std::array<bool, 3> periodic{false, false, false};
  std::array<std::array<double, 3>, 3> lattice{};
  /// The cells' walls (Cells::walls): a vertex key's id -7-k names wall k
  /// (the surface nets' smoothing keeps such vertices on their walls).
  std::vector<Wall> walls;

  std::size_t n_faces() const { return face_offsets.empty() ? 0 : face_offsets.size() - 1; }
  std::size_t n_vertices() const { return vertex_keys.size() / static_cast<std::size_t>(dim + 1); }
  bool is_periodic() const { return periodic[0] || periodic[1] || periodic[2]; }
};

/// Copies of one vertex in a periodic face set. Periodic cells keep their
/// vertices in their own frames (a vertex shared by cells on opposite sides
/// of the box is listed once beside each), so a face set of them holds
/// several copies of one Voronoi vertex, lattice translations apart; their
/// keys agree up to a common shift (FaceSet::vertex_key_shifts). Whatever
/// moves one copy (the surface nets' smoothing) moves all of them alike, and
/// a surface is closed in the box when its edges pair up between copies.
struct VertexCopies {
  /// Per vertex: its group (the copies of one vertex), numbered by first vertex.
  std::vector<std::int32_t> group;
  /// Per group: its first vertex (the lowest id).
  std::vector<std::int32_t> first;
  /// Per vertex, dim integers (periodic face sets only, else empty): the
  /// lattice translation from its group's first vertex to it, in lattice
  /// vectors (FaceSet::lattice).
  std::vector<std::int32_t> shift;

  std::size_t n_groups() const { return first.size(); }
  bool periodic() const { return !shift.empty(); }
};

/// The copies of each vertex of `faces` (every vertex alone, with no
/// shifts, when it is not periodic). std::invalid_argument for a periodic
/// face set without a shift per key entry.
VertexCopies vertex_copies(const FaceSet& faces);

/// The spoke classes of the faces of a face set: domain_boundary and
/// outside for the boundary; region_boundary for a surface net, with
/// capping those two as well; every class for the complex. The cells
/// computed with VoronoiOptions::only_with_faces = face_set_classes(options)
/// are those with a face of the set, and their face set is the one of all
/// cells, byte for byte (for the complex every cell is built).
SpokeClassSet face_set_classes(const FaceSetOptions& options);

/// Extract a face set from cells computed with VoronoiOptions::build_mesh
/// (std::invalid_argument otherwise, and for cells that are some only,
/// Cells::partial, unless Cells::with_faces_of holds face_set_classes). `labels` are the labels the cells were
/// computed with (empty or one per point); they give outside points' labels.
/// Faces are listed in cell (generator-id) order, each cell's faces in its
/// mesh order. Throws InputError for labels of the wrong length or a
/// background label >= 0.
FaceSet extract_faces(const Cells& cells, std::span<const std::int32_t> labels, const FaceSetOptions& options);

}  // namespace tessera

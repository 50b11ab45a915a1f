// tessera::extract_faces: boundary, polygonal complex and surface-net face
// sets over the merged mesh (conventions in include/tessera/faces.hpp).
#include "tessera/faces.hpp"

#include <algorithm>
#include <atomic>
#include <numeric>
#include <stdexcept>
#include <string>
#include <utility>

#include "mesh_faces.hpp"

namespace tessera {

std::optional<FaceSetKind> parse_face_set_kind(std::string_view name) {
  if (name == "boundary") return FaceSetKind::boundary;
  if (name == "complex") return FaceSetKind::complex;
  if (name == "surface-net" || name == "surface_net") return FaceSetKind::surface_net;
  return std::nullopt;
}

const char* face_set_kind_name(FaceSetKind kind) {
  switch (kind) {
    case FaceSetKind::boundary: return "boundary";
    case FaceSetKind::complex: return "complex";
    case FaceSetKind::surface_net: return "surface-net";
  }
  return "?";
}

SpokeClassSet face_set_classes(const FaceSetOptions& options) {
  const SpokeClassSet bounding =
      spoke_class_bit(SpokeClass::domain_boundary) | spoke_class_bit(SpokeClass::outside);
  switch (options.kind) {
    case FaceSetKind::boundary: return bounding;
    case FaceSetKind::complex: return bounding | spoke_class_bit(SpokeClass::same_region) |
                                      spoke_class_bit(SpokeClass::region_boundary);
    case FaceSetKind::surface_net:
      return spoke_class_bit(SpokeClass::region_boundary) | (options.capping ? bounding : SpokeClassSet{0});
  }
  return 0;
}

namespace {

/// Which faces of a cell belong to the set: faces of the classes
/// face_set_classes names, each once. Every face of the tessellation is
/// seen from each cell on its sides; a face between two cells is taken from
/// side 0 only, so each face is listed once and already oriented from side 0
/// to side 1 (cell faces are counter-clockwise seen from outside their cell).
class FaceSelector {
 public:
  FaceSelector(const Cells& c, const FaceSetOptions& o) : c_(c), o_(o) {}

  bool operator()(std::size_t cell, std::size_t face) const {
    const SpokeClass cls = c_.face_class[face];
    const bool bounding = cls == SpokeClass::domain_boundary || cls == SpokeClass::outside;
    switch (o_.kind) {
      case FaceSetKind::boundary: return bounding;
      case FaceSetKind::complex: return bounding || is_side0(cell, face);
      case FaceSetKind::surface_net:
        return (cls == SpokeClass::region_boundary && is_side0(cell, face)) || (o_.capping && bounding);
    }
    return false;
  }

 private:
  /// Between two cells: does `cell` have the smaller (region, generator)?
  /// In a periodic box its twin is the face of the neighbour's cell towards
  /// the opposite shift, so a face with an image of the cell itself is taken
  /// where its shift is lexicographically positive (faces.hpp).
  bool is_side0(std::size_t cell, std::size_t face) const {
    const std::int32_t neighbor = c_.face_neighbor[face];
    const auto other = static_cast<std::size_t>(c_.cell_of[static_cast<std::size_t>(neighbor)]);
    const auto mine = std::pair(c_.region[cell], c_.generator[cell]), theirs = std::pair(c_.region[other], neighbor);
    if (mine != theirs || c_.face_shift.empty()) return mine < theirs;
    const std::int8_t* s = &c_.face_shift[face * static_cast<std::size_t>(c_.dim)];
    for (int a = 0; a < c_.dim; ++a)
      if (s[a] != 0) return s[a] > 0;
    return false;  // a face with itself at shift 0 does not exist
  }

  const Cells& c_;
  const FaceSetOptions& o_;
};

}  // namespace

FaceSet extract_faces(const Cells& c, std::span<const std::int32_t> labels, const FaceSetOptions& options) {
  front::require_mesh(c, "extract_faces", true);
  // Some cells only: those with a face of the set's classes suffice
  // (VoronoiOptions::only_with_faces), others (VoronoiOptions::only) miss faces.
  if (c.partial && (c.with_faces_of == 0 || (face_set_classes(options) & ~c.with_faces_of) != 0))
    throw std::invalid_argument(std::string("extract_faces: these cells are some only (Cells::partial), not every "
                                            "cell with a face of a ") +
                                face_set_kind_name(options.kind) +
                                " face set (VoronoiOptions::only_with_faces = face_set_classes)");
  if (!labels.empty() && labels.size() != c.n_points)
    throw InputError("labels: " + std::to_string(labels.size()) + " values for " + std::to_string(c.n_points) +
                     " points");
  if (options.background_label >= 0)
    throw InputError("background label must be negative (labels >= 0 are regions), got " +
                     std::to_string(options.background_label));
  if (labels.empty() && std::find(c.face_class.begin(), c.face_class.end(), SpokeClass::outside) != c.face_class.end())
    throw InputError("labels: these cells have outside points; pass the labels they were computed with");
  const int D = c.dim;
  const std::size_t nc = c.n_cells(), nv = c.n_vertices();
  const auto& cfo = c.cell_face_offsets;
  const auto& fvo = c.face_vertex_offsets;
  const FaceSelector selected(c, options);

  FaceSet out;
  out.dim = D;
  out.kind = options.kind;
  const bool periodic = c.is_periodic();
  if (periodic) {
    out.periodic = c.periodic;
    out.lattice = c.lattice();
  }
  out.walls = c.walls;

  // Pass 1: per cell, the faces and corners it contributes; mark used vertices.
  std::vector<std::int64_t> face_start(nc + 1, 0), corner_start(nc + 1, 0);
  std::vector<std::uint8_t> used(nv, 0);
  front::for_each_cell(c, [&](std::size_t k) {
    std::int64_t faces = 0, corners = 0;
    for (auto f = cfo[k]; f < cfo[k + 1]; ++f) {
      const auto fu = static_cast<std::size_t>(f);
      if (!selected(k, fu)) continue;
      ++faces;
      corners += fvo[fu + 1] - fvo[fu];
      for (auto q = fvo[fu]; q < fvo[fu + 1]; ++q)
        std::atomic_ref<std::uint8_t>(used[static_cast<std::size_t>(c.face_vertices[static_cast<std::size_t>(q)])])
            .store(1, std::memory_order_relaxed);
    }
    face_start[k + 1] = faces;
    corner_start[k + 1] = corners;
  }, options.progress);
  std::partial_sum(face_start.begin(), face_start.end(), face_start.begin());
  std::partial_sum(corner_start.begin(), corner_start.end(), corner_start.begin());

  // Used vertices keep their relative order.
  std::vector<std::int32_t> new_id(nv, -1);
  std::int32_t nu = 0;
  for (std::size_t v = 0; v < nv; ++v)
    if (used[v]) new_id[v] = nu++;
  const std::size_t dn = static_cast<std::size_t>(D), kn = dn + 1;
  out.vertices.resize(static_cast<std::size_t>(nu) * dn);
  out.vertex_keys.resize(static_cast<std::size_t>(nu) * kn);
  if (periodic) out.vertex_key_shifts.resize(static_cast<std::size_t>(nu) * kn * dn);
  for (std::size_t v = 0; v < nv; ++v) {
    if (new_id[v] < 0) continue;
    const auto w = static_cast<std::size_t>(new_id[v]);
    std::copy_n(&c.vertices[v * dn], dn, &out.vertices[w * dn]);
    std::copy_n(&c.vertex_keys[v * kn], kn, &out.vertex_keys[w * kn]);
    if (periodic) std::copy_n(&c.vertex_key_shifts[v * kn * dn], kn * dn, &out.vertex_key_shifts[w * kn * dn]);
  }

  // Pass 2: fill.
  const std::size_t nf = static_cast<std::size_t>(face_start[nc]);
  out.face_offsets.resize(nf + 1);
  out.face_offsets[0] = 0;
  out.face_vertices.resize(static_cast<std::size_t>(corner_start[nc]));
  out.sides.resize(2 * nf);
  out.boundary_labels.resize(2 * nf);
  out.face_class.resize(nf);
  if (periodic) out.side_shifts.resize(nf * dn);
  front::for_each_cell(c, [&](std::size_t k) {
    auto o = static_cast<std::size_t>(face_start[k]);
    auto q = static_cast<std::size_t>(corner_start[k]);
    for (auto f = cfo[k]; f < cfo[k + 1]; ++f) {
      const auto fu = static_cast<std::size_t>(f);
      if (!selected(k, fu)) continue;
      for (auto t = fvo[fu]; t < fvo[fu + 1]; ++t)
        out.face_vertices[q++] = new_id[static_cast<std::size_t>(c.face_vertices[static_cast<std::size_t>(t)])];
      out.face_offsets[o + 1] = static_cast<std::int64_t>(q);
      const std::int32_t j = c.face_neighbor[fu];
      const SpokeClass cls = c.face_class[fu];
      std::int32_t other_label = options.background_label;
      if (cls == SpokeClass::outside)
        other_label = labels[static_cast<std::size_t>(j)];
      else if (cls == SpokeClass::same_region || cls == SpokeClass::region_boundary)
        other_label = c.region[static_cast<std::size_t>(c.cell_of[static_cast<std::size_t>(j)])];
      out.sides[2 * o] = c.generator[k];
      out.sides[2 * o + 1] = j;
      out.boundary_labels[2 * o] = c.region[k];
      out.boundary_labels[2 * o + 1] = other_label;
      out.face_class[o] = cls;
      if (periodic) std::copy_n(&c.face_shift[fu * dn], dn, &out.side_shifts[o * dn]);
      ++o;
    }
  }, options.progress);
  return out;
}

}  // namespace tessera

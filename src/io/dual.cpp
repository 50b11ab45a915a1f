// Writers for the adjacency graph, face sets and flowers (include/tessera/io/dual.hpp).
#include "tessera/io/dual.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <numeric>
#include <stdexcept>
#include <vector>

#include "tessera/io/atomic_file.hpp"
#include "tessera/io/npy.hpp"
#include "tessera/io/vtk_polydata.hpp"

namespace tessera::io {
namespace {

/// SpokeClass is a one-byte enum: its arrays are written as UInt8 in place.
std::span<const std::uint8_t> class_bytes(const std::vector<SpokeClass>& v) {
  static_assert(sizeof(SpokeClass) == 1);
  return {reinterpret_cast<const std::uint8_t*>(v.data()), v.size()};
}

void check_points(std::span<const double> points, std::size_t n, int dim, const char* who) {
  if (points.size() != n * static_cast<std::size_t>(dim))
    throw std::invalid_argument(std::string(who) + ": points are not the array the product was computed from");
}

}  // namespace

// ------------------------------------------------------------------ graph

void write_graph_vtp(const std::string& path, const AdjacencyGraph& g, std::span<const double> points,
                     std::span<const std::int32_t> labels) {
  check_points(points, g.n_points, g.dim, "write_graph_vtp");
  if (!labels.empty() && labels.size() != g.n_points)
    throw std::invalid_argument("write_graph_vtp: labels do not match the points");
  const GraphEdges edges = graph_edges(g);
  const std::size_t ne = edges.size();
  std::vector<std::int64_t> offsets(ne + 1);
  for (std::size_t e = 0; e <= ne; ++e) offsets[e] = static_cast<std::int64_t>(2 * e);
  std::vector<std::uint8_t> cls(ne);
  std::vector<double> measure(ne);
  for (std::size_t e = 0; e < ne; ++e) {
    const auto s = static_cast<std::size_t>(edges.spoke[e]);
    cls[e] = static_cast<std::uint8_t>(g.spoke_class[s]);
    measure[e] = g.spoke_measure[s];
  }
  std::vector<std::int32_t> region = labels.empty() ? std::vector<std::int32_t>(g.n_points, 0)
                                                    : std::vector<std::int32_t>(labels.begin(), labels.end());

  PolyData pd;
  pd.dim = g.dim;
  pd.points = points;
  pd.lines = {offsets, edges.ends};
  // A periodic graph: edges to images end at extra points, one per edge
  // with a shift, placed at the image (the point moved by its lattice vectors).
  std::vector<double> all_points;
  std::vector<std::int32_t> ends, point_id;
  if (!edges.shift.empty()) {
    const auto du = static_cast<std::size_t>(g.dim);
    all_points.assign(points.begin(), points.end());
    ends = edges.ends;
    point_id.resize(g.n_points);
    std::iota(point_id.begin(), point_id.end(), 0);
    for (std::size_t e = 0; e < ne; ++e) {
      const std::int8_t* s = &edges.shift[e * du];
      if (std::all_of(s, s + du, [](std::int8_t x) { return x == 0; })) continue;
      const auto j = static_cast<std::size_t>(ends[2 * e + 1]);
      double x[3];
      periodic_image(g.lattice, g.dim, &points[j * du], s, x);
      all_points.insert(all_points.end(), x, x + du);
      ends[2 * e + 1] = static_cast<std::int32_t>(point_id.size());
      point_id.push_back(static_cast<std::int32_t>(j));
      region.push_back(region[j]);
    }
    pd.points = all_points;
    pd.lines = {offsets, ends};
    pd.point_data.push_back({"PointId", std::span<const std::int32_t>(point_id)});
  }
  pd.point_data.push_back({"Region", std::span<const std::int32_t>(region)});
  pd.cell_data.push_back({"SpokeClass", std::span<const std::uint8_t>(cls)});
  pd.cell_data.push_back({g.dim == 3 ? "FaceArea" : "FaceLength", std::span<const double>(measure)});
  write_polydata(path, pd);
}

void write_graph_csr_npy(const std::string& path, const AdjacencyGraph& g) {
  std::vector<std::int64_t> a;
  a.reserve(1 + g.wheel_offsets.size() + g.spokes.size());
  a.push_back(static_cast<std::int64_t>(g.n_points));
  a.insert(a.end(), g.wheel_offsets.begin(), g.wheel_offsets.end());
  a.insert(a.end(), g.spokes.begin(), g.spokes.end());
  write_file_atomic(path, npy_bytes(a.data(), {a.size()}));
}

void write_spoke_shifts_npy(const std::string& path, const AdjacencyGraph& g) {
  if (g.spoke_shift.empty()) throw std::invalid_argument("write_spoke_shifts_npy: the graph is not periodic");
  const auto du = static_cast<std::size_t>(g.dim);
  write_file_atomic(path, npy_bytes(g.spoke_shift.data(), {g.spoke_shift.size() / du, du}));
}

void write_spoke_classes_npy(const std::string& path, const AdjacencyGraph& g) {
  write_file_atomic(path, npy_bytes(class_bytes(g.spoke_class).data(), {g.spoke_class.size()}));
}

void write_spoke_measures_npy(const std::string& path, const AdjacencyGraph& g) {
  write_file_atomic(path, npy_bytes(g.spoke_measure.data(), {g.spoke_measure.size()}));
}

// ------------------------------------------------------------------ faces

namespace {
/// A periodic face set's side shifts as VTK cell data (int32: the writer has
/// no int8 arrays), one D-component tuple per face; none for a set that is
/// not periodic. An empty periodic set has the array too, with no tuples:
/// a reader of a series of frames finds the same arrays in every file.
std::vector<std::int32_t> side_shift_data(const FaceSet& fs, PolyData& pd) {
  std::vector<std::int32_t> wide(fs.side_shifts.begin(), fs.side_shifts.end());
  if (fs.is_periodic()) pd.cell_data.push_back({"SideShift", std::span<const std::int32_t>(wide), fs.dim});
  return wide;
}
}  // namespace

void write_faces_vtp(const std::string& path, const FaceSet& fs) {
  PolyData pd;
  pd.dim = fs.dim;
  pd.points = fs.vertices;
  (fs.dim == 3 ? pd.polys : pd.lines) = {fs.face_offsets, fs.face_vertices};
  pd.cell_data.push_back({"BoundaryLabels", std::span<const std::int32_t>(fs.boundary_labels), 2});
  pd.cell_data.push_back({"Sides", std::span<const std::int32_t>(fs.sides), 2});
  pd.cell_data.push_back({"SpokeClass", class_bytes(fs.face_class)});
  const std::vector<std::int32_t> shifts = side_shift_data(fs, pd);
  write_polydata(path, pd);
}

void write_surface_net_vtp(const std::string& path, const SurfaceNet& net) {
  const FaceSet& fs = net.mesh;
  static_assert(sizeof(NetVertexKind) == 1);
  PolyData pd;
  pd.dim = fs.dim;
  pd.points = fs.vertices;
  (fs.dim == 3 ? pd.polys : pd.lines) = {fs.face_offsets, fs.face_vertices};
  pd.point_data.push_back({"VertexKind", std::span<const std::uint8_t>(
                                             reinterpret_cast<const std::uint8_t*>(net.vertex_kind.data()),
                                             net.vertex_kind.size())});
  pd.cell_data.push_back({"BoundaryLabels", std::span<const std::int32_t>(fs.boundary_labels), 2});
  pd.cell_data.push_back({"Sides", std::span<const std::int32_t>(fs.sides), 2});
  pd.cell_data.push_back({"SpokeClass", class_bytes(fs.face_class)});
  pd.cell_data.push_back({"PolygonId", std::span<const std::int64_t>(net.polygon_of_face)});
  const std::vector<std::int32_t> shifts = side_shift_data(fs, pd);
  write_polydata(path, pd);
}

// ------------------------------------------------------------------ flowers

namespace {

/// Accumulates the flower PolyData: points with their data, and the three
/// cell kinds with theirs (kept apart, since VTK orders verts, lines, polys).
class FlowerMesh {
 public:
  explicit FlowerMesh(int dim) : dim_(dim) {}

  struct CellKind {
    std::vector<std::int64_t> offsets{0};
    std::vector<std::int32_t> ids;
    std::vector<std::uint8_t> role;
    std::vector<std::int32_t> generator, spoke;
  };

  std::int32_t point(const double* x, double radius, FlowerRole role, std::int32_t gen, std::int32_t id) {
    coords_.insert(coords_.end(), x, x + dim_);
    radius_.push_back(radius);
    role_.push_back(static_cast<std::uint8_t>(role));
    generator_.push_back(gen);
    point_id_.push_back(id);
    return static_cast<std::int32_t>(radius_.size() - 1);
  }

  void cell(CellKind& kind, std::span<const std::int32_t> ids, FlowerRole role, std::int32_t gen, std::int32_t spoke) {
    kind.ids.insert(kind.ids.end(), ids.begin(), ids.end());
    kind.offsets.push_back(static_cast<std::int64_t>(kind.ids.size()));
    kind.role.push_back(static_cast<std::uint8_t>(role));
    kind.generator.push_back(gen);
    kind.spoke.push_back(spoke);
  }

  /// A circle (2D: closed polyline of 64 segments) or sphere (3D: 8 x 16
  /// latitude-longitude polygons, counter-clockwise from outside) of radius r.
  void glyph(const double* centre, double r, FlowerRole role, std::int32_t gen) {
    constexpr double pi = std::numbers::pi;
    if (dim_ == 2) {
      constexpr int segments = 64;
      std::vector<std::int32_t> ring;
      for (int s = 0; s < segments; ++s) {
        const double a = 2 * pi * s / segments;
        const double x[2] = {centre[0] + r * std::cos(a), centre[1] + r * std::sin(a)};
        ring.push_back(point(x, r, role, gen, -1));
      }
      ring.push_back(ring.front());
      cell(lines, ring, role, gen, kNoSpoke);
      return;
    }
    constexpr int bands = 8, sectors = 16;
    auto at = [&](double theta, double phi) {
      const double x[3] = {centre[0] + r * std::sin(theta) * std::cos(phi),
                           centre[1] + r * std::sin(theta) * std::sin(phi), centre[2] + r * std::cos(theta)};
      return point(x, r, role, gen, -1);
    };
    const std::int32_t north = at(0, 0);
    std::vector<std::int32_t> rings;  // (bands - 1) rings of `sectors` points, north to south
    for (int i = 1; i < bands; ++i)
      for (int j = 0; j < sectors; ++j) rings.push_back(at(pi * i / bands, 2 * pi * j / sectors));
    const std::int32_t south = at(pi, 0);
    auto ring = [&](int i, int j) { return rings[static_cast<std::size_t>((i - 1) * sectors + (j % sectors))]; };
    for (int j = 0; j < sectors; ++j) {
      const std::int32_t cap_n[3] = {north, ring(1, j), ring(1, j + 1)};
      cell(polys, cap_n, role, gen, kNoSpoke);
      for (int i = 1; i + 1 < bands; ++i) {
        const std::int32_t quad[4] = {ring(i, j), ring(i + 1, j), ring(i + 1, j + 1), ring(i, j + 1)};
        cell(polys, quad, role, gen, kNoSpoke);
      }
      const std::int32_t cap_s[3] = {ring(bands - 1, j), south, ring(bands - 1, j + 1)};
      cell(polys, cap_s, role, gen, kNoSpoke);
    }
  }

  void write(const std::string& path) const {
    PolyData pd;
    pd.dim = dim_;
    pd.points = coords_;
    pd.verts = {verts.offsets, verts.ids};
    pd.lines = {lines.offsets, lines.ids};
    pd.polys = {polys.offsets, polys.ids};
    pd.point_data.push_back({"Radius", std::span<const double>(radius_)});
    pd.point_data.push_back({"Role", std::span<const std::uint8_t>(role_)});
    pd.point_data.push_back({"GeneratorId", std::span<const std::int32_t>(generator_)});
    pd.point_data.push_back({"PointId", std::span<const std::int32_t>(point_id_)});
    // Cell data in VTK's cell order.
    std::vector<std::uint8_t> role;
    std::vector<std::int32_t> generator, spoke;
    for (const CellKind* k : {&verts, &lines, &polys}) {
      role.insert(role.end(), k->role.begin(), k->role.end());
      generator.insert(generator.end(), k->generator.begin(), k->generator.end());
      spoke.insert(spoke.end(), k->spoke.begin(), k->spoke.end());
    }
    pd.cell_data.push_back({"Role", std::span<const std::uint8_t>(role)});
    pd.cell_data.push_back({"GeneratorId", std::span<const std::int32_t>(generator)});
    pd.cell_data.push_back({"Spoke", std::span<const std::int32_t>(spoke)});
    write_polydata(path, pd);
  }

  CellKind verts, lines, polys;

 private:
  int dim_;
  std::vector<double> coords_, radius_;
  std::vector<std::uint8_t> role_;
  std::vector<std::int32_t> generator_, point_id_;
};

}  // namespace

void write_flowers_vtp(const std::string& path, std::span<const Flower> flowers, std::span<const double> points,
                       bool glyphs) {
  if (flowers.empty()) throw std::invalid_argument("write_flowers_vtp: no flowers");
  const int dim = flowers.front().dim;
  const auto D = static_cast<std::size_t>(dim);
  if (points.size() % D != 0) throw std::invalid_argument("write_flowers_vtp: bad point array");
  FlowerMesh m(dim);
  for (const Flower& fl : flowers) {
    if (fl.dim != dim) throw std::invalid_argument("write_flowers_vtp: flowers of different dimensions");
    const std::int32_t gen = fl.generator;
    const std::int32_t site = m.point(fl.site.data(), fl.circumflower_radius, FlowerRole::generator, gen, gen);
    m.cell(m.verts, {&site, 1}, FlowerRole::generator, gen, kNoSpoke);
    const std::int32_t first_petal = site + 1;
    for (std::size_t p = 0; p < fl.n_petals(); ++p) {
      const std::int32_t v = m.point(&fl.petal_centres[p * D], fl.petal_radii[p], FlowerRole::petal_centre, gen, -1);
      m.cell(m.verts, {&v, 1}, FlowerRole::petal_centre, gen, kNoSpoke);
    }
    if (fl.neighbor_positions.size() != fl.neighbors.size() * D)
      throw std::invalid_argument("write_flowers_vtp: a flower without its neighbours' positions");
    for (std::size_t e = 0; e < fl.neighbors.size(); ++e) {
      const std::int32_t j = fl.neighbors[e];
      if (j < 0 || static_cast<std::size_t>(j) * D >= points.size())
        throw std::invalid_argument("write_flowers_vtp: neighbour id out of range of the points");
      // Where the neighbour is: its point, or the image across the face.
      const std::int32_t v = m.point(&fl.neighbor_positions[e * D], 0, FlowerRole::neighbor, gen, j);
      m.cell(m.verts, {&v, 1}, FlowerRole::neighbor, gen, kNoSpoke);
      const std::int32_t line[2] = {site, v};
      m.cell(m.lines, line, FlowerRole::spoke, gen, j);
    }
    // The cell: each 3D face as a polygon; the 2D tile as one polygon made of
    // the first vertex of each edge (counter-clockwise).
    std::vector<std::int32_t> loop;
    for (std::size_t f = 0; f + 1 < fl.face_offsets.size(); ++f) {
      const auto b = static_cast<std::size_t>(fl.face_offsets[f]), e = static_cast<std::size_t>(fl.face_offsets[f + 1]);
      if (dim == 2) {
        loop.push_back(first_petal + fl.face_vertices[b]);
        continue;
      }
      loop.clear();
      for (std::size_t q = b; q < e; ++q) loop.push_back(first_petal + fl.face_vertices[q]);
      m.cell(m.polys, loop, FlowerRole::cell, gen, fl.face_neighbor[f]);
    }
    if (dim == 2) m.cell(m.polys, loop, FlowerRole::cell, gen, kNoSpoke);
    if (glyphs) {
      for (std::size_t p = 0; p < fl.n_petals(); ++p)
        m.glyph(&fl.petal_centres[p * D], fl.petal_radii[p], FlowerRole::petal_glyph, gen);
      m.glyph(fl.site.data(), fl.circumflower_radius, FlowerRole::circumflower_glyph, gen);
    }
  }
  m.write(path);
}

}  // namespace tessera::io

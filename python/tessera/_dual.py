"""tessera.adjacency(), tessera.faces(), tessera.flower() and their results.

All three are read off the merged mesh of a :class:`tessera.Voronoi`: pass one
you already have (nothing is recomputed) or points (the cells are computed
first, with the keyword arguments of :func:`tessera.voronoi`).
"""

from __future__ import annotations

import os
from typing import Any, Iterator, List, Optional, Sequence, Tuple, Union

import numpy as np

from . import _core, _inputs
from ._voronoi import Voronoi, cells_of

PathLike = Union[str, "os.PathLike[str]"]

#: Face-set kinds of :func:`faces` ("surface_net" is accepted too).
FACE_KINDS = ("boundary", "complex", "surface-net")


def cells_for(
    what: str,
    source: Any,
    labels: Any,
    bounds: Optional[Sequence[float]],
    padding: Optional[float],
    threads: Optional[int],
    ignore_outside: bool,
    periodic: Any = False,
    tilt: Optional[Sequence[float]] = None,
    radii: Any = None,
    only_with_faces: int = 0,
    walls: Any = None,
) -> Voronoi:
    """The Voronoi result a product is read from: `source` itself when it is
    one (the cell options must then be left out: they were fixed when it was
    computed), else the cells of the points `source`, with the mesh; with
    ``only_with_faces`` (a set of spoke classes) those with a face of one of
    them alone (``VoronoiOptions::only_with_faces``)."""
    if isinstance(source, Voronoi):
        given = [n for n, v in (("labels", labels), ("bounds", bounds), ("padding", padding), ("threads", threads),
                                ("tilt", tilt), ("radii", radii), ("walls", walls)) if v is not None]
        if _inputs.as_flag(ignore_outside, "ignore_outside"):
            given.append("ignore_outside")
        if periodic is not None and periodic is not False and not (isinstance(periodic, np.bool_) and not periodic):
            given.append("periodic")
        if given:
            raise ValueError(
                f"{what}: {', '.join(given)} {'is' if len(given) == 1 else 'are'} for computing cells from points; "
                "this Voronoi result is already computed (pass them to tessera.voronoi())")
        if not source.has_mesh:
            raise ValueError(f"{what}: the Voronoi result was computed with merge=False (no mesh); "
                             "compute it with merge=True")
        if source._partial:  # a graph, faces or flowers of it would silently miss the other cells
            raise ValueError(f"{what}: this Voronoi result holds some cells only (the voronoi of "
                             "tessera.faces or tessera.flower of points); compute all of them with "
                             "tessera.voronoi(points)")
        return source
    return cells_of(source, labels, bounds, 0.01 if padding is None else padding, threads, True, ignore_outside,
                    "auto", periodic, tilt, radii, None, only_with_faces, walls)


def _check_vtp(path: PathLike, what: str) -> str:
    path = _inputs.as_path(path)
    if not path.lower().endswith(".vtp"):
        raise ValueError(f"save: {what} is written as VTK PolyData (.vtp), got {path!r}")
    return path


# --------------------------------------------------------------------- graph

class AdjacencyGraph:
    """Wheels and spokes: every generator linked to its face neighbours.

    Made by :func:`tessera.adjacency`. A *spoke* is a cell face seen from one
    side, as the link from the generator to the point (or domain-box plane)
    across it; a generator's *wheel* is all of its spokes. CSR over all ``N``
    input points: the spokes of point ``i`` are
    ``spokes[wheel_offsets[i]:wheel_offsets[i+1]]``, ascending, the box planes
    first as negative ids (x0=-1, x1=-2, y0=-3, y1=-4, z0=-5, z1=-6; wall k -7-k); points
    without a cell (outside points, duplicates, points dropped outside the
    bounds, empty power cells) have empty wheels. The graph is exactly
    symmetric: every spoke ``i -> j`` between two cells has its twin ``j -> i``.

    Of periodic cells (``voronoi(..., periodic=..., merge=True)``), spokes lead
    to images: :attr:`spoke_shifts` says which, wheels are ascending by
    neighbour then shift, and the twin of ``i -> (j, s)`` is ``j -> (i, -s)``.

    Arrays are read-only views of buffers the compiled result owns.
    """

    def __init__(self, graph: Any, vor: Voronoi, prune_tolerance: float):
        self._g = graph
        self._vor = vor
        self._prune_tolerance = prune_tolerance

    @property
    def voronoi(self) -> Voronoi:
        """The cells the graph was read from."""
        return self._vor

    @property
    def points(self) -> np.ndarray:
        """float64 (N, D): the input points."""
        return self._vor.points

    @property
    def labels(self) -> Optional[np.ndarray]:
        """The labels the cells were computed with (int32 (N,)), or None."""
        return self._vor.labels

    @property
    def ndim(self) -> int:
        return self._g.dim

    @property
    def n_points(self) -> int:
        return self._g.n_points

    @property
    def n_spokes(self) -> int:
        return self._g.n_spokes

    @property
    def wheel_offsets(self) -> np.ndarray:
        """int64 (N + 1,): CSR offsets of each point's wheel in :attr:`spokes`."""
        return self._g.wheel_offsets

    @property
    def spokes(self) -> np.ndarray:
        """int32: the neighbour across each spoke (point id), or a negative box-plane or wall id."""
        return self._g.spokes

    @property
    def spoke_class(self) -> np.ndarray:
        """uint8, per spoke: SAME_REGION (0), REGION_BOUNDARY (1),
        DOMAIN_BOUNDARY (2) or OUTSIDE (3, the point across has label < 0)."""
        return self._g.spoke_class

    @property
    def spoke_measure(self) -> np.ndarray:
        """float64, per spoke: area (3D) or length (2D) of the face behind it,
        the same for both directions of a face."""
        return self._g.spoke_measure

    @property
    def spoke_shifts(self) -> np.ndarray:
        """int8 (n_spokes, D), periodic cells only (empty otherwise): the image
        of the neighbour across each spoke, in box lengths (lattice vectors
        of a triclinic box), as :attr:`Voronoi.neighbor_shifts`."""
        return self._g.spoke_shifts

    @property
    def edge_shifts(self) -> np.ndarray:
        """int8 (E, D), periodic cells only (empty otherwise): the image of
        each edge's second end."""
        return self._g.edge_shifts

    @property
    def prune_tolerance(self) -> float:
        return self._prune_tolerance

    @property
    def prune_threshold(self) -> float:
        """The absolute face measure below which spokes were dropped (0: no pruning)."""
        return self._g.prune_threshold

    @property
    def pruned_spokes(self) -> int:
        """Spokes dropped by pruning, each direction counted."""
        return self._g.pruned_spokes

    def wheel(self, i: int) -> np.ndarray:
        """The spokes of point ``i`` (a view)."""
        off = self.wheel_offsets
        i = _inputs.as_index(i, len(off) - 1, "i", "points")
        return self.spokes[off[i]:off[i + 1]]

    def edges(self) -> np.ndarray:
        """int32 (E, 2): the undirected edges, one per face between two cells
        (lower id first; periodic: the lower of (i, j, s) and (j, i, -s), so
        a point meeting its own image is listed once, see :attr:`edge_shifts`)
        and one per face between a cell and an outside point
        (the cell's generator first); box faces are not edges. In the order of
        their spokes; :attr:`edge_spokes` gives each edge's spoke. Computed on
        first use, then kept."""
        return self._g.edge_ends

    @property
    def edge_spokes(self) -> np.ndarray:
        """int64 (E,): index in :attr:`spokes` of the spoke behind each edge of :meth:`edges`."""
        return self._g.edge_spokes

    def save(self, path: PathLike) -> None:
        """Write the graph for ParaView as ``.vtp``: the input points, one line
        per edge. Point data Region (the label, 0 without labels); cell data
        SpokeClass and FaceArea (3D) / FaceLength (2D). Periodic cells: the
        points as wrapped (:attr:`Voronoi.periodic_points`), and an edge to an
        image ends at an extra point there (point data PointId: whose image).
        ValueError for another extension, OSError when the file cannot be written."""
        pts = self._vor.periodic_points if any(self._vor.periodic) else self.points
        _core.write_graph_vtp(_check_vtp(path, "a graph"), self._g, pts, self.labels)

    def to_vtk(self) -> Any:
        """The graph as a ``vtkPolyData`` of lines with the data of :meth:`save` (needs ``vtk``)."""
        from ._vtk import graph_to_vtk

        return graph_to_vtk(self)

    def __repr__(self) -> str:
        return f"<tessera.AdjacencyGraph {self.ndim}D: {self.n_points} points, {self.n_spokes} spokes>"


def adjacency(
    source: Any,
    labels: Any = None,
    bounds: Optional[Sequence[float]] = None,
    padding: Optional[float] = None,
    threads: Optional[int] = None,
    *,
    prune_tolerance: float = 0.0,
    ignore_outside: bool = False,
    periodic: Any = False,
    tilt: Optional[Sequence[float]] = None,
    radii: Any = None,
    walls: Any = None,
) -> AdjacencyGraph:
    """The adjacency graph (wheels and spokes) of a tessellation.

    Parameters
    ----------
    source : Voronoi or array_like, shape (N, 2) or (N, 3)
        A :class:`Voronoi` computed with ``merge=True`` (reused as is), or
        points whose cells are computed first.
    labels, bounds, padding, threads, ignore_outside, periodic, tilt, radii, walls
        As in :func:`tessera.voronoi`, for points only (ValueError with a
        Voronoi: its cells are already computed). The graph is read off in
        parallel on the thread count the cells were computed with. With
        ``radii`` (power cells) the points whose cell is empty have empty
        wheels.
    prune_tolerance : float
        Drop spokes whose face is tiny, for parity with VTK's PruneTolerance
        and Voro++'s counts (0, the default, keeps every face). Exact
        topology has no slivers from rounding, but on exact lattices (five
        or more points exactly co-spherical, four co-circular in 2D) it
        settles each tie by symbolic perturbation into faces of zero area: a
        simple cubic cell has 14 faces, 8 of area 0; ``1e-9`` leaves the 6
        of Voro++. A spoke goes when its face's area (3D) / length (2D) is below
        ``prune_tolerance * mean_cell_volume ** ((D-1)/D)``; both directions
        of a face are decided alike, so the graph stays symmetric.

    Returns
    -------
    AdjacencyGraph
    """
    tol = _inputs.as_float(prune_tolerance, "prune_tolerance", "a finite number >= 0")
    if not (np.isfinite(tol) and tol >= 0):
        raise ValueError(f"prune_tolerance: expected a finite number >= 0, got {prune_tolerance!r}")
    vor = cells_for("adjacency", source, labels, bounds, padding, threads, ignore_outside, periodic, tilt, radii,
                    walls=walls)
    return AdjacencyGraph(_inputs.call(_core.adjacency_graph, vor._cells, tol), vor, tol)


# --------------------------------------------------------------------- faces

class FaceSet:
    """A set of Voronoi faces (3D: convex polygons; 2D: segments) over merged vertices.

    Made by :func:`tessera.faces`. Each face is listed once and separates
    *side 0*, a cell, from *side 1*: a cell, an outside point or a domain-box
    plane. Side 0 is the cell when side 1 is not one; between two cells it is
    the one with the smaller (region label, generator id). Faces are oriented
    from side 0 towards side 1: a 3D polygon is counter-clockwise seen from
    side 1 (its right-hand normal points into side 1, so boundary faces face
    outward); a 2D segment has side 0 on its left.

    :attr:`boundary_labels` (two per face) are the labels of side 0 (always a
    cell's region, >= 0) and side 1 (the neighbour cell's region, an outside
    point's own negative label, or ``background_label`` for the box). Without
    labels every cell's label is 0.

    Faces as CSR: vertices of face ``f`` are
    ``face_vertices[face_offsets[f]:face_offsets[f+1]]`` (ids into
    :attr:`vertices`, the used merged vertices of the cells in ascending order
    of their id there). Arrays are read-only views of the compiled result.

    Of periodic cells (``voronoi(..., periodic=..., merge=True)``), side 1 of
    a face between cells is an image of its point (:attr:`side_shifts`), and
    each face lies where side 0's cell is: the faces are pieces that fit
    together across the box's faces by lattice translations. A vertex is
    listed once per frame it is seen from; :attr:`vertex_key_shifts` tells
    which copies are one vertex (keys equal up to a common shift). A face
    between a cell and an image of itself is taken from the side whose shift
    is lexicographically positive.
    """

    def __init__(self, fs: Any, vor: Optional[Voronoi], capping: bool, background_label: int):
        self._fs = fs
        self._vor = vor
        self._capping = capping
        self._background_label = background_label

    @property
    def voronoi(self) -> Optional[Voronoi]:
        """The cells the faces were read from: the Voronoi given, or of points
        the cells with a face of the set alone (all of them for ``complex``):
        a partial result, whose ``n_cells`` are the cells built, and which
        :meth:`Voronoi.validate` and the products refuse."""
        return self._vor

    @property
    def ndim(self) -> int:
        return self._fs.dim

    @property
    def kind(self) -> str:
        """'boundary', 'complex' or 'surface-net'."""
        return self._fs.kind

    @property
    def capping(self) -> bool:
        return self._capping

    @property
    def background_label(self) -> int:
        """The side-1 label of faces on the domain box."""
        return self._background_label

    @property
    def n_faces(self) -> int:
        return self._fs.n_faces

    @property
    def n_vertices(self) -> int:
        return self._fs.n_vertices

    @property
    def vertices(self) -> np.ndarray:
        """float64 (n_vertices, D): the vertices the faces use."""
        return self._fs.vertices

    @property
    def vertex_keys(self) -> np.ndarray:
        """int32 (n_vertices, D+1): topological coordinate of each vertex (the
        generators or negative box planes meeting there, ascending)."""
        return self._fs.vertex_keys

    @property
    def face_offsets(self) -> np.ndarray:
        """int64 (n_faces + 1,): CSR offsets into :attr:`face_vertices`."""
        return self._fs.face_offsets

    @property
    def face_vertices(self) -> np.ndarray:
        """int32: vertex ids of every face, in face order (2 per face in 2D)."""
        return self._fs.face_vertices

    @property
    def sides(self) -> np.ndarray:
        """int32 (n_faces, 2): side 0's generator, side 1's generator or negative box-plane (or wall) id."""
        return self._fs.sides

    @property
    def boundary_labels(self) -> np.ndarray:
        """int32 (n_faces, 2): the labels of side 0 and side 1 (see the class docstring)."""
        return self._fs.boundary_labels

    @property
    def face_class(self) -> np.ndarray:
        """uint8 (n_faces,): the class of the spoke from side 0 to side 1
        (SAME_REGION, REGION_BOUNDARY, DOMAIN_BOUNDARY or OUTSIDE)."""
        return self._fs.face_class

    @property
    def periodic(self) -> Tuple[bool, ...]:
        """The periodic axes of the cells (all False for an ordinary box)."""
        return self._fs.periodic

    @property
    def side_shifts(self) -> np.ndarray:
        """int8 (n_faces, D), periodic cells only (empty otherwise): which
        image of side 1 each face meets, in box lengths (lattice vectors in a
        triclinic box); zeros for a box plane."""
        return self._fs.side_shifts

    @property
    def vertex_key_shifts(self) -> np.ndarray:
        """int8 (n_vertices, D+1, D), periodic cells only (empty otherwise):
        per entry of :attr:`vertex_keys`, the shift of that point's image."""
        return self._fs.vertex_key_shifts

    def face(self, f: int) -> np.ndarray:
        """Vertex ids of face ``f`` (a view)."""
        off = self.face_offsets
        f = _inputs.as_index(f, len(off) - 1, "f", "faces")
        return self.face_vertices[off[f]:off[f + 1]]

    def save(self, path: PathLike) -> None:
        """Write the faces for ParaView as ``.vtp`` (3D polygons, 2D lines;
        2D points get z = 0). Cell data BoundaryLabels (2 components), Sides
        (2 components) and SpokeClass. ValueError for another extension,
        OSError when the file cannot be written."""
        _core.write_faces_vtp(_check_vtp(path, "a face set"), self._fs)

    def to_vtk(self) -> Any:
        """The faces as a ``vtkPolyData`` with the cell data of :meth:`save` (needs ``vtk``)."""
        from ._vtk import faces_to_vtk

        return faces_to_vtk(self)

    def __repr__(self) -> str:
        what = "polygons" if self.ndim == 3 else "segments"
        return f"<tessera.FaceSet {self.kind} {self.ndim}D: {self.n_faces} {what}, {self.n_vertices} vertices>"


def as_face_kind(kind: Any) -> str:
    if kind == "surface_net":
        kind = "surface-net"
    return _inputs.as_choice(kind, "kind", FACE_KINDS)


def faces(
    source: Any,
    kind: str = "boundary",
    capping: bool = False,
    background_label: int = -1,
    labels: Any = None,
    bounds: Optional[Sequence[float]] = None,
    padding: Optional[float] = None,
    threads: Optional[int] = None,
    *,
    ignore_outside: bool = False,
    periodic: Any = False,
    tilt: Optional[Sequence[float]] = None,
    radii: Any = None,
    walls: Any = None,
) -> FaceSet:
    """A face set of a tessellation: its boundary, the whole polygonal complex,
    or the surface net between regions.

    Parameters
    ----------
    source : Voronoi or array_like, shape (N, 2) or (N, 3)
        A :class:`Voronoi` computed with ``merge=True`` (reused as is, with the
        labels it was computed with), or points whose cells are computed first:
        of a ``boundary`` or a ``surface-net`` only the cells with a face of
        the set are built with the mesh (after a pass over all cells without
        it), the same faces byte for byte (:attr:`FaceSet.voronoi` is then
        that partial result).
    kind : {'boundary', 'complex', 'surface-net'}
        ``boundary``: the faces on the domain box or against outside points,
        the outward boundary of the union of the cells. ``complex``: every
        Voronoi face exactly once. ``surface-net``: the faces between cells of
        different regions (``surface_net`` is accepted too).
    capping : bool
        surface-net only: add the boundary faces, so every region is enclosed.
    background_label : int
        The side-1 label of faces on the domain box (and walls); must be < 0.
    labels, bounds, padding, threads, ignore_outside, periodic, tilt, radii, walls
        As in :func:`tessera.voronoi`, for points only (ValueError with a
        Voronoi). With ``radii`` the faces are those of the power cells;
        with ``walls`` the boundary includes the faces on them.

    Returns
    -------
    FaceSet
    """
    kind = as_face_kind(kind)
    capping = _inputs.as_flag(capping, "capping")
    if capping and kind != "surface-net":
        raise ValueError(f"capping: applies to kind='surface-net' only, got kind={kind!r}")
    bg = _inputs.as_label_value(background_label, "background_label", negative=True)
    # Of points: the cells with a face of the set alone (their faces are the
    # set of all cells, byte for byte; for the complex every cell is built).
    vor = cells_for("faces", source, labels, bounds, padding, threads, ignore_outside, periodic, tilt, radii,
                    _core.face_set_classes(kind, capping), walls)
    fs = _inputs.call(_core.extract_faces, vor._cells, vor.labels, kind, capping, bg)
    return FaceSet(fs, vor, capping, bg)


# -------------------------------------------------------------------- flower

class Flower:
    """The flower of one cell (an element of :class:`Flowers`).

    Each vertex ``v`` of the cell of generator ``p`` centres a *petal*: the
    ball (disk in 2D) through ``p`` centred at ``v``. A point clips the cell
    iff it lies in some petal; the *circumflower* (radius twice the largest
    petal's, around ``p``) contains them all: the security radius of the
    neighbour search. Arrays are read-only views.
    """

    def __init__(self, fl: Any):
        self._fl = fl

    @property
    def ndim(self) -> int:
        return self._fl.dim

    @property
    def generator(self) -> int:
        """The point id whose cell this is."""
        return self._fl.generator

    @property
    def site(self) -> np.ndarray:
        """float64 (D,): the generator's position."""
        return np.array(self._fl.site)

    @property
    def n_petals(self) -> int:
        return self._fl.n_petals

    @property
    def vertex_ids(self) -> np.ndarray:
        """int32 (n_petals,): ids of the petal centres among the Voronoi result's vertices, ascending."""
        return self._fl.vertex_ids

    @property
    def petal_centres(self) -> np.ndarray:
        """float64 (n_petals, D): the cell's vertices."""
        return self._fl.petal_centres

    @property
    def petal_radii(self) -> np.ndarray:
        """float64 (n_petals,): distance from each centre to the generator."""
        return self._fl.petal_radii

    @property
    def circumflower_radius(self) -> float:
        """2 x the largest petal radius: the security radius."""
        return self._fl.circumflower_radius

    @property
    def face_offsets(self) -> np.ndarray:
        """int64: CSR offsets of the cell's faces in :attr:`face_vertices`."""
        return self._fl.face_offsets

    @property
    def face_vertices(self) -> np.ndarray:
        """int32: petal indices of each face, oriented as in the Voronoi result."""
        return self._fl.face_vertices

    @property
    def face_neighbor(self) -> np.ndarray:
        """int32 (n_faces,): the point across each face, or the negative box-plane (or wall) id."""
        return self._fl.face_neighbor

    @property
    def neighbors(self) -> np.ndarray:
        """int32: the points that clipped the cell (across its faces), ascending."""
        return self._fl.neighbors

    @property
    def neighbor_positions(self) -> np.ndarray:
        """float64 (len(neighbors), D): where each neighbour is; in a periodic
        box the image across the face."""
        return self._fl.neighbor_positions

    @property
    def neighbor_shifts(self) -> np.ndarray:
        """int8 (len(neighbors), D), periodic boxes only (empty otherwise):
        each neighbour's image, as :attr:`Voronoi.neighbor_shifts`."""
        return self._fl.neighbor_shifts

    @property
    def face_shifts(self) -> np.ndarray:
        """int8 (n_faces, D), periodic boxes only (empty otherwise): the image
        across each face (0 for a wall)."""
        return self._fl.face_shifts

    def __repr__(self) -> str:
        return (f"<tessera.Flower of point {self.generator}: {self.n_petals} petals, "
                f"circumflower radius {self.circumflower_radius:.6g}, {len(self.neighbors)} neighbours>")


class Flowers:
    """The flowers of the cells of some points (made by :func:`tessera.flower`):
    a sequence of :class:`Flower`, in the order of the ids asked for, that
    saves as one ``.vtp``."""

    def __init__(self, fs: Any, vor: Voronoi, glyphs: bool):
        self._fs = fs
        self._vor = vor
        self._items = [Flower(fs[k]) for k in range(len(fs))]
        self.glyphs = glyphs

    @property
    def voronoi(self) -> Voronoi:
        return self._vor

    @property
    def ids(self) -> List[int]:
        return [f.generator for f in self._items]

    def __len__(self) -> int:
        return len(self._items)

    def __getitem__(self, k: int) -> Flower:
        return self._items[k]

    def __iter__(self) -> Iterator[Flower]:
        return iter(self._items)

    def save(self, path: PathLike, glyphs: Optional[bool] = None) -> None:
        """Write the flowers for ParaView as one ``.vtp``.

        Points: per flower its site, petal centres and clipping neighbours
        (and glyph points); point data Radius, Role, GeneratorId, PointId.
        Cells: a vertex per point, a line per spoke (site to neighbour), the
        cell's faces (the tile in 2D) and, with ``glyphs`` (default: the value
        given to :func:`tessera.flower`), a circle/sphere per petal and for the
        circumflower; cell data Role, GeneratorId, Spoke. Roles:
        0 generator, 1 petal centre, 2 neighbour, 3 spoke, 4 cell face,
        5 petal glyph, 6 circumflower glyph.
        """
        g = _inputs.as_flag(self.glyphs if glyphs is None else glyphs, "glyphs")
        _core.write_flowers_vtp(_check_vtp(path, "a flower"), self._fs, self._vor.points, g)

    def to_vtk(self, glyphs: Optional[bool] = None) -> Any:
        """The flowers as the ``vtkPolyData`` that :meth:`save` writes (it is
        written to a temporary file and read back: needs ``vtk``)."""
        from ._vtk import flowers_to_vtk

        return flowers_to_vtk(self, _inputs.as_flag(self.glyphs if glyphs is None else glyphs, "glyphs"))

    def __repr__(self) -> str:
        return f"<tessera.Flowers of points {self.ids}>"


def as_ids(ids: Any, n: int) -> np.ndarray:
    """Point ids: one int or a 1-D sequence of ints in [0, n)."""
    try:
        a = np.asarray(ids)
    except (ValueError, TypeError) as e:
        raise ValueError(f"ids: expected a point id or a sequence of them ({e})") from None
    if a.ndim == 0:
        a = a.reshape(1)
    if a.ndim != 1 or a.dtype.kind not in "iu" or a.size == 0:
        raise ValueError(f"ids: expected a point id or a non-empty sequence of them, got {ids!r}")
    bad = a[(a < 0) | (a >= n)]
    if bad.size:
        raise ValueError(f"ids: point {int(bad[0])} does not exist (there are {n} points, ids 0..{n - 1})")
    return np.ascontiguousarray(a, dtype=np.int32)


def _existing_ids(ids: Any, n: int) -> np.ndarray:
    """The ids in [0, n) among ``ids`` (int32), or [0] where there are none
    (or ``ids`` are no integers: :func:`as_ids` names what is wrong)."""
    try:
        a = np.asarray(ids)
    except (ValueError, TypeError):
        a = np.zeros(0, dtype=np.int64)
    if a.dtype.kind not in "iu" or a.ndim > 1:
        a = np.zeros(0, dtype=np.int64)
    a = a.reshape(-1)
    a = a[(a >= 0) & (a < n)]
    return np.ascontiguousarray(a if a.size else [0], dtype=np.int32)


def flower(
    source: Any,
    ids: Union[int, Sequence[int]],
    glyphs: bool = False,
    labels: Any = None,
    bounds: Optional[Sequence[float]] = None,
    padding: Optional[float] = None,
    threads: Optional[int] = None,
    *,
    ignore_outside: bool = False,
    periodic: Any = False,
    tilt: Optional[Sequence[float]] = None,
    walls: Any = None,
) -> Flowers:
    """The flowers of the cells of points ``ids``, for debugging and teaching.

    Parameters
    ----------
    source : Voronoi or array_like, shape (N, 2) or (N, 3)
        A :class:`Voronoi` computed with ``merge=True`` (reused), or points:
        then only the cells of ``ids`` and of their neighbours are built
        (each cell on its own, as the meshless method does; every point
        still clips and sets the box), the same cells as all N cells give.
        :attr:`Flowers.voronoi` is then that partial result (its
        ``n_cells`` the cells built), in which :attr:`Flower.vertex_ids`
        index ``vertices`` (:func:`adjacency`, :func:`faces` and
        :func:`flower` refuse it: they need every cell); in a periodic box
        the layer of images is the one these cells need.
        Not power cells (``voronoi(..., radii=...)``: ``tessera.InputError``):
        a petal is a ball through the generator, which holds for ordinary
        cells only.
    ids : int or sequence of int
        The points whose cells to show; each must own a cell (not an outside
        point, a duplicate or a point dropped outside the bounds).
    glyphs : bool
        Default for :meth:`Flowers.save`: add a circle (2D) / sphere (3D) per
        petal and for the circumflower.
    labels, bounds, padding, threads, ignore_outside, periodic, tilt, walls
        As in :func:`tessera.voronoi`, for points only (ValueError with a Voronoi).

    Returns
    -------
    Flowers
        ``flowers[k]`` is the :class:`Flower` of ``ids[k]``.
    """
    if isinstance(source, Voronoi):
        vor = cells_for("flower", source, labels, bounds, padding, threads, ignore_outside, periodic, tilt,
                        walls=walls)
    else:
        # The cells of the ids asked for (and their neighbours'), not all N.
        # Ids that are no point are refused below, after the cells, as
        # before; where none is one, point 0's cell stands in (input errors,
        # and the cells' own, still come first).
        pts = _inputs.as_points(source)
        vor = cells_of(pts, labels, bounds, 0.01 if padding is None else padding, threads, True, ignore_outside,
                       "auto", periodic, tilt, None, _existing_ids(ids, pts.shape[0]), 0, walls)
    idx = as_ids(ids, vor.points.shape[0])
    fs = _inputs.call(_core.flowers, vor._cells, vor.points, idx)
    return Flowers(fs, vor, _inputs.as_flag(glyphs, "glyphs"))

"""tessera.voronoi() and its result, :class:`Voronoi`."""

from __future__ import annotations

import os
from functools import cached_property
from typing import TYPE_CHECKING, Any, Optional, Sequence, Tuple, Union

import numpy as np

from . import _core, _inputs

if TYPE_CHECKING:  # pragma: no cover
    from ._scipy import ScipyVoronoi

PathLike = Union[str, "os.PathLike[str]"]


class Voronoi:
    """The Voronoi cells of a point set, clipped to a domain box.

    Made by :func:`tessera.voronoi`. Every array attribute is a read-only numpy
    view of a buffer owned by the compiled result (no copy; ``arr.base`` keeps
    it alive); copy what you want to change. Cells are listed in generator-id
    order: cell ``c`` belongs to point ``generators[c]`` and point ``i`` owns cell
    ``cell_of[i]`` (-1 when it owns none: an outside point (label < 0), a point
    dropped outside the bounds, an exact duplicate of a lower id, see
    :attr:`duplicates`, or, of power cells, a point whose cell is empty, see
    :attr:`empty_cells`).

    Per cell (``n_cells`` rows): :attr:`generators`, :attr:`regions`,
    :attr:`volumes`, :attr:`centroids`, :attr:`num_faces`, and the face
    neighbours as CSR (:attr:`neighbor_offsets`, :attr:`neighbors`).

    The merged mesh (``merge=True``): :attr:`vertices` (one per topological
    coordinate, :attr:`vertex_keys`) and the faces of every cell as CSR:
    faces of cell ``c`` are ``cell_face_offsets[c]:cell_face_offsets[c+1]``;
    vertices of face ``f`` are
    ``face_vertices[face_vertex_offsets[f]:face_vertex_offsets[f+1]]``
    (counter-clockwise seen from outside the cell); :attr:`face_neighbor` is
    the point across face ``f``, or the negative box-plane id (a wall's ``-7 - k``) for a face on the
    domain box (x0=-1, x1=-2, y0=-3, y1=-4, z0=-5, z1=-6). In 2D a face is an
    edge of two vertices, and the first vertex of each edge, in order, walks the
    polygon counter-clockwise.

    :attr:`scipy` is a view with the attributes of ``scipy.spatial.Voronoi``.
    """

    def __init__(self, cells: _core.Cells, points: np.ndarray, labels: Optional[np.ndarray],
                 radii: Optional[np.ndarray] = None):
        self._cells = cells
        self._points = points
        self._labels = labels
        self._radii = radii  # kept: validate() measures power cells with them

    @property
    def _partial(self) -> bool:
        """Some cells only (Cells::partial: cells_of with `only` or
        `only_with_faces`): the products and validate refuse it."""
        return bool(self._cells.partial)

    # ---- input and domain -------------------------------------------------
    @property
    def points(self) -> np.ndarray:
        """The input points, float64 (N, D): the caller's array itself when it was
        one (not copied: changed later, it changes what ``validate`` checks)."""
        return self._points

    @property
    def labels(self) -> Optional[np.ndarray]:
        """The region labels given (int32 (N,), a read-only copy), or None."""
        return self._labels

    @property
    def radii(self) -> Optional[np.ndarray]:
        """The radii given (float64 (N,), the caller's array itself when it was
        one), or None."""
        return self._radii

    @property
    def ndim(self) -> int:
        """2 or 3."""
        return self._cells.dim

    @property
    def bounds(self) -> Tuple[float, ...]:
        """The domain box, (x0, x1, y0, y1[, z0, z1]): the given bounds (a periodic
        box's as rounded to its grid) or the padded bounding box."""
        return self._cells.bounds

    @property
    def n_cells(self) -> int:
        return self._cells.n_cells

    @property
    def n_vertices(self) -> int:
        """Merged vertices (0 with merge=False)."""
        return self._cells.n_vertices

    # ---- per cell ---------------------------------------------------------
    @property
    def generators(self) -> np.ndarray:
        """int32 (n_cells,): the point id of each cell, ascending."""
        return self._cells.generator

    @property
    def cell_of(self) -> np.ndarray:
        """int32 (N,): the cell of each point, -1 when it owns none."""
        return self._cells.cell_of

    @property
    def regions(self) -> np.ndarray:
        """int32 (n_cells,): the label of each cell (0 without labels).

        Not scipy's ``regions`` (vertex lists): that one is ``self.scipy.regions``.
        """
        return self._cells.region

    @property
    def volumes(self) -> np.ndarray:
        """float64 (n_cells,): cell volumes (areas in 2D). They sum to the domain's volume."""
        return self._cells.volume

    @property
    def centroids(self) -> np.ndarray:
        """float64 (n_cells, D): cell centroids."""
        return self._cells.centroid

    @property
    def num_faces(self) -> np.ndarray:
        """int32 (n_cells,): faces (3D) or edges (2D) of each cell, box faces included."""
        return self._cells.num_faces

    @property
    def neighbor_offsets(self) -> np.ndarray:
        """int64 (n_cells + 1,): CSR offsets into :attr:`neighbors`."""
        return self._cells.neighbor_offsets

    @property
    def neighbors(self) -> np.ndarray:
        """int32: the point ids across the faces of each cell, ascending per cell
        (box faces are not listed). Neighbours of cell ``c``:
        ``neighbors[neighbor_offsets[c]:neighbor_offsets[c+1]]``."""
        return self._cells.neighbors

    @property
    def neighbor_shifts(self) -> np.ndarray:
        """int8 (len(neighbors), D), periodic boxes only (empty otherwise): the
        image each neighbour is, in box lengths along each axis. The face of
        cell ``c`` at entry ``e`` is shared with point ``neighbors[e]`` moved
        by ``neighbor_shifts[e] * box lengths``; a point may be listed once
        per image (itself too, in a box a few cells wide)."""
        return self._cells.neighbor_shifts

    @property
    def periodic(self) -> Tuple[bool, ...]:
        """The periodic axes (all False for an ordinary box)."""
        return self._cells.periodic

    @property
    def walls(self) -> np.ndarray:
        """The walls as given to :func:`voronoi`, shape (k, D + 1): rows
        (normal..., offset) of the half-spaces ``normal . x <= offset`` that
        cut the box; (0, D + 1) without walls. Wall k's faces have spoke
        ``-7 - k``."""
        return self._cells.walls

    @property
    def tilt(self) -> Tuple[float, ...]:
        """A triclinic box's tilts as rounded, and reduced by whole box lengths
        where one was more than a length (the same lattice): ``(xy,)`` in 2D,
        ``(xy, xz, yz)`` in 3D; all zero for an orthogonal box (see
        :func:`voronoi`'s ``tilt``)."""
        t = self._cells.tilt
        return (t[0],) if self._cells.dim == 2 else (t[0], t[1], t[2])

    @property
    def periodic_points(self) -> np.ndarray:
        """float64 (N, D), periodic boxes only (empty otherwise): the points as
        the cells took them, wrapped into the box and rounded to its grid; the
        neighbour shifts are relative to these."""
        return self._cells.periodic_points

    @property
    def periodic_images(self) -> int:
        """Images of points that took part in a periodic box's cells."""
        return self._cells.periodic_images

    def cell_neighbors(self, c: int) -> np.ndarray:
        """The point ids across the faces of cell ``c`` (a view; negative ``c``
        counts from the end, as Python's sequences)."""
        off = self.neighbor_offsets
        c = _inputs.as_index(c, len(off) - 1, "c", "cells")
        return self.neighbors[off[c]:off[c + 1]]

    # ---- merged mesh ------------------------------------------------------
    @property
    def has_mesh(self) -> bool:
        """False when computed with merge=False: the mesh attributes below then raise ValueError."""
        return self._cells.has_mesh

    @property
    def vertices(self) -> np.ndarray:
        """float64 (n_vertices, D): merged cell vertices, one per topological coordinate."""
        return self._cells.vertices

    @property
    def vertex_keys(self) -> np.ndarray:
        """int32 (n_vertices, D+1): topological coordinate of each vertex: the ids of
        the D+1 points (or negative box planes and walls) whose bisectors meet there, ascending."""
        return self._cells.vertex_keys

    @property
    def cell_face_offsets(self) -> np.ndarray:
        """int64 (n_cells + 1,): CSR offsets of each cell's faces."""
        return self._cells.cell_face_offsets

    @property
    def face_vertex_offsets(self) -> np.ndarray:
        """int64 (n_faces + 1,): CSR offsets of each face's vertices in :attr:`face_vertices`."""
        return self._cells.face_vertex_offsets

    @property
    def face_vertices(self) -> np.ndarray:
        """int32: vertex ids of every face, counter-clockwise seen from outside its cell."""
        return self._cells.face_vertices

    @property
    def face_neighbor(self) -> np.ndarray:
        """int32 (n_faces,): the point across each face, or the negative box-plane id (wall k: -7 - k)."""
        return self._cells.face_neighbor

    @property
    def face_class(self) -> np.ndarray:
        """uint8 (n_faces,): kind of each face: SAME_REGION (0), REGION_BOUNDARY (1),
        DOMAIN_BOUNDARY (2) or OUTSIDE (3, the point across has label < 0)."""
        return self._cells.face_class

    def cell_faces(self, c: int) -> list:
        """The faces of cell ``c``, each an int32 array of vertex ids (views)."""
        cfo, fvo, fv = self.cell_face_offsets, self.face_vertex_offsets, self.face_vertices
        c = _inputs.as_index(c, len(cfo) - 1, "c", "cells")
        return [fv[fvo[f]:fvo[f + 1]] for f in range(cfo[c], cfo[c + 1])]

    # ---- diagnostics ------------------------------------------------------
    @property
    def duplicates(self) -> np.ndarray:
        """int32 (k, 2): (duplicate id, owner id) for exactly coincident points."""
        return self._cells.duplicates

    @property
    def power(self) -> bool:
        """Whether these are power cells (``radii`` given, not all equal: equal
        radii give the ordinary cells, and ``power`` is then False)."""
        return self._cells.power

    @property
    def empty_cells(self) -> np.ndarray:
        """int32, ascending: of power cells, the points whose cell within the
        domain is empty: their sphere's power is nowhere in the box the least
        (the regular triangulation's :attr:`Delaunay.hidden`), or only outside
        the box. They own no cell (``cell_of`` -1) and are nobody's
        neighbour. Empty for ordinary cells."""
        return self._cells.empty_cells

    @property
    def ignored_outside_bounds(self) -> np.ndarray:
        """int32: points dropped outside the bounds or not finite (ignore_outside=True)."""
        return self._cells.ignored_outside_bounds

    @property
    def exact_predicate_calls(self) -> int:
        """Clip decisions the float filter left to exact arithmetic."""
        return self._cells.exact_predicate_calls

    @property
    def far_points(self) -> int:
        """Points far beyond the bulk of the input (likely outliers: they
        stretch the default domain to over four times the bulk's extent)."""
        return self._cells.far_points

    @property
    def threads_used(self) -> int:
        return self._cells.threads_used

    @property
    def from_insertion(self) -> bool:
        """The cells came from the Delaunay triangulation by insertion (``method``)."""
        return self._cells.from_insertion

    @property
    def assembled_from_stars(self) -> int:
        """Of the cells from insertion, those assembled from their Delaunay stars
        with no clip, on the hull too (the rest, with a vertex within rounding
        of the box or too ill-conditioned and far out, were clipped by their
        Delaunay neighbours)."""
        return self._cells.assembled_from_stars

    @property
    def cells_from_pilot(self) -> int:
        """Cells the automatic method's pilot built while it sampled what the
        search costs, kept (not built again) where it chose the search."""
        return self._cells.cells_from_pilot

    # ---- checks, views, files ---------------------------------------------
    def validate(self) -> "_core.ValidationReport":
        """Invariant checks (the CLI's ``--validate``): volumes sum to the domain,
        symmetric neighbours, every merged vertex shared by exactly the cells of
        its key, Euler characteristic (3D), and a sample of cells (the smallest,
        the most elongated and a spread over the rest) whose volume,
        centroid and corners are compared with exact arithmetic
        (``measures_checked``, ``measure_rel_error``, ``vertex_rel_error``).
        The report is truthy when all pass; ``report.messages`` says what
        failed. In a periodic box neighbours must pair up with opposite
        shifts, and the vertex and exact-measure checks place each key's
        points at their images (:attr:`vertex_key_shifts`). Power cells are
        checked with their radii (a vertex has equal powers, not distances,
        to its key's points). ValueError for a result that holds some cells
        only (:attr:`FaceSet.voronoi` and :attr:`Flowers.voronoi` of points)."""
        if self._partial:
            raise ValueError("validate: this Voronoi result holds some cells only (the voronoi of tessera.faces or "
                             "tessera.flower of points); compute all of them with tessera.voronoi(points)")
        return _core.validate_cells(self._cells, self._labels, self._points, self._radii)

    @cached_property
    def scipy(self) -> "ScipyVoronoi":
        """The same cells with the attributes of ``scipy.spatial.Voronoi``."""
        from ._scipy import ScipyVoronoi

        return ScipyVoronoi(self)

    def save(self, path: PathLike) -> None:
        """Write the cells for ParaView: ``.vtu`` (3D, one VTK_POLYHEDRON per cell)
        or ``.vtp`` (2D, one polygon per cell), binary, written atomically.

        Cell data: GeneratorId, Region, Volume (Area), NumberOfFaces
        (NumberOfEdges), NumberOfNeighbors. Needs merge=True. ValueError for a
        wrong extension, OSError when the file cannot be written.
        """
        path = _inputs.as_path(path)
        want = ".vtu" if self.ndim == 3 else ".vtp"
        if not path.lower().endswith(want):
            kind = "UnstructuredGrid" if self.ndim == 3 else "PolyData"
            raise ValueError(f"save: {self.ndim}D cells are written as VTK {kind} ({want}), got {path!r}")
        _core.write_cells_vtk(path, self._cells)

    def to_vtk(self) -> Any:
        """The cells as a ``vtkUnstructuredGrid`` of polyhedra (3D) or a
        ``vtkPolyData`` of polygons (2D), with the cell data of :meth:`save`.
        Per-cell arrays and the 3D vertex coordinates are shared with VTK
        without copies. Needs ``vtk`` (Debian python3-vtk9) and merge=True."""
        from ._vtk import cells_to_vtk

        return cells_to_vtk(self)

    def __repr__(self) -> str:
        mesh = f", {self.n_vertices} vertices" if self.has_mesh else ", no mesh"
        kind = "power cells" if self.power else "cells"
        return f"<tessera.Voronoi {self.ndim}D: {self._cells.n_points} points, {self.n_cells} {kind}{mesh}>"


def voronoi(
    points: Any,
    labels: Any = None,
    bounds: Optional[Sequence[float]] = None,
    padding: float = 0.01,
    threads: Optional[int] = None,
    merge: bool = True,
    *,
    ignore_outside: bool = False,
    method: str = "auto",
    periodic: Any = False,
    tilt: Optional[Sequence[float]] = None,
    radii: Any = None,
    walls: Any = None,
) -> Voronoi:
    """Voronoi cells of 2D or 3D points, clipped to a box, with exact topology.

    Parameters
    ----------
    points : array_like, shape (N, 2) or (N, 3)
        Real numbers (float64 used as is, float32 and integers converted).
    labels : array_like of int, shape (N,), optional
        Region label of each point. A label < 0 marks an outside point: it
        clips its neighbours but owns no cell (carves concave shapes).
    bounds : sequence of float, optional
        The domain box (x0, x1, y0, y1[, z0, z1]). Default: the bounding box of
        the points grown by ``padding``.
    padding : float
        Margin of the default box, as a fraction of the largest extent (it is
        then rounded outward to a short binary fraction).
    threads : int, optional
        Worker threads; default ``TESSERA_NUM_THREADS`` if set, else every
        core. The result is identical for any count.
    merge : bool
        Build the merged mesh (vertices and faces; needed by :meth:`Voronoi.save`,
        :meth:`Voronoi.to_vtk` and the scipy view). False computes only the
        per-cell measures and neighbours: faster and smaller.
    ignore_outside : bool
        With ``bounds``: drop points outside the box (listed in
        ``ignored_outside_bounds``) instead of raising ValueError. Also,
        with or without ``bounds``, points with a NaN or infinite coordinate
        (an organized cloud's missing returns); the default box then comes
        from the others. Point ids stay the input's.
    method : {"auto", "search", "insertion"}
        How each cell finds the points that clip it; the cells are the
        same. ``"search"``: the bins around it (the meshless method).
        ``"insertion"``: its Delaunay neighbours, from incremental insertion
        (much faster where cells reach far: points nearly on a sphere or
        circle, surface samples, dense clusters, 2D curves). ``"auto"``:
        insertion where a sample of cells costs far more than on uniform
        points, else search (:attr:`Voronoi.from_insertion` says which
        ran).
    periodic : bool, str or sequence of bool
        Periodic axes: ``True`` (all), a string such as ``"xyz"`` or ``"x"``,
        or one bool per axis. ``bounds`` is then the box, which repeats along
        them (no walls there); points outside it are wrapped in. The box and
        the coordinates along those axes are rounded to the spacing of
        doubles at a few box lengths (2^-51 for a unit box), so that every
        image is exact; cells keep their shape across the box's faces, and
        :attr:`Voronoi.neighbor_shifts` says which image each neighbour is.
    tilt : sequence of float, optional
        A triclinic (sheared) periodic box: its tilt factors as lengths, as
        LAMMPS and Voro++ give them, ``(xy,)`` in 2D and ``(xy, xz, yz)`` in
        3D. The box is the parallelepiped spanned from ``bounds``' lower
        corner by a = (Lx, 0, 0), b = (xy, Ly, 0), c = (xz, yz, Lz), L the
        extents of ``bounds``; a tilt needs both of its axes periodic. A tilt
        of more than one box length is reduced by whole lengths first (xy by
        Lx; yz by Ly, moving xz by as many xy; xz by Lx): the same lattice, in
        a box that is not thin. Points are wrapped into the box of the tilts
        used (:attr:`Voronoi.tilt`, rounded like the coordinates), and
        :attr:`Voronoi.neighbor_shifts` count its a, b and c.
    radii : array_like of float, shape (N,), optional
        Radii of spheres at the points (finite, >= 0): power cells (the
        radical or Laguerre tessellation of polydisperse spheres, as Voro++'s
        ``container_poly``). Each cell is where its point's power
        ``|x - p|^2 - r^2`` is the least, so the face between two cells lies
        on their spheres' radical plane. A point may own no cell
        (:attr:`Voronoi.empty_cells`) or lie outside its own; of exactly
        coincident points the largest radius owns the cell (ties: the lowest
        id). All radii equal give exactly the ordinary cells. In a periodic
        box every image has its point's radius. Either ``method`` computes
        them: the search, or the regular triangulation's stars
        (``method="insertion"``; automatically where the search is costly).
        The array is kept (:attr:`Voronoi.radii`, no copy when it is float64
        and contiguous) for :meth:`Voronoi.validate`.
    walls : array_like, shape (k, D + 1), optional
        Half-spaces ``normal . x <= offset``, one per row as (normal...,
        offset), that cut the box down to a convex polygon or polyhedron (a
        convex domain: one wall per side). Each cell is its box cell's part
        inside them, cut exactly, so the cells stay conformal and their
        volumes sum to the domain's. A face on wall k has spoke ``-7 - k``
        (below the box planes' -1..-6). Every point must lie inside or on
        every wall (ValueError; ``ignore_outside`` drops such points). Not
        with ``periodic``. Kept as :attr:`Voronoi.walls`.

    Returns
    -------
    Voronoi

    Raises
    ------
    ValueError
        Bad input (``tessera.InputError`` for the library's own checks): wrong
        shape or dtype, NaN or infinite coordinates, label count mismatch,
        empty bounds, points outside the bounds, no extent to build a box from,
        radius count mismatch, a negative, NaN or infinite radius.
    KeyboardInterrupt
        Ctrl-C during the run (it stops between batches of cells).

    The computation runs with the GIL released: other Python threads go on.
    """
    return cells_of(points, labels, bounds, padding, threads, merge, ignore_outside, method, periodic, tilt, radii,
                    None, 0, walls)


def cells_of(points: Any, labels: Any, bounds: Any, padding: float, threads: Any, merge: bool, ignore_outside: bool,
             method: str, periodic: Any, tilt: Any, radii: Any, only: Optional[np.ndarray],
             only_with_faces: int, walls: Any = None) -> Voronoi:
    """:func:`voronoi`'s work, on its arguments (every one given: the
    defaults are voronoi's alone); with ``only`` (int32 ids that exist) the
    cells of those points and their neighbours alone, each as :func:`voronoi`
    computes it among all the points (``VoronoiOptions::only``;
    :func:`tessera.flower` of points); with ``only_with_faces`` (a set of
    spoke classes, ``_core.face_set_classes``; 0: none) the cells with a
    face of one of them alone (``VoronoiOptions::only_with_faces``;
    :func:`tessera.faces` of points). The result is partial where some
    cell was left out (``Cells::partial``): the products refuse it."""
    pts = _inputs.as_points(points)
    dim = pts.shape[1]
    lab = _inputs.as_labels(labels, pts.shape[0])
    per, tilts = periodic_box(periodic, tilt, bounds, dim)
    rad = _inputs.as_radii(radii, pts.shape[0])
    cells = _inputs.call(
        _core.voronoi,
        pts,
        lab,
        _inputs.as_bounds(bounds, dim),
        _inputs.as_padding(padding),
        _inputs.as_flag(ignore_outside, "ignore_outside"),
        _inputs.as_threads(threads),
        _inputs.as_flag(merge, "merge"),
        str(method),
        per,
        tilts,
        rad,
        only,
        only_with_faces,
        _inputs.as_walls(walls, dim),
    )
    return Voronoi(cells, pts, lab, rad)


def periodic_box(periodic: Any, tilt: Any, bounds: Any, dim: int) -> Tuple[Tuple[bool, bool, bool],
                                                                           Tuple[float, float, float]]:
    """``periodic`` and ``tilt`` (of voronoi, delaunay, surface_nets) as three
    flags and (xy, xz, yz); a periodic box needs ``bounds``, a tilt periodic axes."""
    per = _periodic_axes(periodic, dim)
    if any(per) and bounds is None:
        raise ValueError("periodic: give bounds, the box that repeats")
    tilts = _tilts(tilt, dim)
    if any(tilts) and not any(per):
        raise ValueError("tilt: give periodic axes (a triclinic box repeats along its tilted axes)")
    return per, tilts


def _tilts(tilt: Any, dim: int) -> Tuple[float, float, float]:
    """``voronoi``'s ``tilt`` as (xy, xz, yz)."""
    if tilt is None:
        return (0.0, 0.0, 0.0)
    want = "(xy, xz, yz)" if dim == 3 else "(xy,)"
    try:
        a = _inputs.numbers_array(tilt)
    except (TypeError, ValueError, OverflowError):
        a = None
    if a is None or a.ndim != 1:
        raise ValueError(f"tilt: expected {want}, numbers, got {tilt!r}")
    values = [float(t) for t in a]
    if len(values) != (3 if dim == 3 else 1):
        raise ValueError(f"tilt: expected {want} for {dim}D points, got {len(values)} values")
    values += [0.0] * (3 - len(values))
    return (values[0], values[1], values[2])


def _periodic_axes(periodic: Any, dim: int) -> Tuple[bool, bool, bool]:
    """``voronoi``'s ``periodic`` as three flags."""
    if isinstance(periodic, np.bool_):
        periodic = bool(periodic)
    if periodic is None or periodic is False:
        return (False, False, False)
    if periodic is True:
        return (True, True, dim == 3)
    if isinstance(periodic, str):
        axes = [False, False, False]
        for ch in periodic:
            k = "xyz".find(ch)
            if k < 0 or axes[k] or k >= dim:
                raise ValueError(f"periodic: expected axes among {'xyz'[:dim]!r}, each at most once, got {periodic!r}")
            axes[k] = True
        return (axes[0], axes[1], axes[2])
    # One flag per axis, booleans (numpy's too): a bare number, or strings
    # such as "False" (true by truthiness), are not flags.
    try:
        items = list(periodic)
    except TypeError:
        raise ValueError(f"periodic: expected True, False, axes such as 'xyz', or one bool per axis, got {periodic!r}") from None
    if not all(isinstance(f, (bool, np.bool_)) for f in items):
        raise ValueError(f"periodic: expected one bool per axis, got {periodic!r}")
    flags = [bool(f) for f in items]
    if len(flags) != dim:
        raise ValueError(f"periodic: expected {dim} flags (one per axis), got {len(flags)}")
    return (flags[0], flags[1], flags[2] if dim == 3 else False)

"""tessera.delaunay() and its result, :class:`Delaunay`."""

from __future__ import annotations

import os
from typing import Any, List, Optional, Sequence, Tuple, Union

import numpy as np

from . import _core, _inputs
from ._voronoi import periodic_box

PathLike = Union[str, "os.PathLike[str]"]


_TRANSFORM_BLOCK = 1 << 16


def _transform_block(v: np.ndarray, t: np.ndarray) -> None:
    """Fills ``t`` (m, D+1, D) with the barycentric maps of the simplices
    whose corners are ``v`` (m, D+1, D); see :attr:`Delaunay.transform`."""
    d = v.shape[2]
    t[:, d, :] = v[:, d, :]
    # Columns v_k - v_D. A positively oriented simplex is never flat, but its
    # LU factors may round to a zero pivot, where inv would raise: slogdet (the
    # same factorisation, and no underflow at tiny scales) has sign 0 exactly
    # there.
    m = np.transpose(v[:, :d, :] - v[:, d:, :], (0, 2, 1))
    ok = np.linalg.slogdet(m)[0] != 0
    t[:, :d, :] = np.nan
    if ok.all():
        t[:, :d, :] = np.linalg.inv(m)
    elif ok.any():
        t[ok, :d, :] = np.linalg.inv(m[ok])


class Delaunay:
    """The Delaunay triangulation of a point set (triangles in 2D, tetrahedra in 3D).

    Made by :func:`tessera.delaunay`. The attributes a ``scipy.spatial.Delaunay``
    user expects are here with the same meanings: :attr:`points`,
    :attr:`simplices`, :attr:`neighbors`, :attr:`ndim`, :attr:`npoints`,
    :attr:`nsimplex`, :attr:`convex_hull`, :attr:`coplanar`,
    :attr:`vertex_to_simplex`, :attr:`vertex_neighbor_vertices`,
    :attr:`transform` and :meth:`find_simplex`. Arrays are read-only views of
    buffers the compiled result owns (no copy) or, for the derived ones, arrays
    computed on first use and kept.

    Without labels the simplices cover the convex hull of the points exactly
    (hull completion); with labels they are those of that whole triangulation
    whose points are all inside points (label >= 0).

    With ``radii`` (not all equal) it is the regular (weighted Delaunay)
    triangulation, the dual of the power cells (:attr:`power`); points whose
    power cell is empty are in no simplex (:attr:`hidden`).
    """

    def __init__(self, dt: Any, points: np.ndarray, labels: Optional[np.ndarray],
                 radii: Optional[np.ndarray] = None):
        self._dt = dt
        self._points = points
        self._labels = labels
        self._radii = radii  # kept: validate() checks a regular triangulation with them
        self._hull: Optional[np.ndarray] = None
        self._vertex_to_simplex: Optional[np.ndarray] = None
        self._transform: Optional[np.ndarray] = None
        self._vertex_neighbors: Optional[Tuple[np.ndarray, np.ndarray]] = None

    @property
    def points(self) -> np.ndarray:
        """float64 (N, D): the input points, the caller's array itself when it was
        one (not copied: changed before the first ``find_simplex``, it changes
        what the locator finds)."""
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
    def power(self) -> bool:
        """Whether this is a regular (weighted Delaunay) triangulation, the dual
        of the power cells (``radii`` given, not all equal: equal radii give the
        ordinary triangulation, and ``power`` is then False)."""
        return self._dt.power

    @property
    def hidden(self) -> np.ndarray:
        """int32, ascending: of a regular triangulation with hull completion,
        the points in no simplex because their power cell is empty (neither
        duplicates nor ignored outside the bounds); with labels, only inside
        points. Empty for an ordinary triangulation. :attr:`vertex_to_simplex`
        is -1 for them."""
        return self._dt.hidden

    @property
    def ndim(self) -> int:
        return self._dt.dim

    @property
    def npoints(self) -> int:
        return self._points.shape[0]

    @property
    def nsimplex(self) -> int:
        return self._dt.n_simplices

    @property
    def bounds(self) -> Tuple[float, ...]:
        """The domain box of the cells pass, (x0, x1, y0, y1[, z0, z1])."""
        return self._dt.bounds

    @property
    def simplices(self) -> np.ndarray:
        """int32 (nsimplex, D+1): point ids of each simplex; positively oriented
        (2D: counter-clockwise), lowest id first. Rows are ordered by their
        sorted vertex sets (ascending), which, after the orientation's swap
        of two ids, is not the rows' own lexicographic order."""
        return self._dt.simplices

    def _refuse_periodic(self, attribute: str) -> None:
        """What matches simplices by point ids alone (the library's adjacency,
        edges and locator, scipy's attributes) is refused in a periodic box,
        whose rows name images: in this attribute's words, not the library's
        function's. An InputError (a ValueError), as the library's own refusal was."""
        if self.is_periodic:
            raise _core.InputError(f"{attribute}: not available for a periodic triangulation (its simplices meet images)")

    @property
    def neighbors(self) -> np.ndarray:
        """int32 (nsimplex, D+1): ``neighbors[r, k]`` is the simplex across the
        facet opposite vertex ``k`` of simplex ``r``, -1 on the boundary (as scipy).
        Computed on first use."""
        self._refuse_periodic("neighbors")
        return self._dt.neighbors

    @property
    def convex_hull(self) -> np.ndarray:
        """int32 (nfacets, D): the boundary facets (facets of one simplex only),
        each ordered so that its normal points out of the triangulation (3D:
        counter-clockwise seen from outside; 2D: the interior on the left).
        Without labels this is the convex hull, as scipy's; with labels, the
        boundary of the labelled regions. Computed on first use."""
        self._refuse_periodic("convex_hull")
        if self._hull is None:
            nb = self.neighbors
            s, k = np.nonzero(nb < 0)
            rows = self.simplices[s]
            d = self.ndim
            # The facet opposite vertex k, its vertices in cyclic order from
            # k + 1. In 2D that is the counter-clockwise edge, interior on its
            # left. In 3D it faces out of the positively oriented simplex for
            # even k (the cycle (k+1, k+2, k+3, k) is odd) and in for odd k,
            # which one swap turns out.
            idx = (k[:, None] + np.arange(1, d + 1)[None, :]) % (d + 1)
            facets = np.take_along_axis(rows, idx, axis=1)
            if d == 3:
                odd = (k % 2) == 1
                facets[odd] = facets[odd][:, [1, 0, 2]]
            facets.setflags(write=False)
            self._hull = facets
        return self._hull

    @property
    def coplanar(self) -> np.ndarray:
        """int32 (k, 3): the input points left out of the triangulation, as
        scipy's ``coplanar``: ``[point, a simplex of its twin, twin]``. In
        tessera these are exact duplicates: the lowest id of a group of
        coincident points is the vertex, the others are listed here."""
        dup = np.asarray(self.duplicates, dtype=np.int32).reshape(-1, 2)
        out = np.empty((len(dup), 3), dtype=np.int32)
        out[:, 0] = dup[:, 0]
        out[:, 1] = self.vertex_to_simplex[dup[:, 1]] if len(dup) else 0
        out[:, 2] = dup[:, 1]
        out.setflags(write=False)
        return out

    @property
    def vertex_to_simplex(self) -> np.ndarray:
        """int32 (npoints,): a simplex holding each point as a vertex (the
        lowest-indexed one), -1 for a point in none (a duplicate, an outside
        point, a :attr:`hidden` point). Computed on first use."""
        if self._vertex_to_simplex is None:
            v2s = self._dt.vertex_to_simplex()
            v2s.setflags(write=False)
            self._vertex_to_simplex = v2s
        return self._vertex_to_simplex

    @property
    def vertex_neighbor_vertices(self) -> Tuple[np.ndarray, np.ndarray]:
        """``(indptr, indices)``: the Delaunay edges as CSR, as scipy's; the
        neighbours of point ``v`` are ``indices[indptr[v]:indptr[v + 1]]``,
        ascending. Both int32, as scipy's, while the edges fit (``indptr``
        is int64 past 2^31 - 1 entries). Computed on first use (in parallel)."""
        self._refuse_periodic("vertex_neighbor_vertices")
        if self._vertex_neighbors is None:
            indptr, indices = self._dt.vertex_neighbors
            if len(indptr) and indptr[-1] <= np.iinfo(np.int32).max:
                indptr = indptr.astype(np.int32)
                indptr.setflags(write=False)
            self._vertex_neighbors = (indptr, indices)
        return self._vertex_neighbors

    @property
    def transform(self) -> np.ndarray:
        """float64 (nsimplex, D+1, D): affine maps to barycentric coordinates,
        as scipy's: for a point ``x`` in simplex ``s``,
        ``c = transform[s, :D] @ (x - transform[s, D])`` gives the first D
        coordinates and ``1 - c.sum()`` the last. Computed on first use.
        A simplex too thin for its matrix to be inverted in doubles (points
        an ulp apart: exactly non-flat, singular once rounded) gets NaN rows,
        as scipy gives its degenerate simplices."""
        self._refuse_periodic("transform")
        if self._transform is None:
            d = self.ndim
            simplices = self.simplices
            t = np.empty((len(simplices), d + 1, d))
            # In blocks: Ctrl-C is taken between them (numpy's batched calls
            # cannot be interrupted: 7 s at 1M points), and the corner
            # coordinates are never gathered for all simplices at once.
            for lo in range(0, len(simplices), _TRANSFORM_BLOCK):
                _transform_block(self.points[simplices[lo:lo + _TRANSFORM_BLOCK]],
                                 t[lo:lo + _TRANSFORM_BLOCK])
            t.setflags(write=False)
            self._transform = t
        return self._transform

    def find_simplex(self, xi: Any, bruteforce: bool = False, tol: Optional[float] = None) -> np.ndarray:
        """The simplex holding each point of ``xi`` (shape (..., D)), -1 where
        none does (outside the hull; with labels, outside the regions), as
        scipy's. Decided exactly: a point on a shared facet, edge or vertex
        gets the lowest-indexed simplex holding it, whatever the thread count.
        ``bruteforce`` is accepted for scipy compatibility and changes nothing;
        ``tol`` is not supported (there is no tolerance to set). The locator is
        built on the first call and reused: a walk from seeds near each query
        when the triangulation covers its hull, else (labels, or no hull
        completion) a grid of the simplices. The walk steps through
        :attr:`neighbors`, computed once for both."""
        if tol is not None:
            raise ValueError("find_simplex: tol is not supported; containment is decided exactly")
        self._refuse_periodic("find_simplex")
        q, shape = _inputs.as_queries(xi, self.ndim)
        found = _inputs.call(_core.locate, self._dt, self._points, q, self._dt.threads_used)
        return found.reshape(shape)

    @property
    def from_cells(self) -> int:
        """Simplices found by the cells pass (circumcentre inside the domain box)."""
        return self._dt.from_cells

    @property
    def from_hull_completion(self) -> int:
        """Simplices added by hull completion (circumcentre outside the box)."""
        return self._dt.from_hull_completion

    @property
    def from_insertion(self) -> int:
        """Simplices built by incremental insertion (``method``; then all of them)."""
        return self._dt.from_insertion

    @property
    def hull_completed(self) -> bool:
        return self._dt.hull_completed

    @property
    def outside_simplices(self) -> int:
        """With labels (and hull completion), where some inside point's cell reaches
        the domain box so that the whole triangulation was built: its simplices left
        out for an outside vertex (``from_cells``, ``from_hull_completion`` and
        ``from_insertion`` then count the whole triangulation, and sum to
        ``nsimplex`` plus this). 0 where the inside cells alone found every simplex."""
        return self._dt.outside_simplices

    @property
    def duplicates(self) -> np.ndarray:
        """int32 (k, 2): (duplicate id, owner id); duplicates are in no simplex."""
        return self._dt.duplicates

    @property
    def ignored_outside_bounds(self) -> np.ndarray:
        return self._dt.ignored_outside_bounds

    @property
    def exact_predicate_calls(self) -> int:
        return self._dt.exact_predicate_calls

    @property
    def threads_used(self) -> int:
        return self._dt.threads_used

    @property
    def is_periodic(self) -> bool:
        """A periodic box's triangulation (``delaunay(..., periodic=...)``)."""
        return any(self._dt.periodic)

    @property
    def simplex_shifts(self) -> np.ndarray:
        """int8 (nsimplex, D+1, D), periodic boxes only (empty otherwise): the
        image of each vertex of :attr:`simplices`, in box lengths (lattice
        vectors of a triclinic box): vertex ``k`` of simplex ``s`` sits at
        ``periodic_points[simplices[s, k]] + simplex_shifts[s, k] @ lattice``."""
        return self._dt.simplex_shifts

    @property
    def periodic_points(self) -> np.ndarray:
        """float64 (N, D), periodic boxes only: the points as wrapped into the
        box and rounded to its grid (the shifts are relative to these)."""
        return self._dt.periodic_points

    @property
    def tilt(self) -> Tuple[float, ...]:
        """A triclinic box's tilts as used (``(xy,)`` in 2D): rounded, and
        reduced by whole box lengths where one was more than a length; the
        basis :attr:`simplex_shifts` count."""
        t = self._dt.tilt
        return (t[0],) if self.ndim == 2 else (t[0], t[1], t[2])

    def validate(self) -> "_core.DelaunayReport":
        """Checks: orientation, manifold facets, closed and (without labels, and
        with hull completion) convex boundary and every point used, empty
        circumspheres (local Delaunay).
        A regular triangulation (:attr:`power`) is checked with its radii:
        local regularity (power spheres), and every :attr:`hidden` point is
        in no simplex (``hidden_not_hidden``) and, without labels, not in
        conflict with the simplex holding it (``hidden_in_conflict``).
        The report is truthy when all pass; ``report.messages`` says what failed."""
        # Equal radii gave the ordinary triangulation: it is checked without them.
        radii = self._radii if self.power else None
        return _core.validate_delaunay(self._dt, self._points, self._labels, radii)

    def squared_radii(self) -> np.ndarray:
        """float64 (nsimplex,): each simplex's squared circumradius (for a
        regular triangulation, :attr:`power`, its orthosphere's
        ``|c - p|^2 - r_p^2``, which may be negative), in floating point; inf
        where a simplex is flat in floats. To choose an ``alpha`` for
        :meth:`alpha_shape` (``np.sqrt(np.quantile(dt.squared_radii(), 0.9))``)."""
        radii = self._radii if self.power else None
        return _core.simplex_squared_radii(self._dt, self._points, radii)

    def alpha_shape(self, alpha: float) -> "AlphaShape":
        """The alpha shape: the simplices whose circumsphere's radius is at
        most ``alpha`` (for a regular triangulation, whose orthosphere's
        squared radius is at most ``alpha**2``: the dual of the balls grown by
        ``alpha``), the boundary of their union (a concave hull; CGAL's
        REGULARIZED alpha shape at CGAL's alpha = ``alpha**2``), and the alpha
        complex's singular facets (small empty-sphere triangles, or segments
        in 2D, that no kept simplex holds: the surface of a scan's samples).
        Decided exactly. ``alpha`` >= 0; ``float("inf")`` keeps every simplex
        (the boundary is then :attr:`convex_hull`). Of a periodic
        triangulation too: the facets then have their images' shifts
        (:attr:`AlphaShape.boundary_shifts`)."""
        radii = self._radii if self.power else None
        return AlphaShape(_core.alpha_shape(self._dt, self._points, float(alpha), radii), self)

    def save(self, path: PathLike) -> None:
        """Write the simplices for ParaView: ``.vtu`` (VTK_TETRA / VTK_TRIANGLE
        cells over all input points, 2D points with z = 0) or, in 2D, ``.vtp``
        (triangles as polygons); binary, written atomically. Cell data
        SimplexId, point data PointId, and for a regular triangulation
        (:attr:`power`) Radius. ValueError for a wrong extension, OSError when
        the file cannot be written."""
        path = _inputs.as_path(path)
        allowed = (".vtu",) if self.ndim == 3 else (".vtu", ".vtp")
        if not path.lower().endswith(allowed):
            raise ValueError(f"save: a {self.ndim}D triangulation is written as {' or '.join(allowed)}, got {path!r}")
        _core.write_simplices_vtk(path, self._dt, self._points, self._radii if self.power else None)

    def to_vtk(self) -> Any:
        """The triangulation as a ``vtkUnstructuredGrid`` (needs ``vtk``)."""
        from ._vtk import simplices_to_vtk

        return simplices_to_vtk(self)

    def __repr__(self) -> str:
        if self.power:
            return (f"<tessera.Delaunay {self.ndim}D: {self.npoints} points, {self.nsimplex} simplices, "
                    f"regular, {len(self.hidden)} hidden>")
        return f"<tessera.Delaunay {self.ndim}D: {self.npoints} points, {self.nsimplex} simplices>"


def delaunay(
    points: Any,
    labels: Any = None,
    bounds: Optional[Sequence[float]] = None,
    padding: float = 0.01,
    threads: Optional[int] = None,
    *,
    complete_hull: bool = True,
    ignore_outside: bool = False,
    method: str = "auto",
    periodic: Any = False,
    tilt: Optional[Sequence[float]] = None,
    radii: Any = None,
) -> Delaunay:
    """Delaunay triangulation of 2D or 3D points, the dual of the Voronoi cells.

    Parameters are those of :func:`tessera.voronoi` (``bounds`` and ``padding``
    set the domain of the cells pass), plus:

    complete_hull : bool
        Add the thin simplices near the convex hull whose circumcentres lie
        outside the domain box, so the simplices cover the hull exactly (as
        scipy's). With labels the result is then the whole triangulation's
        simplices whose points are all inside, whatever the box; without it,
        only those whose circumcentres lie in the box.
    method : {"auto", "cells", "insertion"}
        How the simplices are built; the result is the same. ``"cells"``: the
        parallel cells pass and hull completion. ``"insertion"``: incremental
        insertion (``complete_hull`` only; parallel by phases).
        ``"auto"``: insertion below 20,000 points, and
        from there where a sample of cells costs far more than it finds
        (surface samples, 2D curves and circles) or meets no ties on one or
        two threads (uniform points), or where 3D hull
        completion stalls (rotated lattices); else the cells (lattices).
    periodic, tilt : as in :func:`tessera.voronoi`, every axis periodic
        The triangulation of the points among all their images (``bounds``
        the box that repeats): each simplex once, translated so that its
        least (id, shift) vertex is at shift 0, and :attr:`Delaunay.simplex_shifts` the
        image of each of its vertices. No hull, so ``complete_hull`` and
        ``method`` do not apply; what matches facets by ids alone
        (``neighbors``, ``vertex_neighbor_vertices``, ``find_simplex``,
        ``convex_hull``, ``transform``) raises ValueError.
    radii : array_like of float, shape (N,), optional
        Radii of spheres at the points (finite, >= 0), as for the power cells
        of :func:`tessera.voronoi`: the regular (weighted Delaunay)
        triangulation, weights ``r**2`` (as CGAL's ``Regular_triangulation``),
        the dual of the power cells. A simplex is regular when no point's
        power ``|x - p|^2 - r^2`` to its orthocentre is below its vertices'.
        A point whose power cell is empty is in no simplex
        (:attr:`Delaunay.hidden`, with hull completion); of exactly
        coincident points the largest radius is the vertex (ties: the lowest
        id). All radii equal give exactly the ordinary triangulation
        (:attr:`Delaunay.power` False). Either ``method`` builds it, with
        the same rows. In a periodic box every image has its point's radius, and
        :attr:`Delaunay.hidden` lists the points in no simplex. The array is kept (:attr:`Delaunay.radii`,
        no copy when it is float64 and contiguous) for :meth:`Delaunay.validate`.

    Exact predicates and a symbolic perturbation decide every simplex, so
    degenerate input (lattices, cospherical points) gets a valid triangulation
    without joggling. Runs with the GIL released; Ctrl-C stops it.
    """
    pts = _inputs.as_points(points)
    dim = pts.shape[1]
    lab = _inputs.as_labels(labels, pts.shape[0])
    per, tilts = periodic_box(periodic, tilt, bounds, dim)
    rad = _inputs.as_radii(radii, pts.shape[0])
    full_hull = _inputs.as_flag(complete_hull, "complete_hull")
    if str(method) == "insertion" and not full_hull:
        raise ValueError("method='insertion' triangulates the whole convex hull: it needs complete_hull=True")
    dt = _inputs.call(
        _core.delaunay,
        pts,
        lab,
        _inputs.as_bounds(bounds, dim),
        _inputs.as_padding(padding),
        _inputs.as_flag(ignore_outside, "ignore_outside"),
        _inputs.as_threads(threads),
        full_hull,
        str(method),
        per,
        tilts,
        rad,
    )
    return Delaunay(dt, pts, lab, rad)


class AlphaShape:
    """An alpha shape of a :class:`Delaunay` triangulation
    (:meth:`Delaunay.alpha_shape`). Arrays are read-only views of buffers the
    compiled result owns."""

    def __init__(self, shape: Any, dt: Delaunay):
        self._shape = shape
        self._dt = dt

    @property
    def alpha(self) -> float:
        return self._shape.alpha

    @property
    def simplex_ids(self) -> np.ndarray:
        """int32 (k,): the triangulation's simplices kept (rows of
        :attr:`Delaunay.simplices`), ascending."""
        return self._shape.simplex_rows

    @property
    def simplices(self) -> np.ndarray:
        """int32 (k, D+1): the kept simplices' point ids (a copy)."""
        return self._dt.simplices[self._shape.simplex_rows]

    @property
    def boundary(self) -> np.ndarray:
        """int32 (b, D): the boundary of the kept simplices' union, facets of
        kept simplices whose other side is not kept. 3D triangles
        counter-clockwise seen from outside; 2D segments with the shape on
        their left (outer boundaries counter-clockwise, holes clockwise).
        Closed; where pieces touch along an edge (at a vertex in 2D) not a
        manifold (:attr:`nonmanifold_ridges`)."""
        return self._shape.boundary

    @property
    def boundary_simplices(self) -> np.ndarray:
        """int32 (b,): per boundary facet, the kept simplex (a row of
        :attr:`Delaunay.simplices`) it bounds."""
        return self._shape.boundary_simplex

    @property
    def singular(self) -> np.ndarray:
        """int32 (s, D): the alpha complex's singular facets: no kept simplex
        holds them, their smallest circumsphere has a radius at most
        ``alpha`` and holds neither opposite vertex. Unoriented."""
        return self._shape.singular

    @property
    def boundary_shifts(self) -> np.ndarray:
        """int8 (b, D, D): of a periodic triangulation's shape, each boundary
        facet's points' images in lattice vectors, in the frame of its
        simplex (:attr:`Delaunay.simplex_shifts`); else empty."""
        return self._shape.boundary_shifts

    @property
    def singular_shifts(self) -> np.ndarray:
        """int8 (s, D, D): the same for :attr:`singular`."""
        return self._shape.singular_shifts

    @property
    def components(self) -> int:
        """Pieces: kept simplices joined through shared facets."""
        return self._shape.components

    @property
    def piece(self) -> np.ndarray:
        """int32 (k,): per kept simplex (as :attr:`simplex_ids`), its piece,
        0 .. :attr:`components` - 1, numbered by the pieces' lowest simplices."""
        return self._shape.piece

    def polygons(self) -> List[List[np.ndarray]]:
        """2D: the boundary chained into polygons, one per piece (in
        :attr:`piece` order): a list of rings, the outer one first
        (counter-clockwise), then the holes (clockwise), each an int32 array
        of point ids once around (not closed). For shapely::

            polys = [shapely.Polygon(pts[rings[0]], [pts[h] for h in rings[1:]]) for rings in a.polygons()]

        Where the shape touches itself at a point, a ring keeps to the side
        it came along, so rings touch there but never cross."""
        if self._dt.ndim != 2:
            raise _core.InputError("polygons: only for a 2D alpha shape")
        self._dt._refuse_periodic("polygons")
        poly_rings, ring_points, ids = _core.boundary_polygons(self._dt._dt, self._dt.points, self._shape)
        rings = [ids[ring_points[r]:ring_points[r + 1]] for r in range(len(ring_points) - 1)]
        return [rings[poly_rings[k]:poly_rings[k + 1]] for k in range(len(poly_rings) - 1)]

    @property
    def nonmanifold_ridges(self) -> int:
        """3D: boundary edges in more than two boundary triangles; 2D:
        boundary vertices in more than two boundary segments."""
        return self._shape.nonmanifold_ridges

    @property
    def volume(self) -> float:
        """Volume (area in 2D) of the kept simplices."""
        return self._shape.volume

    @property
    def boundary_measure(self) -> float:
        """Area (length in 2D) of :attr:`boundary`."""
        return self._shape.boundary_measure

    @property
    def exact_tests(self) -> int:
        """Keep tests the float filter left to exact arithmetic."""
        return self._shape.exact_tests

    def save(self, path: PathLike, singular: bool = True) -> None:
        """Write the boundary (then, with ``singular``, the singular facets):
        ``.vtp`` for ParaView (triangles, 2D segments; cell data SimplexId,
        the :attr:`Delaunay.simplices` row a boundary facet bounds or -1, and
        Singular), ``.npy`` (int64 point ids) or, in 2D, ``.geojson`` (the
        :meth:`polygons` as a MultiPolygon, and the singular segments as a
        MultiLineString), for QGIS and geopandas. Written atomically.
        ValueError for another extension or GeoJSON in 3D, OSError when the
        file cannot be written."""
        self._dt._refuse_periodic("save")
        path = _inputs.as_path(path)
        allowed = (".vtp", ".npy") if self._dt.ndim == 3 else (".vtp", ".npy", ".geojson")
        if not path.lower().endswith(allowed):
            raise ValueError(f"save: a {self._dt.ndim}D alpha shape's boundary is written as "
                             f"{', '.join(allowed)}, got {path!r}")
        _core.write_alpha_boundary(path, self._dt._dt, self._dt.points, self._shape, bool(singular))

    def __repr__(self) -> str:
        return (f"AlphaShape(alpha={self.alpha!r}, simplices={len(self.simplex_ids)}, "
                f"boundary={len(self.boundary)}, singular={len(self.singular)}, components={self.components})")

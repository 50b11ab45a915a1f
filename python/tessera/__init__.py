"""Tessera: parallel meshless Voronoi tessellation in 2D and 3D with exact topology.

numpy in, numpy out::

    import numpy as np, tessera
    pts = np.random.default_rng(0).random((100_000, 3))
    vor = tessera.voronoi(pts)                 # bounded by the padded bounding box
    vor.volumes.sum()                          # == the box volume
    vor.save("cells.vtu")                      # ParaView: one polyhedron per cell
    dt = tessera.delaunay(pts)                 # simplices / neighbors as scipy's
    lab = (pts[:, 0] > 0.5).astype(int)        # a region label per point
    net = tessera.surface_nets(pts, lab)       # the surface between the regions

* :func:`voronoi` -> :class:`Voronoi`: cells clipped to a box, with volumes,
  centroids, neighbours, region labels, the merged mesh, ``save()`` (.vtu/.vtp),
  ``to_vtk()``, ``validate()`` and ``.scipy`` (a ``scipy.spatial.Voronoi``-like view).
* :func:`delaunay` -> :class:`Delaunay`: the dual triangulation (:meth:`Delaunay.alpha_shape`:
  concave hulls, surfaces of samples).
* :func:`adjacency` -> :class:`AdjacencyGraph`: wheels and spokes (CSR), spoke
  classes and face measures, ``edges()``.
* :func:`faces` -> :class:`FaceSet`: the boundary, the polygonal complex or the
  surface net between regions, with ``sides`` and ``boundary_labels``.
* :func:`flower` -> :class:`Flowers`: petals and circumflower of chosen cells.
* :func:`surface_nets` -> :class:`SurfaceNet`: smooth, watertight region
  surfaces of labelled points, with ``vertex_kind``.
* :func:`spherical_voronoi` -> :class:`SphericalVoronoi`: cells on a sphere
  (points or lon/lat), with areas, centroids, neighbours and the dual
  spherical Delaunay triangles; scipy's ``SphericalVoronoi`` layout.
* Point preparation: :func:`sample_image` (label image -> labelled points),
  :func:`read_image`, :func:`read_points`, :func:`read_box`, :func:`read_frames`, :func:`fill`, :func:`joggle`, :func:`threshold`,
  :func:`probe`, :func:`lloyd` (Lloyd relaxation towards a centroidal Voronoi
  tessellation -> :class:`LloydResult`).

:func:`adjacency`, :func:`faces` and :func:`flower` take points or a
:class:`Voronoi` computed with ``merge=True`` (reused, nothing recomputed).
Every product saves to ParaView (``save()``: .vtu / .vtp) and converts to a
VTK object (``to_vtk()``).

Arrays returned are read-only views of buffers the compiled result owns (no
copies); the preparation tools return new, writable arrays that took over the
library's buffers. Work runs in parallel with the GIL released (``threads=``
or the ``TESSERA_NUM_THREADS`` variable; results do not depend on the count),
and Ctrl-C interrupts a long run. Bad input raises ``ValueError``
(:class:`InputError` for the library's own checks).

Everything the library's front end computes is in the module; see
python/README.md for the layout.
"""

from . import _core
from ._core import (
    DelaunayReport,
    DOMAIN_BOUNDARY,
    OUTSIDE,
    REGION_BOUNDARY,
    SAME_REGION,
    InputError,
    SphereReport,
    ValidationReport,
)
from ._delaunay import AlphaShape, Delaunay, delaunay
from ._dual import AdjacencyGraph, FaceSet, Flower, Flowers, adjacency, faces, flower
from ._lloyd import LloydResult, lloyd
from ._prep import (Frame, fill, joggle, probe, read_box, read_frames, read_image, read_points, read_scalars,
                    sample_image, threshold)
from ._scipy import ScipyVoronoi
from ._surface_nets import NET_CORNER, NET_JUNCTION, NET_SURFACE, SurfaceNet, surface_nets
from ._sphere import SPHERE_CELL, SPHERE_DUPLICATE, SPHERE_HIDDEN, SphericalVoronoi, spherical_voronoi
from ._voronoi import Voronoi, voronoi
from ._walls import hull_walls, polygon_walls

__version__: str = _core.__version__

__all__ = [
    "voronoi",
    "Voronoi",
    "spherical_voronoi",
    "SphericalVoronoi",
    "SPHERE_CELL",
    "SPHERE_DUPLICATE",
    "SPHERE_HIDDEN",
    "hull_walls",
    "polygon_walls",
    "ScipyVoronoi",
    "delaunay",
    "AlphaShape",
    "Delaunay",
    "ValidationReport",
    "DelaunayReport",
    "SphereReport",
    "adjacency",
    "AdjacencyGraph",
    "faces",
    "FaceSet",
    "flower",
    "Flowers",
    "Flower",
    "surface_nets",
    "SurfaceNet",
    "sample_image",
    "read_image",
    "read_points",
    "read_scalars",
    "read_box",
    "read_frames",
    "Frame",
    "joggle",
    "fill",
    "threshold",
    "probe",
    "lloyd",
    "LloydResult",
    "InputError",
    "SAME_REGION",
    "REGION_BOUNDARY",
    "DOMAIN_BOUNDARY",
    "OUTSIDE",
    "NET_SURFACE",
    "NET_JUNCTION",
    "NET_CORNER",
    "__version__",
]

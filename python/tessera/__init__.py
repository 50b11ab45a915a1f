"""Tessera: parallel meshless Voronoi tessellation in 2D and 3D with exact topology.

numpy in, numpy out::

    import numpy as np, tessera
    pts = np.random.default_rng(0).random((100_000, 3))
    vor = tessera.voronoi(pts)                 # bounded by the padded bounding box
    vor.volumes.sum()                          # == the box volume
    vor.save("cells.vtu")                      # ParaView: one polyhedron per cell
    dt = tessera.delaunay(pts)                 # simplices / neighbors as scipy's

* :func:`voronoi` -> :class:`Voronoi`: cells clipped to a box, with volumes,
  centroids, neighbours, region labels, the merged mesh, ``save()`` (.vtu/.vtp),
  ``to_vtk()``, ``validate()`` and ``.scipy`` (a ``scipy.spatial.Voronoi``-like view).
* :func:`delaunay` -> :class:`Delaunay`: the dual triangulation.

Arrays returned are read-only views of buffers the compiled result owns (no
copies). Work runs in parallel with the GIL released (``threads=`` or the
``TESSERA_NUM_THREADS`` variable; results do not depend on the count), and
Ctrl-C interrupts a long run. Bad input raises ``ValueError``
(:class:`InputError` for the library's own checks).

Not in the module yet: the other products of the library (adjacency graph,
face sets, surface nets, flowers) and the point preparation tools (joggle,
fill, sample_image, threshold, probe). Each gets a function here, over its
compiled front end, as it lands; see python/README.md.
"""

from . import _core
from ._core import (
    DelaunayReport,
    DOMAIN_BOUNDARY,
    OUTSIDE,
    REGION_BOUNDARY,
    SAME_REGION,
    InputError,
    ValidationReport,
)
from ._delaunay import Delaunay, delaunay
from ._scipy import ScipyVoronoi
from ._voronoi import Voronoi, voronoi

__version__: str = _core.__version__

__all__ = [
    "voronoi",
    "Voronoi",
    "ScipyVoronoi",
    "delaunay",
    "Delaunay",
    "ValidationReport",
    "DelaunayReport",
    "InputError",
    "SAME_REGION",
    "REGION_BOUNDARY",
    "DOMAIN_BOUNDARY",
    "OUTSIDE",
    "__version__",
]

"""Arrays are views of the buffers the compiled result owns: no copies."""

import gc

import numpy as np
import pytest

import tessera
from conftest import random_points

VORONOI_ARRAYS = [
    "generators", "cell_of", "regions", "volumes", "centroids", "num_faces", "neighbor_offsets", "neighbors",
    "vertices", "vertex_keys", "cell_face_offsets", "face_vertex_offsets", "face_vertices", "face_neighbor",
    "face_class",
]


def address(a):
    return a.__array_interface__["data"][0]


@pytest.mark.parametrize("name", VORONOI_ARRAYS)
def test_voronoi_arrays_view_the_result(name):
    vor = tessera.voronoi(random_points(300, 3))
    a = getattr(vor, name)
    assert a.size > 0
    assert not a.flags.owndata
    assert isinstance(a.base, tessera._core.Cells)  # the owner of the buffer
    assert address(a) == address(getattr(vor, name))  # the same memory every time
    assert not a.flags.writeable
    with pytest.raises(ValueError, match="read-only"):
        a[0] = a[0]


@pytest.mark.parametrize("name", ["simplices", "neighbors"])
def test_delaunay_arrays_view_the_result(name):
    dt = tessera.delaunay(random_points(300, 3))
    a = getattr(dt, name)
    assert not a.flags.owndata and a.base is not None
    assert address(a) == address(getattr(dt, name))
    assert not a.flags.writeable


def test_a_view_keeps_its_buffer_alive():
    volumes = tessera.voronoi(random_points(1000, 3), bounds=(0, 1, 0, 1, 0, 1)).volumes
    gc.collect()  # the result object is gone; the array's base still holds the buffer
    junk = [np.ones(1000) for _ in range(100)]  # reuse freed memory, if any was freed
    assert volumes.sum() == pytest.approx(1.0, rel=1e-12)
    del junk


def test_labels_are_copied():
    # A result keeps its labels: a buffer refilled for the next frame left
    # faces() of the earlier cells with the new labels (an outside face's
    # side got a region's label).
    rng = np.random.default_rng(7)
    pts = rng.random((500, 3))
    lab = (pts[:, 0] * 3).astype(np.int32)
    lab[np.linalg.norm(pts - 0.5, axis=1) < 0.2] = -1
    vor = tessera.voronoi(pts, labels=lab)
    before = tessera.faces(vor, kind="boundary").boundary_labels.copy()
    lab[:] = np.where(lab >= 0, -2, 4)
    assert np.array_equal(tessera.faces(vor, kind="boundary").boundary_labels, before)
    assert vor.labels is not lab and not vor.labels.flags.writeable
    assert not np.shares_memory(tessera.delaunay(pts, labels=lab).labels, lab)


def test_float64_points_are_not_copied():
    pts = random_points(100, 2)
    assert tessera.voronoi(pts).points is pts
    assert tessera.delaunay(pts).points is pts
    f32 = pts.astype(np.float32)
    assert tessera.voronoi(f32).points.dtype == np.float64  # converted once, as documented

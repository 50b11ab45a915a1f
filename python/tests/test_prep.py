"""The point preparation tools: threshold, joggle, probe, fill, sample_image,
read_image — exact on small hand-checkable cases — and their bad input."""

import numpy as np
import pytest
from scipy import ndimage
from vtkmodules.util.numpy_support import numpy_to_vtk
from vtkmodules.vtkCommonDataModel import vtkImageData
from vtkmodules.vtkIOXML import vtkXMLImageDataWriter

import tessera
from conftest import random_points


# ----------------------------------------------------------------- threshold

def test_threshold_half_open_intervals():
    values = [-np.inf, -1.0, 0.0, 0.5, np.nextafter(1.0, 0), 1.0, 1.5, 2.0, 7.0, np.inf, np.nan]
    lab = tessera.threshold(values, [(0.0, 1.0, 3), (1.0, 2.0, 4), (5.0, np.inf, 9)])
    assert lab.dtype == np.int32 and lab.flags.writeable
    #                 -inf  -1  0  .5  1-  1  1.5  2  7  inf  nan
    assert lab.tolist() == [-1, -1, 3, 3, 3, 4, 4, -1, 9, -1, -1]
    low = tessera.threshold(values, [(-np.inf, 0.0, 1)], background_label=0)
    assert low.tolist() == [1, 1, 0, 0, 0, 0, 0, 0, 0, 0, 0]


def test_threshold_of_probed_field_labels_points():
    # A field given on a grid becomes labels at scattered points.
    x = np.linspace(0, 1, 11)
    field = np.add.outer(x, x)  # f(x, y) = x + y at voxel (i, j) -> image[j, i]
    pts = random_points(500, 2, seed=1)
    values, valid = tessera.probe(field, pts, spacing=0.1)
    assert valid.all()
    lab = tessera.threshold(values, [(0, 1, 0), (1, 3, 1)])
    assert np.array_equal(lab, (pts.sum(axis=1) >= 1).astype(np.int32))


# -------------------------------------------------------------------- joggle

def test_joggle_mask_passes_points_bit_identical():
    pts = random_points(2000, 3, seed=2)
    mask = np.arange(2000) % 3 == 0
    out = tessera.joggle(pts, radius=1e-3, mask=mask)
    assert out.shape == pts.shape and out.dtype == np.float64 and out is not pts
    assert out[~mask].tobytes() == pts[~mask].tobytes()
    assert np.all(np.any(out[mask] != pts[mask], axis=1))
    # A point's displacement depends only on (seed, id): the unmasked run agrees.
    full = tessera.joggle(pts, radius=1e-3)
    assert np.array_equal(full[mask], out[mask])
    assert np.array_equal(tessera.joggle(pts, radius=1e-3, mask=mask.astype(int)), out)


def test_joggle_radius_modes_and_seeds():
    pts = random_points(5000, 3, seed=3)
    diag = np.linalg.norm(pts.max(axis=0) - pts.min(axis=0))
    rel = tessera.joggle(pts, radius=1e-2)
    d = np.linalg.norm(rel - pts, axis=1)
    assert d.max() <= 1e-2 * diag * (1 + 1e-12) and d.max() > 0.5e-2 * diag
    ab = tessera.joggle(pts, radius=1e-3, absolute=True)
    assert np.linalg.norm(ab - pts, axis=1).max() <= 1e-3 * (1 + 1e-12)
    for axis, mode in ((2, "xy"), (1, "xz"), (0, "yz")):
        planar = tessera.joggle(pts, radius=1e-2, mode=mode)
        assert np.array_equal(planar[:, axis], pts[:, axis]), mode
    assert not np.array_equal(tessera.joggle(pts, seed=1), tessera.joggle(pts, seed=2))
    assert np.array_equal(tessera.joggle(pts, seed=5), tessera.joggle(pts, seed=5))
    assert np.array_equal(tessera.joggle(pts, threads=1), tessera.joggle(pts, threads=2))
    flat = tessera.joggle(pts[:, :2], radius=0)
    assert np.array_equal(flat, pts[:, :2])


# --------------------------------------------------------------------- probe

@pytest.mark.parametrize("dim", [2, 3])
def test_probe_reproduces_a_linear_field(dim):
    shape = (6, 7, 8)[-dim:]  # (nz,) ny, nx
    spacing = np.array([0.5, 0.25, 2.0])[:dim]  # x, y, z
    origin = np.array([1.0, -2.0, 3.0])[:dim]
    coef = np.array([3.0, -2.0, 0.5])[:dim]
    # Voxel (i, j[, k]) = image[(k,) j, i] at origin + (i, j, k) * spacing.
    idx = np.indices(shape)[::-1]  # i, j[, k], each of the image's shape
    pos = [origin[a] + idx[a] * spacing[a] for a in range(dim)]
    image = 1.0 + sum(coef[a] * pos[a] for a in range(dim))
    lo, hi = origin, origin + (np.array(shape[::-1]) - 1) * spacing
    pts = lo + random_points(1000, dim, seed=4) * (hi - lo)
    pts = np.vstack([pts, lo, hi])  # the far corner is inside
    values, valid = tessera.probe(image, pts, spacing=spacing, origin=origin)
    assert valid.dtype == np.bool_ and valid.all()
    assert np.allclose(values, 1.0 + pts @ coef, rtol=1e-12, atol=1e-12)
    outside = np.vstack([lo - 0.01, hi + 0.01])
    v, ok = tessera.probe(image, outside, spacing=spacing, origin=origin, outside_value=-5.0)
    assert not ok.any() and np.all(v == -5.0)
    v, ok = tessera.probe(image, outside, spacing=spacing, origin=origin)
    assert np.all(np.isnan(v))


def test_probe_reads_an_image_file(tmp_path):
    image = np.arange(24, dtype=np.float32).reshape(2, 3, 4)  # value = i + 4j + 12k
    np.save(tmp_path / "field.npy", image)
    values, valid = tessera.probe(tmp_path / "field.npy", [[1.5, 1.0, 0.5]])
    assert valid.all() and values[0] == pytest.approx(1.5 + 4 + 6)
    # x spacing 0.5: voxel i = 3 sits at x = 1.5.
    values, _ = tessera.probe(str(tmp_path / "field.npy"), [[1.5, 2.0, 1.0]], spacing=(0.5, 1, 1))
    assert values[0] == pytest.approx(3 + 8 + 12)


# ---------------------------------------------------------------------- fill

@pytest.mark.parametrize("strategy", ["uniform", "adaptive"])
def test_fill_keeps_the_input_and_adds_background(strategy):
    pts = random_points(3000, 3, seed=5)
    pts = pts[np.linalg.norm(pts - 0.5, axis=1) < 0.3]  # a ball inside the unit box
    lab = np.arange(len(pts)) % 2
    out, out_lab = tessera.fill(pts, lab, strategy=strategy, bounds=(0, 1, 0, 1, 0, 1), background_label=-3)
    n = len(pts)
    assert out.flags.writeable and out_lab.dtype == np.int32
    assert np.array_equal(out[:n], pts) and np.array_equal(out_lab[:n], lab)
    added = out[n:]
    assert len(added) > 0 and np.all(out_lab[n:] == -3)
    assert np.all((added >= 0) & (added <= 1))
    # Empty space is filled: added points lie away from the data (outside the ball, nearly).
    assert np.median(np.linalg.norm(added - 0.5, axis=1)) > 0.3
    # The background carves the ball: the labelled cells' volume is close to it.
    vor = tessera.voronoi(out, labels=out_lab, bounds=(0, 1, 0, 1, 0, 1))
    assert vor.volumes.sum() < 0.5


def test_fill_without_labels_uses_in_label_and_is_deterministic():
    pts = random_points(500, 2, seed=6) * 0.5
    a, la = tessera.fill(pts, in_label=4, bounds=(0, 1, 0, 1))
    b, lb = tessera.fill(pts, in_label=4, bounds=(0, 1, 0, 1))
    assert np.array_equal(a, b) and np.array_equal(la, lb)
    assert np.all(la[:500] == 4) and np.all(la[500:] == -1)
    j, _ = tessera.fill(pts, in_label=4, bounds=(0, 1, 0, 1), joggle=0.3, seed=2)
    assert len(j) == len(a) and np.array_equal(j[:500], pts) and not np.array_equal(j[500:], a[500:])


# -------------------------------------------------------------- sample_image

def label_volume():
    """-1 background with two touching boxes, labels 1 and 2, and a ball of 5."""
    im = np.full((16, 20, 24), -1, dtype=np.int32)  # nz, ny, nx
    im[3:13, 4:16, 3:12] = 1
    im[3:13, 4:16, 12:21] = 2
    k, j, i = np.indices(im.shape)
    im[(i - 6) ** 2 + (j - 10) ** 2 + (k - 8) ** 2 < 9] = 5
    return im


def expected_candidates(im, select, step=2):
    """Voxels the unrandomised exponential schedule keeps: d = 1 + L1 distance
    to the nearest boundary voxel is a power of `step`."""
    sel = np.isin(im, select)
    boundary = np.zeros(im.shape, bool)
    for axis in range(im.ndim):
        a = [slice(None)] * im.ndim
        b = [slice(None)] * im.ndim
        a[axis], b[axis] = slice(None, -1), slice(1, None)
        differ = (im[tuple(a)] != im[tuple(b)]) & (sel[tuple(a)] | sel[tuple(b)])
        boundary[tuple(a)] |= differ
        boundary[tuple(b)] |= differ
    d = 1 + ndimage.distance_transform_cdt(~boundary, metric="taxicab")
    powers = {step ** e for e in range(12)}
    return np.isin(d, list(powers))


@pytest.mark.parametrize("select", [None, [1, 2]])
def test_sample_image_exponential_schedule(select):
    im = label_volume()
    spacing, origin = (0.5, 1.0, 2.0), (10.0, 20.0, 30.0)
    pts, lab = tessera.sample_image(im, spacing=spacing, origin=origin, select=select, randomize=False)
    # Points at voxel centres, in voxel order, with the voxel's label.
    ijk = np.rint((pts - origin) / spacing).astype(int)
    assert np.allclose(pts, origin + ijk * spacing, rtol=0, atol=1e-12)
    flat = np.ravel_multi_index((ijk[:, 2], ijk[:, 1], ijk[:, 0]), im.shape)
    assert np.all(np.diff(flat) > 0)
    assert np.array_equal(lab, im.ravel()[flat])
    assert set(np.unique(lab).tolist()) <= set(np.unique(im).tolist())
    want = expected_candidates(im, [1, 2, 5] if select is None else select)
    assert np.array_equal(np.sort(flat), np.flatnonzero(want.ravel()))


def test_bool_masks_are_the_labels_0_and_1(tmp_path):
    """A boolean mask in memory is what the same array read from its .npy is
    (and what the command line reads): labels 0 and 1, values 0.0 and 1.0."""
    m = np.zeros((6, 7), bool)
    m[2:4, 2:5] = True
    np.save(tmp_path / "mask.npy", m)
    pts, labels = tessera.sample_image(m, randomize=False)
    ref_pts, ref_labels = tessera.sample_image(tmp_path / "mask.npy", randomize=False)
    assert np.array_equal(pts, ref_pts) and np.array_equal(labels, ref_labels)
    assert np.array_equal(pts, tessera.sample_image(m.astype(np.uint8), randomize=False)[0])
    values, valid = tessera.probe(m, [[2.0, 2.0], [0.0, 0.0], [2.5, 2.0]])
    assert valid.all() and list(values) == [1.0, 0.0, 1.0]


def test_sample_image_outputs_selection_and_background_label():
    im = label_volume()
    pts, lab = tessera.sample_image(im, select=[1], background_label=-9, seed=3)
    assert set(np.unique(lab).tolist()) <= {1, -9} and np.any(lab == 1) and np.any(lab == -9)
    inside, lab_in = tessera.sample_image(im, select=[1], output="labelled", seed=3)
    outside, lab_out = tessera.sample_image(im, select=[1], output="background", seed=3)
    assert np.all(lab_in == 1) and not np.any(lab_out == 1)
    assert len(inside) + len(outside) == len(pts)
    assert np.array_equal(np.sort(np.vstack([inside, outside]), axis=0), np.sort(pts, axis=0))
    # Randomised: seeded, and the same for any thread count.
    a = tessera.sample_image(im, seed=7, threads=1)
    b = tessera.sample_image(im, seed=7, threads=2)
    c = tessera.sample_image(im, seed=8)
    assert np.array_equal(a[0], b[0]) and np.array_equal(a[1], b[1])
    assert len(a[0]) != len(c[0]) or not np.array_equal(a[0], c[0])
    full = tessera.sample_image(im, randomize=False)[0]
    assert len(a[0]) < len(full)


def test_sample_image_edge_cases_from_the_fuzz(tmp_path):
    # No points: labels are still an int32 array (were None).
    p, l = tessera.sample_image(np.zeros((4, 4), np.int32))
    assert p.shape == (0, 2) and l.dtype == np.int32 and l.shape == (0,)
    a = np.zeros((3, 3, 3), np.int32)
    a[1, 1, 1] = 1
    p, l = tessera.sample_image(a, probability_range=(0, 0))
    assert p.shape == (0, 3) and l.dtype == np.int32 and l.shape == (0,)
    # Overridden geometry past double's range is refused as the command
    # refuses it (voxel centres came back infinite).
    np.save(tmp_path / "a.npy", a)
    for source in (a, tmp_path / "a.npy"):
        with pytest.raises(ValueError, match="pass double's range"):
            tessera.sample_image(source, spacing=1e308, randomize=False)
    with pytest.raises(ValueError, match="pass double's range"):
        tessera.probe(a.astype(float), [[1.5e308, 0, 0]], spacing=1e308)
    with pytest.raises(ValueError, match="pass double's range"):
        tessera.read_image(tmp_path / "a.npy", spacing=(1, 1e308, 1))


def test_sample_image_2d_from_a_file_and_joggle(tmp_path):
    im = np.zeros((30, 40), dtype=np.uint8)
    im[10:20, 5:35] = 3
    np.save(tmp_path / "labels.npy", im)
    pts, lab = tessera.sample_image(tmp_path / "labels.npy", spacing=0.1, randomize=False)
    assert pts.shape[1] == 2 and set(np.unique(lab).tolist()) == {0, 3}
    same, _ = tessera.sample_image(im, spacing=(0.1, 0.1), randomize=False)
    assert np.array_equal(pts, same)
    jog, jlab = tessera.sample_image(im, spacing=0.1, randomize=False, joggle=0.4)
    assert np.array_equal(jlab, lab)
    offset = np.abs(jog - pts).max()
    assert 0 < offset <= 0.4 * 0.1 * (1 + 1e-9)
    # The sampled points make a surface net of the labelled rectangle.
    net = tessera.surface_nets(pts, lab, select=3)
    assert net.n_faces == 0  # one selected region: no interfaces
    net = tessera.surface_nets(pts, lab)
    assert set(map(tuple, net.boundary_labels.tolist())) == {(0, 3)}


# ---------------------------------------------------------------- read_image

def test_read_image_npy_round_trip(tmp_path):
    im = label_volume().astype(np.int16)
    np.save(tmp_path / "im.npy", im)
    arr, spacing, origin = tessera.read_image(tmp_path / "im.npy")
    assert arr.dtype == np.int32 and arr.flags.writeable and np.array_equal(arr, im)
    assert spacing == (1.0, 1.0, 1.0) and origin == (0.0, 0.0, 0.0)
    arr, spacing, origin = tessera.read_image(tmp_path / "im.npy", spacing=(1, 2, 3), origin=(4, 5, 6))
    assert spacing == (1.0, 2.0, 3.0) and origin == (4.0, 5.0, 6.0)
    f = np.linspace(0, 1, 12).reshape(3, 4)
    np.save(tmp_path / "f.npy", f)
    arr, spacing, _ = tessera.read_image(str(tmp_path / "f.npy"))
    assert arr.dtype == np.float64 and np.array_equal(arr, f) and spacing == (1.0, 1.0)


def test_read_image_vti_written_by_vtk(tmp_path):
    im = label_volume()
    data = vtkImageData()
    data.SetDimensions(im.shape[2], im.shape[1], im.shape[0])  # nx, ny, nz
    data.SetSpacing(0.5, 0.25, 2.0)
    data.SetOrigin(1.0, 2.0, 3.0)
    arr = numpy_to_vtk(im.ravel(), deep=1)  # C order of (nz, ny, nx) = x fastest, as VTK
    arr.SetName("labels")
    data.GetPointData().SetScalars(arr)
    writer = vtkXMLImageDataWriter()
    writer.SetFileName(str(tmp_path / "im.vti"))
    writer.SetInputData(data)
    assert writer.Write() == 1
    back, spacing, origin = tessera.read_image(tmp_path / "im.vti")
    assert np.array_equal(back, im) and spacing == (0.5, 0.25, 2.0) and origin == (1.0, 2.0, 3.0)
    a = tessera.sample_image(tmp_path / "im.vti", randomize=False)
    b = tessera.sample_image(im, spacing=(0.5, 0.25, 2.0), origin=(1, 2, 3), randomize=False)
    assert np.array_equal(a[0], b[0]) and np.array_equal(a[1], b[1])


# ----------------------------------------------------------------- bad input

P3 = random_points(40, 3)
IM = label_volume()

BAD = {
    # threshold
    "threshold no intervals": (lambda: tessera.threshold([1.0], []), r"intervals: no intervals given"),
    "threshold empty interval": (lambda: tessera.threshold([1.0], [(2, 1, 0)]), r"intervals\[0\]: expected lo < hi"),
    "threshold NaN end": (lambda: tessera.threshold([1.0], [(0, np.nan, 0)]), r"intervals\[0\]: expected lo < hi"),
    "threshold overlap": (lambda: tessera.threshold([1.0], [(0, 2, 0), (1, 3, 1)]), r"overlap"),
    "threshold triple": (lambda: tessera.threshold([1.0], [(0, 1)]), r"intervals\[0\]: expected \(lo, hi, label\)"),
    "threshold label float": (lambda: tessera.threshold([1.0], [(0, 1, 0.5)]), r"intervals\[0\] label: expected"),
    "threshold 2-D": (lambda: tessera.threshold(np.zeros((3, 2)), [(0, 1, 0)]), r"scalars: expected a 1-D array"),
    "threshold text": (lambda: tessera.threshold(["a"], [(0, 1, 0)]), r"scalars: expected real numbers"),
    # joggle
    "joggle radius": (lambda: tessera.joggle(P3, radius=-1), r"radius: expected a finite number >= 0"),
    "joggle mode": (lambda: tessera.joggle(P3, mode="xyz"), r"mode: expected one of 'ball', 'xy', 'xz', 'yz'"),
    "joggle plane 2D": (lambda: tessera.joggle(P3[:, :2], mode="xy"), r"mode: 'xy' needs 3D points"),
    "joggle mask length": (lambda: tessera.joggle(P3, mask=np.ones(39, bool)), r"mask: expected one value per point"),
    "joggle mask float": (lambda: tessera.joggle(P3, mask=np.ones(40)), r"mask: expected booleans"),
    "joggle seed": (lambda: tessera.joggle(P3, seed=-1), r"seed: expected an integer in \[0, 2\*\*64\)"),
    "joggle NaN": (lambda: tessera.joggle(np.where(P3 == P3[5, 1], np.nan, P3)), r"point 5"),
    "joggle shape": (lambda: tessera.joggle(np.zeros((4, 5))), r"points: expected shape \(N, 2\) or \(N, 3\)"),
    # probe
    "probe dims": (lambda: tessera.probe(np.zeros((3, 4)), P3), r"points: 3D points for a 2D image"),
    "probe image 1-D": (lambda: tessera.probe(np.zeros(5), P3), r"image: expected shape \(ny, nx\) or \(nz, ny, nx\)"),
    "probe image empty": (lambda: tessera.probe(np.zeros((0, 4)), P3[:, :2]), r"image: no voxels"),
    "probe image complex": (lambda: tessera.probe(np.zeros((3, 4), complex), P3[:, :2]), r"image: expected real"),
    "probe spacing": (lambda: tessera.probe(np.zeros((3, 4)), P3[:, :2], spacing=(1, 0)), r"spacing: expected positive"),
    "probe spacing length": (lambda: tessera.probe(np.zeros((3, 4)), P3[:, :2], spacing=(1, 1, 1)), r"spacing: expected 2"),
    "probe NaN point": (lambda: tessera.probe(np.zeros((3, 4)), [[np.nan, 0.0]]), r"NaN"),
    "probe missing file": (lambda: tessera.probe("/nonexistent/f.npy", P3), r"/nonexistent/f\.npy"),
    # fill
    "fill strategy": (lambda: tessera.fill(P3, strategy="dense"), r"strategy: expected one of 'uniform', 'adaptive'"),
    "fill background": (lambda: tessera.fill(P3, background_label=2), r"background_label: expected a negative"),
    "fill points per bin": (lambda: tessera.fill(P3, points_per_bin=0), r"points_per_bin: expected a finite number > 0"),
    "fill joggle": (lambda: tessera.fill(P3, joggle=0.7), r"joggle: expected a number in \[0, 0\.5\]"),
    "fill labels": (lambda: tessera.fill(P3, labels=np.zeros(3, int)), r"labels: expected one label per point"),
    "fill outside bounds": (lambda: tessera.fill(P3 + 2, bounds=(0, 1, 0, 1, 0, 1)), r"outside the bounds"),
    "fill bounds length": (lambda: tessera.fill(P3, bounds=(0, 1)), r"bounds: expected 6 numbers"),
    # sample_image
    "sample float image": (lambda: tessera.sample_image(np.zeros((4, 4))), r"image: expected integer labels"),
    "sample complex image": (lambda: tessera.sample_image(np.zeros((4, 4), complex)), r"image: expected integer labels"),
    "sample 4-D image": (lambda: tessera.sample_image(np.zeros((2, 2, 2, 2), int)), r"image: expected shape"),
    "sample unknown label": (lambda: tessera.sample_image(IM, select=[1, 4]), r"unknown label 4"),
    "sample empty select": (lambda: tessera.sample_image(IM, select=[]), r"select: empty selection"),
    "sample schedule": (lambda: tessera.sample_image(IM, schedule="log"), r"schedule: expected one of"),
    "sample step": (lambda: tessera.sample_image(IM, step=1), r"step must be >= 2 for the exponential schedule"),
    "sample step 0": (lambda: tessera.sample_image(IM, step=0), r"step: expected an integer >= 2"),
    "sample probability": (lambda: tessera.sample_image(IM, probability_range=(0.5, 0.2)), r"probability_range"),
    "sample output": (lambda: tessera.sample_image(IM, output="inside"), r"output: expected one of"),
    "sample background": (lambda: tessera.sample_image(IM, background_label=3), r"background_label: expected a negative"),
    "sample spacing": (lambda: tessera.sample_image(IM, spacing=(1, 1)), r"spacing: expected 3 numbers"),
    "sample spacing zero": (lambda: tessera.sample_image(IM, spacing=0), r"spacing: expected a positive finite"),
    "sample no voxels": (lambda: tessera.sample_image(np.zeros((0, 3), int)), r"image: no voxels"),
    "sample missing file": (lambda: tessera.sample_image("/nonexistent/im.nrrd"), r"/nonexistent/im\.nrrd"),
    "sample threads": (lambda: tessera.sample_image(IM, threads=-2), r"threads: expected a positive integer"),
    # read_image
    "read missing": (lambda: tessera.read_image("/nonexistent/im.mha"), r"/nonexistent/im\.mha"),
    "read not a path": (lambda: tessera.read_image(IM), r"path: expected a file name"),
}


@pytest.mark.parametrize("case", list(BAD))
def test_bad_input_raises_value_error(case):
    call, message = BAD[case]
    with pytest.raises(ValueError, match=message):
        call()


def test_malformed_file_names_the_file(tmp_path):
    bad = tmp_path / "broken.nrrd"
    bad.write_text("NRRD0004\ntype: what\n\n")
    with pytest.raises(tessera.InputError, match="broken.nrrd"):
        tessera.read_image(bad)
    with pytest.raises(ValueError, match="unknown|extension|format"):
        tessera.read_image(tmp_path / "image.png")

#!/usr/bin/python3
"""VTK's discrete isosurfacing on a labelled .npy volume, one JSON line per run
in the peers' format (../../../shared/peers/README.md).

Usage: vtk_discrete.py VOLUME.npy [--repeat K] [--smooth N]

Filters: vtkDiscreteFlyingEdges3D ("dfe") and vtkDiscreteMarchingCubes
("dmc"), contour values = every label > 0; with --smooth N also DFE followed
by vtkWindowedSincPolyDataFilter (N iterations, pass band 0.1: VTK's usual
recipe to smooth label surfaces) ("dfe+sinc"). Timed: Update() only (the
numpy -> vtkImageData wrap is outside). Watertightness per label surface
(the triangles of one contour value): boundary edges (in one triangle) and
non-manifold edges (in three or more), summed over labels.
"""
import argparse
import json
import resource
import time

import numpy as np
import vtk
from vtk.util.numpy_support import numpy_to_vtk, vtk_to_numpy


def image_of(vol):
    im = vtk.vtkImageData()
    im.SetDimensions(vol.shape[2], vol.shape[1], vol.shape[0])
    arr = numpy_to_vtk(vol.ravel(order="C"), deep=False)
    arr.SetName("labels")
    im.GetPointData().SetScalars(arr)
    return im, arr


def watertight(poly, labels):
    """Per-label boundary and non-manifold edge counts of a contour output."""
    tris = vtk_to_numpy(poly.GetPolys().GetConnectivityArray()).reshape(-1, 3)
    # DFE labels its points, DMC its cells (each triangle one contour value).
    if poly.GetCellData().GetScalars() is not None:
        lab = vtk_to_numpy(poly.GetCellData().GetScalars()).reshape(len(tris), -1)[:, 0]
    elif poly.GetPointData().GetScalars() is not None:
        lab = vtk_to_numpy(poly.GetPointData().GetScalars())[tris[:, 0]]
    else:
        raise SystemExit("contour output has no scalars")
    boundary = nonmanifold = open_labels = 0
    for l in labels:
        t = tris[lab == l]
        if len(t) == 0:
            continue
        e = np.sort(np.concatenate([t[:, [0, 1]], t[:, [1, 2]], t[:, [2, 0]]]), axis=1)
        key = e[:, 0].astype(np.int64) * (poly.GetNumberOfPoints() + 1) + e[:, 1]
        _, counts = np.unique(key, return_counts=True)
        b, m = int(np.sum(counts == 1)), int(np.sum(counts > 2))
        boundary += b
        nonmanifold += m
        open_labels += (b + m) > 0
    return boundary, nonmanifold, open_labels


def run(name, make, im, labels, n_vox, rep):
    f = make()
    f.SetInputData(im)
    ru0 = resource.getrusage(resource.RUSAGE_SELF)
    t0 = time.perf_counter()
    f.Update()
    secs = time.perf_counter() - t0
    ru1 = resource.getrusage(resource.RUSAGE_SELF)
    out = f.GetOutput()
    b, m, o = watertight(out, labels)
    print(json.dumps({"tool": "vtk", "op": "surface-nets:" + name, "n": n_vox, "threads": vtk.vtkSMPTools.GetEstimatedNumberOfThreads(), "seconds": secs,
                      "simplices": out.GetNumberOfPolys(),
                      "extra": {"cpu_user_s": ru1.ru_utime - ru0.ru_utime, "cpu_sys_s": ru1.ru_stime - ru0.ru_stime,
                                "peak_rss_bytes": ru1.ru_maxrss * 1024, "points": out.GetNumberOfPoints(),
                                "triangles": out.GetNumberOfPolys(), "labels": len(labels),
                                "watertight": b + m == 0, "open_labels": o, "boundary_edges": b,
                                "nonmanifold_edges": m, "vtk": vtk.vtkVersion.GetVTKVersion(),
                                "smp_backend": vtk.vtkSMPTools.GetBackend()
                                if hasattr(vtk.vtkSMPTools, "GetBackend") else "?", "repeat": rep}}),
          flush=True)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("volume")
    ap.add_argument("--repeat", type=int, default=1)
    ap.add_argument("--smooth", type=int, default=20)
    a = ap.parse_args()
    vol = np.ascontiguousarray(np.load(a.volume))
    labels = [int(l) for l in np.unique(vol) if l > 0]
    im, _keep = image_of(vol)

    def dfe():
        f = vtk.vtkDiscreteFlyingEdges3D()
        for i, l in enumerate(labels):
            f.SetValue(i, l)
        f.ComputeNormalsOff()
        f.ComputeGradientsOff()
        f.ComputeScalarsOn()
        return f

    def dmc():
        f = vtk.vtkDiscreteMarchingCubes()
        for i, l in enumerate(labels):
            f.SetValue(i, l)
        f.ComputeNormalsOff()
        f.ComputeGradientsOff()
        f.ComputeScalarsOn()
        return f

    class DfeSinc:  # DFE + windowed-sinc smoothing as one timed "filter"
        def __init__(self):
            self.f, self.s = dfe(), vtk.vtkWindowedSincPolyDataFilter()
            self.s.SetInputConnection(self.f.GetOutputPort())
            self.s.SetNumberOfIterations(a.smooth)
            self.s.SetPassBand(0.1)
            self.s.BoundarySmoothingOff()
            self.s.FeatureEdgeSmoothingOff()
            self.s.NonManifoldSmoothingOn()
            self.s.NormalizeCoordinatesOn()

        def SetInputData(self, im):
            self.f.SetInputData(im)

        def Update(self):
            self.s.Update()

        def GetOutput(self):
            return self.s.GetOutput()

    for rep in range(a.repeat):
        run("dfe", dfe, im, labels, vol.size, rep)
        run("dmc", dmc, im, labels, vol.size, rep)
        if a.smooth > 0:
            run("dfe+sinc", DfeSinc, im, labels, vol.size, rep)


if __name__ == "__main__":
    main()

#!/usr/bin/python3
"""Writes the image-reader test files into OUTDIR (run by test_image_readers.cpp).

Usage: /usr/bin/python3 make_images.py OUTDIR

.vti and .mha/.mhd come from VTK's own writers (vtkXMLImageDataWriter,
vtkMetaImageWriter; Debian python3-vtk9), .nrrd/.nhdr are hand-made headers
with raw, gzip (python's gzip) and ascii data. The voxel values follow
formulas the C++ test recomputes:

  labels  L(i, j, k) = (7 i + 13 j + 31 k) % 97 - 20          (int types)
  field   F(i, j, k) = 0.5 i - 0.25 j + 2 k + 0.125            (float types)
  bytes   B(i, j, k) = (3 i + 5 j + 11 k) % 256                (uint8)

with (i, j, k) the 0-based voxel index inside the file (x fastest).
The 3D test geometry: size (5, 4, 3), spacing (0.5, 0.25, 2); origin of voxel
(0, 0, 0) = (2, -2, 5). The .vti files get extent [2..6]x[0..3]x[1..3] with
VTK origin (1, -2, 3), which puts voxel (0, 0, 0) at (2, -2, 5) as well.
"""
import gzip
import os
import struct
import sys

import numpy as np
import vtk
from vtk.util.numpy_support import numpy_to_vtk

NX, NY, NZ = 5, 4, 3
SPACING = (0.5, 0.25, 2.0)
ORIGIN = (2.0, -2.0, 5.0)          # position of voxel (0, 0, 0)
EXT0 = (2, 0, 1)                   # .vti extent start
VTK_ORIGIN = (1.0, -2.0, 3.0)      # ORIGIN - EXT0 * SPACING


def grid(nx, ny, nz):
    k, j, i = np.meshgrid(np.arange(nz), np.arange(ny), np.arange(nx), indexing="ij")
    return i, j, k


def labels(nx=NX, ny=NY, nz=NZ, dtype=np.int16):
    i, j, k = grid(nx, ny, nz)
    return ((7 * i + 13 * j + 31 * k) % 97 - 20).astype(dtype)


def field(nx=NX, ny=NY, nz=NZ, dtype=np.float64):
    i, j, k = grid(nx, ny, nz)
    return (0.5 * i - 0.25 * j + 2.0 * k + 0.125).astype(dtype)


def bytes_(nx=NX, ny=NY, nz=NZ):
    i, j, k = grid(nx, ny, nz)
    return ((3 * i + 5 * j + 11 * k) % 256).astype(np.uint8)


def vtk_image(arrays, nx=NX, ny=NY, nz=NZ, ext0=EXT0, origin=VTK_ORIGIN, active=None):
    """arrays: list of (name, numpy array (nz, ny, nx) or (nz, ny, nx, c))."""
    img = vtk.vtkImageData()
    img.SetExtent(ext0[0], ext0[0] + nx - 1, ext0[1], ext0[1] + ny - 1, ext0[2], ext0[2] + nz - 1)
    img.SetSpacing(*SPACING)
    img.SetOrigin(*origin)
    for idx, (name, a) in enumerate(arrays):
        flat = a.reshape(nx * ny * nz, -1) if a.ndim == 4 else a.ravel()
        va = numpy_to_vtk(np.ascontiguousarray(flat), deep=1)
        va.SetName(name)
        img.GetPointData().AddArray(va)
    img.GetPointData().SetActiveScalars(active if active else arrays[0][0])
    return img


def write_vti(path, img, mode, compressed, header64=False, pieces=1):
    w = vtk.vtkXMLImageDataWriter()
    w.SetInputData(img)
    w.SetFileName(path)
    if mode == "ascii":
        w.SetDataModeToAscii()
    elif mode == "binary":
        w.SetDataModeToBinary()
    else:
        w.SetDataModeToAppended()
        w.SetEncodeAppendedData(mode == "appended_base64")
    if compressed:
        w.SetCompressorTypeToZLib()
        w.SetBlockSize(64)  # several compressed blocks even for small arrays
    else:
        w.SetCompressorTypeToNone()
    if header64:
        w.SetHeaderTypeToUInt64()
    w.SetNumberOfPieces(pieces)
    if w.Write() != 1:
        raise SystemExit("vtkXMLImageDataWriter failed on " + path)


def write_meta(path, img, compressed):
    w = vtk.vtkMetaImageWriter()
    w.SetInputData(img)
    w.SetFileName(path)
    w.SetCompression(bool(compressed))
    w.Write()


def nrrd_header(type_name, sizes, encoding, endian="little", extra=()):
    lines = ["NRRD0004", "# written by tessera's image tests", "type: " + type_name,
             "dimension: %d" % len(sizes), "sizes: " + " ".join(str(s) for s in sizes)]
    if len(sizes) == 3:
        lines += ["space: left-posterior-superior",
                  "space directions: (%r,0,0) (0,%r,0) (0,0,%r)" % SPACING,
                  "space origin: (%r,%r,%r)" % ORIGIN]
    else:
        lines += ["spacings: %r %r" % SPACING[:2]]
    lines += ["kinds: " + " ".join(["domain"] * len(sizes)), "encoding: " + encoding]
    if endian:
        lines.append("endian: " + endian)
    lines += list(extra)
    return "\n".join(lines) + "\n"


NIFTI_TYPES = {"uint8": 2, "int16": 4, "int32": 8, "float32": 16, "float64": 64}


def nifti_header(a, version=1, endian="<", magic=None, sform=None, qform=None, pixdim=None, vox_offset=None,
                 slope=0.0, inter=0.0, dims=None):
    """A NIfTI-1 (348 bytes) or NIfTI-2 (540) header for array a (nz, ny, nx),
    written field by field from the standard's layout (nifti1.h, nifti2.h).
    sform: 3x4 rows; qform: (b, c, d, qx, qy, qz, qfac)."""
    e = endian
    dt = NIFTI_TYPES[a.dtype.name]
    bitpix = a.dtype.itemsize * 8
    dims = dims or ([3, NX, NY, NZ, 1, 1, 1, 1] if a.ndim == 3 else [2, a.shape[1], a.shape[0], 1, 1, 1, 1, 1])
    pd = [1.0] + list(pixdim or SPACING) + [0, 0, 0, 0]
    if qform is not None:
        pd[0] = qform[6]
    qb, qc, qd, qx, qy, qz = qform[:6] if qform is not None else (0, 0, 0, 0, 0, 0)
    srow = sform if sform is not None else [[0] * 4] * 3
    if version == 1:
        h = bytearray(348)
        struct.pack_into(e + "i", h, 0, 348)
        struct.pack_into(e + "8h", h, 40, *dims)
        struct.pack_into(e + "hh", h, 70, dt, bitpix)
        struct.pack_into(e + "8f", h, 76, *pd)
        struct.pack_into(e + "f", h, 108, 352.0 if vox_offset is None else vox_offset)
        struct.pack_into(e + "ff", h, 112, slope, inter)
        struct.pack_into(e + "hh", h, 252, 1 if qform is not None else 0, 1 if sform is not None else 0)
        struct.pack_into(e + "6f", h, 256, qb, qc, qd, qx, qy, qz)
        for r in range(3):
            struct.pack_into(e + "4f", h, 280 + 16 * r, *srow[r])
        h[344:348] = (magic or b"n+1") + b"\0"
        return bytes(h) + b"\0" * 4  # the extension flag: none
    h = bytearray(540)
    struct.pack_into(e + "i", h, 0, 540)
    h[4:12] = (magic or b"n+2") + b"\0\r\n\x1a\n"
    struct.pack_into(e + "hh", h, 12, dt, bitpix)
    struct.pack_into(e + "8q", h, 16, *dims)
    struct.pack_into(e + "8d", h, 104, *pd)
    struct.pack_into(e + "q", h, 168, 544 if vox_offset is None else vox_offset)
    struct.pack_into(e + "dd", h, 176, slope, inter)
    struct.pack_into(e + "ii", h, 344, 1 if qform is not None else 0, 1 if sform is not None else 0)
    struct.pack_into(e + "6d", h, 352, qb, qc, qd, qx, qy, qz)
    for r in range(3):
        struct.pack_into(e + "4d", h, 400 + 32 * r, *srow[r])
    return bytes(h) + b"\0" * 4


def write_nifti(path, a, **kw):
    """a: (nz, ny, nx) as stored; .gz names are gzipped whole."""
    e = kw.get("endian", "<")
    data = nifti_header(a, **kw) + np.ascontiguousarray(a).astype(a.dtype.newbyteorder(e)).tobytes()
    with (gzip.open(path, "wb") if path.endswith(".gz") else open(path, "wb")) as f:
        f.write(data)


def main():
    out = sys.argv[1]
    os.makedirs(out, exist_ok=True)
    p = lambda name: os.path.join(out, name)  # noqa: E731

    lab = labels()
    fld = field()
    # ---- VTK XML image data: every data mode, with and without zlib, both header types
    img = vtk_image([("labels", lab), ("field", fld)])
    for mode in ["ascii", "binary", "appended_raw", "appended_base64"]:
        for comp in [0, 1]:
            if mode == "ascii" and comp:
                continue
            write_vti(p("vti_%s_%s.vti" % (mode, "zlib" if comp else "none")), img, mode, comp)
    for mode in ["binary", "appended_raw", "appended_base64"]:
        write_vti(p("vti_%s_zlib_h64.vti" % mode), img, mode, 1, header64=True)
        write_vti(p("vti_%s_none_h64.vti" % mode), img, mode, 0, header64=True)
    # Several pieces in one file (as a parallel writer produces them; they share
    # the layer z = 2): written piece by piece by VTK, spliced into one file.
    texts = []
    for z0, z1, mode in [(0, 2, "binary"), (1, 3, "ascii")]:
        sub = vtk_image([("labels", lab[z0:z1])], nz=z1 - z0, ext0=(EXT0[0], EXT0[1], EXT0[2] + z0))
        write_vti(p("piece.vti"), sub, mode, mode == "binary")
        with open(p("piece.vti")) as f:
            texts.append(f.read())
    os.remove(p("piece.vti"))
    whole = "%d %d %d %d %d %d" % (EXT0[0], EXT0[0] + NX - 1, EXT0[1], EXT0[1] + NY - 1, EXT0[2], EXT0[2] + NZ - 1)
    head = texts[0][:texts[0].index("<ImageData")]
    pieces = [t[t.index("<Piece"):t.index("</Piece>") + len("</Piece>")] for t in texts]
    with open(p("vti_pieces.vti"), "w") as f:
        f.write(head + '<ImageData WholeExtent="%s" Origin="%r %r %r" Spacing="%r %r %r">\n' %
                ((whole,) + VTK_ORIGIN + SPACING) + "\n".join(pieces) + "\n</ImageData>\n</VTKFile>\n")
    # every integer type (labels), float32 (field)
    for t in ["int8", "uint8", "int16", "uint16", "int32", "uint32", "int64"]:
        a = labels(dtype=t) if not t.startswith("u") else (labels() + 20).astype(t)
        write_vti(p("vti_type_%s.vti" % t), vtk_image([("labels", a)]), "binary", 1)
    write_vti(p("vti_type_float32.vti"), vtk_image([("field", field(dtype=np.float32))]), "appended_raw", 0)
    # active scalars is the second array
    write_vti(p("vti_active_field.vti"), vtk_image([("labels", lab), ("field", fld)], active="field"), "binary", 0)
    # 2D (one z slice), uint8
    b2 = bytes_(nz=1)
    write_vti(p("vti_2d.vti"), vtk_image([("bytes", b2)], nz=1, ext0=(0, 0, 0), origin=ORIGIN), "binary", 1)
    # multi-component: rejected
    vec = np.stack([lab, lab, lab], axis=-1)
    write_vti(p("vti_vector.vti"), vtk_image([("vec", vec)]), "binary", 0)

    # ---- MetaImage (vtkMetaImageWriter; VTK's origin of extent start = Offset)
    img_lab = vtk_image([("labels", lab)])
    img_fld = vtk_image([("field", fld)])
    for comp in [0, 1]:
        tag = "zlib" if comp else "raw"
        write_meta(p("meta_%s.mha" % tag), img_lab, comp)
        write_meta(p("meta_%s.mhd" % tag), img_lab, comp)
        write_meta(p("meta_field_%s.mha" % tag), img_fld, comp)

    # ---- legacy VTK images (vtkStructuredPointsWriter), both modes
    for mode in ("ascii", "binary"):
        sp = vtk.vtkImageData()
        sp.SetDimensions(NX, NY, NZ)
        sp.SetSpacing(*SPACING)
        sp.SetOrigin(*ORIGIN)
        for k, (name, a) in enumerate((("labels", lab), ("field", fld))):
            va = numpy_to_vtk(np.ascontiguousarray(a.ravel()), deep=1)
            va.SetName(name)
            sp.GetPointData().AddArray(va)
        sp.GetPointData().SetActiveScalars("labels")
        w = vtk.vtkStructuredPointsWriter()
        w.SetInputData(sp)
        w.SetFileName(p("legacy_%s.vtk" % mode))
        w.SetFileTypeToBinary() if mode == "binary" else w.SetFileTypeToASCII()
        w.Write()

    # ---- NIfTI, hand-made: the test geometry stored with and without flipped
    # axes (negative steps), read back to the same image.
    ox, oy, oz = ORIGIN
    sx, sy, sz = SPACING
    diag = lambda fx, fy, fz, t: [[fx * sx, 0, 0, t[0]], [0, fy * sy, 0, t[1]], [0, 0, fz * sz, t[2]]]  # noqa: E731
    write_nifti(p("nifti1_sform.nii"), lab, sform=diag(1, 1, 1, ORIGIN))
    # x stored backwards: its first voxel is the last one, at x = 2 + 4 * 0.5
    write_nifti(p("nifti1_flipx.nii.gz"), lab[:, :, ::-1], sform=diag(-1, 1, 1, (ox + 4 * sx, oy, oz)))
    # big-endian, qform only: the identity rotation with qfac -1 (z backwards)
    write_nifti(p("nifti1_qfac_be.nii"), lab[::-1], endian=">", qform=(0, 0, 0, ox, oy, oz + 2 * sz, -1.0))
    # a header/image pair whose qform is 180 degrees about x: y and z backwards
    with open(p("nifti1_pair.hdr"), "wb") as f:
        f.write(nifti_header(lab, magic=b"ni1", vox_offset=0, qform=(1, 0, 0, ox, oy + 3 * sy, oz + 2 * sz, 1.0))[:348])
    with open(p("nifti1_pair.img"), "wb") as f:
        f.write(np.ascontiguousarray(lab[::-1, ::-1]).tobytes())
    write_nifti(p("nifti2_field.nii"), fld, version=2, sform=diag(1, 1, 1, ORIGIN))
    # stored float32 values scaled by scl_slope / scl_inter into the field
    write_nifti(p("nifti1_scaled.nii.gz"), ((fld - 0.125) / 0.5).astype(np.float32), sform=diag(1, 1, 1, ORIGIN),
                slope=0.5, inter=0.125)
    # refused: a rotation, a time series, an Analyze header
    c, s_ = np.cos(0.3), np.sin(0.3)
    write_nifti(p("nifti1_rotated.nii"), lab, sform=[[c * sx, -s_ * sy, 0, 0], [s_ * sx, c * sy, 0, 0], [0, 0, sz, 0]])
    write_nifti(p("nifti1_4d.nii"), np.concatenate([lab, lab]), sform=diag(1, 1, 1, ORIGIN),
                dims=[4, NX, NY, NZ, 2, 1, 1, 1])
    write_nifti(p("analyze.nii"), lab, magic=b"\0\0\0")

    # ---- NRRD, hand-made
    raw16 = lab.astype("<i2").tobytes()
    with open(p("nrrd_raw.nrrd"), "wb") as f:
        f.write(nrrd_header("short", (NX, NY, NZ), "raw").encode() + b"\n" + raw16)
    # Axes stored flipped (negative steps) in each format, read back to the
    # same image: NRRD x, MetaImage y (by TransformMatrix), .vti x and z (by Direction).
    flipped = nrrd_header("short", (NX, NY, NZ), "raw").replace(
        "(%r,0,0) (0,%r,0)" % SPACING[:2], "(%r,0,0) (0,%r,0)" % (-SPACING[0], SPACING[1])).replace(
        "space origin: (%r," % ORIGIN[0], "space origin: (%r," % (ORIGIN[0] + 4 * SPACING[0]))
    with open(p("nrrd_flipx.nrrd"), "wb") as f:
        f.write(flipped.encode() + b"\n" + lab[:, :, ::-1].astype("<i2").tobytes())
    with open(p("meta_flipy.mha"), "wb") as f:
        f.write(("ObjectType = Image\nNDims = 3\nBinaryData = True\nBinaryDataByteOrderMSB = False\n"
                 "TransformMatrix = 1 0 0 0 -1 0 0 0 1\nOffset = %r %r %r\nElementSpacing = %r %r %r\n"
                 "DimSize = %d %d %d\nElementType = MET_SHORT\nElementDataFile = LOCAL\n" %
                 ((ORIGIN[0], ORIGIN[1] + 3 * SPACING[1], ORIGIN[2]) + SPACING + (NX, NY, NZ))).encode() +
                lab[:, ::-1, :].astype("<i2").tobytes())
    fimg = vtk_image([("labels", np.ascontiguousarray(lab[::-1, :, ::-1]))],
                     origin=(ORIGIN[0] + (EXT0[0] + NX - 1) * SPACING[0], VTK_ORIGIN[1],
                             ORIGIN[2] + (EXT0[2] + NZ - 1) * SPACING[2]))
    fimg.SetDirectionMatrix(-1, 0, 0, 0, 1, 0, 0, 0, -1)
    write_vti(p("vti_flipxz.vti"), fimg, "binary", 0)
    # The same flips stored as negative spacings, which VTK's writers keep
    # (voxel i at Origin + i Spacing): .vti x and z, legacy .vtk y.
    nimg = vtk_image([("labels", np.ascontiguousarray(lab[::-1, :, ::-1]))],
                     origin=(ORIGIN[0] + (EXT0[0] + NX - 1) * SPACING[0], VTK_ORIGIN[1],
                             ORIGIN[2] + (EXT0[2] + NZ - 1) * SPACING[2]))
    nimg.SetSpacing(-SPACING[0], SPACING[1], -SPACING[2])
    write_vti(p("vti_negspacing.vti"), nimg, "binary", 0)
    nsp = vtk.vtkImageData()
    nsp.SetDimensions(NX, NY, NZ)
    nsp.SetSpacing(SPACING[0], -SPACING[1], SPACING[2])
    nsp.SetOrigin(ORIGIN[0], ORIGIN[1] + (NY - 1) * SPACING[1], ORIGIN[2])
    nva = numpy_to_vtk(np.ascontiguousarray(lab[:, ::-1, :].ravel()), deep=1)
    nva.SetName("labels")
    nsp.GetPointData().SetScalars(nva)
    nw = vtk.vtkStructuredPointsWriter()
    nw.SetInputData(nsp)
    nw.SetFileName(p("legacy_negspacing.vtk"))
    nw.SetFileTypeToASCII()
    nw.Write()
    with open(p("nrrd_gzip.nrrd"), "wb") as f:
        f.write(nrrd_header("int16", (NX, NY, NZ), "gzip").encode() + b"\n" + gzip.compress(raw16))
    with open(p("nrrd_big.nrrd"), "wb") as f:
        f.write(nrrd_header("int", (NX, NY, NZ), "raw", endian="big").encode() + b"\n" +
                lab.astype(">i4").tobytes())
    with open(p("nrrd_ascii.nrrd"), "wb") as f:
        f.write(nrrd_header("signed short", (NX, NY, NZ), "ascii", endian=None).encode() + b"\n" +
                "\n".join(" ".join(str(v) for v in row) for row in lab.reshape(-1, NX)).encode() + b"\n")
    with open(p("nrrd_field.nrrd"), "wb") as f:
        f.write(nrrd_header("double", (NX, NY, NZ), "gzip").encode() + b"\n" + gzip.compress(fld.astype("<f8").tobytes()))
    # detached data, raw and gzip, with a line skip and a byte skip
    with open(p("nhdr_raw.nhdr"), "w") as f:
        f.write(nrrd_header("short", (NX, NY, NZ), "raw", extra=["data file: nhdr_raw.data", "line skip: 1",
                                                                  "byte skip: 3"]))
    with open(p("nhdr_raw.data"), "wb") as f:
        f.write(b"a comment line\nXYZ" + raw16)
    with open(p("nhdr_gzip.nhdr"), "w") as f:
        f.write(nrrd_header("short", (NX, NY, NZ), "gz", extra=["datafile: nhdr_gzip.raw.gz"]))
    with open(p("nhdr_gzip.raw.gz"), "wb") as f:
        f.write(gzip.compress(raw16))
    # 2D with spacings
    with open(p("nrrd_2d.nrrd"), "wb") as f:
        f.write(nrrd_header("uchar", (NX, NY), "raw", endian=None).encode() + b"\n" + b2.tobytes())

    # ---- .npy
    np.save(p("npy_labels.npy"), lab.astype(np.int32))
    np.save(p("npy_field.npy"), fld)
    np.save(p("npy_2d.npy"), b2[0])
    print("ok")


if __name__ == "__main__":
    main()

#!/usr/bin/env python3
"""Crops an axis-aligned NIfTI-1 (.nii.gz) volume to voxel index ranges, standard library only.

Makes the cropped cases of the example CT (bench/results/2026-12-07-any-ct-cases.md), as a scan that stops
earlier would be:
    python3 bench/crop_nifti.py IN.nii.gz OUT.nii.gz I0 I1 K0 K1      (inclusive; -1 = the last index)
The header extension (the label names TotalSegmentator writes) is kept; the sform and qform offsets move by
the voxels cut off the low ends, so every kept voxel keeps its world position.
"""
import gzip
import struct
import sys


def main(src, dst, i0, i1, k0, k1):
    d = gzip.open(src).read()
    h = bytearray(d[:348])
    vox_offset = int(struct.unpack("<f", h[108:112])[0])
    ext, data = d[348:vox_offset], d[vox_offset:]
    dims = list(struct.unpack("<8h", h[40:56]))
    nx, ny, nz = dims[1:4]
    bytes_per_voxel = struct.unpack("<h", h[72:74])[0] // 8
    i1 = nx - 1 if i1 < 0 else i1
    k1 = nz - 1 if k1 < 0 else k1
    out = bytearray()
    for k in range(k0, k1 + 1):
        for j in range(ny):
            row = (k * ny + j) * nx
            out += data[(row + i0) * bytes_per_voxel:(row + i1 + 1) * bytes_per_voxel]
    dims[1], dims[3] = i1 - i0 + 1, k1 - k0 + 1
    h[40:56] = struct.pack("<8h", *dims)
    srow_x = list(struct.unpack("<4f", h[280:296]))
    srow_z = list(struct.unpack("<4f", h[312:328]))
    if any(abs(v) > 1e-6 for v in (srow_x[1], srow_x[2], srow_z[0], srow_z[1])):
        sys.exit("crop_nifti: only axis-aligned grids (a diagonal sform)")
    srow_x[3] += srow_x[0] * i0
    srow_z[3] += srow_z[2] * k0
    h[280:296] = struct.pack("<4f", *srow_x)
    h[312:328] = struct.pack("<4f", *srow_z)
    q = list(struct.unpack("<3f", h[268:280]))
    q[0], q[2] = srow_x[3], srow_z[3]
    h[268:280] = struct.pack("<3f", *q)
    gzip.open(dst, "wb", compresslevel=1).write(bytes(h) + ext + bytes(out))


if __name__ == "__main__":
    if len(sys.argv) != 7:
        sys.exit(__doc__)
    main(sys.argv[1], sys.argv[2], *map(int, sys.argv[3:7]))

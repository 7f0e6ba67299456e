#!/usr/bin/env python3
"""Anterior rise of the skin per (x, z) column, and how a cropped case's compares with the full one's.

For bench/results/2026-12-07-any-ct-cases.md, standard library only:
    python3 bench/skin_rise.py FULL_CT FULL_DEFORMED CROP_CT CROP_DEFORMED
The skin's height in a column is the most anterior voxel above -500 HU (world mm, from the sform: axis-aligned
RAS grids); its rise is the deformed CT's height minus the CT's. Compared over the columns both cases hold
where the full case rises more than 5 mm: the median rises, their ratio, and the median and 90th percentile
of |crop - full| / full per column.
"""
import array
import gzip
import statistics
import struct
import sys

TYPES = {2: "B", 4: "h", 8: "i", 16: "f", 256: "b", 512: "H", 768: "I"}


def heights(path):
    d = gzip.open(path).read()
    h = d[:348]
    vox_offset = int(struct.unpack("<f", h[108:112])[0])
    nx, ny, nz = struct.unpack("<8h", h[40:56])[1:4]
    sx, sy, sz = (struct.unpack("<4f", h[o:o + 16]) for o in (280, 296, 312))
    a = array.array(TYPES[struct.unpack("<h", h[70:72])[0]])
    a.frombytes(d[vox_offset:vox_offset + nx * ny * nz * a.itemsize])
    out = {}
    for k in range(nz):
        z = round(sz[2] * k + sz[3], 1)
        for i in range(nx):
            x = round(sx[0] * i + sx[3], 1)
            for j in range(ny - 1, -1, -1):
                if a[(k * ny + j) * nx + i] > -500:
                    out[(x, z)] = sy[1] * j + sy[3]
                    break
    return out


def rises(ct, deformed):
    before, after = heights(ct), heights(deformed)
    return {c: after[c] - before[c] for c in before if c in after}


def main(full_ct, full_deformed, crop_ct, crop_deformed):
    full, crop = rises(full_ct, full_deformed), rises(crop_ct, crop_deformed)
    cols = [c for c in crop if c in full and full[c] > 5.0]
    rf, rc = [full[c] for c in cols], [crop[c] for c in cols]
    rel = sorted(abs(crop[c] - full[c]) / full[c] for c in cols)
    print(f"columns {len(cols)}  median rise full {statistics.median(rf):.1f} mm, crop {statistics.median(rc):.1f} mm  "
          f"ratio {statistics.median(rc) / statistics.median(rf):.3f}  |crop-full|/full median {statistics.median(rel):.3f} "
          f"p90 {rel[int(0.9 * len(rel))]:.3f}")


if __name__ == "__main__":
    if len(sys.argv) != 5:
        sys.exit(__doc__)
    main(*sys.argv[1:5])

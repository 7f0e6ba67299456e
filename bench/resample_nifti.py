#!/usr/bin/env python3
"""Nearest-neighbour resampling of an axis-aligned NIfTI-1 volume to another voxel spacing, standard library only.

Makes a clinical-like grid from the example CT for the cube-size measurements (bench/results/2026-12-07-cubes-mm.md):
    python3 bench/resample_nifti.py data/totalseg-example-ct/example_ct.nii.gz out/ct_075.nii.gz 0.75 0.75 2.5
Each output voxel takes the input voxel holding its centre (labels stay labels; the CT keeps its HU values, blocky
in-plane: the grid, not the image, is what is clinical). The field of view is kept: the output covers the input's
extent, its first voxel centred half an output voxel inside the input's corner. Only sform-diagonal files (no
rotation) are taken; extensions are dropped.
"""
import array
import gzip
import struct
import sys

TYPES = {2: "B", 4: "h", 8: "i", 16: "f", 256: "b", 512: "H", 768: "I"}


def main(src, dst, *spacing):
    new = [float(s) for s in spacing]
    raw = gzip.open(src).read() if src.endswith(".gz") else open(src, "rb").read()
    hdr = bytearray(raw[:348])
    dim = list(struct.unpack_from("<8h", hdr, 40))
    datatype, bitpix = struct.unpack_from("<hh", hdr, 70)
    pix = list(struct.unpack_from("<8f", hdr, 76))
    vox_offset = int(struct.unpack_from("<f", hdr, 108)[0])
    srow = list(struct.unpack_from("<12f", hdr, 280))
    if any(srow[4 * r + c] != 0 for r in range(3) for c in range(3) if r != c):
        sys.exit("only axis-aligned (diagonal sform) volumes are resampled")
    code = TYPES[datatype]
    n = dim[1:4]
    data = array.array(code)
    data.frombytes(raw[vox_offset : vox_offset + n[0] * n[1] * n[2] * bitpix // 8])
    old = [abs(srow[5 * a]) for a in range(3)]
    m = [max(1, int(round(n[a] * old[a] / new[a]))) for a in range(3)]
    # Output index o's centre lies at (o + ½)·new from the input's corner: input index floor((o + ½)·new / old).
    maps = [[min(n[a] - 1, int((o + 0.5) * new[a] / old[a])) for o in range(m[a])] for a in range(3)]
    out = array.array(code)
    for k in maps[2]:
        for j in maps[1]:
            base = (k * n[1] + j) * n[0]
            row = data[base : base + n[0]]
            out.extend(row[i] for i in maps[0])
    for a in range(3):
        sign = 1.0 if srow[5 * a] > 0 else -1.0
        corner = srow[4 * a + 3] - sign * 0.5 * old[a]
        srow[5 * a] = sign * new[a]
        srow[4 * a + 3] = corner + sign * 0.5 * new[a]
        dim[1 + a] = m[a]
        pix[1 + a] = new[a]
    struct.pack_into("<8h", hdr, 40, *dim)
    struct.pack_into("<8f", hdr, 76, *pix)
    struct.pack_into("<f", hdr, 108, 352.0)
    struct.pack_into("<12f", hdr, 280, *srow)
    struct.pack_into("<fff", hdr, 268, srow[3], srow[7], srow[11])   # qoffset, should a reader take the qform
    blob = bytes(hdr) + b"\0\0\0\0" + out.tobytes()
    (gzip.open(dst, "wb", compresslevel=1) if dst.endswith(".gz") else open(dst, "wb")).write(blob)
    print(f"{src}: {n} at {old} mm -> {dst}: {m} at {new} mm")


if __name__ == "__main__":
    if len(sys.argv) != 6:
        sys.exit(__doc__)
    main(*sys.argv[1:])

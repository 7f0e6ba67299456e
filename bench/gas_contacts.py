#!/usr/bin/env python3
"""Where a run's gas touches what it must not: the air outside the body, the lungs, the heart.

For bench/results/2026-12-07-any-ct-cases.md (issue "Any patient's CT": no gas voxel adjacent to lung or
heart, none adjacent to the air outside the body):
    python3 bench/gas_contacts.py OUT_DIR CT [LABELS_CSV [MARGIN_MM]]
OUT_DIR holds a run's deformed_ct.nii.gz and deformed_labels.nii.gz (the cavity label 250), CT is the
run's input CT: outside air beyond its cranial, caudal and lateral ends (padding, or where the output
grid grew), or within MARGIN_MM of them (0 by default), is not counted. LABELS_CSV names the label ids
(id,name; the example CT's by default) so that lungs and heart are found by name. Counts voxels
6-adjacent to a gas voxel. RAS-ordered NIfTI grids (x along i, z along k), as pneumo writes them.
"""
import os
import sys

import nibabel as nib
import numpy as np
from scipy import ndimage as nd

CAVITY = 250


def main():
    out, ct_path = sys.argv[1], sys.argv[2]
    csv = sys.argv[3] if len(sys.argv) > 3 else os.path.join(os.path.dirname(__file__), "..", "data",
                                                               "totalseg-example-ct", "labels.csv")
    names = {}
    for line in open(csv):
        parts = line.strip().split(",")
        if parts and parts[0].isdigit():
            names[int(parts[0])] = parts[1]
    img = nib.load(os.path.join(out, "deformed_ct.nii.gz"))
    hu = img.get_fdata()
    lab = np.asarray(nib.load(os.path.join(out, "deformed_labels.nii.gz")).dataobj).astype(int)
    src = nib.load(ct_path)

    def within(axis, margin_mm):   # voxels of the output grid within the CT's extent along axis (x or z)
        ends = [src.affine[axis, 3], src.affine[axis, 3] + src.affine[axis, axis] * (src.shape[axis] - 1)]
        w = img.affine[axis, 3] + img.affine[axis, axis] * np.arange(hu.shape[axis])
        return (w >= min(ends) + margin_mm - 1e-3) & (w <= max(ends) - margin_mm + 1e-3)
    margin = float(sys.argv[4]) if len(sys.argv) > 4 else 0.0
    in_slab = within(0, margin)[:, None, None] & within(2, margin)[None, None, :]

    gas = lab == CAVITY
    air = (hu < -500) & ~gas & (lab == 0)
    parts, _ = nd.label(air)
    faces = [parts[0], parts[-1], parts[:, 0], parts[:, -1], parts[:, :, 0], parts[:, :, -1]]
    border = np.setdiff1d(np.unique(np.concatenate([f.ravel() for f in faces])), [0])
    outside = np.isin(parts, border) & in_slab
    near = nd.binary_dilation(gas) & ~gas
    lung = np.isin(lab, [k for k, v in names.items() if v.startswith("lung")])
    heart = np.isin(lab, [k for k, v in names.items() if v == "heart"])
    ml = float(np.prod(img.header.get_zooms()[:3])) / 1000.0
    print(f"gas {gas.sum() * ml:.0f} ml; voxels touching gas: outside air {int((near & outside).sum())}, "
          f"lung {int((near & lung).sum())}, heart {int((near & heart).sum())}")


if __name__ == "__main__":
    main()

#!/usr/bin/env python3
"""pneumo's image warp against VTK's and ITK's on the same phantom, mesh and deformation, voxel by voxel.

Reads what bench/peers/compare_warp.sh left in DIR:
  phantom.mhd                       the peers' phantom (int16 HU)
  warped_mapcoords.mhd              VTK: vtkProbeFilter pull-back, then scipy map_coordinates (trilinear), rounded
  warped_reslice.mhd                VTK: the same pull-back's dense field through vtkImageReslice + vtkGridTransform
  disp.mhd                          VTK's dense field d (mm, output(x) = input(x + d(x)), float32 x 3)
  warped_itk.mhd                    ITK: ResampleImageFilter through VTK's field (linear)
  warped_itk_pneumo_field.mhd       ITK through pneumo's field (when present)
  pneumo/warped_cpu.mhd             pneumo, CPU reference (float32 HU, not rounded)
  pneumo/warped_opencl.mhd          pneumo, OpenCL (float32 HU)
  pneumo/outcome.mhd                pneumo's outcome per voxel (0 kept, 1 carried, 2 gas)
  pneumo/disp_pneumo.mhd            pneumo's field through its PointMap, same convention as disp.mhd
  vtk_tetwarp.jsonl                 VTK's timings (its last line): total_probe_plus_mapcoords_s is the whole pipeline
  itk_warp.txt                      ITK's RESULT line through VTK's field: resample_s_median
  pneumo_peer_warp.json             pneumo's timings (pneumo bench --peer-warp): the median warp per device

Speeds are compared only within this run, on this machine: each peer's whole job against pneumo's whole warp
(scatter, sample, gas rule; read and write excluded for all).

"Where both are defined": pneumo carried the voxel (a deformed tetrahedron holds it) and its source point's trilinear
stencil lies inside the volume, so no tool's convention for samples beyond the last voxel centre enters (VTK's
map_coordinates and pneumo read -1000 HU there, ITK its default pixel for points outside the buffer). The voxels
left out are counted, and compared too, apart.

Usage: python3 compare_warp.py DIR PEERS_DIR [--json OUT.json] [--markdown OUT.md]
"""
import argparse
import json
import os
import sys

import numpy as np


def stats(a, b, mask):
    """|a - b| over mask: how many voxels, max, mean, and the shares above 0.5 and 1 HU."""
    n = int(mask.sum())
    if n == 0:
        return dict(voxels=0)
    d = np.abs(a[mask].astype(np.float64) - b[mask].astype(np.float64))
    return dict(voxels=n, max_abs=float(d.max()), mean_abs=float(d.mean()),
                frac_gt_0_5=float((d > 0.5).mean()), frac_gt_1=float((d > 1.0).mean()),
                n_gt_1=int((d > 1.0).sum()))


def last_record(path, prefix=None):
    """The JSON in path: the whole file, or with prefix the last line starting with it (after it); None if absent."""
    try:
        with open(path) as f:
            if prefix is None:
                return json.load(f)
            lines = [l[len(prefix):] for l in f if l.startswith(prefix)]
        return json.loads(lines[-1]) if lines else None
    except (OSError, ValueError):
        return None


def speeds(d):
    """Seconds of each whole job in this run, from the logs compare_warp.sh leaves (missing ones are left out)."""
    out = {}
    vtk = last_record(os.path.join(d, "vtk_tetwarp.jsonl"), "")
    if vtk and "total_probe_plus_mapcoords_s" in vtk:
        out["vtk_pipeline"] = vtk["total_probe_plus_mapcoords_s"]
        out["vtk_probe"] = vtk.get("probe_s")
    itk = last_record(os.path.join(d, "itk_warp.txt"), "RESULT ")
    if itk and "resample_s_median" in itk:
        out["itk_resample"] = itk["resample_s_median"]
        out["itk_threads"] = itk.get("threads")
    pn = last_record(os.path.join(d, "pneumo_peer_warp.json"))
    for w in (pn or {}).get("warps", []):
        key = "pneumo_cpu" if w["device"] == "cpu" else "pneumo_opencl"
        out[key] = w["seconds"]
        out[key + "_other_cores_max"] = w.get("other_cores_max")
    for dev in ("pneumo_cpu", "pneumo_opencl"):
        for peer in ("vtk_pipeline", "itk_resample"):
            if dev in out and peer in out:
                out["%s_x_%s" % (dev, peer)] = round(out[peer] / out[dev], 2)
    return out


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("dir")
    ap.add_argument("peers_dir")
    ap.add_argument("--json")
    ap.add_argument("--markdown")
    a = ap.parse_args()
    sys.path.insert(0, a.peers_dir)
    from common import read_mhd  # noqa: E402  (the peers' own MetaImage reader)

    def load(name):
        path = os.path.join(a.dir, name)
        return read_mhd(path)[0] if os.path.exists(path) else None

    src, sp, org = read_mhd(os.path.join(a.dir, "phantom.mhd"))
    nz, ny, nx = src.shape
    outcome = load("pneumo/outcome.mhd")
    pneumo = load("pneumo/warped_cpu.mhd")
    if outcome is None or pneumo is None:
        raise SystemExit("compare_warp: no pneumo/warped_cpu.mhd or pneumo/outcome.mhd in " + a.dir)
    carried = outcome == 1
    field = load("pneumo/disp_pneumo.mhd")
    vtk_field = load("disp.mhd")

    def stencil_inside(d):
        """Voxels whose source point x + d(x) has its trilinear stencil inside the volume: 0 <= index <= n - 1."""
        inside = np.ones(src.shape, dtype=bool)
        for comp, axis in ((0, 2), (1, 1), (2, 0)):   # field component x, y, z <-> numpy axis 2, 1, 0
            shape = [1, 1, 1]
            shape[axis] = -1
            idx = np.arange(src.shape[axis], dtype=np.float64).reshape(shape)
            s = idx + d[..., comp].astype(np.float64) / sp[comp]
            inside &= (s >= 0.0) & (s <= src.shape[axis] - 1)
        return inside

    # VTK's field is the probe's interpolation of float32 positions: on the volume's faces its sources can lie a
    # rounding error outside (x = -1e-16 mm), where scipy returns the background; such voxels are not defined in both.
    inside = stencil_inside(field)
    if vtk_field is not None:
        inside &= stencil_inside(vtk_field)
    both = carried & inside
    edge = carried & ~inside
    rec = dict(dims=[nx, ny, nz], voxels=int(src.size), pneumo_carried=int(carried.sum()),
               pneumo_gas=int((outcome == 2).sum()), pneumo_kept=int((outcome == 0).sum()),
               both_defined=int(both.sum()), carried_but_a_source_outside=int(edge.sum()))

    # Each peer writes int16 its own way: the script rounds map_coordinates' output (np.rint), vtkImageReslice rounds to
    # nearest, ITK's ResampleImageFilter casts (truncates towards zero). So pneumo's float32 can differ from a peer's
    # integer by up to 0.5 HU, or 1 HU for ITK, with the same interpolated value; beyond that bound (plus 0.01 HU for
    # float32 and the two source points' last digits) the values differ.
    pairs = []
    for name, label, bound in (
            ("warped_mapcoords.mhd", "VTK probe + scipy map_coordinates", 0.5),
            ("warped_reslice.mhd", "VTK probe + vtkImageReslice", 0.5),
            ("warped_itk.mhd", "ITK ResampleImageFilter, VTK's field", 1.0),
            ("warped_itk_pneumo_field.mhd", "ITK ResampleImageFilter, pneumo's field", 1.0)):
        peer = load(name)
        if peer is None:
            continue
        d = np.abs(pneumo[both].astype(np.float64) - peer[both])
        pairs.append(dict(peer=label, file=name, rounding_bound_hu=bound, hu=stats(pneumo, peer, both),
                          within_bound_share=float((d <= bound + 0.01).mean()) if d.size else None,
                          beyond_bound=int((d > bound + 0.01).sum()),
                          not_both_defined=stats(pneumo, peer, edge)))
        del peer, d
    rec["ct_hu"] = pairs
    opencl = load("pneumo/warped_opencl.mhd")
    if opencl is not None:
        rec["opencl_vs_cpu_hu"] = stats(opencl, pneumo, np.ones_like(carried))
    if vtk_field is not None:
        d = np.abs(field.astype(np.float64) - vtk_field).max(axis=-1)
        rec["field_mm_pneumo_vs_vtk"] = dict(voxels=int(both.sum()), max_abs=float(d[both].max()),
                                             mean_abs=float(d[both].mean()),
                                             max_abs_all_carried=float(d[carried].max()))
    rec["speed"] = speeds(a.dir)
    text = json.dumps(rec, indent=2)
    print(text)
    if a.json:
        with open(a.json + ".tmp", "w") as f:
            f.write(text + "\n")
        os.replace(a.json + ".tmp", a.json)
    if a.markdown:
        lines = ["| pneumo (float32) against | voxels compared | max abs HU | mean abs HU | the peer's rounding | "
                 "within it (+0.01 HU) |",
                 "|---|---|---|---|---|---|"]
        for p in pairs:
            f = p["hu"]
            lines.append("| %s | %d | %.3f | %.4f | %.1f HU | %.5f %% (%d beyond) |" % (
                p["peer"], f["voxels"], f["max_abs"], f["mean_abs"], p["rounding_bound_hu"],
                100 * p["within_bound_share"], p["beyond_bound"]))
        lines.append("\nNot defined in both (a source outside the volume): %d voxels; pneumo gas %d, kept %d." % (
            rec["carried_but_a_source_outside"], rec["pneumo_gas"], rec["pneumo_kept"]))
        if "field_mm_pneumo_vs_vtk" in rec:
            lines.append("\nSource field, pneumo's PointMap against VTK's probe: max |Δ| %.2e mm, mean %.2e mm." % (
                rec["field_mm_pneumo_vs_vtk"]["max_abs"], rec["field_mm_pneumo_vs_vtk"]["mean_abs"]))
        if "opencl_vs_cpu_hu" in rec:
            lines.append("pneumo OpenCL against its CPU reference, every voxel: max |Δ| %.4f HU." %
                         rec["opencl_vs_cpu_hu"]["max_abs"])
        sp_ = rec["speed"]
        if sp_:
            lines.append("\nSpeed in this run (%d voxels; s, and pneumo's multiple of each peer's rate):\n" % src.size)
            lines.append("| job | seconds | voxels/s | pneumo CPU is | pneumo OpenCL is |")
            lines.append("|---|---|---|---|---|")
            for key, label in (("vtk_pipeline", "VTK probe + map_coordinates"), ("itk_resample", "ITK resampling"),
                               ("pneumo_cpu", "pneumo warp, CPU reference"), ("pneumo_opencl", "pneumo warp, OpenCL")):
                if key not in sp_:
                    continue
                s_ = sp_[key]
                row = "| %s | %.2f | %.1f M |" % (label, s_, src.size / s_ / 1e6)
                for dev in ("pneumo_cpu", "pneumo_opencl"):
                    row += (" %.1fx |" % (s_ / sp_[dev])) if dev in sp_ and not key.startswith("pneumo") else " |"
                lines.append(row)
        with open(a.markdown + ".tmp", "w") as f:
            f.write("\n".join(lines) + "\n")
        os.replace(a.markdown + ".tmp", a.markdown)


if __name__ == "__main__":
    main()

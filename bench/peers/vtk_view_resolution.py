#!/usr/bin/env python3
"""VTK's CPU ray caster beside pneumo's views across CT resolutions (issue 24, item 4).

Reads what `pneumo validate view-resolution --write-volumes --out DIR` left in DIR: the phantom's
volumes at each size (volumes/*.mhd, HU as pneumo renders them, before its views' prefilter) and
peer_views.json (each view's camera, transfer function and lighting; each size's ray step). Renders
every view at every size with vtkFixedPointVolumeRayCastMapper (trilinear samples, VTK's own
gradient shading, the same transfer function, headlight, step and image size), and scores each size
against the finest by SSIM, computed here exactly as pneumo computes it (render/image_out.h: the
luma of the 8-bit RGB with BT.601 weights, an 11x11 Gaussian window of sigma 1.5 px, K1 0.01,
K2 0.03, windows inside the image). It also scores pneumo's own PNGs with this code, a second
implementation of the measure: the two must agree with study.json.

Offscreen VTK needs an X server on Debian's build: run it under xvfb-run (scripts/install_deps.sh
--peers installs it):

    xvfb-run -a python3 bench/peers/vtk_view_resolution.py DIR [--json]
"""
import argparse
import json
import os
import sys

import numpy as np


def luma(rgb):
    rgb = rgb.astype(np.float64)
    return 0.299 * rgb[..., 0] + 0.587 * rgb[..., 1] + 0.114 * rgb[..., 2]


def ssim(a, b):
    """Mean SSIM of two HxWx3 uint8 images (Wang et al. 2004), as render/image_out.h."""
    if a.shape != b.shape:
        return float("nan")
    x, y = luma(a), luma(b)
    r = 5
    g = np.exp(-0.5 * (np.arange(-r, r + 1) / 1.5) ** 2)
    g /= g.sum()

    def filt(img):
        h, w = img.shape
        rows = sum(g[i] * img[:, i:w - 2 * r + i] for i in range(2 * r + 1))
        return sum(g[i] * rows[i:h - 2 * r + i, :] for i in range(2 * r + 1))

    c1, c2 = (0.01 * 255) ** 2, (0.03 * 255) ** 2
    mx, my = filt(x), filt(y)
    vx, vy, cxy = filt(x * x) - mx * mx, filt(y * y) - my * my, filt(x * y) - mx * my
    s = (2 * mx * my + c1) * (2 * cxy + c2) / ((mx * mx + my * my + c1) * (vx + vy + c2))
    return float(s.mean())


def read_png(vtk, path):
    from vtk.util import numpy_support
    rd = vtk.vtkPNGReader()
    rd.SetFileName(path)
    rd.Update()
    im = rd.GetOutput()
    w, h, _ = im.GetDimensions()
    px = numpy_support.vtk_to_numpy(im.GetPointData().GetScalars()).reshape(h, w, -1)[:, :, :3]
    return px[::-1].copy()   # VTK's rows run bottom-up


def read_volume(vtk, mhd_path, size):
    """The MetaImage's int16 voxels placed by the study's RAS origin and spacing (the header's are LPS,
    which VTK's reader would place mirrored: it ignores TransformMatrix)."""
    from vtk.util import numpy_support
    with open(mhd_path) as f:
        header = dict(line.split(" = ", 1) for line in f.read().splitlines() if " = " in line)
    assert header["ElementType"].strip() == "MET_SHORT", header["ElementType"]
    raw = os.path.join(os.path.dirname(mhd_path), header["ElementDataFile"].strip())
    data = np.fromfile(raw, dtype="<i2")
    dims = size["dims"]
    assert data.size == dims[0] * dims[1] * dims[2], (raw, data.size, dims)
    img = vtk.vtkImageData()
    img.SetDimensions(*dims)
    img.SetSpacing(size["spacing_mm"], size["spacing_mm"], size["spacing_mm"])
    img.SetOrigin(*size["origin_ras_mm"])
    arr = numpy_support.numpy_to_vtk(data, deep=True, array_type=vtk.VTK_SHORT)
    img.GetPointData().SetScalars(arr)
    return img


def render(vtk, volume_path, view, size):
    from vtk.util import numpy_support
    step_mm = size["step_mm"]
    ctf = vtk.vtkColorTransferFunction()
    for hu, r, g, b in view["colour"]:
        ctf.AddRGBPoint(hu, r, g, b)
    otf = vtk.vtkPiecewiseFunction()
    for hu, a in view["opacity"]:
        otf.AddPoint(hu, a)
    prop = vtk.vtkVolumeProperty()
    prop.SetColor(ctf)
    prop.SetScalarOpacity(otf)
    prop.SetScalarOpacityUnitDistance(1.0)   # opacities per 1 mm of ray, as pneumo's
    prop.SetInterpolationTypeToLinear()
    prop.ShadeOn()
    prop.SetAmbient(view["ambient"])
    prop.SetDiffuse(view["diffuse"])
    prop.SetSpecular(view["specular"])
    prop.SetSpecularPower(view["shininess"])
    mapper = vtk.vtkFixedPointVolumeRayCastMapper()
    mapper.SetAutoAdjustSampleDistances(0)
    mapper.SetSampleDistance(step_mm)
    mapper.SetInteractiveSampleDistance(step_mm)
    mapper.SetImageSampleDistance(1.0)
    mapper.SetMinimumImageSampleDistance(1.0)
    mapper.SetMaximumImageSampleDistance(1.0)
    mapper.SetInputData(read_volume(vtk, volume_path, size))
    vol = vtk.vtkVolume()
    vol.SetMapper(mapper)
    vol.SetProperty(prop)
    ren = vtk.vtkRenderer()
    ren.SetBackground(0, 0, 0)
    ren.AddVolume(vol)
    cam = ren.GetActiveCamera()
    cam.SetPosition(*view["position_mm"])
    cam.SetFocalPoint(*view["focal_mm"])
    cam.SetViewUp(*view["up"])
    cam.UseHorizontalViewAngleOn()   # pneumo's field of view spans the width
    cam.SetViewAngle(view["fov_deg"])
    cam.SetClippingRange(view["near_mm"], 2000.0)
    ren.LightFollowCameraOn()
    rw = vtk.vtkRenderWindow()
    rw.SetOffScreenRendering(1)
    rw.SetSize(view["width"], view["height"])
    rw.AddRenderer(ren)
    rw.Render()
    cam.SetClippingRange(view["near_mm"], 2000.0)
    rw.Render()
    w2i = vtk.vtkWindowToImageFilter()
    w2i.SetInput(rw)
    w2i.ReadFrontBufferOff()
    w2i.Update()
    im = w2i.GetOutput()
    w, h, _ = im.GetDimensions()
    px = numpy_support.vtk_to_numpy(im.GetPointData().GetScalars()).reshape(h, w, -1)[:, :, :3]
    return px[::-1].copy(), w2i


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("dir", help="the --out folder of pneumo validate view-resolution --write-volumes")
    ap.add_argument("--json", action="store_true")
    a = ap.parse_args()
    import vtk
    with open(os.path.join(a.dir, "peer_views.json")) as f:
        peer = json.load(f)
    with open(os.path.join(a.dir, "study.json")) as f:
        study = json.load(f)
    os.makedirs(os.path.join(a.dir, "vtk"), exist_ok=True)
    sizes = peer["sizes"]            # finest first, as the study renders them
    finest = sizes[0]["size"]
    rows, worst_check = [], 0.0
    ref = {}
    for s in sizes:
        for v in peer["views"]:
            img, w2i = render(vtk, os.path.join(a.dir, s[v["volume"]]), v, s)
            out = os.path.join(a.dir, "vtk", "%s_%s.png" % (v["name"], s["size"]))
            wr = vtk.vtkPNGWriter()
            wr.SetFileName(out)
            wr.SetInputConnection(w2i.GetOutputPort())
            wr.Write()
            if s["size"] == finest:
                ref[v["name"]] = img
            rows.append({"view": v["name"], "size": s["size"], "spacing_mm": s["spacing_mm"], "shading": "vtk",
                         "ssim": ssim(img, ref[v["name"]])})
    # pneumo's own views through this SSIM: a check of the C++ one (study.json).
    for r in study["rows"]:
        mine = read_png(vtk, os.path.join(a.dir, "views", "%s_%s_%s.png" % (r["view"], r["size"], r["shading"])))
        base = read_png(vtk, os.path.join(a.dir, "views", "%s_%s_%s.png" % (r["view"], finest, r["shading"])))
        worst_check = max(worst_check, abs(ssim(mine, base) - r["ssim"]))
    result = {"rows": rows, "pneumo_rows": study["rows"], "ssim_check_max_abs_diff": worst_check,
              "vtk": vtk.vtkVersion.GetVTKVersion()}
    with open(os.path.join(a.dir, "vtk_view_resolution.json"), "w") as f:
        json.dump(result, f, indent=2)
    if a.json:
        print(json.dumps(result, indent=2))
        return 0
    print("%-24s %-8s %-8s %s" % ("view", "size", "shading", "ssim"))
    for r in sorted(rows + study["rows"], key=lambda r: (r["view"], -r["spacing_mm"], r["shading"])):
        print("%-24s %-8s %-8s %.3f" % (r["view"], r["size"], r["shading"], r["ssim"]))
    print("SSIM here vs pneumo's C++ on pneumo's PNGs: largest difference %.2g" % worst_check)
    return 0


if __name__ == "__main__":
    sys.exit(main())

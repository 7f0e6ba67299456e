"""Writes a NIfTI CT as a DICOM CT series with pydicom, as a scanner export would lay it out: one
file per slice, the patient frame (LPS) from the NIfTI's affine (RAS), HU stored as unsigned 16-bit
through Rescale Slope and Intercept. Used by tests/test_dicom_series.cpp, so that pneumo's reader
(host/io/dicom_io.cpp) is checked on files another library wrote.

  write_ct_series.py NIFTI OUT_DIR [key=value ...]
    slope=1 intercept=-2048   the rescale (HU = slope * stored + intercept)
    shuffle=1                 random file names, so order comes from the positions alone
    modality=CT               another modality, to be refused
    split=0                   1: the upper half of the slices in a second series, to be refused
    drop=-1                   the index of a slice to leave out (a missing slice), to be refused
    tilt_mm=0                 shift each slice sideways by k * tilt_mm (a tilted gantry), to be refused
    short_pixels=0            1: the last slice's pixel data cut to half of Rows x Columns, to be refused
    tag_slope=                the Rescale Slope written in the tags instead of slope (pixels still
                              stored through slope), to be refused: 0, 1e300
"""
import os
import random
import sys

import nibabel
import numpy
import pydicom
from pydicom.dataset import FileDataset, FileMetaDataset
from pydicom.uid import ExplicitVRLittleEndian, generate_uid

CT_IMAGE_STORAGE = "1.2.840.10008.5.1.4.1.1.2"


def ds(values):
    """Decimal strings of at most 16 characters (PS3.5 DS): ten significant digits, 1e-7 mm here."""
    return ["%.10g" % v for v in values]


def main():
    nifti, out = sys.argv[1], sys.argv[2]
    opt = dict(slope="1", intercept="-2048", shuffle="1", modality="CT", split="0", drop="-1", tilt_mm="0",
               short_pixels="0", tag_slope="")
    for arg in sys.argv[3:]:
        key, value = arg.split("=", 1)
        if key not in opt:
            sys.exit("unknown option " + key)
        opt[key] = value
    slope, intercept = float(opt["slope"]), float(opt["intercept"])
    image = nibabel.load(nifti)
    hu = numpy.asarray(image.dataobj, dtype=numpy.float64)
    affine = image.affine
    to_lps = numpy.diag([-1.0, -1.0, 1.0])
    step_i, step_j = affine[:3, 0], affine[:3, 1]
    row = to_lps @ step_i / numpy.linalg.norm(step_i)
    column = to_lps @ step_j / numpy.linalg.norm(step_j)
    study, series, other_series = generate_uid(), generate_uid(), generate_uid()
    rng = random.Random(7)
    os.makedirs(out, exist_ok=True)
    nx, ny, nz = hu.shape
    for k in range(nz):
        if k == int(opt["drop"]):
            continue
        meta = FileMetaDataset()
        meta.MediaStorageSOPClassUID = CT_IMAGE_STORAGE
        meta.MediaStorageSOPInstanceUID = generate_uid()
        meta.TransferSyntaxUID = ExplicitVRLittleEndian
        name = ("%016x.dcm" % rng.getrandbits(64)) if opt["shuffle"] == "1" else "%04d.dcm" % k
        d = FileDataset(os.path.join(out, name), {}, file_meta=meta, preamble=b"\0" * 128)
        d.is_little_endian, d.is_implicit_VR = True, False
        d.SOPClassUID, d.SOPInstanceUID = CT_IMAGE_STORAGE, meta.MediaStorageSOPInstanceUID
        d.StudyInstanceUID = study
        d.SeriesInstanceUID = other_series if opt["split"] == "1" and k >= nz // 2 else series
        d.Modality = opt["modality"]
        d.PatientName, d.PatientID = "Phantom^Test", "0"
        d.InstanceNumber = k + 1
        d.Rows, d.Columns = ny, nx
        d.PixelSpacing = ds([numpy.linalg.norm(step_j), numpy.linalg.norm(step_i)])
        d.ImageOrientationPatient = ds(list(row) + list(column))
        position = to_lps @ (affine[:3, :3] @ numpy.array([0.0, 0.0, k]) + affine[:3, 3])
        position = position + k * float(opt["tilt_mm"]) * row
        d.ImagePositionPatient = ds(position)
        d.SliceThickness = ds([numpy.linalg.norm(affine[:3, 2])])[0]
        d.SamplesPerPixel, d.PhotometricInterpretation = 1, "MONOCHROME2"
        d.BitsAllocated, d.BitsStored, d.HighBit, d.PixelRepresentation = 16, 16, 15, 0
        d.RescaleSlope, d.RescaleIntercept, d.RescaleType = ds([slope])[0], ds([intercept])[0], "HU"
        if opt["tag_slope"]:
            d.RescaleSlope = opt["tag_slope"]
        stored = numpy.rint((hu[:, :, k].T - intercept) / slope)   # rows are j, columns i
        if stored.min() < 0 or stored.max() > 65535:
            sys.exit("HU out of the unsigned 16-bit range of this rescale")
        d.PixelData = stored.astype("<u2").tobytes()
        if opt["short_pixels"] == "1" and k == nz - 1:
            d.PixelData = d.PixelData[: len(d.PixelData) // 2]
        d.save_as(os.path.join(out, name), write_like_original=False)
    print(nz - (1 if 0 <= int(opt["drop"]) < nz else 0), "slices")


if __name__ == "__main__":
    main()

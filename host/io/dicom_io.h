#pragma once
// A DICOM CT series in: the folder of one series, as a scanner or PACS export writes it, read with
// GDCM (Debian's libgdcm-dev), which parses every transfer syntax (JPEG, JPEG 2000, RLE, deflate).
//
// What pneumo takes from it, and where: the patient frame from Image Orientation (0020,0037) and
// Image Position (0020,0032), in DICOM's LPS and turned to pneumo's RAS; the slice order and
// spacing from the positions projected on the slice normal (not from Slice Thickness or Instance
// Number, which scanners fill inconsistently); HU by each slice's own Rescale Slope and Intercept.
// Refused, with a message that names the folder and what to do: no DICOM files, more than one
// series, a modality other than CT, multi-frame or colour images, slices whose size, orientation or
// pixel spacing differ, two slices at one position, uneven gaps (a missing slice), and a tilted
// gantry (positions not along the normal).
#include <string>

#include "io/volume.h"

namespace pneumo {

/// Whether `path` is a folder, which read_volume then reads as a DICOM series.
bool is_dicom_series_folder(const std::string& path);

/// Reads the CT series in folder `dir` (not its subfolders) as float32 HU, i along the rows'
/// direction (columns), j down the columns (rows), k in the slices' increasing position along the
/// normal. Throws InputError naming the folder for anything listed above.
Volume read_dicom_series(const std::string& dir);

}  // namespace pneumo

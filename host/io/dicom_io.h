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
//
// The folder is listed by pneumo, every entry accounted for (GDCM's own listing stops at the first
// entry it cannot stat, so a dangling link halfway read half a CT): regular files, and links to
// them, are read; sub-folders (and links to them) are skipped and logged, as a series is one
// folder; anything else (a dangling link, a FIFO, a socket, a device, an entry that cannot be
// examined) is refused naming the entry. No entry is opened to classify it: a FIFO's open blocks.
// Regular files that are not DICOM (notes, thumbnails, .DS_Store) are skipped by the scan.
#include <string>
#include <vector>

#include "core/input_file.h"
#include "io/volume.h"

namespace pneumo {

/// One entry of a series folder: its name and what it is (links followed).
struct FolderEntry {
  std::string name;
  FileProbe probe;
};

/// A series folder's entries sorted out: the files to scan (paths, sorted by name) and the
/// sub-folders skipped (names).
struct SeriesFolder {
  std::vector<std::string> files;
  std::vector<std::string> skipped_folders;
};

/// Sorts out `entries` of folder `dir` as the header says; InputError naming `dir` and the first
/// entry by name that is neither a file nor a folder. Pure, so the rule is fuzzed on its own.
SeriesFolder classify_series_entries(const std::string& dir, std::vector<FolderEntry> entries);

/// Lists `dir` (std::filesystem, not recursive) and classifies each entry with probe_file.
SeriesFolder list_series_folder(const std::string& dir);

/// Whether `path` is a folder, which read_volume then reads as a DICOM series.
bool is_dicom_series_folder(const std::string& path);

/// Reads the CT series in folder `dir` (not its subfolders) as float32 HU, i along the rows'
/// direction (columns), j down the columns (rows), k in the slices' increasing position along the
/// normal. Throws InputError naming the folder for anything listed above.
Volume read_dicom_series(const std::string& dir);

}  // namespace pneumo

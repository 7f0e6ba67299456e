#pragma once
// NRRD in and out (.nrrd, and .nhdr with its data file for reading): 3D Slicer's own format, read
// and written with teem (Debian's libteem-dev), the reference implementation of NRRD by its author,
// which handles every encoding (raw, gzip, bzip2, ascii, hex), byte order and detached headers.
//
// pneumo's part is the geometry: "space" (right-anterior-superior, left-anterior-superior,
// left-posterior-superior or scanner-xyz), "space directions" (one column per axis: direction ×
// spacing) and "space origin", turned to pneumo's world RAS. Written as Slicer and ITK write it:
// left-posterior-superior, kinds "domain", gzip.
#include <string>

#include "io/volume.h"

namespace pneumo {

/// Reads a three-dimensional scalar NRRD. Throws InputError naming the file for what teem cannot
/// read, and for what is not one volume placed in the patient: another dimension, a non-spatial
/// axis, no space or no space origin, a space pneumo cannot place (3D-right-handed), 64-bit
/// integers. The header is checked (sizes, memory) before the voxels are read.
Volume read_nrrd(const std::string& path);

/// Writes atomically (gzip-encoded, a single .nrrd file).
void write_nrrd(const Volume& v, const std::string& path);

}  // namespace pneumo

// Rewrites an image with ITK's own readers and writers, as 3D Slicer (which reads and writes NRRD
// through ITK) would:   convert_image IN OUT
// Voxels as float (CT HU and label ids are exact in float), compressed where the format allows.
// Built only for the tests (tests/test_nrrd.cpp), so that pneumo's NRRD is checked against the
// library whose conventions it claims, in both directions.
#include <itkImage.h>
#include <itkImageFileReader.h>
#include <itkImageFileWriter.h>

#include <cstdio>
#include <exception>

int main(int argc, char** argv) {
  if (argc != 3) {
    std::fprintf(stderr, "usage: %s IN OUT\n", argv[0]);
    return 2;
  }
  try {
    itk::WriteImage(itk::ReadImage<itk::Image<float, 3>>(argv[1]), argv[2], true);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "%s\n", e.what());
    return 1;
  }
  return 0;
}

// Applies a displacement field to an image with ITK, as a user of ITK, ANTs or 3D Slicer would:
//   apply_displacement_field IMAGE FIELD OUT
// IMAGE is resampled onto FIELD's grid through itk::DisplacementFieldTransform (output(x) =
// IMAGE(x + u(x)), u read from FIELD as ITK reads it), linearly, −1000 outside IMAGE; OUT is written
// with ITK's own NIfTI writer. Built only for the tests (tests/test_displacement_field.cpp), so that
// pneumo's field is checked by the library whose conventions it claims, not by pneumo's own reader.
#include <itkDisplacementFieldTransform.h>
#include <itkImage.h>
#include <itkImageFileReader.h>
#include <itkImageFileWriter.h>
#include <itkLinearInterpolateImageFunction.h>
#include <itkResampleImageFilter.h>
#include <itkVector.h>

#include <cstdio>
#include <exception>

int main(int argc, char** argv) {
  if (argc != 4) {
    std::fprintf(stderr, "usage: %s IMAGE FIELD OUT\n", argv[0]);
    return 2;
  }
  using Image = itk::Image<float, 3>;
  using Field = itk::Image<itk::Vector<double, 3>, 3>;
  try {
    auto image = itk::ReadImage<Image>(argv[1]);
    auto field = itk::ReadImage<Field>(argv[2]);
    auto transform = itk::DisplacementFieldTransform<double, 3>::New();
    transform->SetDisplacementField(field);
    auto resample = itk::ResampleImageFilter<Image, Image, double>::New();
    resample->SetInput(image);
    resample->SetTransform(transform);
    resample->SetInterpolator(itk::LinearInterpolateImageFunction<Image, double>::New());
    resample->SetOutputParametersFromImage(field);
    resample->SetDefaultPixelValue(-1000.0f);
    itk::WriteImage(resample->GetOutput(), argv[3]);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "%s\n", e.what());
    return 1;
  }
  return 0;
}

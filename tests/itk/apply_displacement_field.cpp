// Applies a displacement field to an image with ITK, as a user of ITK, ANTs or 3D Slicer would:
//   apply_displacement_field IMAGE FIELD OUT
// FIELD is either a vector image (.nii.gz), read as an image, or an ITK transform file (.h5), read
// by ITK's TransformFileReader as a DisplacementFieldTransform. IMAGE is resampled onto the field's
// grid through itk::DisplacementFieldTransform (output(x) = IMAGE(x + u(x)), u as ITK reads it),
// linearly, −1000 outside IMAGE; OUT is written with ITK's own NIfTI writer. Built only for the
// tests (tests/test_displacement_field.cpp), so that pneumo's field is checked by the library
// whose conventions it claims, not by pneumo's own reader.
#include <itkDisplacementFieldTransform.h>
#include <itkHDF5TransformIOFactory.h>
#include <itkImage.h>
#include <itkImageFileReader.h>
#include <itkImageFileWriter.h>
#include <itkLinearInterpolateImageFunction.h>
#include <itkResampleImageFilter.h>
#include <itkTransformFileReader.h>
#include <itkVector.h>

#include <cstdio>
#include <exception>
#include <string>

namespace {

using Transform = itk::DisplacementFieldTransform<double, 3>;

Transform::Pointer read_field(const std::string& path) {
  if (path.size() < 3 || path.compare(path.size() - 3, 3, ".h5") != 0) {
    auto transform = Transform::New();
    transform->SetDisplacementField(itk::ReadImage<Transform::DisplacementFieldType>(path));
    return transform;
  }
  itk::HDF5TransformIOFactory::RegisterOneFactory();
  auto reader = itk::TransformFileReaderTemplate<double>::New();
  reader->SetFileName(path);
  reader->Update();
  if (reader->GetTransformList()->size() != 1) throw std::runtime_error(path + ": not one transform");
  Transform::Pointer transform = dynamic_cast<Transform*>(reader->GetTransformList()->front().GetPointer());
  if (!transform) throw std::runtime_error(path + ": not a DisplacementFieldTransform");
  return transform;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 4) {
    std::fprintf(stderr, "usage: %s IMAGE FIELD OUT\n", argv[0]);
    return 2;
  }
  using Image = itk::Image<float, 3>;
  try {
    auto image = itk::ReadImage<Image>(argv[1]);
    const Transform::Pointer transform = read_field(argv[2]);
    auto resample = itk::ResampleImageFilter<Image, Image, double>::New();
    resample->SetInput(image);
    resample->SetTransform(transform);
    resample->SetInterpolator(itk::LinearInterpolateImageFunction<Image, double>::New());
    resample->SetOutputParametersFromImage(transform->GetDisplacementField());
    resample->SetDefaultPixelValue(-1000.0f);
    itk::WriteImage(resample->GetOutput(), argv[3]);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "%s\n", e.what());
    return 1;
  }
  return 0;
}

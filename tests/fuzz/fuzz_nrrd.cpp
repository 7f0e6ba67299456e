// libFuzzer target: the NRRD reader (teem underneath, pneumo's geometry and size checks on top) on
// arbitrary bytes as a single-file .nrrd (a header naming a data file is followed, relative to the
// scratch folder). Every input must give a volume or an InputError.
#include "fuzz_support.h"
#include "io/volume_io.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace pneumo;
  fuzz::quiet();
  const std::string path = fuzz::write_input("input.nrrd", data, size);
  return fuzz::expect_only_input_errors([&] {
    const Volume v = read_volume(path);
    v.geometry().validate(path);
  });
}

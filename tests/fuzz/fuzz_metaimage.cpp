// libFuzzer target: the MetaImage reader on arbitrary bytes as a single-file .mha (a header naming
// another data file is followed, relative to the scratch folder). Every input must give a volume or
// an InputError.
#include "fuzz_support.h"
#include "io/volume_io.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace pneumo;
  fuzz::quiet();
  const std::string path = fuzz::write_input("input.mha", data, size);
  return fuzz::expect_only_input_errors([&] {
    const Volume v = read_volume(path);
    v.geometry().validate(path);
  });
}

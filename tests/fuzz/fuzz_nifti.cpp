// libFuzzer target: the NIfTI-1 reader (.nii, and .nii.gz when the input starts with gzip's magic)
// on arbitrary bytes. It must answer every input with a volume or an InputError, within the memory
// the file can justify (run with -rss_limit_mb and -malloc_limit_mb).
#include "fuzz_support.h"
#include "io/volume_io.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace pneumo;
  fuzz::quiet();
  const bool gz = size >= 2 && data[0] == 0x1f && data[1] == 0x8b;
  const std::string path = fuzz::write_input(gz ? "input.nii.gz" : "input.nii", data, size);
  return fuzz::expect_only_input_errors([&] {
    const Volume v = read_volume(path);
    // A volume that was read is a valid grid (the reader's contract).
    v.geometry().validate(path);
  });
}

#pragma once
// The real CT beside the repository (../shared/data). A clone without ../shared skips these tests
// with a message; CI always has it.
#include <gtest/gtest.h>

#include <filesystem>
#include <string>

namespace pneumo::testing_support {

inline std::string totalseg_dir() { return std::string(PNEUMO_SHARED_DIR) + "/data/totalseg-example-ct"; }

#define PNEUMO_REQUIRE_SHARED_DATA()                                                              \
  do {                                                                                            \
    if (!std::filesystem::exists(::pneumo::testing_support::totalseg_dir() + "/example_ct.nii.gz")) \
      GTEST_SKIP() << "no ../shared/data/totalseg-example-ct beside the repository";              \
  } while (0)

}  // namespace pneumo::testing_support

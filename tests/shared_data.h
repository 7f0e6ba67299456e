#pragma once
// The real CT the repository carries (data/totalseg-example-ct, Apache-2.0; its README says where it
// comes from). Tests that read it fail, not skip, when it is missing: a clone always has it.
#include <gtest/gtest.h>

#include <filesystem>
#include <string>

namespace pneumo::testing_support {

inline std::string totalseg_dir() { return std::string(PNEUMO_SOURCE_DIR) + "/data/totalseg-example-ct"; }

#define PNEUMO_REQUIRE_REAL_CT()                                                                    \
  do {                                                                                              \
    ASSERT_TRUE(std::filesystem::exists(::pneumo::testing_support::totalseg_dir() + "/example_ct.nii.gz")) \
        << "data/totalseg-example-ct is missing from the repository";                               \
  } while (0)

}  // namespace pneumo::testing_support

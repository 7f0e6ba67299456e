// CTest must hand every test the whole environment tests/CMakeLists.txt sets: the PoCL cache folder, one OpenMP
// thread per test and, in the sanitizer build, the LeakSanitizer suppressions. gtest_discover_tests once passed only
// the first variable on, silently (no OpenMP limit, no suppressions); this catches that coming back.
#include <gtest/gtest.h>

#include <cstdlib>
#include <string>

namespace {
std::string env(const char* name) {
  const char* v = std::getenv(name);
  return v ? v : "";
}
}  // namespace

TEST(CTestEnvironment, EveryVariableArrives) {
  if (env("PNEUMO_CTEST").empty()) GTEST_SKIP() << "not run through CTest";
  EXPECT_NE(env("POCL_CACHE_DIR"), "");
  EXPECT_EQ(env("OMP_NUM_THREADS"), "1");
#if defined(__SANITIZE_ADDRESS__)
  EXPECT_NE(env("LSAN_OPTIONS").find("suppressions="), std::string::npos);
  EXPECT_NE(env("UBSAN_OPTIONS").find("halt_on_error=1"), std::string::npos);
#endif
}

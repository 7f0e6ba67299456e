#pragma once
// The seed of a randomised test: fixed, so that every run checks the same cases and a failure replays
// as it happened. PNEUMO_TEST_SEED (a whole number) tries another, to explore or to replay one a
// failure named; the tests print the seed they used in their failure messages.
#include <cstdlib>
#include <string>

namespace pneumo::testing_support {

inline unsigned test_seed(unsigned fixed) {
  const char* chosen = std::getenv("PNEUMO_TEST_SEED");
  return chosen && *chosen ? unsigned(std::stoul(chosen)) : fixed;
}

}  // namespace pneumo::testing_support

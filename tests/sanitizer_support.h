#pragma once
// Whether this build runs under AddressSanitizer, whose shadow memory maps terabytes: tests that
// bound a child's memory with `ulimit -v` cannot do so then.

namespace pneumo::testing_support {

#if defined(__SANITIZE_ADDRESS__)
inline constexpr bool kAddressSanitizer = true;
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
inline constexpr bool kAddressSanitizer = true;
#else
inline constexpr bool kAddressSanitizer = false;
#endif
#else
inline constexpr bool kAddressSanitizer = false;
#endif

}  // namespace pneumo::testing_support

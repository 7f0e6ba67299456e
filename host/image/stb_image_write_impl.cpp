// stb_image_write's implementation, in a translation unit of its own so that the sanitizer build can
// leave out one check for stb's code alone: its JPEG bit writer (stbiw__jpg_writeBits) shifts a
// negative int left, which C++17 calls undefined and C++20 defines as the two's-complement result GCC
// computes anyway; UndefinedBehaviorSanitizer stopped the JPEG tests there. With PNEUMO_SANITIZE this
// file alone is compiled with -fno-sanitize=shift-base (CMakeLists.txt); png.cpp, pneumo's own image
// code, stays fully checked.
#define STB_IMAGE_WRITE_IMPLEMENTATION
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wunused-function"
#pragma GCC diagnostic ignored "-Wmissing-field-initializers"
#pragma GCC diagnostic ignored "-Wsign-compare"
#include <stb/stb_image_write.h>
#pragma GCC diagnostic pop

#pragma once
// A large buffer written as gzip on every core. RFC 1952 §2.2: a gzip file is a series of members,
// each a complete deflate stream with its own CRC-32 and length; every reader pneumo's users have
// (zlib's gzread under niftilib, ITK, VTK and 3D Slicer; Python's gzip under nibabel) reads them as
// one stream. So the data is cut into pieces of kGzipMemberBytes, each deflated on its own by
// libdeflate (whole-buffer, faster than zlib at the same ratio; Debian's libdeflate-dev), on as many
// threads as OpenMP gives, and the members are written in order. A member costs 18 bytes of header
// and trailer and restarts the 32 KiB window: under 0.1 % of a CT's compressed size.
#include <cstdint>
#include <cstdio>
#include <string>
#include <vector>

namespace pneumo {

/// Input bytes per gzip member: enough that the restarted window costs nothing, small enough that
/// two threads share a 10⁸-voxel volume evenly.
inline constexpr uint64_t kGzipMemberBytes = 8ull << 20;

/// One piece of what is written: `bytes` bytes at `data`.
struct ByteSpan {
  const void* data = nullptr;
  uint64_t bytes = 0;
};

/// Writes the concatenation of `parts` to the open file `f` as gzip members at deflate `level`
/// (1 fastest … 12 smallest, libdeflate's scale): each part starts a new member and is cut into
/// members of at most kGzipMemberBytes. Throws std::runtime_error naming `path` when a write fails
/// (a full disk) or libdeflate cannot start.
void write_gzip_members(std::FILE* f, const std::string& path, const std::vector<ByteSpan>& parts, int level);

}  // namespace pneumo

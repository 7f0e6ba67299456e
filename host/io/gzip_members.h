#pragma once
// A large buffer written as gzip on every core. RFC 1952 §2.2: a gzip file is a series of members,
// each a complete deflate stream with its own CRC-32 and length; every reader pneumo's users have
// (zlib's gzread under niftilib, ITK, VTK and 3D Slicer; Python's gzip under nibabel) reads them as
// one stream. So the data is cut into pieces of kGzipMemberBytes, each deflated on its own by
// libdeflate (whole-buffer, faster than zlib at the same ratio; Debian's libdeflate-dev), on as many
// threads as OpenMP gives, and the members are written in order. A member costs 18 bytes of header
// and trailer and restarts the 32 KiB window: under 0.1 % of a CT's compressed size.
//
// Each member's header carries its own length in an extra field (RFC 1952 §2.3.1.1, FEXTRA; subfield
// 'P','M', 4 bytes little-endian: the member's bytes from its first header byte to the end of its
// trailer), as htslib's BGZF does for its blocks. Readers that do not know the subfield skip it. A
// reader that does can find every member without inflating the ones before it, and so inflate them
// all at once (inflate_gzip_members).
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

/// Bytes [offset, offset + bytes) of what the gzip file at `path` inflates to, into `dst`, with the
/// members inflated side by side on every thread (libdeflate, each member's CRC-32 and length
/// checked). Only for files in write_gzip_members' layout: every member carrying its length, one
/// starting exactly at `offset`, and the whole inflating to exactly offset + bytes. Returns false,
/// having read nothing it vouches for, for anything else (another writer's file, a truncated or
/// corrupt one): the caller then reads the file as a stream and reports what is wrong.
bool inflate_gzip_members(const std::string& path, uint64_t offset, uint64_t bytes, void* dst);

}  // namespace pneumo

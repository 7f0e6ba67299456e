#include "io/gzip_members.h"

#include <libdeflate.h>
#include <omp.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <memory>
#include <stdexcept>

#include <fcntl.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <unistd.h>

namespace pneumo {

namespace {

struct CompressorDeleter {
  void operator()(libdeflate_compressor* c) const { libdeflate_free_compressor(c); }
};
using Compressor = std::unique_ptr<libdeflate_compressor, CompressorDeleter>;
struct DecompressorDeleter {
  void operator()(libdeflate_decompressor* d) const { libdeflate_free_decompressor(d); }
};
using Decompressor = std::unique_ptr<libdeflate_decompressor, DecompressorDeleter>;

// A member: the 10-byte gzip header with FLG = FEXTRA, XLEN = 8, the subfield 'P','M' of 4 bytes
// holding the member's length; the raw deflate stream; CRC-32 and ISIZE (RFC 1952 §2.3).
constexpr std::size_t kHeaderBytes = 10 + 2 + 8, kTrailerBytes = 8;
constexpr unsigned char kFlagExtra = 0x04;

void put_le32(unsigned char* p, uint32_t v) {
  for (int b = 0; b < 4; ++b) p[b] = static_cast<unsigned char>(v >> (8 * b));
}
uint32_t get_le32(const unsigned char* p) {
  return uint32_t(p[0]) | uint32_t(p[1]) << 8 | uint32_t(p[2]) << 16 | uint32_t(p[3]) << 24;
}

/// `data` deflated as one member into `out` (resized to fit); returns the member's length, 0 when
/// libdeflate found no room within its own bound.
std::size_t deflate_member(libdeflate_compressor* c, const unsigned char* data, uint64_t bytes,
                           std::vector<unsigned char>& out) {
  out.resize(kHeaderBytes + libdeflate_deflate_compress_bound(c, bytes) + kTrailerBytes);
  const std::size_t deflated =
      libdeflate_deflate_compress(c, data, bytes, out.data() + kHeaderBytes, out.size() - kHeaderBytes - kTrailerBytes);
  if (deflated == 0) return 0;
  const std::size_t length = kHeaderBytes + deflated + kTrailerBytes;
  unsigned char* h = out.data();
  h[0] = 0x1f, h[1] = 0x8b, h[2] = 8, h[3] = kFlagExtra;   // ID1, ID2, CM deflate, FLG
  put_le32(h + 4, 0);                                       // MTIME: none
  h[8] = 0, h[9] = 3;                                       // XFL, OS: Unix
  h[10] = 8, h[11] = 0;                                     // XLEN
  h[12] = 'P', h[13] = 'M', h[14] = 4, h[15] = 0;           // SI1, SI2, LEN
  put_le32(h + 16, uint32_t(length));
  unsigned char* t = out.data() + kHeaderBytes + deflated;
  put_le32(t, libdeflate_crc32(0, data, bytes));
  put_le32(t + 4, uint32_t(bytes));   // ISIZE: members hold at most kGzipMemberBytes
  return length;
}

/// The file mapped read-only, unmapped on destruction; empty when it cannot be.
struct MappedFile {
  const unsigned char* data = nullptr;
  std::size_t size = 0;
  explicit MappedFile(const std::string& path) {
    // O_NONBLOCK: a path swapped for a FIFO since it was checked is refused by fstat, not waited on.
    const int fd = ::open(path.c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC);
    if (fd < 0) return;
    struct stat st {};
    if (::fstat(fd, &st) == 0 && S_ISREG(st.st_mode) && st.st_size > 0) {
      void* p = ::mmap(nullptr, std::size_t(st.st_size), PROT_READ, MAP_PRIVATE, fd, 0);
      if (p != MAP_FAILED) data = static_cast<const unsigned char*>(p), size = std::size_t(st.st_size);
    }
    ::close(fd);
  }
  ~MappedFile() {
    if (data) ::munmap(const_cast<unsigned char*>(data), size);
  }
  MappedFile(const MappedFile&) = delete;
  MappedFile& operator=(const MappedFile&) = delete;
};

}  // namespace

void write_gzip_members(std::FILE* f, const std::string& path, const std::vector<ByteSpan>& parts, int level) {
  // The members in file order: (start, length) within their part.
  struct Member { const unsigned char* data; uint64_t bytes; };
  std::vector<Member> members;
  for (const ByteSpan& p : parts) {
    uint64_t at = 0;
    do {   // an empty part is one empty member
      const uint64_t n = std::min(kGzipMemberBytes, p.bytes - at);
      members.push_back({static_cast<const unsigned char*>(p.data) + at, n});
      at += n;
    } while (at < p.bytes);
  }
  const int threads = std::max(1, std::min<int>(omp_get_max_threads(), int(members.size())));
  std::vector<Compressor> compressors;
  for (int t = 0; t < threads; ++t) {
    compressors.emplace_back(libdeflate_alloc_compressor(level));
    if (!compressors.back()) throw std::runtime_error(path + ": libdeflate could not start (level " + std::to_string(level) + ")");
  }
  // In waves of one member per thread: compress side by side, then write in order, so that memory
  // holds a wave's output, not the whole file's.
  std::vector<std::vector<unsigned char>> out(static_cast<std::size_t>(threads));
  std::vector<std::size_t> sizes(static_cast<std::size_t>(threads));
  for (std::size_t first = 0; first < members.size(); first += std::size_t(threads)) {
    const int wave = int(std::min<std::size_t>(std::size_t(threads), members.size() - first));
#pragma omp parallel for num_threads(wave) schedule(static, 1)
    for (int t = 0; t < wave; ++t) {
      const Member& m = members[first + std::size_t(t)];
      sizes[std::size_t(t)] = deflate_member(compressors[std::size_t(t)].get(), m.data, m.bytes, out[std::size_t(t)]);
    }
    for (int t = 0; t < wave; ++t) {
      if (sizes[std::size_t(t)] == 0)   // cannot happen with the bound's room; never write a short member
        throw std::runtime_error(path + ": libdeflate found no room for a member within its own bound");
      if (std::fwrite(out[std::size_t(t)].data(), 1, sizes[std::size_t(t)], f) != sizes[std::size_t(t)])
        throw std::runtime_error(path + ": writing failed: " + std::strerror(errno) + " (disk full?)");
    }
  }
}

bool inflate_gzip_members(const std::string& path, uint64_t offset, uint64_t bytes, void* dst) {
  const MappedFile file(path);
  if (!file.data) return false;
  // Walk the members by the lengths their headers carry; anything else is not this layout.
  struct Member { std::size_t at, length; uint64_t inflated_at; uint32_t inflated; };
  std::vector<Member> members;
  uint64_t inflated = 0;
  for (std::size_t at = 0; at < file.size;) {
    const unsigned char* h = file.data + at;
    if (file.size - at < kHeaderBytes + kTrailerBytes) return false;
    if (h[0] != 0x1f || h[1] != 0x8b || h[2] != 8 || h[3] != kFlagExtra || h[10] != 8 || h[11] != 0 ||
        h[12] != 'P' || h[13] != 'M' || h[14] != 4 || h[15] != 0)
      return false;
    const std::size_t length = get_le32(h + 16);
    if (length < kHeaderBytes + kTrailerBytes || length > file.size - at) return false;
    const uint32_t size = get_le32(h + length - 4);
    members.push_back({at, length, inflated, size});
    inflated += size;
    at += length;
  }
  if (inflated != offset + bytes) return false;
  std::size_t first = 0;
  while (first < members.size() && members[first].inflated_at < offset) ++first;
  if (first < members.size() ? members[first].inflated_at != offset : bytes != 0) return false;

  const int count = int(members.size() - first);
  bool good = true;
#pragma omp parallel reduction(&& : good)
  {
    Decompressor d(libdeflate_alloc_decompressor());
    good = d != nullptr;
#pragma omp for schedule(dynamic, 1)
    for (int n = 0; n < count; ++n) {
      if (!good) continue;
      const Member& m = members[first + std::size_t(n)];
      unsigned char* out = static_cast<unsigned char*>(dst) + (m.inflated_at - offset);
      const unsigned char* in = file.data + m.at + kHeaderBytes;
      const std::size_t in_bytes = m.length - kHeaderBytes - kTrailerBytes;
      std::size_t used_in = 0, produced = 0;
      good = libdeflate_deflate_decompress_ex(d.get(), in, in_bytes, out, m.inflated, &used_in, &produced) ==
                 LIBDEFLATE_SUCCESS &&
             used_in == in_bytes && produced == m.inflated &&
             libdeflate_crc32(0, out, produced) == get_le32(file.data + m.at + m.length - kTrailerBytes);
    }
  }
  return good;
}

}  // namespace pneumo

#include "io/gzip_members.h"

#include <libdeflate.h>
#include <omp.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <memory>
#include <stdexcept>

namespace pneumo {

namespace {

struct CompressorDeleter {
  void operator()(libdeflate_compressor* c) const { libdeflate_free_compressor(c); }
};
using Compressor = std::unique_ptr<libdeflate_compressor, CompressorDeleter>;

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
      libdeflate_compressor* c = compressors[std::size_t(t)].get();
      out[std::size_t(t)].resize(libdeflate_gzip_compress_bound(c, m.bytes));
      sizes[std::size_t(t)] = libdeflate_gzip_compress(c, m.data, m.bytes, out[std::size_t(t)].data(), out[std::size_t(t)].size());
    }
    for (int t = 0; t < wave; ++t) {
      if (sizes[std::size_t(t)] == 0)   // cannot happen with the bound's room; never write a short member
        throw std::runtime_error(path + ": libdeflate found no room for a member within its own bound");
      if (std::fwrite(out[std::size_t(t)].data(), 1, sizes[std::size_t(t)], f) != sizes[std::size_t(t)])
        throw std::runtime_error(path + ": writing failed: " + std::strerror(errno) + " (disk full?)");
    }
  }
}

}  // namespace pneumo

// libFuzzer target: the DICOM series folder listing (io/dicom_io.h, list_series_folder). The input
// describes a small folder, entry by entry: a kind byte, a name (from a few characters, dot files
// included) and, for a file, its bytes. The target makes that folder for real (files, sub-folders,
// links to a file or a folder outside it, dangling links, a link to itself, FIFOs) and lists it.
// The listing must account for every entry: the files (and links to files) in name order, the
// sub-folders (and links to them) skipped, or an InputError naming the first other entry by name.
// Anything else aborts; a FIFO that was opened would hang (libFuzzer's -timeout reports it). The
// folder is not read as a series here: Debian's GDCM 3.0 scan aborts on an assert() for some
// 9-byte non-DICOM files (gdcmFileMetaInformation.cxx:498), which would stop every run there.
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <set>
#include <string>
#include <vector>

#include "fuzz_support.h"
#include "io/dicom_io.h"

namespace fs = std::filesystem;

namespace {

enum Kind { kFile, kFolder, kLinkToFile, kLinkToFolder, kDangling, kLoop, kFifo, kKinds };

[[noreturn]] void fail(const std::string& what) {
  std::fprintf(stderr, "%s\n", what.c_str());
  std::abort();
}

struct Reader {
  const uint8_t* data;
  size_t size, at = 0;
  bool more() const { return at < size; }
  uint8_t next() { return at < size ? data[at++] : 0; }
};

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace pneumo;
  fuzz::quiet();
  const fs::path scratch = fuzz::scratch_dir(), dir = scratch / "series";
  fs::remove_all(dir);
  fs::create_directories(dir);
  if (!fs::exists(scratch / "outside.dcm")) std::ofstream(scratch / "outside.dcm") << "not DICOM";
  fs::create_directories(scratch / "outside_folder");

  static const char kAlphabet[] = "ab0.-_x";
  Reader in{data, size};
  std::set<std::string> files, folders, refused;
  for (int e = 0; e < 8 && in.more(); ++e) {
    const Kind kind = Kind(in.next() % kKinds);
    std::string name;
    for (int c = in.next() % 6 + 1; c > 0; --c) name += kAlphabet[in.next() % (sizeof kAlphabet - 1)];
    if (name == "." || name == ".." || files.count(name) || folders.count(name) || refused.count(name)) continue;
    const fs::path p = dir / name;
    std::error_code ec;
    switch (kind) {
      case kFile: {
        const size_t n = std::min<size_t>(in.next(), size - in.at);
        std::ofstream(p, std::ios::binary).write(reinterpret_cast<const char*>(data + in.at), std::streamsize(n));
        in.at += n;
        files.insert(name);
        break;
      }
      case kFolder: fs::create_directory(p, ec), folders.insert(name); break;
      case kLinkToFile: fs::create_symlink(scratch / "outside.dcm", p, ec), files.insert(name); break;
      case kLinkToFolder: fs::create_directory_symlink(scratch / "outside_folder", p, ec), folders.insert(name); break;
      case kDangling: fs::create_symlink(scratch / "nowhere", p, ec), refused.insert(name); break;
      case kLoop: fs::create_symlink(p, p, ec), refused.insert(name); break;
      case kFifo: ::mkfifo(p.c_str(), 0600), refused.insert(name); break;
      case kKinds: break;
    }
    if (ec) fail("cannot make the entry " + name + ": " + ec.message());
  }

  try {
    const SeriesFolder listing = list_series_folder(dir.string());
    if (!refused.empty()) fail("listed a folder holding " + *refused.begin() + " without refusing it");
    std::vector<std::string> expected;
    for (const std::string& f : files) expected.push_back((dir / f).string());
    if (listing.files != expected) fail("the files listed are not the folder's files in name order");
    if (listing.skipped_folders != std::vector<std::string>(folders.begin(), folders.end()))
      fail("the sub-folders skipped are not the folder's sub-folders in name order");
  } catch (const InputError& e) {
    const std::string m = e.what();
    // The first entry by name that is neither a file nor a folder is the one named.
    std::string first;
    for (const std::string& n : refused)
      if (first.empty() || n < first) first = n;
    if (first.empty()) fail("refused a folder of files and sub-folders: " + m);
    if (m.rfind(dir.string() + ": " + first + " ", 0) != 0) fail("the refusal does not name " + first + ": " + m);
  }
  return 0;
}

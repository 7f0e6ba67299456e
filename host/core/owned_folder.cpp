#include "core/owned_folder.h"

#include "core/atomic_file.h"
#include "core/error.h"

namespace pneumo {

namespace fs = std::filesystem;

bool is_owned_folder(const fs::path& dir) {
  std::error_code ec;
  return fs::is_directory(fs::symlink_status(dir, ec)) && fs::is_regular_file(fs::symlink_status(dir / kOwnedFolderMarker, ec));
}

void check_owned_or_absent(const fs::path& dir) {
  std::error_code ec;
  if (!fs::exists(fs::symlink_status(dir, ec)) || is_owned_folder(dir)) return;
  // An empty folder holds nothing to lose: a run killed between making its folder and marking it
  // leaves one (the marker's own temporary is removed by the output lock), and the next run takes it.
  if (fs::is_directory(fs::symlink_status(dir, ec)) && fs::is_empty(dir, ec) && !ec) return;
  throw file_error(dir.string(), std::string("is not a folder pneumo made (it has no ") + kOwnedFolderMarker +
                                     "), and pneumo writes its own there; move it or choose another --out");
}

void create_owned_folder(const fs::path& dir) {
  check_owned_or_absent(dir);
  fs::create_directories(dir);
  if (!is_owned_folder(dir))
    write_text_file_atomic((dir / kOwnedFolderMarker).string(), "made by pneumo: replacing its results removes this folder\n");
}

bool remove_owned_folder(const fs::path& dir) {
  if (!is_owned_folder(dir)) return false;
  std::error_code ec;
  return fs::remove_all(dir, ec) > 0;
}

}  // namespace pneumo

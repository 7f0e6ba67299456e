#pragma once
// The folders pneumo fills below an output folder (views/, flythrough/, timelapse/) carry a marker
// file when pneumo makes them, so that replacing an earlier run's results (--force) removes only
// folders pneumo made: a user's own folder that happens to share the name is never taken for one.
#include <filesystem>
#include <string>

namespace pneumo {

/// The marker's name: hidden, so that listings of the views show only the views.
inline constexpr const char* kOwnedFolderMarker = ".pneumo-output";

/// Creates `dir` (and its parents) if missing and marks it as pneumo's. Throws InputError where `dir`
/// exists and is not pneumo's (check_owned_or_absent).
void create_owned_folder(const std::filesystem::path& dir);

/// Whether `dir` is a folder pneumo made (it holds the marker).
bool is_owned_folder(const std::filesystem::path& dir);

/// Throws InputError naming `dir` when it exists, is not empty and pneumo did not make it: pneumo would
/// otherwise write into, or remove, a folder of the user's. An empty folder is taken (nothing to lose).
void check_owned_or_absent(const std::filesystem::path& dir);

/// Removes `dir` with everything in it if pneumo made it; a folder of the user's is left as it is
/// (check_owned_or_absent refuses it first). Returns whether anything was removed.
bool remove_owned_folder(const std::filesystem::path& dir);

}  // namespace pneumo

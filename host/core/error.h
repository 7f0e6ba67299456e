#pragma once
// Errors pneumo reports to its users. The CLI maps them to exit codes:
//   InputError -> 2 (the user's input is wrong: a file, a scene, an argument),
//   any other std::exception -> 1 (pneumo failed on valid input).
#include <stdexcept>
#include <string>

namespace pneumo {

/// The input is wrong. The message is one line and names what (a file, a key) and why.
class InputError : public std::runtime_error {
 public:
  explicit InputError(const std::string& what) : std::runtime_error(what) {}
};

/// An input file is wrong: the message starts with the file name.
inline InputError file_error(const std::string& path, const std::string& problem) {
  return InputError(path + ": " + problem);
}

}  // namespace pneumo

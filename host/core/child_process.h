#pragma once
// Runs another program with an argument vector, never through a shell: a path the user chose (an
// --out folder named "O'Brien", or one holding "$(…)") reaches the program as one argument, byte for
// byte, and nothing in it is ever interpreted.
#include <optional>
#include <string>
#include <vector>

namespace pneumo {

/// The executable file `name` resolves to on $PATH (as execvp would find it), or nothing.
std::optional<std::string> find_program(const std::string& name);

/// Runs argv[0] (looked up on $PATH) with argv, standard input from /dev/null, and waits for it;
/// its standard output and error go to `output_path` (created or truncated) where one is given.
/// Returns its exit status, 128 + the signal that ended it, or −1 when it could not be started.
int run_program(const std::vector<std::string>& argv, const std::string& output_path = "");

}  // namespace pneumo

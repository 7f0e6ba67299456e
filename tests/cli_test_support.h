#pragma once
// Runs the pneumo executable as a user would, capturing its exit code, stdout and stderr.
#include <sys/wait.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>
#include <string>

#include "io_test_support.h"

namespace pneumo::testing_support {

struct CliResult {
  int code = -1;
  std::string out, err;
};

inline std::string slurp(const std::string& path) {
  std::ifstream in(path);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

/// Every path under `root`, relative, sorted (hidden temporary files included): what a command that
/// must write nothing is compared by, before and after.
inline std::set<std::string> tree(const std::filesystem::path& root) {
  std::set<std::string> out;
  for (const auto& e : std::filesystem::recursive_directory_iterator(root))
    out.insert(std::filesystem::relative(e.path(), root).string());
  return out;
}

/// A shell command line with no standard input; its output goes through files in a scratch folder.
inline CliResult run_shell(const std::string& command) {
  ScratchDir tmp;
  const std::string out = tmp.file("stdout.txt"), err = tmp.file("stderr.txt");
  const std::string cmd = command + " >" + out + " 2>" + err + " </dev/null";
  const int status = std::system(cmd.c_str());
  CliResult r;
  r.code = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
  r.out = slurp(out);
  r.err = slurp(err);
  return r;
}

/// `pneumo ARGS`, as run_shell runs it.
inline CliResult run_pneumo(const std::string& args) { return run_shell(std::string(PNEUMO_CLI_PATH) + " " + args); }

/// `pneumo ARGS` killed after `seconds` (exit 124; 137 where it ignores SIGTERM): for input a faulty
/// reader would wait on forever (a FIFO), so that such a fault fails its test instead of hanging the suite.
inline CliResult run_pneumo_within(int seconds, const std::string& args) {
  return run_shell("timeout -k 5 " + std::to_string(seconds) + " " + PNEUMO_CLI_PATH + " " + args);
}

}  // namespace pneumo::testing_support

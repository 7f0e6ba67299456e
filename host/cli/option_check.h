#pragma once
// A flag that mirrors something pneumo parses elsewhere (a scene key, a back end) is checked by that
// parser when the command line is read: its InputError becomes CLI11's message and exit 2, so the flag
// accepts exactly what the parser does and says why in the parser's words.
#include <CLI/CLI.hpp>

#include <functional>
#include <string>

namespace pneumo::cli {

/// A validator named `name` that runs `parse` on the value and refuses it with parse's InputError.
CLI::Validator checked_by(std::function<void(const std::string&)> parse, const std::string& name);

}  // namespace pneumo::cli

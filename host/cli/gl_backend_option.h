#pragma once
// --backend, the same flag on every command that draws: one wording, the allowed values taken from
// the back ends render/gl_context.h knows, and a value it does not know refused when the command line
// is read (exit 2), not after the solve.
#include <CLI/CLI.hpp>

#include <string>

namespace pneumo::cli {

/// Adds --backend to `cmd`, writing `backend`; `what` says what it draws ("the views", "the heat map").
CLI::Option* add_gl_backend_option(CLI::App* cmd, std::string& backend, const std::string& what);

}  // namespace pneumo::cli

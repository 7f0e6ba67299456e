#pragma once
// --device, the same flag on every command that computes: its help is the scene key `device`'s own
// meaning and allowed values (scene_key_help), and a value the key would refuse is refused with the
// key's own message, so the flag and the key cannot drift apart.
#include <CLI/CLI.hpp>

#include <string>

namespace pneumo::cli {

/// Adds --device to `cmd`, writing `device`; `role` says what it sets there ("overrides the scene's
/// device", "the solve's device").
CLI::Option* add_device_option(CLI::App* cmd, std::string& device, const std::string& role);

}  // namespace pneumo::cli

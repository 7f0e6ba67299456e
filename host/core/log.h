#pragma once
// One-line diagnostics on stderr. Level from --verbose/--quiet or PNEUMO_LOG=quiet|info|debug.
#include <string>

namespace pneumo::log {

enum class Level { Quiet = 0, Info = 1, Debug = 2 };
void set_level(Level l);
Level level();
void info(const std::string& msg);
void debug(const std::string& msg);
void warn(const std::string& msg);   // shown unless quiet

}  // namespace pneumo::log

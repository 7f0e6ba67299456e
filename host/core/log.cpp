#include "core/log.h"

#include <atomic>
#include <cstdio>
#include <cstdlib>
#include <cstring>

namespace pneumo::log {

namespace {
Level from_env() {
  const char* e = std::getenv("PNEUMO_LOG");
  if (!e) return Level::Info;
  if (!std::strcmp(e, "quiet")) return Level::Quiet;
  if (!std::strcmp(e, "debug")) return Level::Debug;
  return Level::Info;
}
std::atomic<int> g_level{static_cast<int>(from_env())};
void emit(const char* tag, const std::string& msg) { std::fprintf(stderr, "pneumo: %s%s\n", tag, msg.c_str()); }
}  // namespace

void set_level(Level l) { g_level = static_cast<int>(l); }
Level level() { return static_cast<Level>(g_level.load()); }
void info(const std::string& msg) { if (g_level >= int(Level::Info)) emit("", msg); }
void debug(const std::string& msg) { if (g_level >= int(Level::Debug)) emit("debug: ", msg); }
void warn(const std::string& msg) { if (g_level >= int(Level::Info)) emit("warning: ", msg); }

}  // namespace pneumo::log

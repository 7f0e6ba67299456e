#include "core/progress.h"

#include <unistd.h>

#include <atomic>
#include <cstdio>

namespace pneumo {

namespace {
std::atomic<bool> g_enabled{true};
constexpr double kQuietFirstSeconds = 1.0;   // work shorter than this shows nothing
constexpr double kTtyIntervalSeconds = 0.2;
constexpr double kLogIntervalSeconds = 5.0;

std::string format_seconds(double s) {
  char buf[32];
  if (s < 60) std::snprintf(buf, sizeof buf, "%.1fs", s);
  else if (s < 3600) std::snprintf(buf, sizeof buf, "%dm%02ds", int(s) / 60, int(s) % 60);
  else std::snprintf(buf, sizeof buf, "%dh%02dm", int(s) / 3600, (int(s) % 3600) / 60);
  return buf;
}
}  // namespace

void Progress::set_enabled(bool on) { g_enabled = on; }

Progress::Progress(std::string stage, int64_t total)
    : stage_(std::move(stage)), total_(total), start_(Clock::now()), last_print_(start_),
      tty_(::isatty(STDERR_FILENO) != 0) {}

Progress::~Progress() {
  if (shown_ && !finished_) finish();
}

void Progress::update(int64_t done, const std::string& detail, double eta_s) {
  if (!g_enabled) return;
  last_done_ = done;
  const auto now = Clock::now();
  const double elapsed = std::chrono::duration<double>(now - start_).count();
  if (elapsed < kQuietFirstSeconds) return;
  const double since = std::chrono::duration<double>(now - last_print_).count();
  if (shown_ && since < (tty_ ? kTtyIntervalSeconds : kLogIntervalSeconds)) return;
  last_print_ = now;
  print(done, detail, false, eta_s);
}

void Progress::finish(const std::string& detail) {
  if (finished_) return;
  finished_ = true;
  if (!g_enabled || !shown_) return;
  print(total_ > 0 ? total_ : last_done_, detail, true, -1.0);
}

void Progress::print(int64_t done, const std::string& detail, bool final, double eta_s) {
  const double elapsed = std::chrono::duration<double>(Clock::now() - start_).count();
  std::string line = "[" + stage_ + "] ";
  if (total_ > 0) {
    const double frac = double(done) / double(total_);
    char buf[96];
    std::snprintf(buf, sizeof buf, "%lld/%lld (%3.0f%%)", (long long)done, (long long)total_, 100.0 * frac);
    line += buf;
    line += " elapsed " + format_seconds(elapsed);
    if (!final && frac > 0.0 && eta_s < 0.0) line += " ETA " + format_seconds(elapsed * (1.0 - frac) / frac);
  } else {
    line += std::to_string(done) + " elapsed " + format_seconds(elapsed);
  }
  if (!final && eta_s >= 0.0) line += " ETA ~" + format_seconds(eta_s);
  if (!detail.empty()) line += "  " + detail;
  if (tty_) std::fprintf(stderr, "\r\033[K%s%s", line.c_str(), final ? "\n" : "");
  else std::fprintf(stderr, "%s\n", line.c_str());
  std::fflush(stderr);
  shown_ = true;
}

}  // namespace pneumo

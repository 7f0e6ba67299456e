#pragma once
// Peak resident memory of this process, per stretch of work: Linux keeps the high-water mark (VmHWM) and lets a
// process reset it (/proc/self/clear_refs, "5"), so each case of `pneumo bench` reports its own peak.
namespace pneumo::bench {

/// Resets the high-water mark to the current resident size; false where the kernel does not allow it (then the
/// peaks are the process's since it started, which only overstates later cases).
bool reset_peak_rss();

/// The high-water mark in MiB (VmHWM; getrusage's ru_maxrss where /proc is missing).
double peak_rss_mib();

}  // namespace pneumo::bench

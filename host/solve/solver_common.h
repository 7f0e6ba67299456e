#pragma once
// What every solver shares: holds, the residual and its reference load, divergence checks,
// the history and progress. Internal to host/solve.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "core/progress.h"
#include "solve/solver.h"

namespace pneumo::detail {

class Monitor;

/// The progress line's ETA (seconds; < 0: none yet) from the residual history: at the full load,
/// log-linear decay to `tolerance` at the slower of the recent rates at that load, never beyond the
/// time left to `max_steps`, `step_limit` when that budget is what bounds it (the residual is not
/// falling fast enough); while the load still rises from `start_pressure_pa` to
/// `final_pressure_pa`, the time so far scaled by the load still to apply.
struct SolverEta {
  double seconds = -1.0;
  bool step_limit = false;
};
SolverEta solver_eta(const std::vector<SolveSample>& history, double tolerance, int64_t max_steps,
                     double seconds_per_step, double start_pressure_pa = 0.0, double final_pressure_pa = 0.0);

// ---- shared by the CPU reference and the device solvers ----------------------------------------

/// FIRE's parameters (Bitzek 2006 / Guénolé 2020 defaults), in pseudo-time units where ω_max ≤ √2.
struct Fire {
  static constexpr double kMaxIncrementMmHg = 4.0;   // load steps of at most this
  static constexpr double kDtMax = 1.0, kDtStart = 0.1, kDtMin = 0.02;
  static constexpr int kDelaySteps = 5;
  static constexpr double kGrow = 1.1, kShrink = 0.5, kAlphaStart = 0.1, kAlphaShrink = 0.99;
  static constexpr double kIntermediateToleranceFactor = 10.0;   // rough equilibrium between increments
};
/// FIRE's step control: after each power P = F·v, grow the step and relax the mixing while P > 0
/// (after a delay), or shrink the step and restart (the caller then moves x back by ½Δt·v and
/// zeroes v) when P ≤ 0. Shared by the CPU and device solvers so both take the same steps.
struct FireControl {
  double dt = Fire::kDtStart, alpha = Fire::kAlphaStart;
  int positive = 0;
  /// Returns true when the caller must restart (P ≤ 0).
  bool after_power(double power) {
    if (power > 0.0) {
      if (++positive > Fire::kDelaySteps) {
        dt = std::min(dt * Fire::kGrow, Fire::kDtMax);
        alpha *= Fire::kAlphaShrink;
      }
      return false;
    }
    positive = 0;
    dt = std::max(dt * Fire::kShrink, Fire::kDtMin);
    alpha = Fire::kAlphaStart;
    return true;
  }
};

/// Newmark-β's inner loop control, shared by the CPU and device solvers: call next() after each
/// iteration with the largest change of the accelerations and the scale it is measured against
/// (max |a|, floored); it says when to stop. The loop stops when the change is below the tolerance,
/// is not finite, or has not fallen for 3 iterations (a fixed-point iteration that keeps growing
/// diverges). With `noise_floor` > 0 (float32 devices), a change that stops falling below
/// noise_floor·scale is the arithmetic's floor, not a divergence.
class NewmarkInnerLoop {
 public:
  NewmarkInnerLoop(double tolerance, double noise_floor) : tolerance_(tolerance), noise_floor_(noise_floor) {}
  bool next(double change, double scale) {
    change_ = change;
    scale_ = scale;
    ++iterations_;
    if (!std::isfinite(change) || change <= tolerance_ * scale) return true;
    growing_ = change >= previous_ ? growing_ + 1 : 0;
    previous_ = change;
    return growing_ >= 3;
  }
  bool failed() const {
    if (!std::isfinite(change_)) return true;
    return change_ > tolerance_ * scale_ && !(change_ <= noise_floor_ * scale_);
  }
  /// Failed because the change grew (or is not finite), not because the iteration cap came first.
  bool diverging() const { return !std::isfinite(change_) || growing_ >= 3; }
  double relative_change() const { return change_ / scale_; }
  int iterations() const { return iterations_; }

 private:
  double tolerance_, noise_floor_;
  double change_ = INFINITY, previous_ = INFINITY, scale_ = 1.0;
  int growing_ = 0, iterations_ = 0;
};

/// The springs' FIRE masses (ForceField::fire_masses): each node's spring stiffness sum (plus the
/// volume term's, when on).
std::vector<double> fire_masses(const Mesh& m, const ForceModel& model);
/// Number of load increments for the static solver (from start_pressure_pa to the target).
int load_increments(const SolveOptions& opt);
/// The pressure of load increment k of n (k = n: the target).
double increment_pressure(const SolveOptions& opt, int increment, int increments);
/// The dynamic schemes' pressure at time t: the ramp from start_pressure_pa to the target.
double ramped_pressure(const SolveOptions& opt, double t_s);
/// Each node's spring stiffness sum D_i (the 2004 scheme's scaling).
std::vector<double> stiffness_sums(const Mesh& m);
/// The time step the dynamic schemes use, recording it and the stable estimate in r.
double chosen_dt(const Mesh& m, const SolveOptions& opt, bool damping, SolveResult& r);
/// What to tell the user when a dynamic scheme diverges.
std::string dt_advice(double dt_s, double dt_stable_s);
/// Newmark's inner loop measures its change against max(|a|, this floor): the acceleration the
/// reference load gives the heaviest node (near equilibrium |a| vanishes and rounding would
/// otherwise look like divergence).
double newmark_acceleration_floor(const Mesh& m, const Monitor& mon);
/// The message of a Newmark inner loop that did not converge: a loop that diverged needs a smaller
/// Δt; one still converging when solver.newmark_max_inner ran out needs more iterations.
std::string newmark_failure(int64_t step, const NewmarkInnerLoop& inner, const SolveOptions& opt, double dt_s,
                            double dt_stable_s);
inline const char* kKitasakaAdvice =
    "solver.kitasaka_step is too large for this mesh; try a smaller value (the paper uses 0.3)";
/// A run that left the model's size without a time step to blame (the static solvers, or a dynamic one
/// within its stable step): the load is more than the material holds within the model (every part is
/// anchored: check_solvable ran first).
inline const char* kLoadAdvice =
    "no equilibrium within the model's size: the pressure is too high for the material (lower "
    "load.pressure_mmhg or raise material.young_kpa), or tetrahedra turned inside out (solver.on_inverted = "
    "\"stop\" stops at the first)";

/// Zeroes the held world axes of each node (fixed nodes, symmetry planes).
void apply_holds(const Mesh& m, std::vector<Vec3>& vec);

class Monitor {
 public:
  Monitor(const Mesh& m, const SolveOptions& opt, const std::string& solver, SolveResult& result);
  /// max over free components of |f| divided by the reference load (the largest nodal pressure
  /// force of the target pressure at rest; a 0.1 % spring strain force when there is no pressure).
  double residual(const std::vector<Vec3>& f) const;
  double max_speed(const std::vector<Vec3>& v) const;
  double max_displacement(const std::vector<Vec3>& x) const;
  /// Throws DivergedError when x holds a non-finite value or moved further than the model's size.
  void check_diverged(const std::vector<Vec3>& x, int64_t step, const std::string& parameter_advice) const;
  /// The same from the largest displacement (NaN or infinite for non-finite positions).
  void check_diverged(double max_displacement_m, int64_t step, const std::string& parameter_advice) const;
  /// Throws DivergedError (naming the material keys) when `residual` is not finite; record() calls it.
  void check_finite_forces(double residual, int64_t step) const;
  /// Records a history row, shows progress; returns true when the run must stop for inversion.
  bool record(int64_t step, double time_s, double pressure_pa, double residual, const std::vector<Vec3>& x,
              const std::vector<Vec3>& v);
  /// The same from scalars measured elsewhere (a device); `positions` is called only when the
  /// inversion check needs them.
  bool record(int64_t step, double time_s, double pressure_pa, double residual, double max_displacement_m,
              double max_speed_m_s, const std::function<const std::vector<Vec3>&()>& positions);
  /// Every monitor_every steps of a dynamic scheme: checks divergence, records, and counts how long
  /// residual and speed have stayed below their tolerances after the ramp. Returns none to go on,
  /// else why to stop (Converged, InvertedTetrahedra); `residual` is updated when checked.
  std::optional<StopReason> check_dynamic(int64_t step, double time_s, double pressure_pa, const std::vector<Vec3>& f,
                            const std::vector<Vec3>& x, const std::vector<Vec3>& v, const std::string& advice,
                            double* residual);
  /// The same from scalars (the residual already divided by reference_load()); call it only on
  /// monitoring steps.
  std::optional<StopReason> check_dynamic(int64_t step, double time_s, double pressure_pa, double residual_now,
                            double max_displacement_m, double max_speed_m_s, const std::string& advice,
                            const std::function<const std::vector<Vec3>&()>& positions, double* residual);
  void finish(const std::vector<Vec3>& x, const std::vector<Vec3>& v, int64_t steps, int64_t force_evaluations,
              StopReason stop_reason, double residual);
  double reference_load() const { return ref_load_; }

 private:
  const Mesh& m_;
  const SolveOptions& opt_;
  SolveResult& r_;
  double ref_load_ = 1.0, extent_m_ = 1.0;
  int64_t held_steps_ = 0;
  int64_t next_snapshot_ = 0;   // the first monitoring step at or past it shows a snapshot
  std::chrono::steady_clock::time_point start_;
  Progress progress_;
};

}  // namespace pneumo::detail

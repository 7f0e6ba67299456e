#pragma once
// What every solver shares: holds, the residual and its reference load, divergence checks,
// the history and progress. Internal to host/solve.
#include <chrono>
#include <string>
#include <vector>

#include "core/progress.h"
#include "solve/solver.h"

namespace pneumo::detail {

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
  /// Records a history row, shows progress; returns true when the run must stop for inversion.
  bool record(int64_t step, double time_s, double pressure_pa, double residual, const std::vector<Vec3>& x,
              const std::vector<Vec3>& v);
  /// Every monitor_every steps of a dynamic scheme: checks divergence, records, and counts how long
  /// residual and speed have stayed below their tolerances after the ramp. Returns "" to go on, or
  /// the stop reason ("converged", "inverted tetrahedra"); `residual` is updated when checked.
  std::string check_dynamic(int64_t step, double time_s, double pressure_pa, const std::vector<Vec3>& f,
                            const std::vector<Vec3>& x, const std::vector<Vec3>& v, const std::string& advice,
                            double* residual);
  void finish(const std::vector<Vec3>& x, const std::vector<Vec3>& v, int64_t steps, int64_t force_evaluations,
              bool converged, const std::string& stop_reason, double residual);
  double reference_load() const { return ref_load_; }

 private:
  const Mesh& m_;
  const SolveOptions& opt_;
  SolveResult& r_;
  double ref_load_ = 1.0, extent_m_ = 1.0;
  int64_t held_steps_ = 0;
  std::chrono::steady_clock::time_point start_;
  Progress progress_;
};

}  // namespace pneumo::detail

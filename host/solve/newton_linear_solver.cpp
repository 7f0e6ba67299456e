#include "solve/newton_linear_solver.h"

#include "solve/force_field.h"
#include "solve/interface_tie.h"
#include "solve/pressure_stiffness.h"

namespace pneumo {

namespace {

class HostNewtonLinearSolver final : public NewtonLinearSolver {
 public:
  HostNewtonLinearSolver(const Mesh& m, ForceField& field) : m_(m), field_(field) {}

  void linearize(const ForceModel& model, const std::vector<Vec3>& x) override {
    field_.linearize(model, x);
    pressure_.linearize(m_, x, model.pressure_pa);
    field_.stiffness_diagonal(blocks_);
    precond_ = block_jacobi(m_, blocks_);
  }

  CgOutcome solve(const std::vector<Vec3>& b, double eta, int max_iterations, Shift& shift,
                  std::vector<Vec3>& d) override {
    const LinearOperator K = [&](const std::vector<Vec3>& p, std::vector<Vec3>& kp) {
      field_.stiffness_product(p, kp);
      pressure_.add_product(p, kp);
    };
    return shifted_conjugate_gradients(m_, K, blocks_, precond_, b, eta, max_iterations, shift, d);
  }

 private:
  const Mesh& m_;
  ForceField& field_;
  PressureStiffness pressure_;
  std::vector<Mat3> blocks_, precond_;
};

}  // namespace

std::unique_ptr<NewtonLinearSolver> host_newton_linear_solver(const Mesh& m, ForceField& field) {
  return std::make_unique<HostNewtonLinearSolver>(m, field);
}

std::unique_ptr<NewtonLinearSolver> newton_linear_solver(const Mesh& m, ForceField& field) {
  if (std::unique_ptr<NewtonLinearSolver> device = field.device_linear_solver({})) return device;
  return host_newton_linear_solver(m, field);
}

}  // namespace pneumo

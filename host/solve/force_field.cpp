// The one place a material model is chosen (force_field.h).
#include "solve/force_field.h"

#include <stdexcept>

#include "solve/contact.h"
#include "solve/interface_tie.h"
#include "solve/thorax_beyond_cut.h"
#include "solve/newton_linear_solver.h"

namespace pneumo {

namespace {
std::unique_ptr<ForceField> make_material_field(const Mesh& m, const ForceModel& model) {
  switch (model.material) {
    case MaterialModel::Msd: return make_spring_force_field(m);
    case MaterialModel::FemCorotational:
    case MaterialModel::FemNeoHookean: return make_fem_force_field(m, model.material);
  }
  throw std::logic_error("unknown material model");
}
}  // namespace

std::unique_ptr<NewtonLinearSolver> ForceField::device_linear_solver(const std::vector<TiedPair>&) { return nullptr; }

std::unique_ptr<ForceField> make_force_field(const Mesh& m, const ForceModel& model) {
  return with_thorax_beyond_cut(m, with_interface_tie(m, model, with_contact(m, model, make_material_field(m, model))));
}

}  // namespace pneumo

// SPDX-License-Identifier: BSD-2-Clause
#include "models/PKM4PUU_Inverse/inverse_data.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <optional>

#include "models/common/slider_partials.hpp"
#include "pkm4puu/dynamics/inverse_dynamics_derivatives.hpp"
#include "pkm4puu/kinematics/constraints.hpp"
#include "pkm4puu/kinematics/workspace_guard.hpp"

namespace pkm_fmi {
namespace pkm4puu_inverse_model {

Status InverseData::make(Context& ctx, const char* function, pkm::Model& out) {
  const pkm::Configuration c = parameters();
  std::string why;
  if (pkm::make_model(c.params, out, &why) != pkm::Status::Ok) {
    ctx.log.error("%s: %s", function, why.c_str());
    return Status::Error;
  }
  why = pkm::validate(c.solver.limits());
  if (!why.empty()) {
    ctx.log.error("%s: %s", function, why.c_str());
    return Status::Error;
  }
  limits = c.solver.limits();
  return Status::OK;
}

Status InverseData::exit_initialization(Context& ctx) {
  auto m = std::make_unique<pkm::Model>();
  const Status st = make(ctx, "ExitInitializationMode", *m);
  if (st != Status::OK) return st;
  model = std::move(m);
  return Status::OK;
}

Status InverseData::tune(Context& ctx, const char* function, bool& states_changed) {
  states_changed = false;  // no states: the outputs follow the new model at the next get
  if (!model) return Status::OK;
  pkm::Model next;
  if (make(ctx, function, next) != Status::OK) {
    put_back_tunable(model->p);
    return Status::Error;
  }
  *model = next;
  return Status::OK;
}

const pkm::Model* InverseData::current_model(Context& ctx, const char* function,
                                             std::optional<pkm::Model>& temporary) {
  if (ctx.initialization_mode) return make(ctx, function, temporary.emplace()) == Status::OK ? &*temporary : nullptr;
  if (!model) ctx.log.error("%s: outputs not available (initialisation did not succeed)", function);
  return model.get();
}

Status InverseData::update_outputs(Context& ctx, unsigned groups) {
  // After initialisation the instance's model, as current_model gives it,
  // without the optional (whose storage would be zeroed on every call).
  if (!ctx.initialization_mode && model) return compute_outputs(ctx, *model, groups);
  std::optional<pkm::Model> temporary;
  const pkm::Model* m = current_model(ctx, "get", temporary);
  if (!m) return Status::Error;
  return compute_outputs(ctx, *m, groups);
}

Status InverseData::compute_outputs(Context& ctx, const pkm::Model& with, unsigned groups) {
  const pkm::Model* m = &with;
  const pkm::Pose p(pose[0], pose[1], pose[2], pose[3]);
  const pkm::Pose pd(vel[0], vel[1], vel[2], vel[3]);
  const pkm::Pose pdd(acc[0], acc[1], acc[2], acc[3]);
  const pkm::Wrench we(wrench[0], wrench[1], wrench[2], wrench[3]);
  auto beyond_guard = [&](const pkm::GuardReport& guard) {
    ctx.log.discard("get: the requested pose x = %.17g m, y = %.17g m, z = %.17g m, phi = %.17g rad is beyond a "
                    "singularity guard: %s; the outputs keep their values of the last pose within the guards",
                    pose[0], pose[1], pose[2], pose[3],
                    pkm::describe_configuration_failure(*m, p, limits, guard).c_str());
    return Status::Discard;
  };
  auto failed = [&](pkm::Status s) {
    // A singular pose is one beyond the guards (whose floor is the core's):
    // Discard with the guard's reason, as for a pose the guards refuse.
    pkm::GuardReport guard;
    if (s == pkm::Status::Singular && pkm::check_configuration(*m, p, limits, &guard) == pkm::Status::Singular)
      return beyond_guard(guard);
    ctx.log.error("get: inverse dynamics at x = %g m, y = %g m, z = %g m, phi = %g rad failed: %s "
                  "(outputs not written)",
                  pose[0], pose[1], pose[2], pose[3], pkm::status_name(s));
    return Status::Error;
  };
  // The forces first: their legs' Jacobian and measures serve the guards
  // (check_jacobian), which every group passes before anything is written.
  pkm::InverseActuators r;
  const pkm::Status s = pkm::inverse_actuators(*m, p, pd, pdd, we, r);
  if (s != pkm::Status::Ok) return failed(s);
  {
    pkm::Mat4 J = r.J_rho;
    J.col(3) /= pkm::kConditionLength;
    const pkm::Vec4 measure2 = r.leg_measure.cwiseProduct(r.leg_measure);
    pkm::GuardReport guard;
    if (pkm::check_jacobian(J, measure2, limits, &guard) == pkm::Status::Singular) return beyond_guard(guard);
  }
  // Every group computed before any output is written: a failure writes nothing.
  pkm::InverseDynamicsResult full;
  if (groups & kGroupMultipliers) {  // the whole reduced path, angles and lambda
    const pkm::Status sf = pkm::inverse_dynamics(*m, p, pd, pdd, we, full);
    if (sf != pkm::Status::Ok) return failed(sf);
  }
  double cond = condition;
  if (groups & kGroupCondition) {  // the actuator Jacobian's SVD
    pkm::Vec16 q;
    const pkm::Status sq = pkm::closed_form_position(*m, p, q);
    if (sq != pkm::Status::Ok) return failed(sq);
    cond = pkm::actuator_jacobian_condition(*m, q);
  }
  if (groups & kGroupMultipliers)
    for (int k = 0; k < 12; ++k) lambda[k] = full.lambda[k];
  condition = cond;
  if (!(groups & kGroupActuators)) return Status::OK;
  for (int i = 0; i < 4; ++i) {
    F[i] = r.F[i];
    tau[i] = r.tau[i];
    rho[i] = r.rho[i];
    drho[i] = r.rhod[i];
  }
  leg_measure_min = r.leg_measure_min;
  const unsigned entered = r.beyond_stops & ~beyond_stops;
  beyond_stops = r.beyond_stops;
  if (entered == 0) return Status::OK;
  for (int k = 0; k < 8; ++k) {
    if (!(entered & (1u << k))) continue;
    const bool lower = k < 4;
    ctx.log.warning("get: the requested pose x = %g m, y = %g m, z = %g m, phi = %g rad puts slider %d at rho = %.9g m, "
                    "%s its %s end stop %s = %.9g m: the forces include the stop's reaction, a real machine would not "
                    "follow",
                    pose[0], pose[1], pose[2], pose[3], k % 4 + 1, rho[k % 4], lower ? "below" : "above",
                    lower ? "lower" : "upper", lower ? "rho_min" : "rho_max",
                    lower ? m->p.rho_min : m->p.rho_max);
  }
  return Status::Warning;
}

// Analytic (inverse_dynamics_derivatives.hpp): F, tau, rho and drho with
// respect to the inputs; the multipliers are refused with Error (not
// differentiated yet).
Status InverseData::partial_derivatives(Context& ctx, const Variable* const unknowns[], std::size_t nu,
                                        const Variable* const knowns[], std::size_t nk, double J[]) {
  const char* fn = "GetDirectionalDerivative";
  std::optional<pkm::Model> temporary;
  const pkm::Model* m = current_model(ctx, fn, temporary);
  if (!m) return Status::Error;
  pkm::InverseDynamicsPartials d;
  const pkm::Status s = pkm::inverse_dynamics_derivatives(*m, pkm::Pose(pose), pkm::Pose(vel), pkm::Pose(acc),
                                                          pkm::Wrench(wrench), d);
  if (s != pkm::Status::Ok) {
    ctx.log.error("%s: the derivatives at x = %g m, y = %g m, z = %g m, phi = %g rad cannot be evaluated: %s", fn,
                  pose[0], pose[1], pose[2], pose[3], pkm::status_name(s));
    return Status::Error;
  }
  // One row over the 16 inputs (value references 1..16: pose, rates, accelerations, wrench) per unknown.
  Eigen::Matrix<double, 1, 16> row;
  for (std::size_t i = 0; i < nu; ++i) {
    const Variable& v = *unknowns[i];
    row.setZero();
    if (std::strncmp(v.name, "F[", 2) == 0 || std::strncmp(v.name, "tau[", 4) == 0) {
      const double scale = v.name[0] == 'F' ? 1.0 : 1.0 / m->drive_ratio;  // tau = F p / (2 pi)
      row << d.dp.row(v.index), d.dpd.row(v.index), d.dpdd.row(v.index), d.dwe.row(v.index);
      row *= scale;
    } else if (!slider_partials(v.name, v.index, d.J_rho, d.drhod_dp, row)) {
      ctx.log.error("%s: the partial derivatives of %s are not provided (analytic so far: F, tau, rho and drho)", fn,
                    v.name);
      return Status::Error;
    }
    for (std::size_t j = 0; j < nk; ++j) J[i * nk + j] = row[static_cast<int>(knowns[j]->vr) - 1];
  }
  return Status::OK;
}

void InverseData::save(StateWriter& w) const { w.u8(model ? 1 : 0); }

bool InverseData::load(StateReader& r, Context& ctx) {
  const bool has_model = r.u8() != 0;
  if (!r.ok()) return false;
  if (!has_model && ctx.initialized) {  // ExitInitializationMode built it
    ctx.log.error("SetFMUState: malformed FMU state (no model in a state after initialisation)");
    return false;
  }
  model.reset();
  if (has_model) {
    auto m = std::make_unique<pkm::Model>();
    if (make(ctx, "SetFMUState", *m) != Status::OK) return false;
    model = std::move(m);
  }
  return true;
}

}  // namespace pkm4puu_inverse_model
}  // namespace pkm_fmi

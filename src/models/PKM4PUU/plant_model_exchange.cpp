// SPDX-License-Identifier: BSD-2-Clause
// The plant FMU's Model Exchange hooks (the continuous states, their
// derivatives, the event indicators and the event update) and its partial
// derivatives (fmiGetDirectionalDerivative).

#include "models/PKM4PUU/plant_data.hpp"
#include "models/common/slider_partials.hpp"
#include "pkm4puu/dynamics/reduced_dynamics_derivatives.hpp"
#include "pkm4puu/kinematics/actuator_positions.hpp"
#include "pkm4puu/kinematics/workspace_guard.hpp"
#include "pkm4puu/machine/passive_force.hpp"

namespace pkm_fmi {
namespace pkm4puu_model {

Status PlantData::get_states(Context& ctx, double x[]) {
  const Status st = ready(ctx, "GetContinuousStates");
  if (st != Status::OK) return st;
  for (int k = 0; k < 8; ++k) x[k] = plant->state()[k];
  x[8] = plant->energy_integrals().actuator_work;
  x[9] = plant->energy_integrals().dissipated;
  return Status::OK;
}

Status PlantData::set_states(Context& ctx, const double x[]) {
  const Status st = ready(ctx, "SetContinuousStates");
  if (st != Status::OK) return st;
  const pkm::Vec8 y = Eigen::Map<const pkm::Vec8>(x);
  if (!std::isfinite(x[8]) || !std::isfinite(x[9])) {
    ctx.log.error("SetContinuousStates: actuator_work = %g J or dissipated_energy = %g J is not finite; the states "
                  "are unchanged", x[8], x[9]);
    return Status::Error;
  }
  const pkm::Status s = plant->set_state(y);
  if (s == pkm::Status::Ok) plant->set_energy_integrals({x[8], x[9]});
  if (s != pkm::Status::Ok) {
    ctx.log.discard("SetContinuousStates: the pose x = %.9g m, y = %.9g m, z = %.9g m, phi = %.9g rad at t = %.17g "
                    "cannot be assembled (%s: %s); the states are unchanged (a smaller step may stay within the "
                    "workspace)",
                    x[0], x[1], x[2], x[3], absolute_time(ctx), pkm::status_name(s), plant->last_error().c_str());
    return Status::Discard;
  }
  return Status::OK;
}

Status PlantData::get_derivatives(Context& ctx, double dx[]) {
  const Status st = ready(ctx, "GetDerivatives");
  if (st != Status::OK) return st;
  pkm::Vec10 xdot;
  const pkm::Status s = plant->derivative_now(inputs(plant->time()).signal(), xdot);
  if (s != pkm::Status::Ok || !xdot.allFinite()) {
    ctx.log.error("GetDerivatives: the state derivative at t = %.17g cannot be evaluated: %s", absolute_time(ctx),
                  s != pkm::Status::Ok ? pkm::status_name(s) : "not finite (singular configuration?)");
    return Status::Error;
  }
  for (int k = 0; k < kStates; ++k) dx[k] = xdot[k];
  return Status::OK;
}

// ---------------------------------------------------------------- partial derivatives

// Analytic (reduced_dynamics_derivatives.hpp) at the current state and
// inputs, the end stops acting when their joint is past them: der(x) ..
// der(dphi), der(actuator_work) (= Fa . drho + we . pd) and
// der(dissipated_energy) (machine.hpp, dissipated_power_slopes), the states
// as outputs, rho[i] and drho[i]. The other computed variables are refused
// with Error (not differentiated yet).
bool PlantData::JacobianCache::holds(const pkm::Vec8& y_now, const double u_now[], unsigned stops_now) const {
  // Bitwise: the same point, not merely a close one.
  return valid && stops == stops_now && std::memcmp(y.data(), y_now.data(), sizeof(double) * 8) == 0 &&
         std::memcmp(u, u_now, sizeof u) == 0;
}

Status PlantData::partial_derivatives(Context& ctx, const Variable* const unknowns[], std::size_t nu,
                                      const Variable* const knowns[], std::size_t nk, double J[]) {
  const char* fn = "GetDirectionalDerivative";
  const Status st = ready(ctx, fn);
  if (st != Status::OK) return st;
  const pkm::Vec4 F(u[0], u[1], u[2], u[3]), we(u[4], u[5], u[6], u[7]), tau(u[8], u[9], u[10], u[11]);
  const pkm::Vec8& y = plant->state();
  JacobianCache& c = jacobian_cache;
  if (!c.holds(y, u, plant->stops())) {
    c.valid = false;
    pkm::Vec8 ydot;
    const pkm::Status s =
        pkm::state_derivative_jacobians(plant->model(), y, F, tau, we, plant->stops(), ydot, c.A, c.B, &c.joints);
    if (s != pkm::Status::Ok) {
      ctx.log.error("%s: the derivatives at t = %.17g cannot be evaluated: %s", fn, plant->time(),
                    pkm::status_name(s));
      return Status::Error;
    }
    if (pkm::actuator_positions(plant->model(), y.head<4>(), c.rho) != pkm::Status::Ok) {
      ctx.log.error("%s: the actuator positions at t = %.17g cannot be evaluated", fn, plant->time());
      return Status::Error;
    }
    c.y = y;
    std::copy(u, u + kInputs, c.u);
    c.stops = plant->stops();
    c.valid = true;
  }
  const pkm::Mat8& A = c.A;
  const pkm::Mat8x12& B = c.B;
  const pkm::JointJacobians& joints = c.joints;
  const pkm::Vec4& rho = c.rho;
  const pkm::Vec4 rhod = joints.J_rho * y.tail<4>();
  // One row over [the 10 states, the 12 inputs u] per unknown.
  Eigen::Matrix<double, 1, kStates + kInputs> row;
  for (std::size_t i = 0; i < nu; ++i) {
    const Variable& v = *unknowns[i];
    row.setZero();
    if (v.state_of >= 0 && v.state_of < 8) {
      row.head<8>() = A.row(v.state_of);
      row.tail<kInputs>() = B.row(v.state_of);
    } else if (v.state_of == 8) {  // der(actuator_work)
      const pkm::Vec4 Fa = F + plant->model().drive_ratio * tau;
      row.head<4>() = Fa.transpose() * joints.drhod_dp;
      row.segment<4>(4) = Fa.transpose() * joints.J_rho + we.transpose();
      row.segment<4>(kStates) = rhod.transpose();
      row.segment<4>(kStates + 4) = y.tail<4>().transpose();
      row.segment<4>(kStates + 8) = plant->model().drive_ratio * rhod.transpose();
    } else if (v.state_of == 9) {  // der(dissipated_energy): sum over the joints
      for (int l = 0; l < 4; ++l) {
        const pkm::PassiveSlopes d = pkm::dissipated_power_slopes(plant->model().p, l, plant->stops(), rho[l], rhod[l]);
        row.head<4>() += d.drho * joints.J_rho.row(l) + d.drhod * joints.drhod_dp.row(l);
        row.segment<4>(4) += d.drhod * joints.J_rho.row(l);
      }
    } else if (v.state >= 0) {
      row[v.state] = 1.0;
    } else if (!slider_partials(v.name, v.index, joints.J_rho, joints.drhod_dp, row)) {
      ctx.log.error("%s: the partial derivatives of %s are not provided (analytic so far: the states' "
                    "derivatives, the states, rho[1..4] and drho[1..4])",
                    fn, v.name);
      return Status::Error;
    }
    for (std::size_t j = 0; j < nk; ++j) {
      const Variable& k = *knowns[j];
      J[i * nk + j] = row[k.state >= 0 ? k.state : kStates + k.index];
    }
  }
  return Status::OK;
}

Status PlantData::get_event_indicators(Context& ctx, double z[]) {
  const Status st = ready(ctx, "GetEventIndicators");
  if (st != Status::OK) return st;
  pkm::Status s = pkm::guard_indicators(plant->model(), plant->state().head<4>(), plant->solver().limits(), z);
  if (s == pkm::Status::Ok) s = plant->contact_indicators(z + pkm::kGuardIndicators);
  if (s != pkm::Status::Ok) {
    ctx.log.error("GetEventIndicators: not defined at t = %.17g: %s", absolute_time(ctx), pkm::status_name(s));
    return Status::Error;
  }
  return Status::OK;
}

Status PlantData::event_update(Context& ctx, bool& terminate) {
  terminate = false;
  const Status ready_st = ready(ctx, "NewDiscreteStates");
  if (ready_st != Status::OK) return ready_st;
  // The relations change here and only here (FMI 2.0.4 §3.2.2, FMI 3.0.2
  // §3.1.1): the contact mode by the event rule, after which every stop
  // indicator is nonzero and consistent (end_stops.hpp, kStopHysteresis),
  // so one iteration suffices.
  unsigned switched = 0;
  const pkm::Status us = plant->update_stops(switched);
  if (us != pkm::Status::Ok) {
    ctx.log.error("event at t = %.17g: the end stops cannot be evaluated: %s", absolute_time(ctx),
                  pkm::status_name(us));
    return Status::Error;
  }
  log_stop_changes(ctx, plant->stops(), "event");
  double z[kIndicators];
  const Status st = get_event_indicators(ctx, z);
  if (st != Status::OK) return st;
  for (int k = 0; k < pkm::kGuardIndicators; ++k) {
    if (z[k] > 0.0) continue;
    terminate = true;
    if (k == 0) {
      ctx.log.warning("event at t = %.17g: the actuator Jacobian's condition number reached max_jacobian_condition "
                      "= %g (parallel-singularity guard); terminateSimulation = true",
                      absolute_time(ctx), plant->solver().max_jacobian_condition);
    } else {
      ctx.log.warning("event at t = %.17g: leg %d reached min_leg_measure = %g (leg-singularity guard: rod nearly "
                      "horizontal or vertical); terminateSimulation = true",
                      absolute_time(ctx), k, plant->solver().min_leg_measure);
    }
    return Status::Warning;
  }
  return Status::OK;
}

}  // namespace pkm4puu_model
}  // namespace pkm_fmi

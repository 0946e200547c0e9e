// SPDX-License-Identifier: BSD-2-Clause
#include "models/PKM4PUU/plant_data.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <iterator>

#include "pkm4puu/kinematics/actuator_positions.hpp"
#include "pkm4puu/kinematics/constraints.hpp"
#include "pkm4puu/kinematics/workspace_guard.hpp"

namespace pkm_fmi {
namespace pkm4puu_model {

Status PlantData::make_plant(Context& ctx, const char* function, std::unique_ptr<pkm::Plant>& out) const {
  pkm::Model model;
  pkm::SolverSettings s;
  const Status st = configuration(ctx, function, model, s);
  if (st != Status::OK) return st;
  auto plant_new = std::make_unique<pkm::Plant>(model);
  std::string why;
  if (plant_new->set_solver(s, &why) != pkm::Status::Ok) {
    ctx.log.error("%s: %s", function, why.c_str());
    return Status::Error;
  }
  out = std::move(plant_new);
  return Status::OK;
}

bool PlantData::built_from(const pkm::Model& model, const pkm::SolverSettings& s) const {
  static_assert(sizeof(pkm::Params) % sizeof(double) == 0, "Params holds doubles only: no padding to compare");
  return plant && std::memcmp(&plant->model().p, &model.p, sizeof(pkm::Params)) == 0 && plant->solver() == s;
}

Status PlantData::configuration(Context& ctx, const char* function, pkm::Model& model,
                                pkm::SolverSettings& s) const {
  const pkm::Configuration c = parameters();
  std::string why;
  if (pkm::make_model(c.params, model, &why) != pkm::Status::Ok) {
    ctx.log.error("%s: %s", function, why.c_str());
    return Status::Error;
  }
  s = c.solver;
  const std::string invalid = pkm::validate(s);
  if (!invalid.empty()) {
    ctx.log.error("%s: %s", function, invalid.c_str());
    return Status::Error;
  }
  return Status::OK;
}

Status PlantData::build(Context& ctx, const char* function) {
  std::unique_ptr<pkm::Plant> p;
  const Status st = make_plant(ctx, function, p);
  if (st != Status::OK) return st;
  const pkm::InitialState initial = parameters().initial;
  const auto& pose0 = initial.pose0;
  const auto& vel0 = initial.vel0;
  const pkm::Pose pose_0(pose0[0], pose0[1], pose0[2], pose0[3]);
  const pkm::Pose vel_0(vel0[0], vel0[1], vel0[2], vel0[3]);
  const pkm::Status s = p->initialize(0.0, pose_0, vel_0);  // model time: since ctx.start_time
  if (s != pkm::Status::Ok) {
    const char* what = s == pkm::Status::Unreachable ? "cannot be assembled elbow-down"
                       : s == pkm::Status::Singular  ? "lies beyond the singularity limits"
                       : s == pkm::Status::SolverFailure ? "cannot be integrated (the solver could not be set up)"
                                                     : "cannot be used";
    ctx.log.error("%s: the initial state x0 = %.9g m, y0 = %.9g m, z0 = %.9g m, phi0 = %.9g rad (velocity dx0 = %g, "
                  "dy0 = %g, dz0 = %g m/s, dphi0 = %g rad/s) %s: %s: %s",
                  function, pose0[0], pose0[1], pose0[2], pose0[3], vel0[0], vel0[1], vel0[2], vel0[3], what,
                  pkm::status_name(s), p->last_error().c_str());
    return Status::Error;
  }
  plant = std::move(p);
  jacobian_cache.valid = false;
  contact_events = plant->contact_events();
  logged_stops = plant->stops();
  may_continue = false;
  return Status::OK;
}

void PlantData::log_stop_changes(Context& ctx, unsigned now, const char* where) {
  const unsigned changed = now ^ logged_stops;
  for (int k = 0; k < pkm::kStopIndicators; ++k) {
    if (!(changed & (1u << k))) continue;
    const bool lower = k < 4;
    ctx.log.event("%s at t = %.17g: slider %d %s its %s end stop (%s = %.9g m)", where, absolute_time(ctx), k % 4 + 1,
                  (now & (1u << k)) ? "passes" : "leaves", lower ? "lower" : "upper", lower ? "rho_min" : "rho_max",
                  lower ? plant->model().p.rho_min : plant->model().p.rho_max);
  }
  logged_stops = now;
}

pkm::LinearInputs PlantData::inputs(double t0) const {
  pkm::LinearInputs in;
  in.t0 = t0;
  in.F0 = pkm::Vec4(u[0], u[1], u[2], u[3]);
  in.dF = pkm::Vec4(du[0], du[1], du[2], du[3]);
  in.we0 = pkm::Wrench(u[4], u[5], u[6], u[7]);
  in.dwe = pkm::Wrench(du[4], du[5], du[6], du[7]);
  in.tau0 = pkm::Vec4(u[8], u[9], u[10], u[11]);
  in.dtau = pkm::Vec4(du[8], du[9], du[10], du[11]);
  return in;
}

Status PlantData::exit_initialization(Context& ctx) { return build(ctx, "ExitInitializationMode"); }

Status PlantData::tune(Context& ctx, const char* function, bool& states_changed) {
  states_changed = false;
  if (!plant) return Status::OK;  // no run (initialisation failed): the next one is built with the new values
  const double work = plant->energy_integrals().actuator_work;
  if (plant->retune(parameters().params) != pkm::Status::Ok) {
    ctx.log.error("%s: %s; the parameters in effect are kept", function, plant->last_error().c_str());
    put_back_tunable(plant->model().p);
    return Status::Error;
  }
  jacobian_cache.valid = false;
  may_continue = false;  // CVODE restarts: the dynamics changed here
  if (!plant->initialized()) return Status::OK;
  states_changed = true;  // actuator_work took the jump of kinetic and potential energy
  ctx.log.event("%s at t = %.17g: the payload changed (payload_mass = %g kg); the platform's velocity is kept, the "
                "jump of kinetic and potential energy, %.9g J, is booked into actuator_work",
                function, absolute_time(ctx), plant->model().p.payload_mass,
                plant->energy_integrals().actuator_work - work);
  return Status::OK;
}

Status PlantData::ready(Context& ctx, const char* function) {
  if (ctx.initialization_mode) {
    // Initial values for the parameters set so far.
    const Status st = build(ctx, function);
    if (st != Status::OK) return st;
  }
  if (!plant || !plant->initialized()) {
    ctx.log.error("%s: no state (initialisation did not succeed)", function);
    return Status::Error;
  }
  return Status::OK;
}

Status PlantData::do_step(Context& ctx, double t, double h, double& t_reached) {
  if (!plant || !plant->initialized()) {
    ctx.log.error("DoStep: no state (initialisation did not succeed)");
    return Status::Error;
  }
  const double t_start = plant->time();
  const double t_end = t + h;
  t_reached = t_start;
  pkm::LinearInputs in = inputs(t_start);
  const double span = t_end - t_start;
  if (!(in.F0 + in.dF * span).allFinite() || !(in.we0 + in.dwe * span).allFinite() ||
      !(in.tau0 + in.dtau * span).allFinite()) {
    ctx.log.error("DoStep: the inputs extrapolated with their derivatives to t = %.17g are not finite", t_end);
    return Status::Error;
  }
  const bool continuous = may_continue && inputs_continue();
  const pkm::Status s = plant->advance(t_end, in.signal(), continuous);
  t_reached = plant->time();
  // The inputs now refer to the time reached.
  if (t_reached != t_start)
    for (int k = 0; k < kInputs; ++k)
      if (du[k] != 0.0) u[k] += du[k] * (t_reached - t_start);
  may_continue = s == pkm::Status::Ok;
  std::memcpy(u_end, u, sizeof u_end);
  if (plant->contact_events() != contact_events) {
    contact_events = plant->contact_events();
    // Also with logEvents off: the record of the stops passed stays current.
    log_stop_changes(ctx, plant->stops(), "DoStep");
  }
  switch (s) {
    case pkm::Status::Ok:
      return Status::OK;
    case pkm::Status::SolverFailure:
    case pkm::Status::Unreachable:
    case pkm::Status::Singular:
    case pkm::Status::NotConverged:
      // The plant kept its last good state (RK4: last whole step; CVODE: the
      // step start), within the singularity limits. The layer says what
      // follows (FMI 2.0: StepFailed, terminated; FMI 3.0: back to the state
      // at the call).
      ctx.log.discard("DoStep: integration from t = %.17g to %.17g failed (%s%s%s, times since startTime); the "
                      "last good state is at t = %.17g",
                      ctx.start_time + t_start, ctx.start_time + t_end, pkm::status_name(s),
                      plant->last_error().empty() ? "" : ": ", plant->last_error().c_str(), ctx.start_time + t_reached);
      return Status::Discard;
    default:
      ctx.log.error("DoStep: integration from t = %.17g to %.17g failed: %s%s%s", ctx.start_time + t_start,
                    ctx.start_time + t_end,
                    pkm::status_name(s), plant->last_error().empty() ? "" : ": ", plant->last_error().c_str());
      return Status::Error;
  }
}

bool PlantData::inputs_continue() const {
  for (int k = 0; k < kInputs; ++k)
    if (!(std::abs(u[k] - u_end[k]) <= kInputJump * (1.0 + std::abs(u_end[k])))) return false;
  return true;
}

Status PlantData::check_step(Context& ctx, double h) const {
  const std::string why = plant ? plant->advance_refusal(h, "a communication step") : std::string();
  if (why.empty()) return Status::OK;
  ctx.log.error("DoStep: %s; the call has no effect", why.c_str());
  return Status::Error;
}

Status PlantData::update_outputs(Context& ctx, unsigned groups) {
  const Status st = ready(ctx, "get");
  if (st != Status::OK) return st;
  const double t = absolute_time(ctx);  // for the messages; the model's own time is plant->time()
  bool finite = true;
  auto all_finite = [&finite](const double* v, int n) {
    for (int i = 0; i < n; ++i) finite = finite && std::isfinite(v[i]);
  };
  auto cannot_assemble = [&ctx, t](pkm::Status s) {
    ctx.log.error("get: the legs cannot be assembled at t = %.17g: %s", t, pkm::status_name(s));
    return Status::Error;
  };
  if (groups & kGroupState) {  // copies of the state
    const pkm::Vec8& y = plant->state();
    for (int i = 0; i < 4; ++i) {
      pose[i] = y[i];
      vel[i] = dy[i] = y[4 + i];
    }
  }
  if (groups & kGroupEnergy) {
    energy[0] = plant->energy_integrals().actuator_work;
    energy[1] = plant->energy_integrals().dissipated;
  }
  if (groups & kGroupJoints) {
    pkm::Vec16 q, qd;
    const pkm::Status s = plant->coordinates(q, qd);
    if (s != pkm::Status::Ok) {
      return cannot_assemble(s);
    }
    for (int i = 0; i < 4; ++i) {
      const int o = pkm::leg_offset(i);
      drho[i] = qd[o];
      theta1[i] = q[o + 1];
      theta2[i] = q[o + 2];
    }
    for (const double* block : {drho, theta1, theta2}) all_finite(block, 4);
  }
  if (groups & kGroupSliders) {
    pkm::Vec4 r;
    const pkm::Status s = plant->actuator_positions(r);
    if (s != pkm::Status::Ok) {
      return cannot_assemble(s);
    }
    for (int i = 0; i < 4; ++i) rho[i] = r[i];
    all_finite(rho, 4);
  }
  if (groups & kGroupDynamics) {  // Eqs. 12-13 and the multipliers
    pkm::MechanismState ms;
    const pkm::Status s = plant->mechanism(inputs(plant->time()).signal(), ms);
    if (s != pkm::Status::Ok) {
      ctx.log.error("get: the mechanism cannot be evaluated at t = %.17g: %s", t, pkm::status_name(s));
      return Status::Error;
    }
    for (int i = 0; i < 4; ++i) dy[4 + i] = ms.qdd[12 + i];
    for (int k = 0; k < 12; ++k) lambda[k] = ms.lambda[k];
    all_finite(dy + 4, 4);
    all_finite(lambda, 12);
  }
  if (groups & kGroupMachine) {
    pkm::MachineOutputs mo;
    const pkm::Status s = plant->machine_outputs(inputs(plant->time()).signal(), mo);
    if (s != pkm::Status::Ok) {
      ctx.log.error("get: the machine's outputs cannot be evaluated at t = %.17g: %s", t, pkm::status_name(s));
      return Status::Error;
    }
    for (int i = 0; i < 4; ++i) {
      F_hold[i] = mo.F_hold[i];
      stop_force[i] = mo.stop_force[i];
    }
    kinetic = mo.kinetic_energy;
    potential = mo.potential_energy;
    dy[8] = mo.actuator_power;
    dy[9] = mo.dissipation_rate;
    for (int k = 0; k < pkm::kStopIndicators; ++k) z[pkm::kGuardIndicators + k] = mo.stop_indicators[k];
    for (int i = 0; i < 4; ++i) z[pkm::kGuardIndicators + pkm::kStopIndicators + i] = mo.clamp_indicators[i];
    for (const double* block : {F_hold, stop_force}) all_finite(block, 4);
    for (double v : {kinetic, potential, dy[8], dy[9]}) finite = finite && std::isfinite(v);
  }
  if (groups & kGroupHealth) {  // one SVD for the condition number and its guard indicator
    pkm::Vec16 q, qd;
    pkm::Status s = plant->coordinates(q, qd);
    if (s == pkm::Status::Ok)
      s = pkm::guard_indicators(plant->model(), plant->state().head<4>(), plant->solver().limits(), z, &condition);
    if (s != pkm::Status::Ok) {
      return cannot_assemble(s);
    }
    residual = pkm::constraints(plant->model(), q).norm();
    finite = finite && std::isfinite(residual) && !std::isnan(condition);  // +inf at a singularity, never NaN
  }
  if (!finite) {
    ctx.log.error("get: non-finite outputs at t = %.17g (singular configuration?)", t);
    return Status::Error;
  }
  return Status::OK;
}

}  // namespace pkm4puu_model
}  // namespace pkm_fmi

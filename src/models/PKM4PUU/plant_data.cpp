// SPDX-License-Identifier: BSD-2-Clause
#include "models/PKM4PUU/plant_data.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <iterator>

#include "pkm4puu/dynamics/reduced_dynamics_derivatives.hpp"
#include "pkm4puu/kinematics/actuator_positions.hpp"
#include "pkm4puu/kinematics/constraints.hpp"
#include "pkm4puu/kinematics/workspace_guard.hpp"
#include "pkm4puu/machine/passive_force.hpp"

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
  if (plant && plant->solver().solver == pkm::Solver::Cvode && h < pkm::kMinCvodeSpan) {
    ctx.log.error("DoStep: a communication step of %.17g s is shorter than CVODE can start with (%.6g s, "
                  "sqrt(DBL_MIN)); the call has no effect",
                  h, pkm::kMinCvodeSpan);
    return Status::Error;
  }
  if (!plant || !pkm::fixed_step(plant->solver().solver)) return Status::OK;
  const double step = plant->solver().rk4_step;
  const double steps = pkm::rk4_steps_for(h, step);
  if (steps <= pkm::kMaxInnerStepsPerCall) return Status::OK;
  ctx.log.error("DoStep: a communication step of %.6g s needs %.3g fixed steps of rk4_step = %.6g s, more than the "
                "%.0f inner steps one call may take: use shorter communication steps or a larger rk4_step; the call "
                "has no effect",
                h, steps, step, pkm::kMaxInnerStepsPerCall);
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

// ---------------------------------------------------------------- Model Exchange

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
    } else if (std::strncmp(v.name, "rho[", 4) == 0) {
      row.head<4>() = joints.J_rho.row(v.index);
    } else if (std::strncmp(v.name, "drho[", 5) == 0) {
      row.head<4>() = joints.drhod_dp.row(v.index);
      row.segment<4>(4) = joints.J_rho.row(v.index);
    } else {
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

// ---------------------------------------------------------------- FMU state

// The plant's part of an FMU state: its snapshot (plant.hpp), the
// integrators' memory whole, as its bytes after their count (a state of a
// build whose memory differs in size is refused).
void PlantData::save(StateWriter& w) const {
  const bool has = plant && plant->initialized();
  w.u8(has ? 1 : 0);
  if (!has) return;
  const pkm::PlantSnapshot s = plant->snapshot();
  w.f64(s.t);
  w.f64s(s.y.data(), s.y.data() + 8);
  w.f64s(s.theta1_ref.data(), s.theta1_ref.data() + 4);
  w.f64(s.energy.actuator_work);
  w.f64(s.energy.dissipated);
  w.u32(s.stops);  // the contact mode: part of the hybrid state
  w.u32(static_cast<std::uint32_t>(sizeof s.memory));
  w.bytes(&s.memory, sizeof s.memory);
}

bool PlantData::load(StateReader& r, Context& ctx) {
  const char* fn = "SetFMUState";
  if (r.u8() == 0) {
    if (!r.ok()) return false;
    if (ctx.initialized) {  // Step Mode, Event Mode, ...: only after ExitInitializationMode built the plant
      ctx.log.error("%s: malformed FMU state (no plant in a state after initialisation)", fn);
      return false;
    }
    plant.reset();
    jacobian_cache.valid = false;
    return true;
  }
  pkm::PlantSnapshot snap;
  snap.t = r.f64();
  r.f64s(snap.y.data(), snap.y.data() + 8);
  r.f64s(snap.theta1_ref.data(), snap.theta1_ref.data() + 4);
  snap.energy.actuator_work = r.f64();
  snap.energy.dissipated = r.f64();
  snap.stops = r.u32();
  const std::uint32_t memory_size = r.u32();
  if (!r.ok()) return false;
  if (memory_size != sizeof snap.memory) {
    ctx.log.error("%s: malformed FMU state (integrators' memory of %u bytes, this FMU keeps %u)", fn, memory_size,
                  static_cast<unsigned>(sizeof snap.memory));
    return false;
  }
  r.bytes(&snap.memory, sizeof snap.memory);
  if (!r.ok()) return false;
  if (snap.stops & ~pkm::kContactModeBits) {  // the rest of its consistency: Plant::restore
    ctx.log.error("%s: malformed FMU state (end-stop record %#x: no contact mode)", fn, snap.stops);
    return false;
  }
  // Co-Simulation: the model's time is the time since startTime, as the
  // layer counts it (they part only in the Error state).
  if (ctx.interface == Interface::CoSimulation && ctx.initialized && snap.t != ctx.model_time) {
    ctx.log.error("%s: malformed FMU state (the plant's time %.17g s differs from the time since startTime %.17g s)",
                  fn, snap.t, ctx.model_time);
    return false;
  }
  // The plant, with its solver's objects, is kept when the restored
  // parameters are those it was built with (restore() restarts CVODE): a
  // restore allocates nothing. Otherwise a new one.
  pkm::Model model;
  pkm::SolverSettings settings;
  if (configuration(ctx, fn, model, settings) != Status::OK) return false;
  std::unique_ptr<pkm::Plant> fresh;
  if (!built_from(model, settings) && make_plant(ctx, fn, fresh) != Status::OK) return false;
  pkm::Plant& p = fresh ? *fresh : *plant;
  // Co-Simulation locates every switch of the contact mode itself: each of
  // its states holds the mode the event rule keeps there. Model Exchange
  // switches it in Event Mode only, so between events it may lag the state
  // the importer's integrator reached.
  const pkm::Status s = p.restore(snap, ctx.interface == Interface::CoSimulation);
  if (s != pkm::Status::Ok) {
    ctx.log.error("%s: the saved state at t = %.17g cannot be restored: %s%s%s", fn, snap.t, pkm::status_name(s),
                  p.last_error().empty() ? "" : ": ", p.last_error().c_str());
    return false;
  }
  if (fresh) plant = std::move(fresh);
  jacobian_cache.valid = false;
  contact_events = plant->contact_events();  // the count continues from here
  logged_stops = plant->stops();
  may_continue = false;  // CVODE restarts here: its history is not part of the state
  return true;
}

}  // namespace pkm4puu_model
}  // namespace pkm_fmi

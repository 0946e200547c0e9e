// SPDX-License-Identifier: BSD-2-Clause
// pkm.h: forward dynamics (a run from pkm_init_pose), its outputs and
// state, and the state derivative's Jacobians.
#include <cmath>

#include "capi/capi_model.hpp"
#include "pkm4puu/dynamics/lagrangian.hpp"
#include "pkm4puu/dynamics/reduced_dynamics_derivatives.hpp"
#include "pkm4puu/kinematics/constraints.hpp"

namespace pkm_capi {
namespace {

/// Constant inputs u[PKM_PLANT_INPUTS] (NULL: zero): F, Fe and Me_z, tau.
pkm::LinearInputs constant_inputs(const double* u) {
  pkm::LinearInputs in;
  if (u) {
    in.F0 = vec4(u);
    in.we0 = vec4(u + 4);
    in.tau0 = vec4(u + 8);
  }
  return in;
}

/// The caller's input callback as the core's InputSignal: one call per
/// time, its torques kept for eval_tau, which read_inputs asks for next.
struct CallbackInputs {
  pkm_input_fn fn;
  void* user;
  double t = std::nan("");
  double u[PKM_PLANT_INPUTS] = {};

  void at(double time) {
    if (time == t) return;
    for (double& v : u) v = 0.0;
    fn(user, time, u);
    t = time;
  }
  static void eval(void* self, double t, pkm::Vec4& F, pkm::Wrench& we) {
    auto* c = static_cast<CallbackInputs*>(self);
    c->at(t);
    F = vec4(c->u);
    we = vec4(c->u + 4);
  }
  static void eval_tau(void* self, double t, pkm::Vec4& tau) {
    auto* c = static_cast<CallbackInputs*>(self);
    c->at(t);
    tau = vec4(c->u + 8);
  }
};

// The ABI 1.0 structs' sizes (fields appended later are written when a caller's size reaches them).
constexpr std::size_t kOutputsSize = PKM_CAPI_SIZE_THROUGH(pkm_outputs, stop_indicators);
constexpr std::size_t kStateSize = PKM_CAPI_SIZE_THROUGH(pkm_state, stops);

/// Forward dynamics needs a run: NOT_INITIALIZED, with why there is none.
pkm_status no_run(const pkm_model* m, const char* fn) {
  return fail(m, PKM_ERR_NOT_INITIALIZED, fn,
              m->run_ended.empty() ? "no run: call pkm_init_pose first" : "no run: " + m->run_ended);
}

}  // namespace
}  // namespace pkm_capi

using namespace pkm_capi;

extern "C" {

pkm_status pkm_init_pose(pkm_model* m, double t0, const double pose[4], const double velocity[4]) {
  if (!m) return PKM_ERR_INVALID_ARGUMENT;
  if (!pose) return null_argument(m, "pkm_init_pose", "pose");
  const pkm::Status s = m->plant->initialize(t0, vec4(pose), vec4(velocity));
  if (s != pkm::Status::Ok) return fail(m, s, at_pose("pkm_init_pose", pose));
  m->run_ended.clear();
  return PKM_OK;
}

pkm_status pkm_advance(pkm_model* m, double t_end, const double u[PKM_PLANT_INPUTS]) {
  const char* fn = "pkm_advance";
  if (!m) return PKM_ERR_INVALID_ARGUMENT;
  if (!m->plant->initialized()) return no_run(m, fn);
  pkm::LinearInputs in = constant_inputs(u);
  if (!in.F0.allFinite() || !in.we0.allFinite() || !in.tau0.allFinite())
    return fail(m, PKM_ERR_NONFINITE, fn, "an input is not finite");
  const pkm::Status s = m->plant->advance(t_end, in.signal(), false);
  return s == pkm::Status::Ok ? PKM_OK : fail(m, s, fn);
}

pkm_status pkm_advance_fn(pkm_model* m, double t_end, pkm_input_fn inputs, void* user, int continuous) {
  const char* fn = "pkm_advance_fn";
  if (!m) return PKM_ERR_INVALID_ARGUMENT;
  if (!inputs) return null_argument(m, fn, "inputs");
  if (!m->plant->initialized()) return no_run(m, fn);
  CallbackInputs cb{inputs, user};
  const pkm::InputSignal in{&CallbackInputs::eval, &cb, &CallbackInputs::eval_tau};
  const pkm::Status s = m->plant->advance(t_end, in, continuous != 0);
  return s == pkm::Status::Ok ? PKM_OK : fail(m, s, fn);
}

pkm_status pkm_get_outputs(pkm_model* m, const double u[PKM_PLANT_INPUTS], pkm_outputs* out) {
  const char* fn = "pkm_get_outputs";
  if (!m) return PKM_ERR_INVALID_ARGUMENT;
  const pkm_status a = struct_argument(m, fn, "out", "pkm_outputs", out, kOutputsSize);
  if (a != PKM_OK) return a;
  if (!m->plant->initialized()) return no_run(m, fn);
  pkm::LinearInputs in = constant_inputs(u);
  const pkm::Plant& plant = *m->plant;
  pkm::MechanismState ms;
  pkm::Status s = plant.mechanism(in.signal(), ms);
  if (s != pkm::Status::Ok) return fail(m, s, fn);
  pkm::MachineOutputs mo;
  s = plant.machine_outputs(in.signal(), mo);
  if (s != pkm::Status::Ok) return fail(m, s, fn);
  pkm_outputs o{};
  o.t = plant.time();
  copy<4>(plant.state().head<4>().eval(), o.pose);
  copy<4>(plant.state().tail<4>().eval(), o.velocity);
  copy<4>(ms.qdd.segment<4>(pkm::kPlatform).eval(), o.acceleration);
  for (int i = 0; i < 4; ++i) {
    const int k = pkm::leg_offset(i);
    o.rho[i] = ms.q[k];
    o.drho[i] = ms.qd[k];
    o.theta1[i] = ms.q[k + 1];
    o.theta2[i] = ms.q[k + 2];
  }
  copy<16>(ms.q, o.q);
  copy<16>(ms.qd, o.qd);
  copy<16>(ms.qdd, o.qdd);
  copy<12>(ms.lambda, o.lambda);
  o.constraint_residual = pkm::constraints(plant.model(), ms.q).norm();
  o.jacobian_condition = pkm::actuator_jacobian_condition(plant.model(), ms.q);
  copy<4>(mo.stop_force, o.stop_force);
  copy<4>(mo.friction_force, o.friction_force);
  copy<4>(mo.F_hold, o.F_hold);
  o.kinetic_energy = mo.kinetic_energy;
  o.potential_energy = mo.potential_energy;
  o.actuator_work = mo.actuator_work;
  o.dissipated_energy = mo.dissipated_energy;
  for (int k = 0; k < 8; ++k) o.stop_indicators[k] = mo.stop_indicators[k];
  deliver(out, o);
  return PKM_OK;
}

pkm_status pkm_get_state(const pkm_model* m, pkm_state* state) {
  const char* fn = "pkm_get_state";
  if (!m) return PKM_ERR_INVALID_ARGUMENT;
  const pkm_status a = struct_argument(m, fn, "state", "pkm_state", state, kStateSize);
  if (a != PKM_OK) return a;
  if (!m->plant->initialized()) return no_run(m, fn);
  const pkm::Plant& plant = *m->plant;
  pkm_state r{};
  r.t = plant.time();
  copy<8>(plant.state(), r.y);
  copy<4>(plant.theta1_ref(), r.theta1_ref);
  r.actuator_work = plant.energy_integrals().actuator_work;
  r.dissipated_energy = plant.energy_integrals().dissipated;
  r.stops = plant.stops();
  deliver(state, r);
  return PKM_OK;
}

pkm_status pkm_set_state(pkm_model* m, const pkm_state* state) {
  const char* fn = "pkm_set_state";
  if (!m) return PKM_ERR_INVALID_ARGUMENT;
  const pkm_status a = struct_argument(m, fn, "state", "pkm_state", state, kStateSize);
  if (a != PKM_OK) return a;
  // pkm_get_state settled the energy balance (energy_integrals()), so the
  // integrators' memory is a restarted one's, the snapshot's default
  // (SolverMemory{}): the run continues bit for bit.
  pkm::PlantSnapshot snap;
  snap.t = state->t;
  snap.y = Eigen::Map<const pkm::Vec8>(state->y);
  snap.theta1_ref = vec4(state->theta1_ref);
  snap.energy = {state->actuator_work, state->dissipated_energy};
  snap.stops = state->stops;
  const pkm::Status s = m->plant->restore(snap);
  if (s != pkm::Status::Ok) return fail(m, s, fn);
  m->run_ended.clear();
  return PKM_OK;
}

pkm_status pkm_forward_derivatives(pkm_model* m, const double state[8], const double u[PKM_PLANT_INPUTS],
                                   double ydot[8], double A[64], double B[8 * PKM_PLANT_INPUTS]) {
  const char* fn = "pkm_forward_derivatives";
  if (!m) return PKM_ERR_INVALID_ARGUMENT;
  const pkm_status a = first_null(m, fn, {{"state", state}, {"A", A}, {"B", B}});
  if (a != PKM_OK) return a;
  const pkm::Vec8 y = Eigen::Map<const pkm::Vec8>(state);
  const double zero[PKM_PLANT_INPUTS] = {};
  const double* in = u ? u : zero;
  pkm::Vec8 yd;
  pkm::Mat8 Ay;
  pkm::Mat8x12 By;
  const pkm::Status s = pkm::state_derivative_jacobians(m->plant->model(), y, vec4(in), vec4(in + 8), vec4(in + 4),
                                                        pkm::kStopsFromState, yd, Ay, By);
  if (s != pkm::Status::Ok) return fail(m, s, fn);
  if (ydot) copy<8>(yd, ydot);
  Eigen::Map<Eigen::Matrix<double, 8, 8, Eigen::RowMajor>> A_out(A);
  Eigen::Map<Eigen::Matrix<double, 8, PKM_PLANT_INPUTS, Eigen::RowMajor>> B_out(B);
  A_out = Ay;
  B_out = By;
  return PKM_OK;
}

}  // extern "C"

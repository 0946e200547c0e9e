// SPDX-License-Identifier: BSD-2-Clause
// The C API over the core (pkm.h). Converts arrays and status codes; holds
// no mathematics of its own.
#include "pkm4puu/pkm.h"

#include <cstdio>
#include <cstring>
#include <memory>
#include <new>
#include <string>

#include "pkm4puu/kinematics/constraints.hpp"
#include "pkm4puu/dynamics/inverse_dynamics.hpp"
#include "pkm4puu/dynamics/inverse_dynamics_derivatives.hpp"
#include "pkm4puu/dynamics/lagrangian.hpp"
#include "pkm4puu/dynamics/regressor.hpp"
#include "pkm4puu/sim/plant.hpp"
#include "pkm4puu/dynamics/reduced_dynamics_derivatives.hpp"

struct pkm_model {
  explicit pkm_model(const pkm::Model& m) : plant(m) {}
  pkm::Plant plant;
  std::string error;
};

namespace {

using pkm::Status;

pkm_status to_c(Status s) { return static_cast<pkm_status>(static_cast<int>(s)); }

pkm::Params from_c(const pkm_params& c) {
  pkm::Params p;
  p.h = c.h;
  p.l = c.l;
  p.h_prime = c.h_prime;
  p.r_b = c.r_b;
  p.r_Q = c.r_Q;
  for (int i = 0; i < 4; ++i) {
    p.beta[i] = c.beta[i];
    p.gamma[i] = c.gamma[i];
  }
  p.m_slider = c.m_slider;
  p.m_rod = c.m_rod;
  for (int i = 0; i < 3; ++i) p.I_rod[i] = c.I_rod[i];
  p.m_platform = c.m_platform;
  p.Izz_platform = c.Izz_platform;
  p.g = c.g;
  return p;
}

pkm::Vec4 vec4(const double* a) { return a ? pkm::Vec4(a[0], a[1], a[2], a[3]) : pkm::Vec4::Zero(); }

void copy(const pkm::Vec4& v, double* out) { for (int i = 0; i < 4; ++i) out[i] = v[i]; }
template <int N>
void copy(const Eigen::Matrix<double, N, 1>& v, double* out) { for (int i = 0; i < N; ++i) out[i] = v[i]; }

pkm_status fail(pkm_model* m, Status s, const std::string& what) {
  m->error = what + ": " + pkm::status_name(s);
  if (!m->plant.last_error().empty()) m->error += " (" + m->plant.last_error() + ")";
  return to_c(s);
}

struct CallbackInputs {
  pkm_input_fn fn;
  void* user;
  pkm_torque_fn torques = nullptr;
  static void eval(void* self, double t, pkm::Vec4& F, pkm::Wrench& we) {
    auto* c = static_cast<CallbackInputs*>(self);
    double f[4] = {0, 0, 0, 0}, w[4] = {0, 0, 0, 0};
    c->fn(c->user, t, f, w);
    F = vec4(f);
    we = vec4(w);
  }
  static void eval_tau(void* self, double t, pkm::Vec4& tau) {
    auto* c = static_cast<CallbackInputs*>(self);
    double a[4] = {0, 0, 0, 0};
    c->torques(c->user, t, a);
    tau = vec4(a);
  }
};

void to_params(const pkm_machine_params& c, pkm::Params& p) {
  p.screw_lead = c.screw_lead;
  p.rotor_inertia = c.rotor_inertia;
  p.friction_viscous = c.friction_viscous;
  p.friction_coulomb = c.friction_coulomb;
  p.friction_velocity = c.friction_velocity;
  p.rho_min = c.rho_min;
  p.rho_max = c.rho_max;
  p.stop_stiffness = c.stop_stiffness;
  p.stop_damping = c.stop_damping;
  p.payload_mass = c.payload_mass;
  p.payload_com = {c.payload_com[0], c.payload_com[1]};
  p.payload_Izz = c.payload_Izz;
}

pkm_status create(const pkm::Params& params, pkm_model** out, char* err, size_t err_len) {
  auto message = [&](const std::string& s) {
    if (err && err_len > 0) std::snprintf(err, err_len, "%s", s.c_str());
  };
  pkm::Model model;
  std::string why;
  const Status s = pkm::make_model(params, model, &why);
  if (s != Status::Ok) {
    message(why);
    return to_c(s);
  }
  *out = new (std::nothrow) pkm_model(model);
  if (!*out) {
    message("pkm_create: out of memory");
    return PKM_ERR_INVALID_ARGUMENT;
  }
  message("");
  return PKM_OK;
}

}  // namespace

extern "C" {

void pkm_default_params(pkm_params* c) {
  if (!c) return;
  const pkm::Params p;
  c->h = p.h;
  c->l = p.l;
  c->h_prime = p.h_prime;
  c->r_b = p.r_b;
  c->r_Q = p.r_Q;
  for (int i = 0; i < 4; ++i) {
    c->beta[i] = p.beta[i];
    c->gamma[i] = p.gamma[i];
  }
  c->m_slider = p.m_slider;
  c->m_rod = p.m_rod;
  for (int i = 0; i < 3; ++i) c->I_rod[i] = p.I_rod[i];
  c->m_platform = p.m_platform;
  c->Izz_platform = p.Izz_platform;
  c->g = p.g;
}

void pkm_default_solver_settings(pkm_solver_settings* c) {
  if (!c) return;
  const pkm::SolverSettings s;
  c->solver = static_cast<int>(s.solver);
  c->rk4_step = s.rk4_step;
  c->rtol = s.rtol;
  c->atol = s.atol;
  c->cvode_method = static_cast<int>(s.cvode_method);
  c->formulation = static_cast<int>(s.formulation);
  c->max_jacobian_condition = s.max_jacobian_condition;
  c->min_leg_measure = s.min_leg_measure;
}

pkm_status pkm_create(const pkm_params* p, pkm_model** out, char* err, size_t err_len) {
  auto message = [&](const std::string& s) {
    if (err && err_len > 0) std::snprintf(err, err_len, "%s", s.c_str());
  };
  if (!out) {
    message("pkm_create: out is NULL");
    return PKM_ERR_INVALID_ARGUMENT;
  }
  *out = nullptr;
  if (!p) {
    message("pkm_create: params is NULL");
    return PKM_ERR_INVALID_ARGUMENT;
  }
  return create(from_c(*p), out, err, err_len);
}

void pkm_default_machine_params(pkm_machine_params* c) {
  if (!c) return;
  const pkm::Params p;
  c->screw_lead = p.screw_lead;
  c->rotor_inertia = p.rotor_inertia;
  c->friction_viscous = p.friction_viscous;
  c->friction_coulomb = p.friction_coulomb;
  c->friction_velocity = p.friction_velocity;
  c->rho_min = p.rho_min;
  c->rho_max = p.rho_max;
  c->stop_stiffness = p.stop_stiffness;
  c->stop_damping = p.stop_damping;
  c->payload_mass = p.payload_mass;
  c->payload_com[0] = p.payload_com[0];
  c->payload_com[1] = p.payload_com[1];
  c->payload_Izz = p.payload_Izz;
}

pkm_status pkm_create_machine(const pkm_params* p, const pkm_machine_params* mp, pkm_model** out, char* err,
                              size_t err_len) {
  auto message = [&](const std::string& s) {
    if (err && err_len > 0) std::snprintf(err, err_len, "%s", s.c_str());
  };
  if (!out) {
    message("pkm_create_machine: out is NULL");
    return PKM_ERR_INVALID_ARGUMENT;
  }
  *out = nullptr;
  if (!p) {
    message("pkm_create_machine: params is NULL");
    return PKM_ERR_INVALID_ARGUMENT;
  }
  pkm::Params params = from_c(*p);
  if (mp) to_params(*mp, params);
  return create(params, out, err, err_len);
}

pkm_status pkm_advance_drives(pkm_model* m, double t_end, const double F[4], const double tau[4],
                              const double wrench[4]) {
  if (!m) return PKM_ERR_INVALID_ARGUMENT;
  pkm::LinearInputs in;
  in.F0 = vec4(F);
  in.tau0 = vec4(tau);
  in.we0 = vec4(wrench);
  if (!in.F0.allFinite() || !in.we0.allFinite() || !in.tau0.allFinite())
    return fail(m, Status::NonFinite, "pkm_advance_drives: inputs");
  const Status s = m->plant.advance(t_end, in.signal(), false);
  return s == Status::Ok ? PKM_OK : fail(m, s, "pkm_advance_drives");
}

pkm_status pkm_advance_fn_drives(pkm_model* m, double t_end, pkm_input_fn fn, pkm_torque_fn torques, void* user,
                                 int continuous) {
  if (!m || !fn) return PKM_ERR_INVALID_ARGUMENT;
  CallbackInputs cb{fn, user, torques};
  pkm::InputSignal in{&CallbackInputs::eval, &cb, torques ? &CallbackInputs::eval_tau : nullptr};
  const Status s = m->plant.advance(t_end, in, continuous != 0);
  return s == Status::Ok ? PKM_OK : fail(m, s, "pkm_advance_fn_drives");
}

pkm_status pkm_get_machine_outputs(pkm_model* m, const double F[4], const double tau[4], const double wrench[4],
                                   pkm_machine_outputs* out) {
  if (!m || !out) return PKM_ERR_INVALID_ARGUMENT;
  pkm::LinearInputs in;
  in.F0 = vec4(F);
  in.tau0 = vec4(tau);
  in.we0 = vec4(wrench);
  pkm::MachineOutputs o;
  const Status s = m->plant.machine_outputs(in.signal(), o);
  if (s != Status::Ok) return fail(m, s, "pkm_get_machine_outputs");
  copy(o.stop_force, out->stop_force);
  copy(o.friction_force, out->friction_force);
  copy(o.F_hold, out->F_hold);
  out->kinetic_energy = o.kinetic_energy;
  out->potential_energy = o.potential_energy;
  out->actuator_work = o.actuator_work;
  out->dissipated_energy = o.dissipated_energy;
  for (int k = 0; k < 8; ++k) out->stop_indicators[k] = o.stop_indicators[k];
  return PKM_OK;
}

pkm_status pkm_inverse_dynamics_machine(pkm_model* m, const double pose[4], const double velocity[4],
                                        const double acceleration[4], const double wrench[4],
                                        pkm_inverse_machine_result* out) {
  if (!m || !pose || !velocity || !acceleration || !out) return PKM_ERR_INVALID_ARGUMENT;
  pkm::InverseDynamicsResult r;
  const Status s = pkm::inverse_dynamics(m->plant.model(), vec4(pose), vec4(velocity), vec4(acceleration),
                                         vec4(wrench), r);
  if (s != Status::Ok) return fail(m, s, "pkm_inverse_dynamics_machine");
  copy(r.F, out->F);
  copy(r.tau, out->tau);
  copy<12>(r.lambda, out->lambda);
  out->beyond_stops = r.beyond_stops;
  return PKM_OK;
}

pkm_status pkm_forward_derivatives(pkm_model* m, const double state[8], const double inputs[12], double ydot[8],
                                   double A[64], double B[96]) {
  if (!m || !state || !A || !B) return PKM_ERR_INVALID_ARGUMENT;
  const pkm::Vec8 y = Eigen::Map<const pkm::Vec8>(state);
  const double zero[PKM_PLANT_INPUTS] = {};
  const double* u = inputs ? inputs : zero;
  pkm::Vec8 yd;
  pkm::Mat8 Ay;
  pkm::Mat8x12 By;
  const Status s = pkm::state_derivative_jacobians(m->plant.model(), y, vec4(u), vec4(u + 8), vec4(u + 4),
                                                   pkm::kStopsFromState, yd, Ay, By);
  if (s != Status::Ok) return fail(m, s, "pkm_forward_derivatives");
  if (ydot) copy<8>(yd, ydot);
  Eigen::Map<Eigen::Matrix<double, 8, 8, Eigen::RowMajor>> A_out(A);
  Eigen::Map<Eigen::Matrix<double, 8, 12, Eigen::RowMajor>> B_out(B);
  A_out = Ay;
  B_out = By;
  return PKM_OK;
}

pkm_status pkm_inverse_derivatives(pkm_model* m, const double pose[4], const double velocity[4],
                                   const double acceleration[4], const double wrench[4], double F[4], double dF[64]) {
  if (!m || !pose || !velocity || !acceleration || !F || !dF) return PKM_ERR_INVALID_ARGUMENT;
  pkm::InverseDynamicsPartials d;
  const Status s = pkm::inverse_dynamics_derivatives(m->plant.model(), vec4(pose), vec4(velocity),
                                                     vec4(acceleration), vec4(wrench), d);
  if (s != Status::Ok) return fail(m, s, "pkm_inverse_derivatives");
  copy(d.F, F);
  Eigen::Map<Eigen::Matrix<double, 4, 16, Eigen::RowMajor>> J(dF);
  J << d.dp, d.dpd, d.dpdd, d.dwe;
  return PKM_OK;
}

void pkm_destroy(pkm_model* m) { delete m; }

const char* pkm_last_error(const pkm_model* m) { return m ? m->error.c_str() : "NULL handle"; }

const char* pkm_version(void) { return PKM_VERSION_STRING; }

const char* pkm_status_string(pkm_status s) { return pkm::status_name(static_cast<Status>(s)); }

pkm_status pkm_set_solver(pkm_model* m, const pkm_solver_settings* c) {
  if (!m || !c) return PKM_ERR_INVALID_ARGUMENT;
  pkm::SolverSettings s = m->plant.solver();  // the step checks kept
  s.solver = static_cast<pkm::Solver>(c->solver);
  s.rk4_step = c->rk4_step;
  s.rtol = c->rtol;
  s.atol = c->atol;
  s.cvode_method = static_cast<pkm::CvodeMethod>(c->cvode_method);
  s.formulation = static_cast<pkm::Formulation>(c->formulation);
  s.max_jacobian_condition = c->max_jacobian_condition;
  s.min_leg_measure = c->min_leg_measure;
  std::string why;
  if (m->plant.set_solver(s, &why) != Status::Ok) {
    m->error = why;
    return PKM_ERR_INVALID_ARGUMENT;
  }
  return PKM_OK;
}

pkm_status pkm_set_step_checks(pkm_model* m, double work_budget, double energy_tolerance) {
  if (!m) return PKM_ERR_INVALID_ARGUMENT;
  pkm::SolverSettings s = m->plant.solver();
  s.work_budget = work_budget;
  s.energy_tolerance = energy_tolerance;
  std::string why;
  if (m->plant.set_solver(s, &why) != Status::Ok) {
    m->error = why;
    return PKM_ERR_INVALID_ARGUMENT;
  }
  return PKM_OK;
}

pkm_status pkm_get_step_checks(const pkm_model* m, double* work_budget, double* energy_tolerance) {
  if (!m || !work_budget || !energy_tolerance) return PKM_ERR_INVALID_ARGUMENT;
  *work_budget = m->plant.solver().work_budget;
  *energy_tolerance = m->plant.solver().energy_tolerance;
  return PKM_OK;
}

pkm_status pkm_init_pose(pkm_model* m, double t0, const double pose[4], const double velocity[4]) {
  if (!m || !pose) return PKM_ERR_INVALID_ARGUMENT;
  const Status s = m->plant.initialize(t0, vec4(pose), vec4(velocity));
  if (s != Status::Ok) {
    char buf[200];
    std::snprintf(buf, sizeof buf, "pkm_init_pose(x=%g, y=%g, z=%g, phi=%g)", pose[0], pose[1], pose[2],
                  pose[3]);
    return fail(m, s, buf);
  }
  return PKM_OK;
}

pkm_status pkm_inverse_dynamics(pkm_model* m, const double pose[4], const double velocity[4],
                                const double acceleration[4], const double wrench[4],
                                pkm_inverse_result* out) {
  if (!m || !pose || !velocity || !acceleration || !out) return PKM_ERR_INVALID_ARGUMENT;
  pkm::InverseDynamicsResult r;
  const Status s = pkm::inverse_dynamics(m->plant.model(), vec4(pose), vec4(velocity), vec4(acceleration),
                                         vec4(wrench), r);
  if (s != Status::Ok) return fail(m, s, "pkm_inverse_dynamics");
  copy(r.F, out->F);
  copy<12>(r.lambda, out->lambda);
  copy<16>(r.q, out->q);
  copy<16>(r.qd, out->qd);
  copy<16>(r.qdd, out->qdd);
  return PKM_OK;
}

pkm_status pkm_advance(pkm_model* m, double t_end, const double F[4], const double wrench[4]) {
  if (!m) return PKM_ERR_INVALID_ARGUMENT;
  pkm::LinearInputs in;
  in.F0 = vec4(F);
  in.we0 = vec4(wrench);
  if (!in.F0.allFinite() || !in.we0.allFinite()) return fail(m, Status::NonFinite, "pkm_advance: inputs");
  const Status s = m->plant.advance(t_end, in.signal(), false);
  return s == Status::Ok ? PKM_OK : fail(m, s, "pkm_advance");
}

pkm_status pkm_advance_fn(pkm_model* m, double t_end, pkm_input_fn fn, void* user, int continuous) {
  if (!m || !fn) return PKM_ERR_INVALID_ARGUMENT;
  CallbackInputs cb{fn, user};
  const Status s = m->plant.advance(t_end, {&CallbackInputs::eval, &cb}, continuous != 0);
  return s == Status::Ok ? PKM_OK : fail(m, s, "pkm_advance_fn");
}

pkm_status pkm_get_outputs(pkm_model* m, const double F[4], const double wrench[4], pkm_outputs* out) {
  if (!m || !out) return PKM_ERR_INVALID_ARGUMENT;
  pkm::LinearInputs in;
  in.F0 = vec4(F);
  in.we0 = vec4(wrench);
  pkm::MechanismState ms;
  const Status s = m->plant.mechanism(in.signal(), ms);
  if (s != Status::Ok) return fail(m, s, "pkm_get_outputs");
  out->t = m->plant.time();
  copy(m->plant.state().head<4>().eval(), out->pose);
  copy(m->plant.state().tail<4>().eval(), out->velocity);
  copy(ms.qdd.segment<4>(pkm::kPlatform).eval(), out->acceleration);
  for (int i = 0; i < 4; ++i) {
    const int o = pkm::leg_offset(i);
    out->rho[i] = ms.q[o];
    out->drho[i] = ms.qd[o];
    out->theta1[i] = ms.q[o + 1];
    out->theta2[i] = ms.q[o + 2];
  }
  copy<16>(ms.q, out->q);
  copy<16>(ms.qd, out->qd);
  copy<16>(ms.qdd, out->qdd);
  copy<12>(ms.lambda, out->lambda);
  out->constraint_residual = pkm::constraints(m->plant.model(), ms.q).norm();
  out->jacobian_condition = pkm::actuator_jacobian_condition(m->plant.model(), ms.q);
  return PKM_OK;
}

pkm_status pkm_get_state(const pkm_model* m, double* t, double y[8], double theta1_ref[4]) {
  if (!m || !t || !y) return PKM_ERR_INVALID_ARGUMENT;
  if (!m->plant.initialized()) return PKM_ERR_NOT_INITIALIZED;
  *t = m->plant.time();
  copy<8>(m->plant.state(), y);
  if (theta1_ref) copy(m->plant.theta1_ref(), theta1_ref);
  return PKM_OK;
}

pkm_status pkm_set_state(pkm_model* m, double t, const double y[8], const double theta1_ref[4]) {
  if (!m || !y) return PKM_ERR_INVALID_ARGUMENT;
  pkm::Vec8 v;
  for (int i = 0; i < 8; ++i) v[i] = y[i];
  const Status s = m->plant.restore(t, v, theta1_ref ? vec4(theta1_ref) : m->plant.theta1_ref());
  return s == Status::Ok ? PKM_OK : fail(m, s, "pkm_set_state");
}

pkm_status pkm_energy(pkm_model* m, double* kinetic, double* potential) {
  if (!m || !kinetic || !potential) return PKM_ERR_INVALID_ARGUMENT;
  pkm::MechanismState ms;
  pkm::LinearInputs none;
  const Status s = m->plant.mechanism(none.signal(), ms);
  if (s != Status::Ok) return fail(m, s, "pkm_energy");
  *kinetic = pkm::kinetic_energy(m->plant.model(), ms.q, ms.qd);
  *potential = pkm::potential_energy(m->plant.model(), ms.q);
  return PKM_OK;
}

}  // extern "C"

static_assert(PKM_REGRESSOR_PARAMS == pkm::kParams, "pkm.h's parameter count is the core's");

int pkm_regressor_param_count(void) { return PKM_REGRESSOR_PARAMS; }

const char* pkm_regressor_param_name(int j) { return pkm::regressor_param_info(j).name; }

const char* pkm_regressor_param_unit(int j) { return pkm::regressor_param_info(j).unit; }

pkm_status pkm_regressor_params(pkm_model* m, double pi[PKM_REGRESSOR_PARAMS]) {
  if (!m || !pi) return PKM_ERR_INVALID_ARGUMENT;
  copy<pkm::kParams>(pkm::parameter_vector(m->plant.model().p), pi);
  return PKM_OK;
}

namespace {

using RowRegressor = Eigen::Matrix<double, 4, pkm::kParams, Eigen::RowMajor>;

pkm_status regressor_failure(pkm_model* m, Status s, const char* what, size_t k, size_t n, const double* at,
                             const char* at_name) {
  char buf[256];
  std::snprintf(buf, sizeof buf, "%s: sample %zu of %zu (%s %.9g, %.9g, %.9g, %.9g): %s", what, k, n, at_name,
                at[0], at[1], at[2], at[3], pkm::status_name(s));
  m->error = buf;
  return to_c(s);
}

}  // namespace

pkm_status pkm_regressor(pkm_model* m, const double pose[4], const double velocity[4], const double acceleration[4],
                         const double wrench[4], double* Y, double F0[4]) {
  if (!m || !pose || !velocity || !acceleration || !Y) return PKM_ERR_INVALID_ARGUMENT;
  pkm::RegressorSample r;
  const Status s = pkm::regressor(m->plant.model(), vec4(pose), vec4(velocity), vec4(acceleration), vec4(wrench), r);
  if (s != Status::Ok) {
    m->error = std::string("pkm_regressor: ") + pkm::status_name(s);
    return to_c(s);
  }
  Eigen::Map<RowRegressor> Y_out(Y);
  Y_out = r.Y;
  if (F0) copy(r.F0, F0);
  return PKM_OK;
}

pkm_status pkm_regressor_poses(pkm_model* m, size_t n, const double* pose, const double* velocity,
                               const double* acceleration, double* Y, double* F0, double* rho, double* drho) {
  if (!m || (n > 0 && (!pose || !velocity || !acceleration || !Y))) return PKM_ERR_INVALID_ARGUMENT;
  pkm::RegressorSample r;
  for (size_t k = 0; k < n; ++k) {
    const Status s = pkm::regressor(m->plant.model(), vec4(pose + 4 * k), vec4(velocity + 4 * k),
                                    vec4(acceleration + 4 * k), pkm::Wrench::Zero(), r);
    if (s != Status::Ok) return regressor_failure(m, s, "pkm_regressor_poses", k, n, pose + 4 * k, "pose");
    Eigen::Map<RowRegressor>(Y + 4 * pkm::kParams * k, 4, pkm::kParams) = r.Y;
    if (F0) copy(r.F0, F0 + 4 * k);
    if (rho) copy(r.rho, rho + 4 * k);
    if (drho) copy(r.rhod, drho + 4 * k);
  }
  return PKM_OK;
}

pkm_status pkm_regressor_joints(pkm_model* m, size_t n, const double* rho, const double* drho, const double* ddrho,
                                const double guess[4], double* Y, double* F0, double* pose, size_t* done) {
  if (done) *done = 0;
  if (!m || (n > 0 && (!rho || !drho || !ddrho || !Y))) return PKM_ERR_INVALID_ARGUMENT;
  pkm::RegressorSample r;
  r.pose = guess ? vec4(guess) : pkm::Pose(0.0, 0.0, 0.05, 0.0);
  for (size_t k = 0; k < n; ++k) {
    const Status s =
        pkm::joint_regressor(m->plant.model(), vec4(rho + 4 * k), vec4(drho + 4 * k), vec4(ddrho + 4 * k),
                             pkm::Wrench::Zero(), r);
    if (s != Status::Ok) return regressor_failure(m, s, "pkm_regressor_joints", k, n, rho + 4 * k, "rho");
    Eigen::Map<RowRegressor>(Y + 4 * pkm::kParams * k, 4, pkm::kParams) = r.Y;
    if (F0) copy(r.F0, F0 + 4 * k);
    if (pose) copy(r.pose, pose + 4 * k);
    if (done) *done = k + 1;
  }
  return PKM_OK;
}

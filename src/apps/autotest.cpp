// SPDX-License-Identifier: BSD-2-Clause
#include "apps/autotest.hpp"

#include <algorithm>
#include <cmath>

namespace pkm {
namespace {

void path_forces(void* user, double t, Vec4& F, Wrench& we) {
  auto* pf = static_cast<PathForces*>(user);
  Pose p, pd, pdd;
  pf->path.eval(t, p, pd, pdd);
  we.setZero();
  // The reduced inverse dynamics: closed-form legs, no iteration.
  const Status s = inverse_dynamics(*pf->model, p, pd, pdd, we, pf->id);
  if (s != Status::Ok) {
    pf->status = s;
    F.setConstant(std::numeric_limits<double>::quiet_NaN());  // makes the step fail visibly
    return;
  }
  F = pf->id.F;
}

}  // namespace

InputSignal PathForces::signal() { return {&path_forces, this}; }

Status run_autotest(const Model& m, const AutotestOptions& opt, AutotestResult& out) {
  out = AutotestResult{};
  Plant plant(m);
  std::string why;
  Status s = plant.set_solver(opt.solver, &why);
  if (s != Status::Ok) {
    out.error = why;
    return s;
  }
  PathForces forces;
  forces.model = &m;
  forces.path = opt.path;
  const InputSignal input = forces.signal();

  Pose p, pd, pdd;
  opt.path.eval(0.0, p, pd, pdd);
  s = plant.initialize(0.0, p, pd);
  if (s != Status::Ok) {
    out.error = "initial pose: " + std::string(status_name(s));
    return s;
  }
  const double t_end = opt.path.duration;
  const long n = std::lround(t_end / opt.sample_dt);
  out.samples.reserve(static_cast<size_t>(n) + 1);
  MechanismState ms;
  for (long k = 0; k <= n; ++k) {
    const double t = (k == n) ? t_end : static_cast<double>(k) * opt.sample_dt;
    if (k > 0) {
      s = plant.advance(t, input, /*continuous=*/k > 1);
      if (s != Status::Ok || forces.status != Status::Ok) {
        const Status bad = forces.status != Status::Ok ? forces.status : s;
        out.error = std::string("forward dynamics stopped at t = ") + std::to_string(plant.time()) +
                    " s: " + status_name(bad) + (plant.last_error().empty() ? "" : " (" + plant.last_error() + ")");
        return bad;
      }
    }
    s = plant.mechanism(input, ms);
    if (s != Status::Ok) return s;
    AutotestSample smp;
    smp.t = t;
    opt.path.eval(t, smp.desired, pd, pdd);
    smp.simulated = plant.state().head<4>();
    smp.F = forces.id.F;
    InverseDynamicsResult at_rest;
    s = inverse_dynamics(m, smp.desired, Pose::Zero(), Pose::Zero(), Wrench::Zero(), at_rest);
    if (s != Status::Ok) return s;
    smp.F_static = at_rest.F;
    for (int i = 0; i < kLegs; ++i) smp.rho[i] = ms.q[leg_offset(i)];
    smp.constraint_residual = plant.constraint_residual();
    smp.jacobian_condition = plant.jacobian_condition();
    const Pose e = smp.simulated - smp.desired;
    out.max_position_error = std::max(out.max_position_error, e.head<3>().lpNorm<Eigen::Infinity>());
    out.max_angle_error = std::max(out.max_angle_error, std::fabs(e[3]));
    out.max_constraint_residual = std::max(out.max_constraint_residual, smp.constraint_residual);
    out.max_jacobian_condition = std::max(out.max_jacobian_condition, smp.jacobian_condition);
    out.max_dynamic_force = std::max(out.max_dynamic_force, (smp.F - smp.F_static).lpNorm<Eigen::Infinity>());
    out.samples.push_back(smp);
    if (opt.progress && (k % std::max(1L, n / 10) == 0 || k == n)) opt.progress(opt.progress_user, t, t_end);
  }
  out.rhs_evaluations = plant.rhs_evaluations();
  return Status::Ok;
}

}  // namespace pkm

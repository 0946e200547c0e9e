// SPDX-License-Identifier: BSD-2-Clause
// pkm_bench ticks: the core Plant's 1-ms steps per solver and kind of input, then the stiff cases per solver.
#include <cstdio>

#include "core/core_bench.hpp"
#include "pkm4puu/dynamics/inverse_dynamics.hpp"
#include "pkm4puu/sim/parameters.hpp"

namespace pkm::bench {
namespace {

constexpr long kTicks = 1000;  // 1 s

/// F[1]'s perturbation beyond the static forces, given per step as a master
/// gives it: ramp 0.2 t N (value and slope at each step start: continuous);
/// sampled 0.2 cos(2 pi 3 t) N (value and slope: lines that miss each other
/// by f'' h^2 / 2 at the step boundary); held (the same at the step's midpoint).
enum class Inputs { Ramp, Sampled, Held };
const char* const kInputNames[] = {"ramp", "sampled", "held"};

LinearInputs step_inputs(Inputs kind, long k, const Vec4& F_static) {
  constexpr double a = 0.2, w = 2.0 * 3.14159265358979323846 * 3.0;
  const double t = static_cast<double>(k) * kTick;
  LinearInputs in;
  in.t0 = t;
  in.F0 = F_static;
  in.dF.setZero();
  if (kind == Inputs::Ramp) in.F0[0] += a * t, in.dF[0] = a;
  if (kind == Inputs::Sampled) in.F0[0] += a * std::cos(w * t), in.dF[0] = -a * w * std::sin(w * t);
  if (kind == Inputs::Held) in.F0[0] += a * std::cos(w * (t + 0.5 * kTick));
  return in;
}

/// A tick's step for plant_steps: the inputs of `kind`, CVODE continued across the steps if `cont`.
auto tick_step(Inputs kind, bool cont, const Vec4& F_static) {
  return [=](Plant& plant, long k) {
    LinearInputs in = step_inputs(kind, k, F_static);
    return plant.advance(static_cast<double>(k + 1) * kTick, in.signal(), cont && k > 0);
  };
}

/// The stiff cases (their table's heading and legend say what is measured).
void stiff_cases(double rk4_tick_us) {
  const struct {
    const char* name;
    std::vector<std::pair<const char*, double>> set;  // parameters beyond the defaults
  } cases[] = {{"friction_viscous 1000", {{"friction_viscous", 1000}}},
               {"friction_coulomb 5", {{"friction_coulomb", 5}}},
               {"friction_coulomb 10, v_s 1e-6", {{"friction_coulomb", 10}, {"friction_velocity", 1e-6}}},
               {"stops 1e9/1e6", {{"stop_stiffness", 1e9}, {"stop_damping", 1e6}}},
               {"stops, m_slider 1e-2", {{"stop_stiffness", 1e9}, {"stop_damping", 1e6}, {"m_slider", 1e-2}}},
               {"stops, m_slider 1e-6", {{"stop_stiffness", 1e9}, {"stop_damping", 1e6}, {"m_slider", 1e-6}}}};
  auto run = [](const Model& m, Solver solver) {
    return timed_steps(m, settings(solver, 1e-10, 1e-12, CvodeMethod::BDF), 200, [](Plant& plant, long k) {
      return plant.advance(static_cast<double>(k + 1) * kTick, InputSignal{});
    });
  };
  std::printf("\nthe stiff cases: F = 0 from the home pose, 1 ms steps, 200 steps; CVODE BDF rtol 1e-10 is the "
              "reference\n(targets: ROS2 within 1 %% of CVODE, at most 3x an RK4 tick)\n");
  std::printf("%-30s %14s %14s %14s %10s %10s %10s %12s\n", "case", "CVODE us/ok", "RK4 us/ok", "ROS2 us/ok",
              "ROS2/RK4", "/RK4 tick", "ROS2/CVODE", "ROS2 |ddz|");
  for (const auto& c : cases) {
    Configuration config;
    for (const auto& [parameter, value] : c.set) find_parameter(parameter)->set(config, value);
    Model m;
    if (make_model(config.params, m) != Status::Ok) continue;
    const StepRun cv = run(m, Solver::Cvode), r4 = run(m, Solver::Rk4), rb = run(m, Solver::Rosenbrock);
    double dev = 0, scale = 0;
    for (long k = 1; k <= std::min(cv.ok_steps, rb.ok_steps); ++k) {
      dev = std::max(dev, std::fabs(rb.states[k][6] - cv.states[k][6]));
      scale = std::max(scale, std::fabs(cv.states[k][6]));
    }
    std::printf("%-30s", c.name);
    for (const StepRun* o : {&cv, &r4, &rb}) {
      char cell[32];
      std::snprintf(cell, sizeof cell, "%.2f/%ld", o->us, o->ok_steps);
      std::printf(" %14s", cell);
    }
    std::printf(" %10.2f %10.2f %10.2f %11.2g%%\n", r4.ok_steps ? rb.us / r4.us : 0.0, rb.us / rk4_tick_us,
                rb.us / cv.us, scale > 0 ? 100 * dev / scale : 0.0);
  }
  std::printf("us/ok: median microseconds per step (the failing step included) / steps answered OK; /RK4 tick: ROS2\n"
              "against the held-input RK4 tick above (%.3f us, the default machine); ROS2's deviation: over the steps\n"
              "CVODE answered.\n", rk4_tick_us);
}

}  // namespace

/// The ticks per input kind and solver, each against the same inputs integrated tightly (restarted at every
/// step: exact for inputs smooth within each step); then the stiff cases.
int ticks_part(bool parseable) {
  Model model;
  InverseDynamicsResult id;
  if (make_model(Params{}, model) != Status::Ok ||
      inverse_dynamics(model, kHome, Pose::Zero(), Pose::Zero(), Wrench::Zero(), id, false) != Status::Ok)
    return 1;
  const SolverSettings cvode = settings(Solver::Cvode), tight = settings(Solver::Cvode, 1e-12, 1e-14),
                       rk4 = settings(Solver::Rk4), ros2 = settings(Solver::Rosenbrock);
  const struct {
    const char* name;
    const SolverSettings& st;
    bool cont;
  } cases[] = {{"CVODE 1e-8, restart every step", cvode, false},
               {"CVODE 1e-8, continued across steps", cvode, true},
               {"RK4, rk4_step 1 ms", rk4, false},
               {"Rosenbrock (ROS2), 1 ms", ros2, false}};
  if (!parseable) {
    std::printf("pkm_bench ticks: 1-ms communication steps of the core's Plant, 1 s from the home pose\n"
                "inputs on F[1], beyond the static force: ramp 0.2 t N (value and slope per step); sampled 0.2 cos(2 pi "
                "3 t) N\n(value and slope per step); held: the same at the step's midpoint\n\n");
    std::printf("%-44s %9s %9s %9s %9s %12s\n", "run", "us/step", "rhs/step", "rhs max", "steps/step", "max|dxyz| m");
  }
  int failures = 0;
  double rk4_us = 0, restart_us = 0;
  for (const Inputs kind : {Inputs::Ramp, Inputs::Sampled, Inputs::Held}) {
    const StepRun ref =
        parseable ? StepRun{} : plant_steps(model, tight, kHome, Pose::Zero(), kTicks, tick_step(kind, false, id.F));
    for (const auto& c : cases) {
      const StepRun r = timed_steps(model, c.st, kTicks, tick_step(kind, c.cont, id.F));
      char name[64];
      std::snprintf(name, sizeof name, "%s: %s", kInputNames[static_cast<int>(kind)], c.name);
      if (r.status != Status::Ok) {
        std::printf(parseable ? "tick;%s;FAILED\n" : "%-44s FAILED\n", name);
        ++failures;
        continue;
      }
      const Vec8& last = r.states.back();
      if (parseable) {
        std::printf("tick;%s;%.6f;%.17g;%.17g;%.17g;%.17g\n", name, r.us, last[0], last[1], last[2], last[3]);
        continue;
      }
      double dev = 0;
      for (size_t k = 0; k < r.states.size() && k < ref.states.size(); ++k)
        dev = std::max(dev, (r.states[k].head<3>() - ref.states[k].head<3>()).lpNorm<Eigen::Infinity>());
      std::printf("%-44s %9.3f %9.2f %9ld %9.2f %12.2e", name, r.us, static_cast<double>(r.rhs) / kTicks, r.rhs_max,
                  static_cast<double>(r.cvode_steps) / kTicks, dev);
      if (&c.st == &cvode && !c.cont) restart_us = r.us;
      if (&c.st == &cvode && c.cont) std::printf("   %.1fx faster than restarting", restart_us / r.us);
      if (&c.st == &rk4) rk4_us = r.us;
      if (&c.st == &ros2) std::printf("   %.2fx RK4 (target <= 3x)", r.us / rk4_us);
      std::printf("\n");
    }
  }
  if (parseable) return failures ? 1 : 0;
  std::printf("\nreference: CVODE rtol 1e-12, restarted every step, the same inputs\n");
  stiff_cases(rk4_us);
  return failures ? 1 : 0;
}

}  // namespace pkm::bench

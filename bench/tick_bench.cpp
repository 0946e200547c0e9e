// pkm_tick_bench: the work of one 1-ms communication step of the core's
// Plant, CVODE restarted at every step against CVODE continued across the
// steps (issue 16 item 2), beside RK4. Prints a table; not a test.
//
// Scenario: the home pose, 1 s of 1-ms steps, F[1..4] at the static holding
// force (inverse dynamics at rest) plus a perturbation on F[1], given per
// step as a master gives it:
//   ramp:    0.2 t N, value and slope at each step start (continuous);
//   sampled: 0.2 cos(2 pi 3 t) N, value and slope at each step start
//            (fmi2SetRealInputDerivatives): the lines of two steps miss each
//            other by f'' h^2 / 2 at the step boundary, a small jump;
//   held:    0.2 cos(2 pi 3 t) N at the step's midpoint, constant over the step.
// Per run: derivative evaluations per step (mean and maximum), CVODE's
// internal steps per step, time per step (median of 15 runs), and the
// largest deviation of the pose (x, y, z) from the reference: the same
// inputs integrated with CVODE at rtol 1e-12, restarted at every step
// (exact for inputs that are smooth within each step).
//
// Built with ARKODE (PKM_TICK_BENCH_ARKODE, bench/CMakeLists.txt), a second
// table: ARKODE's explicit adaptive Runge-Kutta (ERKStep, one-step methods
// with no history to rebuild) on the same ODE as the Plant's CVODE (pose,
// velocity and the two energy integrals from pkm::state_derivative with the
// same forces; rtol and atol as CVODE's on every component; the end stops'
// indicators as roots, none is reached here), restarted at every step
// (ERKStepReInit: a fresh initial step estimate; ERKStepReset: keeps the last
// step size) or continued across the steps (ramp only), beside the time one
// derivative evaluation takes alone, so that the solver's own cost per step
// (the time not spent in the derivative) can be read off.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <vector>

#include "pkm4puu/dynamics/inverse_dynamics.hpp"
#include "pkm4puu/dynamics/lagrangian.hpp"
#include "pkm4puu/machine/passive_force.hpp"
#include "pkm4puu/dynamics/state_derivative.hpp"
#include "pkm4puu/sim/plant.hpp"

#if PKM_TICK_BENCH_ARKODE
#include <arkode/arkode_erkstep.h>
#include <nvector/nvector_serial.h>
#endif

namespace {

using Clock = std::chrono::steady_clock;
using pkm::Pose;
using pkm::Status;
using pkm::Vec4;

constexpr double kH = 1e-3;
constexpr int kSteps = 1000;
constexpr int kRuns = 15;
constexpr double kAmplitude = 0.2, kOmega = 2.0 * 3.14159265358979323846 * 3.0;

enum class Inputs { Ramp, Sampled, Held };

struct Result {
  double median_us = 0, rhs_mean = 0, cvode_steps_mean = 0, max_dev = 0;
  long rhs_max = 0, rhs_max_later = 0;  // the latter over the steps after the first
  bool ok = true;
};

/// The inputs of step k (header comment).
void step_inputs(Inputs kind, int k, const Vec4& F_static, pkm::LinearInputs& in) {
  const double t = k * kH;
  in.t0 = t;
  in.F0 = F_static;
  in.dF.setZero();
  if (kind == Inputs::Ramp) {
    in.F0[0] += kAmplitude * t;
    in.dF[0] = kAmplitude;
  } else if (kind == Inputs::Sampled) {
    in.F0[0] += kAmplitude * std::cos(kOmega * t);
    in.dF[0] = -kAmplitude * kOmega * std::sin(kOmega * t);
  } else {
    in.F0[0] += kAmplitude * std::cos(kOmega * (t + 0.5 * kH));
  }
}

std::vector<Pose> run_once(const pkm::Model& model, const pkm::SolverSettings& st, Inputs kind, bool cont,
                           const Vec4& F_static, Result* r, double* seconds) {
  std::vector<Pose> traj;
  traj.reserve(kSteps + 1);
  pkm::Plant plant(model);
  if (plant.set_solver(st) != Status::Ok || plant.initialize(0.0, Pose(0, 0, 0.05, 0), Pose::Zero()) != Status::Ok) {
    if (r) r->ok = false;
    return traj;
  }
  traj.push_back(plant.state().head<4>());
  pkm::LinearInputs in;
  long rhs_max = 0, rhs_max_later = 0;
  const auto t0 = Clock::now();
  for (int k = 0; k < kSteps; ++k) {
    const double t = k * kH;
    step_inputs(kind, k, F_static, in);
    const long before = plant.rhs_evaluations();
    if (plant.advance(t + kH, in.signal(), cont && k > 0) != Status::Ok) {
      if (r) r->ok = false;
      return traj;
    }
    rhs_max = std::max(rhs_max, plant.rhs_evaluations() - before);
    if (k > 0) rhs_max_later = std::max(rhs_max_later, plant.rhs_evaluations() - before);
    traj.push_back(plant.state().head<4>());
  }
  if (seconds) *seconds = std::chrono::duration<double>(Clock::now() - t0).count();
  if (r) {
    r->rhs_mean = static_cast<double>(plant.rhs_evaluations()) / kSteps;
    r->rhs_max = rhs_max;
    r->rhs_max_later = rhs_max_later;
    r->cvode_steps_mean = static_cast<double>(plant.cvode_steps()) / kSteps;
  }
  return traj;
}

/// kRuns runs of run(&result, &seconds) (one simulated second each): the
/// median time per step, and the largest deviation of the last run's
/// positions from the reference.
template <class Run>
Result measure_runs(Run run, const std::vector<Pose>& reference) {
  Result r;
  std::vector<double> times;
  std::vector<Pose> traj;
  for (int i = 0; i < kRuns && r.ok; ++i) {
    double s = 0;
    traj = run(&r, &s);
    times.push_back(s);
  }
  if (!r.ok) return r;
  std::sort(times.begin(), times.end());
  r.median_us = 1e6 * times[times.size() / 2] / kSteps;
  for (size_t k = 0; k < traj.size() && k < reference.size(); ++k)
    r.max_dev = std::max(r.max_dev, (traj[k] - reference[k]).head<3>().lpNorm<Eigen::Infinity>());
  return r;
}

Result measure(const pkm::Model& model, const pkm::SolverSettings& st, Inputs kind, bool cont, const Vec4& F_static,
               const std::vector<Pose>& reference) {
  return measure_runs([&](Result* r, double* s) { return run_once(model, st, kind, cont, F_static, r, s); },
                      reference);
}

#if PKM_TICK_BENCH_ARKODE

/// The Plant's ODE (Plant::machine_rates with no motor torque, no external
/// wrench and no end stop acting, as in these runs): pose and velocity from
/// the minimal-state derivative, then the actuators' power and the power
/// dissipated by friction.
bool machine_rates(const pkm::Model& model, const pkm::LinearInputs& in, double t, const double* x, double* xdot) {
  const Vec4 F = in.F0 + in.dF * (t - in.t0);
  const pkm::Vec8 y = Eigen::Map<const pkm::Vec8>(x);
  pkm::Vec8 ydot;
  pkm::JointMotion jm;
  constexpr unsigned kNoStops = 0u;
  if (pkm::state_derivative(model, pkm::Formulation::LegPartitioned, y, pkm::generalized_forces(F, pkm::Wrench::Zero()),
                            ydot, nullptr, &jm, kNoStops) != Status::Ok)
    return false;
  Eigen::Map<pkm::Vec8> out(xdot);
  out = ydot;
  xdot[8] = F.dot(jm.rhod);
  xdot[9] = 0.0;
  for (int i = 0; i < pkm::kLegs; ++i) xdot[9] += pkm::dissipated_power(model.p, i, kNoStops, jm.rho[i], jm.rhod[i]);
  return true;
}

struct ArkProblem {
  const pkm::Model* model = nullptr;
  pkm::LinearInputs in;
  long evals = 0;
};

int ark_rhs(double t, N_Vector y, N_Vector ydot, void* user) {
  auto* p = static_cast<ArkProblem*>(user);
  ++p->evals;
  // A trial state off the workspace: recoverable, as in Plant::cvode_rhs.
  return machine_rates(*p->model, p->in, t, N_VGetArrayPointer(y), N_VGetArrayPointer(ydot)) ? 0 : 1;
}

int ark_roots(double, N_Vector y, double* g, void* user) {  // as Plant::cvode_roots
  const auto* p = static_cast<const ArkProblem*>(user);
  if (pkm::stop_indicators(*p->model, Eigen::Map<const Pose>(N_VGetArrayPointer(y)), g) != Status::Ok)
    for (int k = 0; k < pkm::kStopIndicators; ++k) g[k] = 1.0;
  return 0;
}

enum class ArkMode { ReInit, Reset, Continue };

struct ArkTable {
  const char* name;
  ARKODE_ERKTableID id;
};

std::vector<Pose> run_arkode(const pkm::Model& model, const pkm::SolverSettings& st, ARKODE_ERKTableID table,
                             ArkMode mode, Inputs kind, const Vec4& F_static, Result* r, double* seconds,
                             long* roots) {
  std::vector<Pose> traj;
  traj.reserve(kSteps + 1);
  // The initial state as the Plant makes it; the energy integrals start at 0.
  pkm::Plant plant(model);
  if (plant.initialize(0.0, Pose(0, 0, 0.05, 0), Pose::Zero()) != Status::Ok) {
    if (r) r->ok = false;
    return traj;
  }
  SUNContext ctx = nullptr;
  if (SUNContext_Create(nullptr, &ctx) != 0) {
    if (r) r->ok = false;
    return traj;
  }
  N_Vector y = N_VNew_Serial(10, ctx);
  Eigen::Map<pkm::Vec10> yv(N_VGetArrayPointer(y));
  yv.setZero();
  yv.head<8>() = plant.state();
  traj.push_back(yv.head<4>());
  ArkProblem prob;
  prob.model = &model;
  void* mem = ERKStepCreate(&ark_rhs, 0.0, y, ctx);
  int flag = mem ? 0 : -1;
  if (mem) {
    flag |= ERKStepSetTableNum(mem, table);
    flag |= ERKStepSStolerances(mem, st.rtol, st.atol);  // CVODE's: atol on every component
    flag |= ERKStepSetUserData(mem, &prob);
    flag |= ERKStepSetMaxNumSteps(mem, 100000);  // CvodeIntegrator's limits
    flag |= ERKStepSetMinStep(mem, pkm::kMinStep);
    flag |= ERKStepRootInit(mem, pkm::kStopIndicators, &ark_roots);
  }
  long rhs_max = 0, rhs_max_later = 0, steps = 0;
  if (roots) *roots = 0;
  const auto t0 = Clock::now();
  for (int k = 0; k < kSteps && flag == 0; ++k) {
    const double t = k * kH;
    step_inputs(kind, k, F_static, prob.in);
    if (k > 0 && mode == ArkMode::ReInit) flag |= ERKStepReInit(mem, &ark_rhs, t, y);
    if (k > 0 && mode == ArkMode::Reset) flag |= ERKStepReset(mem, t, y);
    flag |= ERKStepSetStopTime(mem, t + kH);
    long steps_before = 0, steps_after = 0;
    ERKStepGetNumSteps(mem, &steps_before);
    const long before = prob.evals;
    double t_reached = t;
    while (flag == 0 && t_reached < t + kH) {
      const int f = ERKStepEvolve(mem, t + kH, y, &t_reached, ARK_NORMAL);
      if (f < 0) flag = f;
      if (f == ARK_ROOT_RETURN && roots) ++*roots;
    }
    ERKStepGetNumSteps(mem, &steps_after);
    steps += steps_after - steps_before;
    rhs_max = std::max(rhs_max, prob.evals - before);
    if (k > 0) rhs_max_later = std::max(rhs_max_later, prob.evals - before);
    traj.push_back(yv.head<4>());
  }
  if (seconds) *seconds = std::chrono::duration<double>(Clock::now() - t0).count();
  if (mem) ERKStepFree(&mem);
  N_VDestroy(y);
  SUNContext_Free(&ctx);
  if (r) {
    r->ok = r->ok && flag == 0;
    r->rhs_mean = static_cast<double>(prob.evals) / kSteps;
    r->rhs_max = rhs_max;
    r->rhs_max_later = rhs_max_later;
    r->cvode_steps_mean = static_cast<double>(steps) / kSteps;
  }
  return traj;
}

Result measure_arkode(const pkm::Model& model, const pkm::SolverSettings& st, ARKODE_ERKTableID table, ArkMode mode,
                      Inputs kind, const Vec4& F_static, const std::vector<Pose>& reference, long* roots) {
  return measure_runs(
      [&](Result* r, double* s) { return run_arkode(model, st, table, mode, kind, F_static, r, s, roots); },
      reference);
}

/// One derivative evaluation alone (machine_rates at the home pose), us:
/// the minimum over 5 runs of the mean of 20000 evaluations.
double derivative_us(const pkm::Model& model, const Vec4& F_static) {
  pkm::LinearInputs in;
  in.F0 = F_static;
  pkm::Vec10 x = pkm::Vec10::Zero(), xdot;
  x.head<4>() = Pose(0, 0, 0.05, 0);
  constexpr int kEvals = 20000;
  double best = 1e30;
  for (int run = 0; run < 5; ++run) {
    const auto t0 = Clock::now();
    for (int i = 0; i < kEvals; ++i) {
      x[4] = 1e-9 * i;  // a new state each time
      machine_rates(model, in, 0.0, x.data(), xdot.data());
    }
    best = std::min(best, std::chrono::duration<double>(Clock::now() - t0).count());
  }
  return 1e6 * best / kEvals;
}

#endif  // PKM_TICK_BENCH_ARKODE

}  // namespace

int main() {
  pkm::Model model;
  if (pkm::make_model(pkm::Params{}, model) != Status::Ok) return 1;
  pkm::InverseDynamicsResult id;
  if (pkm::inverse_dynamics(model, Pose(0, 0, 0.05, 0), Pose::Zero(), Pose::Zero(), pkm::Wrench::Zero(), id,
                            false) != Status::Ok)
    return 1;
  const Vec4 F_static = id.F;

  pkm::SolverSettings cvode;  // defaults: Adams, rtol 1e-8, atol 1e-10
  pkm::SolverSettings tight = cvode;
  tight.rtol = 1e-12;
  tight.atol = 1e-14;
  pkm::SolverSettings rk4;
  rk4.solver = pkm::Solver::Rk4;
  rk4.rk4_step = kH;

  std::printf("pkm_tick_bench: 1-ms communication steps of the core's Plant, 1 s from the home pose\n");
  std::printf("inputs on F[1], beyond the static force: ramp %.1f t N (value and slope per step); sampled %.1f cos(2 pi "
              "3 t) N\n(value and slope per step); held: the same at the step's midpoint\n\n",
              kAmplitude, kAmplitude);
  std::printf("%-44s %9s %9s %9s %9s %12s\n", "run", "us/step", "rhs/step", "rhs max", "steps/step",
              "max|dxyz| m");
  int failures = 0;
  const Inputs kinds[] = {Inputs::Ramp, Inputs::Sampled, Inputs::Held};
  const char* knames[] = {"ramp", "sampled", "held"};
  std::vector<Pose> references[3];
  Result cvode_restarted[3];
  for (int ki = 0; ki < 3; ++ki) {
    const Inputs kind = kinds[ki];
    const char* kname = knames[ki];
    references[ki] = run_once(model, tight, kind, false, F_static, nullptr, nullptr);
    const std::vector<Pose>& reference = references[ki];
    struct Case {
      const char* name;
      const pkm::SolverSettings* st;
      bool cont;
    } cases[] = {{"CVODE 1e-8, restart every step", &cvode, false},
                 {"CVODE 1e-8, continued across steps", &cvode, true},
                 {"RK4, rk4_step 1 ms", &rk4, false}};
    double restart_us = 0;
    for (const Case& c : cases) {
      const Result r = measure(model, *c.st, kind, c.cont, F_static, reference);
      char name[64];
      std::snprintf(name, sizeof name, "%s: %s", kname, c.name);
      if (!r.ok) {
        std::printf("%-44s FAILED\n", name);
        ++failures;
        continue;
      }
      if (c.st == &cvode && !c.cont) {
        restart_us = r.median_us;
        cvode_restarted[ki] = r;
      }
      std::printf("%-44s %9.3f %9.2f %9ld %9.2f %12.2e", name, r.median_us, r.rhs_mean, r.rhs_max,
                  r.cvode_steps_mean, r.max_dev);
      if (c.st == &cvode && c.cont) std::printf("   %.1fx faster than restarting", restart_us / r.median_us);
      std::printf("\n");
    }
  }
  std::printf("\nreference: CVODE rtol 1e-12, restarted every step, the same inputs. Continuing across the jumps of\n"
              "sampled or held inputs costs accuracy: the FMU continues only where the inputs continue (pkm4puu.cpp).\n");
#if PKM_TICK_BENCH_ARKODE
  const double eval_us = derivative_us(model, F_static);
  std::printf("\nARKODE %s ERKStep on the same ODE (pose, velocity, energy integrals), rtol %.0e, atol %.0e on every\n"
              "component, the stop indicators as roots. One derivative evaluation alone: %.3f us; 'other us' is\n"
              "us/step - rhs/step x that (the solver's own work, and the Plant's for CVODE).\n\n",
              SUNDIALS_VERSION, cvode.rtol, cvode.atol, eval_us);
  std::printf("%-56s %8s %8s %8s %8s %10s %12s %9s %9s\n", "run", "us/step", "rhs/step", "rhs max", "max k>0",
              "steps/step", "max|dxyz| m", "vs CVODE", "other us");
  const ArkTable tables[] = {{"ERK order 4 (Zonneveld 5-3-4, default)", ARKODE_ZONNEVELD_5_3_4},
                             {"ERK Dormand-Prince 7-4-5", ARKODE_DORMAND_PRINCE_7_4_5},
                             {"ERK Verner 8-5-6", ARKODE_VERNER_8_5_6}};
  long roots_total = 0;
  for (int ki = 0; ki < 3; ++ki) {
    const Result& cv = cvode_restarted[ki];
    if (!cv.ok || cv.median_us <= 0) continue;
    char name[96];
    std::snprintf(name, sizeof name, "%s: CVODE 1e-8, restart every step", knames[ki]);
    std::printf("%-56s %8.3f %8.2f %8ld %8ld %10.2f %12.2e %8.2fx %9.2f\n", name, cv.median_us, cv.rhs_mean,
                cv.rhs_max, cv.rhs_max_later, cv.cvode_steps_mean, cv.max_dev, 1.0, cv.median_us - cv.rhs_mean * eval_us);
    for (const ArkTable& tb : tables) {
      for (ArkMode mode : {ArkMode::ReInit, ArkMode::Reset, ArkMode::Continue}) {
        if (mode == ArkMode::Continue && kinds[ki] != Inputs::Ramp) continue;  // jumps: a restart is needed
        const char* mname = mode == ArkMode::ReInit ? "ReInit" : mode == ArkMode::Reset ? "Reset" : "continued";
        long roots = 0;
        const Result r = measure_arkode(model, cvode, tb.id, mode, kinds[ki], F_static, references[ki], &roots);
        roots_total += roots;
        std::snprintf(name, sizeof name, "%s: %s, %s", knames[ki], tb.name, mname);
        if (!r.ok) {
          std::printf("%-56s FAILED\n", name);
          ++failures;
          continue;
        }
        std::printf("%-56s %8.3f %8.2f %8ld %8ld %10.2f %12.2e %8.2fx %9.2f\n", name, r.median_us, r.rhs_mean,
                    r.rhs_max, r.rhs_max_later, r.cvode_steps_mean, r.max_dev, r.median_us / cv.median_us, r.median_us - r.rhs_mean * eval_us);
      }
    }
  }
  std::printf("\n'vs CVODE': time per step over CVODE's restarted at every step, the same inputs. ReInit and Reset:\n"
              "ERKStepReInit / ERKStepReset at every step (ReInit estimates the first step afresh; Reset keeps the last\n"
              "step size); continued: neither. Roots found: %ld (no stop is reached in these runs).\n",
              roots_total);
#else
  std::printf("\n(built without ARKODE: libsundials_arkode.a was not found at configure time)\n");
#endif
  return failures ? 1 : 0;
}

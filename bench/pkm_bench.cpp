// SPDX-License-Identifier: BSD-2-Clause
// pkm_bench [core|ticks] [--quick] [--parseable]: the core's timing figures as
// tables, each with its ratios to a baseline measured in the same run (never a
// pass/fail exit code). core: the state derivative, its analytic derivatives,
// the regressor, the inverse dynamics, the 2-s auto-test; ticks: 1-ms steps of
// the Plant per solver and input, then the stiff cases. --quick: short batches
// (the documentation build's run); --parseable (ticks): one line a run,
// tick;<run>;<us/step>;<x>;<y>;<z>;<phi>, the pose after 1 s (tests/platform_ticks.py).
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include <sundials/sundials_config.h>

#include "apps/autotest.hpp"
#include "apps/trajectory.hpp"
#include "pkm4puu/dynamics/inverse_dynamics.hpp"
#include "pkm4puu/dynamics/inverse_dynamics_derivatives.hpp"
#include "pkm4puu/dynamics/lagrangian.hpp"
#include "pkm4puu/dynamics/reduced_dynamics_derivatives.hpp"
#include "pkm4puu/dynamics/regressor.hpp"
#include "pkm4puu/dynamics/state_derivative.hpp"
#include "pkm4puu/kinematics/servo_kinematics.hpp"
#include "pkm4puu/sim/parameters.hpp"
#include "pkm4puu/sim/plant.hpp"
#include "timer.h"

namespace pkm {
namespace {

volatile double g_sink = 0;  // results go here so that no call is optimised away

/// How long each figure is measured: the defaults, or --quick.
struct Effort {
  int batches = 31;                 // batches per per-call figure
  double batch_s = 4e-3;            // a per-call batch lasts at least this
  int max_runs = 31, min_runs = 5;  // whole runs: at most, at least, and the wall-time budget
  double runs_budget_s = 6.0;
  int tick_runs = 15;  // runs of a simulated second per tick row
} effort;

struct Figure {
  double median = NAN, min = NAN;  // s per call (per run)
  int batches = 0;
};

Figure summarise(std::vector<double> v) {
  Figure f;
  if (!v.empty()) f.median = bench_median(v.data(), v.size(), &f.min), f.batches = static_cast<int>(v.size());
  return f;
}

/// Per-call time of body(): N calls per batch, N grown until a batch lasts effort.batch_s.
template <class Body>
Figure time_per_call(Body&& body) {
  long n = 1;
  for (double dt = 0; n < (1L << 26); n = std::lround(n * std::clamp(1.2 * effort.batch_s / dt, 2.0, 10.0))) {
    const double t0 = bench_now();
    for (long k = 0; k < n; ++k) body();
    if ((dt = bench_now() - t0) >= effort.batch_s) break;
  }
  std::vector<double> per_call;
  for (int b = 0; b < effort.batches; ++b) {
    const double t0 = bench_now();
    for (long k = 0; k < n; ++k) body();
    per_call.push_back((bench_now() - t0) / static_cast<double>(n));
  }
  return summarise(per_call);
}

/// Whole runs: run() returns the seconds it measured itself (set-up kept
/// outside), < 0 on failure; one warm-up, then min..max runs within the budget.
template <class Run>
Figure time_runs(Run&& run, int min_runs = effort.min_runs, int max_runs = effort.max_runs) {
  std::vector<double> v;
  const double start = bench_now();
  run();
  for (int r = 0; r < max_runs; ++r) {
    const double s = run();
    if (!(s >= 0)) break;
    v.push_back(s);
    if (r + 1 >= min_runs && bench_now() - start > effort.runs_budget_s) break;
  }
  return summarise(v);
}

std::string fmt_time(double s) {  // "123 ns", "1.234 us", "1.234 ms", "1.234 s"
  char buf[32];
  if (!std::isfinite(s)) return "n/a";
  if (s < 1e-6) std::snprintf(buf, sizeof buf, "%.0f ns", s * 1e9);
  else if (s < 1e-3) std::snprintf(buf, sizeof buf, "%.3f us", s * 1e6);
  else if (s < 1.0) std::snprintf(buf, sizeof buf, "%.3f ms", s * 1e3);
  else std::snprintf(buf, sizeof buf, "%.3f s", s);
  return buf;
}

const char* ok_mark(double value, double target) { return value <= target ? "ok" : "OVER"; }
void rule() { std::printf("%s\n", std::string(96, '-').c_str()); }

constexpr double kTick = 1e-3;  // s, the communication step of sections 3 and the ticks
const Pose kHome(0, 0, 0.05, 0);

/// Solver settings: CVODE's defaults (Adams) but these, RK4 and ROS2 at the 1-ms step.
SolverSettings settings(Solver solver, double rtol = 1e-8, double atol = 1e-10,
                        CvodeMethod method = CvodeMethod::Adams) {
  SolverSettings st;
  st.solver = solver, st.rk4_step = kTick, st.rtol = rtol, st.atol = atol, st.cvode_method = method;
  return st;
}

struct StepRun {
  double seconds = 0;  // the steps' wall time, up to the first failing step included
  Status status = Status::Ok;
  long ok_steps = 0, rhs = 0, rhs_max = 0, cvode_steps = 0;  // rhs_max: the most in one step
  std::vector<Vec8> states;                                  // pose and rates after each step, the initial first
};

/// n steps of the Plant from (p0, pd0) at rest, set up outside the timing:
/// step(plant, k) advances it to step k's end. The one loop of the 1-ms
/// steps (section 3 and the ticks).
template <class Step>
StepRun plant_steps(const Model& m, const SolverSettings& st, const Pose& p0, const Pose& pd0, long n, Step&& step) {
  StepRun r;
  Plant plant(m);
  r.status = plant.set_solver(st);
  if (r.status == Status::Ok) r.status = plant.initialize(0.0, p0, pd0);
  if (r.status != Status::Ok) return r;
  r.states.reserve(static_cast<size_t>(n) + 1);
  r.states.push_back(plant.state().head<8>());
  const double t0 = bench_now();
  for (; r.ok_steps < n; ++r.ok_steps) {
    const long before = plant.rhs_evaluations();
    if ((r.status = step(plant, r.ok_steps)) != Status::Ok) break;
    r.rhs_max = std::max(r.rhs_max, plant.rhs_evaluations() - before);
    r.states.push_back(plant.state().head<8>());
  }
  r.seconds = bench_now() - t0;
  r.rhs = plant.rhs_evaluations();
  r.cvode_steps = plant.cvode_steps();
  return r;
}

const std::pair<Formulation, const char*> kFormulations[] = {
    {Formulation::LegPartitioned, "LegPartitioned"}, {Formulation::NullSpaceQR, "NullSpaceQR"},
    {Formulation::Augmented, "Augmented"}};
constexpr double kDerivativeTarget = 0.25e-6;                  // s, one LegPartitioned state derivative
constexpr double kInverseTarget = 1.0, kInverseStretch = 0.5;  // x one state derivative

/// Forces tabulated at t_j = j dt, looked up by index round(t / dt).
struct ForceTable {
  double dt = 0.5 * kTick;
  std::vector<Vec4> F;
  long misses = 0;  // lookups off the grid (a stage time off the grid)
  InputSignal signal() { return {&ForceTable::eval, this}; }
  static void eval(void* user, double t, Vec4& F, Wrench& we) {
    auto* tb = static_cast<ForceTable*>(user);
    const long j = std::lround(t / tb->dt);
    if (std::fabs(t / tb->dt - static_cast<double>(j)) > 1e-6) ++tb->misses;
    F = tb->F[static_cast<size_t>(std::clamp(j, 0L, static_cast<long>(tb->F.size()) - 1))];
    we.setZero();
  }
};

/// What the core sections measure on: the model, the auto-test path, the
/// state at t = 1 s, the stage-time grid t_j = j h/2 with its forces, the
/// solvers; and the failure count.
struct Core {
  Model model;
  RestToRest path;
  long n_out = 0, n_grid = 0;  // 2000 one-ms steps; 4001 grid points
  int failures = 0;
  Pose p, pd, pdd, p0, pd0, pdd0;  // the path at t = 1 s and at 0
  InverseDynamicsResult id_mid;
  Vec8 y_mid;
  Vec16 f_mid;
  std::vector<Pose> gp, gpd, gpdd;
  ForceTable table;
  LinearInputs held;  // the static forces at P0, held
  SolverSettings rk4 = settings(Solver::Rk4), cv_tight = settings(Solver::Cvode, 1e-12, 1e-14),
                 cv_default = settings(Solver::Cvode);

  void check(Status s, const char* what) {
    if (s == Status::Ok) return;
    std::printf("  !! %s failed: %s\n", what, status_name(s));
    ++failures;
  }
  // The inverse dynamics at grid point j: reduced, for the actuators, general.
  Status inverse_at(size_t j, InverseDynamicsResult& r, bool warm) const {
    return inverse_dynamics(model, gp[j], gpd[j], gpdd[j], Wrench::Zero(), r, warm);
  }
  Status actuators_at(size_t j, InverseActuators& a) const {
    return inverse_actuators(model, gp[j], gpd[j], gpdd[j], Wrench::Zero(), a);
  }
  Status general_at(size_t j, InverseDynamicsResult& r, bool warm) const {
    return inverse_dynamics_general(model, gp[j], gpd[j], gpdd[j], Wrench::Zero(), r, warm);
  }
};

bool set_up(Core& b) {
  std::string why;
  if (make_model(Params{}, b.model, &why) != Status::Ok) {
    std::fprintf(stderr, "pkm_bench: make_model failed: %s\n", why.c_str());
    return false;
  }
  b.n_out = std::lround(b.path.duration / kTick);
  b.n_grid = 2 * b.n_out + 1;
  b.path.eval(1.0, b.p, b.pd, b.pdd);
  b.path.eval(0.0, b.p0, b.pd0, b.pdd0);
  InverseDynamicsResult r;
  if (inverse_dynamics(b.model, b.p, b.pd, b.pdd, Wrench::Zero(), b.id_mid, false) != Status::Ok ||
      inverse_dynamics(b.model, b.p0, Pose::Zero(), Pose::Zero(), Wrench::Zero(), r, false) != Status::Ok) {
    std::fprintf(stderr, "pkm_bench: inverse dynamics failed on the path\n");
    return false;
  }
  b.held.F0 = r.F;
  b.y_mid << b.p, b.pd;
  b.f_mid = generalized_forces(b.id_mid.F, Wrench::Zero());
  for (long j = 0; j < b.n_grid; ++j) {
    Pose q, qd, qdd;
    b.path.eval(static_cast<double>(j) * b.table.dt, q, qd, qdd);
    b.gp.push_back(q), b.gpd.push_back(qd), b.gpdd.push_back(qdd);
    if (b.inverse_at(j, r, j > 0) != Status::Ok) return false;  // forces on the grid, warm-started as PathForces
    b.table.F.push_back(r.F);
  }
  return true;
}

void print_header() {
#ifdef NDEBUG
  const char* asserts = "NDEBUG";
#else
  const char* asserts = "asserts ON";
#endif
  rule();
  std::printf("pkm_bench  ");
  bench_print_machine();
  std::printf("           build: %s (%s), %s, Eigen %d.%d.%d, SUNDIALS %s\n",
              *PKM_BENCH_BUILD_TYPE ? PKM_BENCH_BUILD_TYPE : "none", asserts, PKM_BENCH_COMPILER, EIGEN_WORLD_VERSION,
              EIGEN_MAJOR_VERSION, EIGEN_MINOR_VERSION, SUNDIALS_VERSION);
  std::printf("           timing: median and min over %d batches of N calls (N: a batch >= %g ms)%s\n", effort.batches,
              1e3 * effort.batch_s, effort.batches < 31 ? " (--quick)" : "");
  rule();
}

/// Per-call time of body(acc) (returns a Status, adds a result to acc); a
/// failed call is reported under `what`.
template <class Body>
Figure time_checked(Core& b, const char* what, Body&& body) {
  double acc = 0;
  Status bad = Status::Ok;
  const Figure f = time_per_call([&] {
    const Status s = body(acc);
    if (s != Status::Ok) bad = s;
  });
  g_sink = acc;
  b.check(bad, what);
  return f;
}

/// time_checked of one expression: `call` gives a Status, `result` a number kept from it.
#define PKM_TIMED(b, what, call, result) \
  time_checked(b, what, [&](double& acc) { const Status s_ = (call); acc += (result); return s_; })

/// v = base with its first entry moved by 1e-12 * (k % 1024): each call sees a new state.
template <class V>
const V& nudge(V& v, const V& base, long k) {
  v[0] = base[0] + 1e-12 * static_cast<double>(k & 1023);
  return v;
}

/// A row of the per-call tables: median, min, the ratio to a baseline, a note.
void line(const char* name, const Figure& f, double baseline, const std::string& note = "") {
  std::printf("   %-48s %12s %12s %9.2fx  %s\n", name, fmt_time(f.median).c_str(), fmt_time(f.min).c_str(),
              f.median / baseline, note.c_str());
}
void heading(const char* title, const char* ratio) {
  std::printf("%s\n   %-48s %12s %12s %10s  target / note\n", title, "evaluation", "median/call", "min/call", ratio);
}
std::string target_mark(double value, double target, const char* unit = "x") {
  char s[48];
  std::snprintf(s, sizeof s, "<= %g%s  %s", target, unit, ok_mark(value, target));
  return s;
}

/// 1: one state derivative per formulation at t = 1 s of the path.
Figure state_derivative_section(Core& b) {
  Figure legp;
  heading("1. Forward dynamics: one pkm::state_derivative at t = 1.000 s of the auto-test path\n"
          "   (y = path pose and velocity, f = inverse-dynamics forces there; y[0] += 1e-12*(k%1024) per call)",
          "vs LegP");
  for (const auto& [formulation, name] : kFormulations) {
    Vec8 yk = b.y_mid, ydot;
    long k = 0;
    const Figure f = PKM_TIMED(b, name, state_derivative(b.model, formulation, nudge(yk, b.y_mid, k++), b.f_mid, ydot),
                               ydot[4] + ydot[7]);
    const bool first = formulation == Formulation::LegPartitioned;
    if (first) legp = f;
    char err[48] = "";  // |pdd - prescribed| at the unperturbed state (sanity)
    if (state_derivative(b.model, formulation, b.y_mid, b.f_mid, ydot) == Status::Ok)
      std::snprintf(err, sizeof err, "|pdd-path| %.2e", (ydot.tail<4>() - b.pdd).lpNorm<Eigen::Infinity>());
    line(name, f, legp.median,
         (first ? target_mark(f.median * 1e6, kDerivativeTarget * 1e6, " us") + "; " : std::string()) + err);
  }
  rule();
  return legp;
}

/// 1b and 1c: the analytic derivatives and the regressor, each beside what
/// it differentiates or stands for, that baseline measured right beside it.
void derivatives_section(Core& b) {
  Vec8 yk = b.y_mid, ydot;
  Pose pk = b.p;
  Mat8 A;
  Mat8x12 B;
  InverseDynamicsPartials d;
  InverseDynamicsResult r;
  RegressorSample rs;
  long k = 0;
  auto id = [&] {
    return PKM_TIMED(b, "inverse_dynamics",
                     inverse_dynamics(b.model, nudge(pk, b.p, k++), b.pd, b.pdd, Wrench::Zero(), r, false), r.F[0]);
  };
  const Figure jac = PKM_TIMED(b, "state_derivative_jacobians",
                               state_derivative_jacobians(b.model, nudge(yk, b.y_mid, k++), b.id_mid.F, Vec4::Zero(),
                                                          Wrench::Zero(), kStopsFromState, ydot, A, B),
                               A(4, 0) + B(7, 3));
  const Figure sd1 = PKM_TIMED(
      b, "state_derivative",
      state_derivative(b.model, Formulation::LegPartitioned, nudge(yk, b.y_mid, k++), b.f_mid, ydot), ydot[4]);
  const Figure idd = PKM_TIMED(
      b, "inverse_dynamics_derivatives",
      inverse_dynamics_derivatives(b.model, nudge(pk, b.p, k++), b.pd, b.pdd, Wrench::Zero(), d), d.dp(0, 0));
  const Figure id1 = id();
  const Figure reg = PKM_TIMED(b, "regressor", regressor(b.model, nudge(pk, b.p, k++), b.pd, b.pdd, Wrench::Zero(), rs),
                               rs.Y(0, 0));
  const Figure id2 = id();
  Vec4 rho, rhod, rhodd;  // the sliders' motion, from the same inverse dynamics
  b.check(inverse_dynamics(b.model, b.p, b.pd, b.pdd, Wrench::Zero(), r, false), "inverse_dynamics");
  for (int i = 0; i < kLegs; ++i)
    rho[i] = r.q[leg_offset(i)], rhod[i] = r.qd[leg_offset(i)], rhodd[i] = r.qdd[leg_offset(i)];
  Vec4 rk = rho;
  const Figure joints = PKM_TIMED(b, "joint_regressor",  // from the previous sample's pose, 1e-12 m away
                                  (rs.pose = b.p, joint_regressor(b.model, nudge(rk, rho, k++), rhod, rhodd,
                                                                  Wrench::Zero(), rs)),
                                  rs.Y(0, 0));
  heading("1b. Analytic derivatives at the same state (reduced_dynamics_derivatives.hpp)", "ratio");
  line("state_derivative (LegPartitioned, baseline)", sd1, sd1.median);
  line("state_derivative_jacobians: ydot, A 8x8, B 8x12", jac, sd1.median, target_mark(jac.median / sd1.median, 3.0));
  std::printf("   %-48s %12s %12s %9.2fx\n", "  (central differences: 24 state derivatives)", "", "", 24.0);
  line("inverse_dynamics (cold, baseline)", id1, id1.median);
  line("inverse_dynamics_derivatives: F, dF 4x16", idd, id1.median);
  rule();
  heading("1c. Calibration regressor at the same motion (regressor.hpp)", "ratio");
  line("inverse_dynamics (cold, baseline)", id2, id2.median);
  line("regressor: Y 4x14, F0 from the platform motion", reg, id2.median, target_mark(reg.median / id2.median, 2.0));
  line("joint_regressor: from rho, drho, ddrho", joints, id2.median);
  rule();
}

/// 2: the reduced inverse dynamics (closed-form legs, no iteration) along
/// the stage-time grid against one state derivative, and the general path
/// (Newton on the servo constraints, Eqs. 10-11 in full).
Figure inverse_dynamics_section(Core& b, const Figure& sd) {
  InverseDynamicsResult r;
  InverseActuators a;
  long j = 0, c = 0, dir = 1;
  auto next = [&] { return j = (j + 1) % b.n_grid; };
  const Figure reduced = PKM_TIMED(b, "inverse_dynamics", b.inverse_at(next(), r, false), r.F[0]);
  const Figure actuators = PKM_TIMED(b, "inverse_actuators", b.actuators_at(next(), a), a.F[0]);
  // The RK4 round trip's stage times as PathForces sees them: t_k, t_k + h/2
  // twice, t_k + h, then t_k + h again as the next step's first.
  auto stage = [&] {  // warm-started from the call before, but the first of a pass
    const long m = c++ % (4 * b.n_out);
    return b.inverse_at(2 * (m / 4) + (m % 4 == 0 ? 0 : m % 4 == 3 ? 2 : 1), r, m != 0);
  };
  const Figure stages = PKM_TIMED(b, "inverse_dynamics (stage sequence)", stage(), r.F[0]);
  const Figure cold = PKM_TIMED(b, "inverse_dynamics_general (cold)", b.general_at(next(), r, false), r.F[0]);
  j = 0;  // back and forth along the grid: each warm start is the neighbour 0.5 ms away
  b.check(b.general_at(0, r, false), "inverse_dynamics_general");
  auto step = [&] { return j += (j + dir < 0 || j + dir >= b.n_grid) ? (dir = -dir) : dir; };
  const Figure warm = PKM_TIMED(b, "inverse_dynamics_general (warm)", b.general_at(step(), r, true), r.F[0]);
  const size_t mid = static_cast<size_t>(b.n_out);
  auto newton = [&](size_t from) {  // solve_position's iterations at t = 1 s, from grid point from's solution
    Vec16 q;
    NewtonReport rep;
    const bool ok = closed_form_position(b.model, b.gp[from], q) == Status::Ok &&
                    (from == mid || solve_position(b.model, b.gp[from], q) == Status::Ok) &&
                    solve_position(b.model, b.gp[mid], q, {}, &rep) == Status::Ok;
    return std::to_string(ok ? rep.iterations : -1);
  };
  const double ratio = reduced.min / sd.min;  // the minimums: what load on the machine disturbs least
  heading("2. Inverse dynamics: one call per point of the stage-time grid (t = j*0.5 ms, 4001 points)", "vs sd(LegP)");
  line("inverse_dynamics (reduced: q, qd, qdd, F, lambda)", reduced, sd.median);
  line("inverse_actuators (reduced: F, tau, rho, rhod)", actuators, sd.median);
  line("inverse_dynamics, RK4 stage sequence [**]", stages, sd.median, "~ 1 + ID[**] / sd: see 3.");
  line("inverse_dynamics_general, cold (closed form)", cold, sd.median, "Newton it " + newton(mid));
  line("inverse_dynamics_general, warm (0.5 ms away)", warm, sd.median, "Newton it " + newton(mid - 1));
  std::printf("   target: inverse_dynamics / sd(LegP), mins = %.2fx <= %gx: %s (stretch <= %gx: %s); "
              "general cold / reduced = %.1fx\n",
              ratio, kInverseTarget, ok_mark(ratio, kInverseTarget), kInverseStretch, ok_mark(ratio, kInverseStretch),
              cold.median / reduced.median);
  std::printf("   (Newton it = iterations of solve_position at t = 1 s, residual tolerance 1e-14)\n"
              "   [**] t_k, t_k+h/2, t_k+h/2, t_k+h, t_k+h, ... as PathForces sees them in the RK4 round trip.\n");
  rule();
  return stages;
}

struct RunInfo {
  Figure fig;
  long rhs = 0;
  double err = NAN;  // max |x, y, z - reference| over the 1-ms samples, m
  std::string note;
};

/// Plant::advance over the 2 s in 1-ms calls driven by `input` (`at_rest`:
/// the error against P0 instead of the path); `input_status`: the input's
/// own failure (PathForces).
RunInfo plant_run(Core& b, const SolverSettings& st, InputSignal input, bool continuous, bool at_rest,
                  const Status* input_status = nullptr) {
  RunInfo info;
  StepRun last;
  info.fig = time_runs([&] {
    last = plant_steps(b.model, st, b.p0, b.pd0, b.n_out, [&](Plant& plant, long k) {
      const Status s = plant.advance(static_cast<double>(k + 1) * kTick, input, continuous && k > 0);
      return s == Status::Ok && input_status ? *input_status : s;
    });
    return last.status == Status::Ok ? last.seconds : -1.0;
  });
  info.rhs = last.rhs;
  if (last.status != Status::Ok) {
    info.note = std::string("FAILED: ") + status_name(last.status);
    ++b.failures;
    return info;
  }
  info.err = 0;
  for (long k = 0; k <= b.n_out; ++k) {
    Pose q = b.p0, qd, qdd;
    if (!at_rest) b.path.eval(static_cast<double>(k) * kTick, q, qd, qdd);
    const Vec8& x = last.states[static_cast<size_t>(k)];
    info.err = std::max(info.err, (x.head<3>() - q.head<3>()).lpNorm<Eigen::Infinity>());
  }
  return info;
}

/// The round trip: pkm::run_autotest as a whole (with its 2001 samples).
RunInfo autotest_run(Core& b, const SolverSettings& st) {
  RunInfo info;
  AutotestResult res;
  Status bad = Status::Ok;
  info.fig = time_runs([&]() -> double {
    AutotestOptions opt;
    opt.solver = st;
    opt.path = b.path;
    const double t0 = bench_now();
    if ((bad = run_autotest(b.model, opt, res)) != Status::Ok) return -1;
    return bench_now() - t0;
  });
  info.rhs = res.rhs_evaluations;
  info.err = res.max_position_error;
  if (bad != Status::Ok) {
    info.note = std::string("FAILED: ") + status_name(bad) + " " + res.error;
    ++b.failures;
  }
  return info;
}

/// 3: the 2-s auto-test with each solver: forward only (RK4: the forces
/// tabulated; CVODE: the static forces held), the round trip bare
/// (PathForces) and run_autotest as a whole; and the ratios among them.
void autotest_section(Core& b, const Figure& sd, const Figure& stages) {
  auto round_trip = [&](const SolverSettings& st) {
    PathForces forces;
    forces.model = &b.model;
    forces.path = b.path;
    return plant_run(b, st, forces.signal(), true, false, &forces.status);
  };
  const struct {
    const char* name;
    RunInfo r;
    const char* note;
  } rows[] = {{"RK4 1 ms  (a) forward only [table]", plant_run(b, b.rk4, b.table.signal(), false, false), ""},
              {"RK4 1 ms  (b) round trip, bare [*]", round_trip(b.rk4), ""},
              {"RK4 1 ms  (b) round trip, run_autotest", autotest_run(b, b.rk4), ""},
              {"CVODE 1e-12/1e-14 (a') forward, held F", plant_run(b, b.cv_tight, b.held.signal(), true, true),
               "held static F; error vs P0"},
              {"CVODE 1e-12/1e-14 (b) round trip, bare", round_trip(b.cv_tight), ""},
              {"CVODE 1e-12/1e-14 (b) run_autotest", autotest_run(b, b.cv_tight), ""},
              {"CVODE 1e-8/1e-10 (a') forward, held F", plant_run(b, b.cv_default, b.held.signal(), true, true),
               "held static F; error vs P0"},
              {"CVODE 1e-8/1e-10 (b) round trip, bare", round_trip(b.cv_default), ""},
              {"CVODE 1e-8/1e-10 (b) run_autotest", autotest_run(b, b.cv_default), ""}};
  if (b.table.misses != 0) b.check(Status::InvalidArgument, "the force table's lookups on the stage-time grid");
  std::printf("3. The 2-s auto-test (t = 0..2 s, 2000 Plant::advance calls of 1 ms; set-up outside the timing)\n");
  std::printf("   %-40s %10s %10s %5s %9s %7s %10s %s\n", "run", "median", "min", "runs", "RT factor", "rhs",
              "max|dxyz|m", "target / note");
  for (const auto& r : rows) {
    const bool first = &r == rows;
    std::printf("   %-40s %10s %10s %5d %8.0fx %7ld %10.2e %s%s%s\n", r.name, fmt_time(r.r.fig.median).c_str(),
                fmt_time(r.r.fig.min).c_str(), r.r.fig.batches, 2.0 / r.r.fig.median, r.r.rhs, r.r.err,
                first ? "<= 10 ms  " : r.note, first ? ok_mark(r.r.fig.median, 10e-3) : "", r.r.note.c_str());
  }
  const double fwd = rows[0].r.fig.median, s = sd.median;
  auto ratio = [&](int row, int baseline) { return rows[row].r.fig.median / rows[baseline].r.fig.median; };
  auto estimate = [&](int held, int round_trip) {  // held-F time x round-trip rhs / held-F rhs
    return fmt_time(rows[held].r.fig.median * rows[round_trip].r.rhs / rows[held].r.rhs);
  };
  std::printf("   RT factor = 2 s simulated / wall time; rhs = state-derivative evaluations per run (RK4: 4 per step).\n"
              "   (a)  the forces tabulated at the 4001 stage times: forward dynamics + RK4 only. (a') CVODE picks its\n"
              "        own stage times: the static forces at P0, held (the platform at rest; CVODE's per-call cost).\n"
              "   [*]  bare = Plant::advance with pkm::PathForces, without run_autotest's per-sample work.\n");
  std::printf("   RK4: forward run / (8000 x sd(LegP)) %.2f (integrator + input overhead); bare round trip /\n"
              "        forward %.2f (~ 1 + ID[**] / sd = %.2f); run_autotest / forward %.2f\n",
              fwd / (8000.0 * s), ratio(1, 0), 1.0 + stages.median / s, ratio(2, 0));
  std::printf("   CVODE 1e-12, 1e-8: rhs / RK4's 8000 %.2f, %.2f; run_autotest / RK4's %.2f, %.2f; forward-only\n"
              "        estimate for the path (held-F time x round-trip rhs / held-F rhs, derived) %s, %s,\n"
              "        of which derivatives (rhs x sd) %s, %s\n",
              rows[5].r.rhs / 8000.0, rows[8].r.rhs / 8000.0, ratio(5, 2), ratio(8, 2), estimate(3, 5).c_str(),
              estimate(6, 8).c_str(), fmt_time(rows[5].r.rhs * s).c_str(), fmt_time(rows[8].r.rhs * s).c_str());
  rule();
}

int core_part() {
  Core b;
  if (!set_up(b)) return 1;
  print_header();
  const Figure sd = state_derivative_section(b);
  derivatives_section(b);
  const Figure stages = inverse_dynamics_section(b, sd);
  autotest_section(b, sd, stages);
  if (b.failures) std::printf("%d measurement(s) FAILED (see the marks above)\n", b.failures);
  return b.failures ? 1 : 0;
}

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

StepRun tick_run(const Model& m, const SolverSettings& st, Inputs kind, bool cont, const Vec4& F_static) {
  return plant_steps(m, st, kHome, Pose::Zero(), kTicks, [&](Plant& plant, long k) {
    LinearInputs in = step_inputs(kind, k, F_static);
    return plant.advance(static_cast<double>(k + 1) * kTick, in.signal(), cont && k > 0);
  });
}

/// The stiff cases: F = 0 from the home pose, 200 steps of 1 ms; per solver
/// the median time per step and the steps answered OK; ROS2's deviation in dz
/// from CVODE (BDF, rtol 1e-10) over the steps CVODE answered; the ratios.
void stiff_cases(double rk4_tick_us) {
  struct Setting {
    const char* parameter;
    double value;
  };
  const struct {
    const char* name;
    std::vector<Setting> set;  // beyond the defaults
  } cases[] = {{"friction_viscous 1000", {{"friction_viscous", 1000}}},
               {"friction_coulomb 5", {{"friction_coulomb", 5}}},
               {"friction_coulomb 10, v_s 1e-6", {{"friction_coulomb", 10}, {"friction_velocity", 1e-6}}},
               {"stops 1e9/1e6", {{"stop_stiffness", 1e9}, {"stop_damping", 1e6}}},
               {"stops, m_slider 1e-2", {{"stop_stiffness", 1e9}, {"stop_damping", 1e6}, {"m_slider", 1e-2}}},
               {"stops, m_slider 1e-6", {{"stop_stiffness", 1e9}, {"stop_damping", 1e6}, {"m_slider", 1e-6}}}};
  struct Outcome {
    StepRun last;
    double us;  // the median microseconds per step
  };
  auto run = [](const Model& m, Solver solver) {
    const SolverSettings st = settings(solver, 1e-10, 1e-12, CvodeMethod::BDF);
    std::vector<double> per_step;
    StepRun r;
    for (int i = 0; i < effort.tick_runs; ++i) {
      r = plant_steps(m, st, kHome, Pose::Zero(), 200, [](Plant& plant, long k) {
        return plant.advance(static_cast<double>(k + 1) * kTick, InputSignal{});
      });
      per_step.push_back(r.seconds / static_cast<double>(std::min(r.ok_steps + 1, 200L)));
    }
    return Outcome{r, 1e6 * summarise(per_step).median};
  };
  std::printf("\nthe stiff cases: F = 0 from the home pose, 1 ms steps, 200 steps; CVODE BDF rtol 1e-10 is the "
              "reference\n(targets: ROS2 within 1 %% of CVODE, at most 3x an RK4 tick)\n");
  std::printf("%-30s %14s %14s %14s %10s %10s %10s %12s\n", "case", "CVODE us/ok", "RK4 us/ok", "ROS2 us/ok",
              "ROS2/RK4", "/RK4 tick", "ROS2/CVODE", "ROS2 |ddz|");
  for (const auto& c : cases) {
    Configuration config;
    for (const Setting& s : c.set) find_parameter(s.parameter)->set(config, s.value);
    Model m;
    if (make_model(config.params, m) != Status::Ok) continue;
    const Outcome cv = run(m, Solver::Cvode), r4 = run(m, Solver::Rk4), rb = run(m, Solver::Rosenbrock);
    double dev = 0, scale = 0;
    for (long k = 1; k <= std::min(cv.last.ok_steps, rb.last.ok_steps); ++k) {
      dev = std::max(dev, std::fabs(rb.last.states[k][6] - cv.last.states[k][6]));
      scale = std::max(scale, std::fabs(cv.last.states[k][6]));
    }
    std::printf("%-30s", c.name);
    for (const Outcome* o : {&cv, &r4, &rb}) {
      char cell[32];
      std::snprintf(cell, sizeof cell, "%.2f/%ld", o->us, o->last.ok_steps);
      std::printf(" %14s", cell);
    }
    std::printf(" %10.2f %10.2f %10.2f %11.2g%%\n", r4.last.ok_steps ? rb.us / r4.us : 0.0, rb.us / rk4_tick_us,
                rb.us / cv.us, scale > 0 ? 100 * dev / scale : 0.0);
  }
  std::printf("us/ok: median microseconds per step (the failing step included) / steps answered OK; /RK4 tick: ROS2\n"
              "against the held-input RK4 tick above (%.3f us, the default machine). RK4 refuses the stuck-friction\n"
              "case at initialisation (0 steps) and runs out of its work budget at the stiff stops' impact; ROS2's\n"
              "deviation covers the steps CVODE answered.\n",
              rk4_tick_us);
}

/// 1 s of 1-ms steps of the Plant from the home pose, per input kind: CVODE
/// restarted at every step and continued across them, RK4, ROS2; each row's
/// deviation from the same inputs integrated at rtol 1e-12 (restarted at
/// every step: exact for inputs smooth within each step).
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
    const StepRun ref = parseable ? StepRun{} : tick_run(model, tight, kind, false, id.F);
    for (const auto& c : cases) {
      StepRun r;
      const Figure f = time_runs(
          [&] {
            r = tick_run(model, c.st, kind, c.cont, id.F);
            return r.status == Status::Ok ? r.seconds : -1.0;
          },
          effort.tick_runs, effort.tick_runs);
      const double us = 1e6 * f.median / kTicks;
      char name[64];
      std::snprintf(name, sizeof name, "%s: %s", kInputNames[static_cast<int>(kind)], c.name);
      if (r.status != Status::Ok) {
        std::printf(parseable ? "tick;%s;FAILED\n" : "%-44s FAILED\n", name);
        ++failures;
        continue;
      }
      const Vec8& last = r.states.back();
      if (parseable) {
        std::printf("tick;%s;%.6f;%.17g;%.17g;%.17g;%.17g\n", name, us, last[0], last[1], last[2], last[3]);
        continue;
      }
      double dev = 0;
      for (size_t k = 0; k < r.states.size() && k < ref.states.size(); ++k)
        dev = std::max(dev, (r.states[k].head<3>() - ref.states[k].head<3>()).lpNorm<Eigen::Infinity>());
      std::printf("%-44s %9.3f %9.2f %9ld %9.2f %12.2e", name, us, static_cast<double>(r.rhs) / kTicks, r.rhs_max,
                  static_cast<double>(r.cvode_steps) / kTicks, dev);
      if (&c.st == &cvode && !c.cont) restart_us = us;
      if (&c.st == &cvode && c.cont) std::printf("   %.1fx faster than restarting", restart_us / us);
      if (&c.st == &rk4) rk4_us = us;
      if (&c.st == &ros2) std::printf("   %.2fx RK4 (target <= 3x)", us / rk4_us);
      std::printf("\n");
    }
  }
  if (parseable) return failures ? 1 : 0;
  std::printf("\nreference: CVODE rtol 1e-12, restarted every step, the same inputs. Continuing across the jumps of\n"
              "sampled or held inputs costs accuracy: the FMU continues only where the inputs continue (pkm4puu.cpp).\n");
  stiff_cases(rk4_us);
  return failures ? 1 : 0;
}

}  // namespace
}  // namespace pkm

int main(int argc, char** argv) {
  bool core = false, ticks = false, parseable = false;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "core") core = true;
    else if (a == "ticks") ticks = true;
    else if (a == "--parseable") parseable = true;
    else if (a == "--quick") pkm::effort = pkm::Effort{7, 2e-3, 7, 3, 1.0, 3};
    else {
      std::fprintf(stderr, "pkm_bench: unknown argument %s (usage: pkm_bench [core|ticks] [--quick] [--parseable])\n",
                   argv[i]);
      return 2;
    }
  }
  if (!core && !ticks) core = !parseable, ticks = true;  // no part named: both (--parseable: the ticks)
  int status = core ? pkm::core_part() : 0;
  if (ticks) status |= pkm::ticks_part(parseable);
  return status;
}

// SPDX-License-Identifier: BSD-2-Clause
// pkm_bench [core|ticks] [--quick] [--parseable]: the core's timings, each with
// its ratios to a baseline of the same run (never a pass/fail exit code).
// core (here): items 1 to 3; ticks (ticks.cpp). --quick: the docs build's short
// batches; --parseable (ticks): "tick;<run>;<us/step>;<x>;<y>;<z>;<phi>" lines.
#include <cassert>
#include <cstdio>
#include <string>

#include <sundials/sundials_config.h>

#include "apps/autotest.hpp"
#include "apps/trajectory.hpp"
#include "core/core_bench.hpp"
#include "pkm4puu/dynamics/forward_dynamics.hpp"
#include "pkm4puu/dynamics/inverse_dynamics.hpp"
#include "pkm4puu/dynamics/inverse_dynamics_derivatives.hpp"
#include "pkm4puu/dynamics/lagrangian.hpp"
#include "pkm4puu/dynamics/reduced_dynamics_derivatives.hpp"
#include "pkm4puu/dynamics/regressor.hpp"
#include "pkm4puu/dynamics/state_derivative.hpp"
#include "pkm4puu/kinematics/servo_kinematics.hpp"

namespace pkm::bench {

Effort effort;

namespace {

volatile double g_sink = 0;  // results go here so that no call is optimised away

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

/// What the core sections measure on: the model, the auto-test path, its state at t = 1 s, the stage-time grid
/// t_j = j h/2 with its forces, the solvers; and the failure count.
struct Core {
  Model model;
  RestToRest path;
  long n_out = 0, n_grid = 0;  // 2000 one-ms steps; 4001 grid points
  int failures = 0;
  Pose p, pd, pdd;  // the path at t = 1 s (it starts at rest at path.p0)
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
  InverseDynamicsResult r;
  if (inverse_dynamics(b.model, b.p, b.pd, b.pdd, Wrench::Zero(), b.id_mid, false) != Status::Ok ||
      inverse_dynamics(b.model, b.path.p0, Pose::Zero(), Pose::Zero(), Wrench::Zero(), r, false) != Status::Ok) {
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
  bool asserts = false;
  assert((asserts = true));  // true where asserts are compiled in
  rule();
  std::printf("pkm_bench  ");
  bench_print_machine();
  std::printf("           build: %s (%s), %s, Eigen %d.%d.%d, SUNDIALS %s\n",
              *PKM_BENCH_BUILD_TYPE ? PKM_BENCH_BUILD_TYPE : "none", asserts ? "asserts ON" : "NDEBUG",
              PKM_BENCH_COMPILER, EIGEN_WORLD_VERSION, EIGEN_MAJOR_VERSION, EIGEN_MINOR_VERSION, SUNDIALS_VERSION);
  std::printf("           timing: median and min over %d batches of N calls (N: a batch >= %g ms)%s\n", effort.batches,
              1e3 * effort.batch_s, effort.batches < 31 ? " (--quick)" : "");
  rule();
}

/// Per-call time of body(acc) (returns a Status, adds a result to acc): N calls per batch, N grown until a batch
/// lasts effort.batch_s, the batches timed as runs; a failed call is reported under `what`.
template <class Body>
Figure time_checked(Core& b, const char* what, Body&& body) {
  double acc = 0;
  Status bad = Status::Ok;
  long n = 1;
  auto batch = [&] {  // the time per call of a batch of n calls
    const double t0 = bench_now();
    for (long k = 0; k < n; ++k)
      if (const Status s = body(acc); s != Status::Ok) bad = s;
    return (bench_now() - t0) / static_cast<double>(n);
  };
  for (double dt; n < (1L << 26) && (dt = batch() * static_cast<double>(n)) < effort.batch_s;)
    n = std::lround(static_cast<double>(n) * std::clamp(1.2 * effort.batch_s / dt, 2.0, 10.0));
  const Figure f = time_runs(batch);
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
  for (const Formulation formulation :
       {Formulation::LegPartitioned, Formulation::NullSpaceQR, Formulation::Augmented}) {
    const char* name = formulation_name(formulation);
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

/// 1b and 1c: the analytic derivatives and the regressor, each beside what it
/// differentiates or stands for, measured right before it.
void derivatives_section(Core& b) {
  Vec8 yk = b.y_mid, ydot;
  Pose pk = b.p;
  Mat8 A;
  Mat8x12 B;
  InverseDynamicsPartials d;
  InverseDynamicsResult r;
  RegressorSample rs;
  long k = 0;
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
  const Figure id = PKM_TIMED(
      b, "inverse_dynamics", inverse_dynamics(b.model, nudge(pk, b.p, k++), b.pd, b.pdd, Wrench::Zero(), r, false),
      r.F[0]);
  const Figure reg = PKM_TIMED(b, "regressor", regressor(b.model, nudge(pk, b.p, k++), b.pd, b.pdd, Wrench::Zero(), rs),
                               rs.Y(0, 0));
  Vec4 rho, rhod, rhodd;  // the sliders' motion at the same state (set_up's inverse dynamics)
  for (int i = 0; i < kLegs; ++i)
    rho[i] = b.id_mid.q[leg_offset(i)], rhod[i] = b.id_mid.qd[leg_offset(i)], rhodd[i] = b.id_mid.qdd[leg_offset(i)];
  Vec4 rk = rho;
  const Figure joints = PKM_TIMED(b, "joint_regressor",  // from the previous sample's pose, 1e-12 m away
                                  (rs.pose = b.p, joint_regressor(b.model, nudge(rk, rho, k++), rhod, rhodd,
                                                                  Wrench::Zero(), rs)),
                                  rs.Y(0, 0));
  heading("1b. Analytic derivatives at the same state (reduced_dynamics_derivatives.hpp)", "ratio");
  line("state_derivative (LegPartitioned, baseline)", sd1, sd1.median);
  line("state_derivative_jacobians: ydot, A 8x8, B 8x12", jac, sd1.median, target_mark(jac.median / sd1.median, 3.0));
  std::printf("   %-48s %12s %12s %9.2fx\n", "  (central differences: 24 state derivatives)", "", "", 24.0);
  line("inverse_dynamics (cold, baseline)", id, id.median);
  line("inverse_dynamics_derivatives: F, dF 4x16", idd, id.median);
  rule();
  heading("1c. Calibration regressor at the same motion (regressor.hpp)", "ratio");
  line("inverse_dynamics (cold, baseline, as in 1b)", id, id.median);
  line("regressor: Y 4x14, F0 from the platform motion", reg, id.median, target_mark(reg.median / id.median, 2.0));
  line("joint_regressor: from rho, drho, ddrho", joints, id.median);
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

/// Plant::advance over the 2 s in 1-ms calls driven by `input` (`at_rest`: the error against P0 instead of the
/// path); `input_status`: the input's own failure (PathForces).
RunInfo plant_run(Core& b, const SolverSettings& st, InputSignal input, bool continuous, bool at_rest,
                  const Status* input_status = nullptr) {
  RunInfo info;
  StepRun last;
  info.fig = time_runs([&] {
    last = plant_steps(b.model, st, b.path.p0, Pose::Zero(), b.n_out, [&](Plant& plant, long k) {
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
    Pose q = b.path.p0, qd, qdd;
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

/// 3: the 2-s auto-test per solver, forward only and round trip (the rows' legend says how), and their ratios.
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

}  // namespace
}  // namespace pkm::bench

int main(int argc, char** argv) {
  using namespace pkm::bench;
  bool core = false, ticks = false, parseable = false;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "core") core = true;
    else if (a == "ticks") ticks = true;
    else if (a == "--parseable") parseable = true;
    else if (a == "--quick") effort = Effort{7, 2e-3, 3};
    else {
      std::fprintf(stderr, "pkm_bench: unknown argument %s (usage: pkm_bench [core|ticks] [--quick] [--parseable])\n",
                   argv[i]);
      return 2;
    }
  }
  if (!core && !ticks) core = !parseable, ticks = true;  // no part named: both (--parseable: the ticks)
  int status = core ? core_part() : 0;
  if (ticks) status |= ticks_part(parseable);
  return status;
}

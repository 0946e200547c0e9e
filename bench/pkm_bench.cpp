// SPDX-License-Identifier: BSD-2-Clause
// pkm_bench: timing figures of the 4-PUU core. It prints a table; it is not
// a test (no pass/fail exit code for the timings; targets are shown for
// context only).
//
//   1. one forward-dynamics state derivative, for the three formulations;
//   1b. the analytic derivatives beside the evaluations they differentiate;
//   2. one inverse-dynamics solve, cold (closed-form start) and warm-started;
//   3. the 2-s auto-test with RK4 at 1 ms, forward only (forces tabulated
//      beforehand) and round trip (inverse dynamics at every stage), then
//      the same with CVODE;
//   4. heap allocations inside time steps (the malloc family, operator new
//      included, counted by tests/alloc_interposer.c on glibc; that none
//      happens where none may is checked by the test core_allocations);
// and the machine-independent ratios of those figures.
//
// Timing (timing.hpp): std::chrono::steady_clock; every figure is the median
// (and the minimum) of 31 batches. A batch is N calls, N chosen so that a
// batch lasts a few milliseconds; whole runs (item 3) are timed one run per
// batch.
#include <sys/utsname.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <string>
#include <thread>
#include <vector>

#include <sundials/sundials_config.h>

#if PKM_BENCH_COUNTS_ALLOCATIONS
#include "alloc_interposer.h"
#endif
#include "apps/autotest.hpp"
#include "pkm4puu/dynamics/inverse_dynamics.hpp"
#include "pkm4puu/dynamics/inverse_dynamics_derivatives.hpp"
#include "pkm4puu/dynamics/regressor.hpp"
#include "pkm4puu/dynamics/lagrangian.hpp"
#include "pkm4puu/dynamics/state_derivative.hpp"
#include "pkm4puu/sim/plant.hpp"
#include "pkm4puu/dynamics/reduced_dynamics_derivatives.hpp"
#include "pkm4puu/kinematics/servo_kinematics.hpp"
#include "timing.hpp"
#include "apps/trajectory.hpp"

namespace {

using bench::Figure;
using bench::fmt_time;
using bench::time_per_call;
using bench::time_runs;
using pkm::Formulation;
using pkm::Pose;
using pkm::Status;
using pkm::Vec16;
using pkm::Vec4;
using pkm::Vec8;
using pkm::Wrench;
using Clock = bench::Clock;

volatile double g_sink = 0;  // results go here so no call is optimised away

constexpr int kForms = 3;
const Formulation kFormulations[kForms] = {Formulation::LegPartitioned, Formulation::NullSpaceQR,
                                           Formulation::Augmented};
const char* const kFormNames[kForms] = {"LegPartitioned", "NullSpaceQR", "Augmented"};

const char* ok_mark(double value, double target) { return value <= target ? "ok" : "OVER"; }
// One LegPartitioned state derivative, s.
constexpr double kDerivativeTarget = 0.25e-6;

void rule() {
  std::printf("------------------------------------------------------------------------------------------------\n");
}

std::string cpu_model() {
  std::ifstream in("/proc/cpuinfo");
  std::string line;
  while (std::getline(in, line)) {
    if (line.rfind("model name", 0) == 0) {
      const auto c = line.find(':');
      if (c != std::string::npos) return line.substr(c + 2);
    }
  }
  return "unknown CPU";
}

/// Forces tabulated at t_j = j * dt (j = 0..n-1), looked up exactly by
/// index round(t / dt).
struct ForceTable {
  double dt = 0.5e-3;
  std::vector<Vec4> F;
  long misses = 0;  // lookups off the table (would mean a stage time off the grid)
  pkm::InputSignal signal() { return {&ForceTable::eval, this}; }
  static void eval(void* user, double t, Vec4& F, Wrench& we) {
    auto* tb = static_cast<ForceTable*>(user);
    const double x = t / tb->dt;
    long j = std::lround(x);
    if (std::fabs(x - static_cast<double>(j)) > 1e-6) ++tb->misses;
    j = std::clamp(j, 0L, static_cast<long>(tb->F.size()) - 1);
    F = tb->F[static_cast<size_t>(j)];
    we.setZero();
  }
};

/// What every section measures on: the model, the auto-test path, the state
/// at t = 1 s, the stage-time grid, the solvers; and the failure count.
struct Bench {
  pkm::Model model;
  pkm::RestToRest path;
  double T = 0;
  double h = 1e-3;   // RK4 step and output interval
  long n_out = 0;    // 2000 one-ms calls
  int failures = 0;

  // The state of items 1-2: the auto-test path at t = 1 s.
  double t_mid = 1.0;
  Pose p, pd, pdd;
  pkm::InverseDynamicsResult id_mid;
  Vec8 y_mid;
  Vec16 f_mid;

  // The stage-time grid of the auto-test, t_j = j * h/2, j = 0..4000.
  double half_h = 0;
  long n_grid = 0;
  std::vector<Pose> gp, gpd, gpdd;

  Pose p0, pd0, pdd0;         // the path at t = 0
  ForceTable table;           // forces on the grid (item 3 (a))
  pkm::LinearInputs held;     // static forces at P0, held constant
  pkm::SolverSettings rk4, cv_tight, cv_default;

  /// Counts and reports a failed measurement.
  void check(Status s, const char* what) {
    if (s == Status::Ok) return;
    std::printf("  !! %s failed: %s\n", what, pkm::status_name(s));
    ++failures;
  }
  /// Inverse dynamics along the path, at any time (the round trip's input).
  pkm::PathForces path_forces() const {
    pkm::PathForces forces;
    forces.model = &model;
    forces.path = path;
    return forces;
  }
  /// Inverse dynamics at grid point j.
  Status inverse_at(long j, pkm::InverseDynamicsResult& r, bool warm) const {
    const size_t u = static_cast<size_t>(j);
    return pkm::inverse_dynamics(model, gp[u], gpd[u], gpdd[u], Wrench::Zero(), r, warm);
  }
  /// The general path (servo constraints, Newton) at grid point j.
  Status general_at(long j, pkm::InverseDynamicsResult& r, bool warm) const {
    const size_t u = static_cast<size_t>(j);
    return pkm::inverse_dynamics_general(model, gp[u], gpd[u], gpdd[u], Wrench::Zero(), r, warm);
  }
};

/// Everything the sections share; false (with the reason on stderr) if the
/// set-up itself fails.
bool set_up(Bench& b) {
  std::string why;
  if (pkm::make_model(pkm::Params{}, b.model, &why) != Status::Ok) {
    std::fprintf(stderr, "make_model failed: %s\n", why.c_str());
    return false;
  }
  b.T = b.path.duration;
  b.n_out = std::lround(b.T / b.h);

  b.path.eval(b.t_mid, b.p, b.pd, b.pdd);
  if (pkm::inverse_dynamics(b.model, b.p, b.pd, b.pdd, Wrench::Zero(), b.id_mid, false) != Status::Ok) {
    std::fprintf(stderr, "inverse dynamics failed at t = 1 s\n");
    return false;
  }
  b.y_mid << b.p, b.pd;
  b.f_mid = pkm::generalized_forces(b.id_mid.F, Wrench::Zero());

  b.half_h = 0.5 * b.h;
  b.n_grid = 2 * b.n_out + 1;  // 4001
  b.gp.resize(static_cast<size_t>(b.n_grid));
  b.gpd.resize(b.gp.size());
  b.gpdd.resize(b.gp.size());
  for (long j = 0; j < b.n_grid; ++j) {
    const size_t u = static_cast<size_t>(j);
    b.path.eval(static_cast<double>(j) * b.half_h, b.gp[u], b.gpd[u], b.gpdd[u]);
  }

  // Forces on the stage-time grid, by warm-started inverse dynamics (as PathForces does).
  b.table.dt = b.half_h;
  b.table.F.resize(static_cast<size_t>(b.n_grid));
  pkm::InverseDynamicsResult r;
  for (long j = 0; j < b.n_grid; ++j) {
    if (b.inverse_at(j, r, j > 0) != Status::Ok) {
      std::fprintf(stderr, "inverse dynamics failed at t = %g s\n", static_cast<double>(j) * b.half_h);
      return false;
    }
    b.table.F[static_cast<size_t>(j)] = r.F;
  }
  b.path.eval(0.0, b.p0, b.pd0, b.pdd0);
  if (pkm::inverse_dynamics(b.model, b.p0, Pose::Zero(), Pose::Zero(), Wrench::Zero(), r, false) != Status::Ok) {
    std::fprintf(stderr, "static forces failed\n");
    return false;
  }
  b.held.F0 = r.F;

  b.rk4.solver = pkm::Solver::Rk4;
  b.rk4.rk4_step = b.h;
  b.cv_tight.solver = pkm::Solver::Cvode;
  b.cv_tight.cvode_method = pkm::CvodeMethod::Adams;
  b.cv_tight.rtol = 1e-12;
  b.cv_tight.atol = 1e-14;
  b.cv_default = b.cv_tight;
  b.cv_default.rtol = 1e-8;
  b.cv_default.atol = 1e-10;
  return true;
}

void print_header() {
  utsname un{};
  uname(&un);
#ifdef PKM_BENCH_BUILD_TYPE
  const char* build_type = PKM_BENCH_BUILD_TYPE;
#else
  const char* build_type = "unknown";
#endif
#ifdef NDEBUG
  const char* ndebug = "NDEBUG";
#else
  const char* ndebug = "asserts ON";
#endif
  rule();
  std::printf("pkm_bench  machine: %s, %u hardware threads (%s)\n", un.machine,
              std::thread::hardware_concurrency(), cpu_model().c_str());
  std::printf("           build: %s (%s), %s %s, Eigen %d.%d.%d, SUNDIALS %s\n", build_type, ndebug,
#if defined(__clang__)
              "clang",
#else
              "gcc",
#endif
              __VERSION__, EIGEN_WORLD_VERSION, EIGEN_MAJOR_VERSION, EIGEN_MINOR_VERSION, SUNDIALS_VERSION);
  std::printf("           timing: steady_clock; median and min over %d batches of N calls (N: a batch >= %g ms)%s\n",
              bench::effort.batches, 1e3 * bench::effort.batch_s, bench::effort.batches < 31 ? " (--quick)" : "");
  std::printf("           allocation counter: %s\n", PKM_BENCH_COUNTS_ALLOCATIONS
                                                        ? "malloc family incl. operator new (glibc interposition)"
                                                        : "none in this build (glibc, no sanitizers)");
  rule();
}

/// Per-call time of body(acc), which returns a Status and adds a result to
/// acc (kept, so that no call is optimised away); a failed call, or a failed
/// `seed` before the timing, is reported under `what`.
template <class Body>
Figure time_checked(Bench& b, const char* what, Body&& body, Status seed = Status::Ok) {
  double acc = 0;
  Status bad = seed;
  const Figure f = time_per_call([&] {
    const Status s = body(acc);
    if (s != Status::Ok) bad = s;
  });
  g_sink = acc;
  b.check(bad, what);
  return f;
}

/// v = base with x moved by 1e-12 * (k % 1024): each call sees a new state.
template <class V>
const V& nudge(V& v, const V& base, long k) {
  v[0] = base[0] + 1e-12 * static_cast<double>(k & 1023);
  return v;
}

// ------------------------------------------------------- 1. state derivative
using StateDerivativeFigures = std::array<Figure, kForms>;

StateDerivativeFigures state_derivative_section(Bench& b) {
  StateDerivativeFigures sd;
  double acc_err[kForms] = {0, 0, 0};  // |pdd - prescribed| at the unperturbed state (sanity)
  for (int i = 0; i < kForms; ++i) {
    Vec8 yk = b.y_mid, ydot;
    long k = 0;
    const std::string what = std::string("state_derivative(") + kFormNames[i] + ")";
    sd[static_cast<size_t>(i)] = time_checked(b, what.c_str(), [&](double& acc) {
      const Status s = pkm::state_derivative(b.model, kFormulations[i], nudge(yk, b.y_mid, k++), b.f_mid, ydot);
      acc += ydot[4] + ydot[7];
      return s;
    });
    if (pkm::state_derivative(b.model, kFormulations[i], b.y_mid, b.f_mid, ydot) == Status::Ok)
      acc_err[i] = (ydot.tail<4>() - b.pdd).lpNorm<Eigen::Infinity>();
  }
  std::printf("1. Forward dynamics: one pkm::state_derivative at t = %.3f s of the auto-test path\n", b.t_mid);
  std::printf("   (y = path pose and velocity, f = inverse-dynamics forces there; y[0] += 1e-12*(k%%1024) per call)\n");
  std::printf("   %-16s %12s %12s %10s %9s %16s %13s\n", "formulation", "median/call", "min/call", "N/batch",
              "vs LegP", "target", "|pdd-path|");
  for (int i = 0; i < kForms; ++i) {
    const Figure& f = sd[static_cast<size_t>(i)];
    char target[32] = "";
    if (i == 0) std::snprintf(target, sizeof target, "<= %g us  %s", kDerivativeTarget * 1e6,
                            ok_mark(sd[0].median, kDerivativeTarget));
    std::printf("   %-16s %12s %12s %10ld %8.2fx %16s %13.2e\n", kFormNames[i], fmt_time(f.median).c_str(),
                fmt_time(f.min).c_str(), f.per_batch, f.median / sd[0].median, target, acc_err[i]);
  }
  rule();
  return sd;
}

// ----------------------------------------- 1b. analytic derivatives
// The full Jacobian of the state derivative, A (8x8) and B (8x12), and the
// inverse dynamics' dF/d(p, pd, pdd, we), each against its own value
// measured here in the same run: one state_derivative (LegPartitioned,
// item 1's figure) and one cold inverse_dynamics. Central differences
// would need 24 state derivatives for A and B. Returns Jacobians /
// state derivative.
double derivatives_section(Bench& b) {
  Vec8 yk = b.y_mid, ydot;
  Pose pk = b.p;
  pkm::Mat8 A;
  pkm::Mat8x12 B;
  long k = 0;
  const char* what = "derivatives";
  const Figure jac = time_checked(b, what, [&](double& acc) {
    const Status s = pkm::state_derivative_jacobians(b.model, nudge(yk, b.y_mid, k++), b.id_mid.F, Vec4::Zero(),
                                                     Wrench::Zero(), pkm::kStopsFromState, ydot, A, B);
    acc += A(4, 0) + B(7, 3);
    return s;
  });
  const Figure sd_same = time_checked(b, what, [&](double& acc) {  // the baseline again, right beside it
    const Status s = pkm::state_derivative(b.model, Formulation::LegPartitioned, nudge(yk, b.y_mid, k++), b.f_mid, ydot);
    acc += ydot[4];
    return s;
  });
  pkm::InverseDynamicsPartials d;
  pkm::InverseDynamicsResult r;
  const Figure idd = time_checked(b, what, [&](double& acc) {
    const Status s = pkm::inverse_dynamics_derivatives(b.model, nudge(pk, b.p, k++), b.pd, b.pdd, Wrench::Zero(), d);
    acc += d.dp(0, 0);
    return s;
  });
  const Figure id_plain = time_checked(b, what, [&](double& acc) {
    const Status s = pkm::inverse_dynamics(b.model, nudge(pk, b.p, k++), b.pd, b.pdd, Wrench::Zero(), r, false);
    acc += r.F[0];
    return s;
  });
  const double jac_ratio = jac.median / sd_same.median;
  std::printf("1b. Analytic derivatives at the same state (reduced_dynamics_derivatives.hpp)\n");
  std::printf("   %-44s %12s %12s %10s %16s\n", "evaluation", "median/call", "min/call", "ratio", "target");
  std::printf("   %-44s %12s %12s %10s\n", "state_derivative (LegPartitioned, baseline)",
              fmt_time(sd_same.median).c_str(), fmt_time(sd_same.min).c_str(), "1.00x");
  std::printf("   %-44s %12s %12s %9.2fx %16s\n", "state_derivative_jacobians: ydot, A 8x8, B 8x12",
              fmt_time(jac.median).c_str(), fmt_time(jac.min).c_str(), jac_ratio,
              (std::string("<= 3x  ") + ok_mark(jac_ratio, 3.0)).c_str());
  std::printf("   %-44s %12s %12s %9.2fx\n", "  (central differences: 24 state derivatives)", "", "", 24.0);
  std::printf("   %-44s %12s %12s %10s\n", "inverse_dynamics (cold, baseline)", fmt_time(id_plain.median).c_str(),
              fmt_time(id_plain.min).c_str(), "1.00x");
  std::printf("   %-44s %12s %12s %9.2fx\n", "inverse_dynamics_derivatives: F, dF 4x16", fmt_time(idd.median).c_str(),
              fmt_time(idd.min).c_str(), idd.median / id_plain.median);
  rule();
  return jac_ratio;
}

// ----------------------------------------- 1c. calibration regressor
// The regressor Y (4 x 14) of the forces in the dynamic parameters
// (regressor.hpp) at the same motion as one cold inverse_dynamics, both
// measured here in the same run; and from the sliders' measurements
// (forward kinematics from the previous pose, as the identification calls
// it). Returns regressor / inverse dynamics (target <= 2).
double regressor_section(Bench& b) {
  Pose pk = b.p;
  long k = 0;
  const char* what = "regressor";
  pkm::RegressorSample rs;
  pkm::InverseDynamicsResult r;
  const Figure reg = time_checked(b, what, [&](double& acc) {
    const Status s = pkm::regressor(b.model, nudge(pk, b.p, k++), b.pd, b.pdd, Wrench::Zero(), rs);
    acc += rs.Y(0, 0);
    return s;
  });
  const Figure id = time_checked(b, what, [&](double& acc) {  // the baseline, right beside it
    const Status s = pkm::inverse_dynamics(b.model, nudge(pk, b.p, k++), b.pd, b.pdd, Wrench::Zero(), r, false);
    acc += r.F[0];
    return s;
  });
  // The sliders' positions, rates and accelerations of the same motion.
  pkm::RegressorSample at;
  Vec4 rho = Vec4::Zero(), rhod = Vec4::Zero(), rhodd = Vec4::Zero();
  if (pkm::inverse_dynamics(b.model, b.p, b.pd, b.pdd, Wrench::Zero(), r, false) == Status::Ok) {
    for (int i = 0; i < pkm::kLegs; ++i) {
      rho[i] = r.q[pkm::leg_offset(i)];
      rhod[i] = r.qd[pkm::leg_offset(i)];
      rhodd[i] = r.qdd[pkm::leg_offset(i)];
    }
  }
  Vec4 rk = rho;
  const Figure joints = time_checked(b, what, [&](double& acc) {
    at.pose = b.p;  // the previous sample's pose, 1e-12 m away
    const Status s = pkm::joint_regressor(b.model, nudge(rk, rho, k++), rhod, rhodd, Wrench::Zero(), at);
    acc += at.Y(0, 0);
    return s;
  });
  const double ratio = reg.median / id.median;
  std::printf("1c. Calibration regressor at the same motion (regressor.hpp)\n");
  std::printf("   %-44s %12s %12s %10s %16s\n", "evaluation", "median/call", "min/call", "ratio", "target");
  std::printf("   %-44s %12s %12s %10s\n", "inverse_dynamics (cold, baseline)", fmt_time(id.median).c_str(),
              fmt_time(id.min).c_str(), "1.00x");
  std::printf("   %-44s %12s %12s %9.2fx %16s\n", "regressor: Y 4x14, F0 from the platform motion",
              fmt_time(reg.median).c_str(), fmt_time(reg.min).c_str(), ratio,
              (std::string("<= 2x  ") + ok_mark(ratio, 2.0)).c_str());
  std::printf("   %-44s %12s %12s %9.2fx\n", "joint_regressor: from rho, drho, ddrho", fmt_time(joints.median).c_str(),
              fmt_time(joints.min).c_str(), joints.median / id.median);
  rule();
  return ratio;
}

// ------------------------------------------------------- 2. inverse dynamics
// The reduced path (inverse_dynamics: closed-form leg inverse kinematics,
// the leg-partitioned reduced system, no iteration) against one forward
// state derivative, and the general path (inverse_dynamics_general: Newton
// on the servo constraints, Eqs. 10-11 in full) it replaced.
constexpr double kInverseTarget = 1.0, kInverseStretch = 0.5;  // x one state derivative

struct InverseDynamicsFigures {
  Figure reduced, actuators, stages, general_cold, general_warm;
};

/// Newton iterations of solve_position at grid point `mid`: from the closed
/// form, and from the grid neighbour's solution (-1: failed).
std::array<int, 2> newton_iterations(const Bench& b, size_t mid) {
  std::array<int, 2> it = {-1, -1};
  Vec16 q;
  pkm::NewtonReport rep;
  if (pkm::closed_form_position(b.model, b.gp[mid], q) == Status::Ok &&
      pkm::solve_position(b.model, b.gp[mid], q, {}, &rep) == Status::Ok)
    it[0] = rep.iterations;
  if (pkm::closed_form_position(b.model, b.gp[mid - 1], q) == Status::Ok &&
      pkm::solve_position(b.model, b.gp[mid - 1], q) == Status::Ok &&
      pkm::solve_position(b.model, b.gp[mid], q, {}, &rep) == Status::Ok)
    it[1] = rep.iterations;
  return it;
}

InverseDynamicsFigures inverse_dynamics_section(Bench& b, const Figure& sd) {
  InverseDynamicsFigures f;
  pkm::InverseDynamicsResult r;
  {
    long j = 0;
    f.reduced = time_checked(b, "inverse_dynamics", [&](double& acc) {
      const Status s = b.inverse_at(j, r, false);
      j = (j + 1) % b.n_grid;
      acc += r.F[0];
      return s;
    });
  }
  {
    long j = 0;
    pkm::InverseActuators a;
    f.actuators = time_checked(b, "inverse_actuators", [&](double& acc) {
      const size_t u = static_cast<size_t>(j);
      const Status s = pkm::inverse_actuators(b.model, b.gp[u], b.gpd[u], b.gpdd[u], Wrench::Zero(), a);
      j = (j + 1) % b.n_grid;
      acc += a.F[0];
      return s;
    });
  }
  {
    // The RK4 round trip's sequence of stage times (what PathForces sees):
    // t_k, t_k + h/2, t_k + h/2, t_k + h, then t_k + h again as the next step's
    // first stage: grid indices 2k, 2k+1, 2k+1, 2k+2, 2k+2, 2k+3, ...
    long c = 0;
    f.stages = time_checked(b, "inverse_dynamics (stage sequence)", [&](double& acc) {
      const long m = c % (4 * b.n_out);  // one pass over the 2 s = 4 * 2000 calls
      ++c;
      const long step = m / 4, stage = m % 4;
      const long j = 2 * step + (stage == 0 ? 0 : stage == 3 ? 2 : 1);
      const Status s = b.inverse_at(j, r, m != 0);
      acc += r.F[0];
      return s;
    });
  }
  {
    long j = 0;
    f.general_cold = time_checked(b, "inverse_dynamics_general (cold)", [&](double& acc) {
      const Status s = b.general_at(j, r, false);
      j = (j + 1) % b.n_grid;
      acc += r.F[0];
      return s;
    });
  }
  {
    // Ping-pong along the grid so that every warm start is the neighbour 0.5 ms away.
    long j = 0, dir = 1;
    const Status seed = b.general_at(0, r, false);
    f.general_warm = time_checked(
        b, "inverse_dynamics_general (warm)",
        [&](double& acc) {
          if (j + dir < 0 || j + dir >= b.n_grid) dir = -dir;
          j += dir;
          const Status s = b.general_at(j, r, true);
          acc += r.F[0];
          return s;
        },
        seed);
  }
  const std::array<int, 2> it = newton_iterations(b, static_cast<size_t>(b.n_out));  // t = 1 s
  // Mins for the target: section 1 measured sd(LegP) minutes apart, and on a
  // loaded machine the min is the figure load disturbs least.
  const double ratio = f.reduced.min / sd.min;

  std::printf("2. Inverse dynamics: one call per point of the stage-time grid (t = j*0.5 ms, 4001 points)\n");
  std::printf("   %-44s %12s %12s %10s %12s %8s\n", "evaluation", "median/call", "min/call", "N/batch", "vs sd(LegP)",
              "Newton it");
  auto row = [&](const char* name, const Figure& x, const std::string& iterations) {
    std::printf("   %-44s %12s %12s %10ld %11.2fx %8s\n", name, fmt_time(x.median).c_str(), fmt_time(x.min).c_str(),
                x.per_batch, x.median / sd.median, iterations.c_str());
  };
  row("inverse_dynamics (reduced: q, qd, qdd, F, lambda)", f.reduced, "-");
  row("inverse_actuators (reduced: F, tau, rho, rhod)", f.actuators, "-");
  row("inverse_dynamics, RK4 stage sequence [**]", f.stages, "-");
  row("inverse_dynamics_general, cold (closed form)", f.general_cold, std::to_string(it[0]));
  row("inverse_dynamics_general, warm (0.5 ms away)", f.general_warm, std::to_string(it[1]));
  std::printf("   target: inverse_dynamics / sd(LegP), mins = %.2fx <= %gx: %s (stretch <= %gx: %s); "
              "general cold / reduced = %.1fx\n",
              ratio, kInverseTarget, ok_mark(ratio, kInverseTarget), kInverseStretch, ok_mark(ratio, kInverseStretch),
              f.general_cold.median / f.reduced.median);
  std::printf("   (Newton it = iterations of solve_position at t = 1 s, residual tolerance 1e-14)\n");
  std::printf("   [**] t_k, t_k+h/2, t_k+h/2, t_k+h, t_k+h, ... as PathForces sees them in the RK4 round trip.\n");
  rule();
  return f;
}

// ------------------------------------------------------- 3. the 2-s auto-test
struct RunInfo {
  Figure fig;
  long rhs = 0;
  double err = NAN;  // max |x,y,z - path| over the 1-ms samples, m
  std::string note;
};

/// Largest |x, y, z - reference(t_k)| over a recorded trajectory (one pose per ms).
template <class Reference>
double max_error(const Bench& b, const std::vector<Pose>& traj, Reference&& reference) {
  double e = 0;
  for (long k = 0; k <= b.n_out; ++k) {
    const Pose d = traj[static_cast<size_t>(k)] - reference(static_cast<double>(k) * b.h);
    e = std::max(e, d.head<3>().lpNorm<Eigen::Infinity>());
  }
  return e;
}

/// Plant::advance over 2 s in 1-ms calls, driven by `input`; Plant built and
/// initialised outside the timing; CVODE objects are created by the first
/// advance (inside the timing). `input_status`, if given, is the input's own
/// failure (PathForces). `at_rest`: the error is taken against P0 (held
/// forces) instead of the path.
RunInfo plant_run(Bench& b, const pkm::SolverSettings& st, pkm::InputSignal input, bool record_continuous,
                  const Status* input_status, bool at_rest) {
  RunInfo info;
  std::vector<Pose> traj(static_cast<size_t>(b.n_out) + 1);
  Status bad = Status::Ok;
  info.fig = time_runs([&]() -> double {
    pkm::Plant plant(b.model);
    if (plant.set_solver(st) != Status::Ok || plant.initialize(0.0, b.p0, b.pd0) != Status::Ok) return -1;
    traj[0] = plant.state().head<4>();
    const auto t0 = Clock::now();
    for (long k = 1; k <= b.n_out; ++k) {
      Status s = plant.advance(static_cast<double>(k) * b.h, input, record_continuous && k > 1);
      if (s == Status::Ok && input_status) s = *input_status;
      if (s != Status::Ok) {
        bad = s;
        return -1;
      }
      traj[static_cast<size_t>(k)] = plant.state().head<4>();
    }
    const double dt = bench::seconds(Clock::now() - t0);
    info.rhs = plant.rhs_evaluations();
    return dt;
  });
  if (bad != Status::Ok) {
    info.note = std::string("FAILED: ") + pkm::status_name(bad);
    ++b.failures;
  }
  if (at_rest) {
    info.err = max_error(b, traj, [&](double) { return b.p0; });
  } else {
    info.err = max_error(b, traj, [&](double t) {
      Pose q, qd, qdd;
      b.path.eval(t, q, qd, qdd);
      return q;
    });
  }
  return info;
}

/// Forward only: forces from `input` (the table, or held).
RunInfo forward_run(Bench& b, const pkm::SolverSettings& st, pkm::InputSignal input, bool record_continuous,
                    bool at_rest) {
  return plant_run(b, st, input, record_continuous, nullptr, at_rest);
}

/// Round trip, bare: Plant::advance with PathForces (inverse dynamics at
/// every stage time), no sampling work.
RunInfo bare_round_trip(Bench& b, const pkm::SolverSettings& st) {
  pkm::PathForces forces = b.path_forces();
  return plant_run(b, st, forces.signal(), true, &forces.status, false);
}

/// Round trip: pkm::run_autotest as a whole (includes its 2001 samples:
/// mechanism state, constraint residual, Jacobian condition).
RunInfo autotest_run(Bench& b, const pkm::SolverSettings& st) {
  RunInfo info;
  Status bad = Status::Ok;
  std::string err;
  info.fig = time_runs([&]() -> double {
    pkm::AutotestOptions opt;
    opt.solver = st;
    opt.path = b.path;
    pkm::AutotestResult res;
    const auto t0 = Clock::now();
    const Status s = pkm::run_autotest(b.model, opt, res);
    const double dt = bench::seconds(Clock::now() - t0);
    if (s != Status::Ok) {
      bad = s;
      err = res.error;
      return -1;
    }
    info.rhs = res.rhs_evaluations;
    info.err = res.max_position_error;
    return dt;
  });
  if (bad != Status::Ok) {
    info.note = std::string("FAILED: ") + pkm::status_name(bad) + " " + err;
    ++b.failures;
  }
  return info;
}

struct AutotestFigures {
  RunInfo rk4_fwd, rk4_bare, rk4_rt, cvt_fwd, cvt_bare, cvt_rt, cvd_fwd, cvd_bare, cvd_rt;
};

AutotestFigures autotest_section(Bench& b, const Figure& sd) {
  AutotestFigures a;
  a.rk4_fwd = forward_run(b, b.rk4, b.table.signal(), false, false);
  a.rk4_bare = bare_round_trip(b, b.rk4);
  a.rk4_rt = autotest_run(b, b.rk4);
  a.cvt_fwd = forward_run(b, b.cv_tight, b.held.signal(), true, true);
  a.cvt_bare = bare_round_trip(b, b.cv_tight);
  a.cvt_rt = autotest_run(b, b.cv_tight);
  a.cvd_fwd = forward_run(b, b.cv_default, b.held.signal(), true, true);
  a.cvd_bare = bare_round_trip(b, b.cv_default);
  a.cvd_rt = autotest_run(b, b.cv_default);
  if (b.table.misses != 0) {
    std::printf("  !! %ld force-table lookups were off the stage-time grid\n", b.table.misses);
    ++b.failures;
  }

  std::printf("3. The 2-s auto-test (t = 0..2 s, 2000 Plant::advance calls of 1 ms; set-up outside the timing)\n");
  std::printf("   %-40s %10s %10s %5s %9s %7s %10s %s\n", "run", "median", "min", "runs", "RT factor", "rhs",
              "max|dxyz|m", "target / note");
  auto row = [&](const char* name, const RunInfo& r, const char* note) {
    const double rt = b.T / r.fig.median;
    std::printf("   %-40s %10s %10s %5d %8.0fx %7ld %10.2e %s%s\n", name, fmt_time(r.fig.median).c_str(),
                fmt_time(r.fig.min).c_str(), r.fig.batches, rt, r.rhs, r.err, note, r.note.c_str());
  };
  char rk4_target[48];
  std::snprintf(rk4_target, sizeof rk4_target, "<= 10 ms  %s", ok_mark(a.rk4_fwd.fig.median, 10e-3));
  row("RK4 1 ms  (a) forward only [table]", a.rk4_fwd, rk4_target);
  row("RK4 1 ms  (b) round trip, bare [*]", a.rk4_bare, "");
  row("RK4 1 ms  (b) round trip, run_autotest", a.rk4_rt, "");
  row("CVODE 1e-12/1e-14 (a') forward, held F", a.cvt_fwd, "held static F; error vs P0");
  row("CVODE 1e-12/1e-14 (b) round trip, bare", a.cvt_bare, "");
  row("CVODE 1e-12/1e-14 (b) run_autotest", a.cvt_rt, "");
  row("CVODE 1e-8/1e-10 (a') forward, held F", a.cvd_fwd, "held static F; error vs P0");
  row("CVODE 1e-8/1e-10 (b) round trip, bare", a.cvd_bare, "");
  row("CVODE 1e-8/1e-10 (b) run_autotest", a.cvd_rt, "");
  // Forward-only estimate for the path: held-F time x round-trip rhs / held-F rhs.
  auto estimate = [](const RunInfo& held, const RunInfo& round_trip) {
    return fmt_time(held.fig.median * static_cast<double>(round_trip.rhs) / static_cast<double>(held.rhs));
  };
  std::printf("   RT factor = 2 s simulated / wall time; rhs = state-derivative evaluations per run (RK4: 4 per step).\n");
  std::printf("   (a)  forces tabulated beforehand by inverse dynamics at the 4001 stage times j*0.5 ms, looked up\n");
  std::printf("        by index round(t/0.5 ms): the timing is forward dynamics + RK4 only.\n");
  std::printf("   (a') CVODE picks its own stage times, so no table is possible: the forward-only CVODE runs use\n");
  std::printf("        the static forces at P0 held constant (the platform stays at rest; a measure of CVODE's\n");
  std::printf("        per-call overhead with at least one step per 1-ms output, not of the path's dynamics).\n");
  std::printf("        Forward-only estimate for the path (derived, not measured): held-F time x round-trip rhs /\n");
  std::printf("        held-F rhs = %s (1e-12), %s (1e-8); of which derivatives (rhs x sd(LegP)) %s, %s.\n",
              estimate(a.cvt_fwd, a.cvt_rt).c_str(), estimate(a.cvd_fwd, a.cvd_rt).c_str(),
              fmt_time(static_cast<double>(a.cvt_rt.rhs) * sd.median).c_str(),
              fmt_time(static_cast<double>(a.cvd_rt.rhs) * sd.median).c_str());
  std::printf("        CVODE's steps are capped by the 1-ms output calls (stop time): ~1 step and ~1 rhs per call.\n");
  std::printf("   [*]  bare = Plant::advance with pkm::PathForces (inverse dynamics at every stage time), without\n");
  std::printf("        run_autotest's per-sample work (mechanism state, residual, Jacobian condition, static forces).\n");
  rule();
  return a;
}

// ------------------------------------------------------- 4. allocations
/// The heap allocations between its construction and stop() (-1: not counted in this build).
class AllocWindow {
 public:
  AllocWindow() : start_(now()) {}
  void stop() { count_ = start_ < 0 ? -1 : now() - start_; }
  long count() const { return count_; }

 private:
  static long now() {
#if PKM_BENCH_COUNTS_ALLOCATIONS
    return alloc_count();
#else
    return -1;
#endif
  }
  long start_, count_ = 0;
};

void alloc_row(const char* name, const AllocWindow& w, const char* expected) {
  std::printf("   %-62s %8s  %s\n", name, w.count() < 0 ? "n/a" : std::to_string(w.count()).c_str(), expected);
}

/// The allocations of 1000 one-ms Plant::advance calls after initialisation
/// (`skip_first`: after the first call too, which creates the CVODE objects).
void plant_window(const Bench& b, const char* name, const pkm::SolverSettings& st, pkm::InputSignal input,
                  bool skip_first, const char* expected) {
  pkm::Plant plant(b.model);
  Status status = Status::Ok;
  AllocWindow w;
  w.stop();
  if (plant.set_solver(st) != Status::Ok || plant.initialize(0.0, b.p0, b.pd0) != Status::Ok) {
    status = Status::InvalidArgument;
  } else {
    long k = 1;
    if (skip_first) {
      status = plant.advance(b.h, input, false);
      ++k;
    }
    const long k_end = k + 999;  // 1000 calls = 1 s
    AllocWindow counted;
    for (; k <= k_end && status == Status::Ok; ++k)
      status = plant.advance(static_cast<double>(k) * b.h, input, k > 1);
    counted.stop();
    w = counted;
  }
  alloc_row(name, w, expected);
  if (status != Status::Ok) std::printf("      !! advance failed: %s\n", pkm::status_name(status));
}

void allocations_section(Bench& b) {
  std::printf("4. Heap allocations inside time steps (malloc family incl. operator new; checked: core_allocations)\n");
  std::printf("   %-62s %8s  %s\n", "window", "malloc", "expected");
  // (i) state derivatives
  for (int i = 0; i < kForms; ++i) {
    Vec8 yk = b.y_mid, ydot;
    double acc = 0;
    AllocWindow w;
    for (int k = 0; k < 1000; ++k) {
      pkm::state_derivative(b.model, kFormulations[i], nudge(yk, b.y_mid, k), b.f_mid, ydot);
      acc += ydot[4];
    }
    w.stop();
    g_sink = acc;
    const std::string name = std::string("(i) 1000 state_derivative, ") + kFormNames[i];
    alloc_row(name.c_str(), w, "0");
  }
  // inverse dynamics (context)
  {
    pkm::InverseDynamicsResult r;
    b.inverse_at(0, r, false);
    for (const bool warm : {true, false}) {
      AllocWindow w;
      for (long j = 1; j <= 1000; ++j) b.inverse_at(j, r, warm);
      w.stop();
      alloc_row(warm ? "    1000 inverse_dynamics, warm" : "    1000 inverse_dynamics, cold", w, "0");
    }
  }
  // the analytic derivatives (item 1b)
  {
    Vec8 yk = b.y_mid, ydot;
    pkm::Mat8 A;
    pkm::Mat8x12 B;
    pkm::InverseDynamicsPartials d;
    double acc = 0;
    AllocWindow w;
    for (int k = 0; k < 1000; ++k) {
      nudge(yk, b.y_mid, k);
      pkm::state_derivative_jacobians(b.model, yk, b.id_mid.F, Vec4::Zero(), Wrench::Zero(), pkm::kStopsFromState,
                                      ydot, A, B);
      pkm::inverse_dynamics_derivatives(b.model, yk.head<4>(), b.pd, b.pdd, Wrench::Zero(), d);
      acc += A(4, 0) + d.dp(0, 0);
    }
    w.stop();
    g_sink = acc;
    alloc_row("    1000 state_derivative_jacobians + inverse_dynamics_derivatives", w, "0");
  }
  // (ii) RK4 Plant::advance, 1 s in 1-ms calls, after initialisation; (iii) CVODE, from the second call on
  pkm::PathForces rk4_forces = b.path_forces(), cvt_forces = b.path_forces(), cvd_forces = b.path_forces();
  plant_window(b, "(ii) RK4 advance 0..1 s, 1000 calls, table forces", b.rk4, b.table.signal(), false, "0");
  plant_window(b, "     RK4 advance 0..1 s, 1000 calls, PathForces (round trip)", b.rk4, rk4_forces.signal(), false,
               "0");
  const char* no_step_alloc = "0 (no alloc in steps)";
  plant_window(b, "(iii) CVODE 1e-12 advance 1..1001 ms, 1000 calls, PathForces", b.cv_tight, cvt_forces.signal(),
               true, no_step_alloc);
  plant_window(b, "      CVODE 1e-8 advance 1..1001 ms, 1000 calls, PathForces", b.cv_default, cvd_forces.signal(),
               true, no_step_alloc);
  plant_window(b, "      CVODE 1e-12 advance 1..1001 ms, 1000 calls, held forces", b.cv_tight, b.held.signal(), true,
               no_step_alloc);
  // Controls: windows that do allocate, to show that the counter sees them.
  {
    pkm::Plant plant(b.model);
    Status s = plant.set_solver(b.cv_tight);
    if (s == Status::Ok) s = plant.initialize(0.0, b.p0, b.pd0);
    AllocWindow w;
    if (s == Status::Ok) s = plant.advance(b.h, b.held.signal(), false);
    w.stop();
    alloc_row("control: CVODE first advance (creates the SUNDIALS objects)", w, "> 0");
    pkm::AutotestOptions opt;
    opt.solver = b.rk4;
    opt.path = b.path;
    pkm::AutotestResult res;
    AllocWindow w2;
    pkm::run_autotest(b.model, opt, res);
    w2.stop();
    alloc_row("control: one run_autotest, RK4 (samples vector, ...)", w2, "> 0");
  }
  rule();
}

// ------------------------------------------------------- machine-independent ratios
void ratios_section(const StateDerivativeFigures& sd, double jac_ratio, double reg_ratio,
                    const InverseDynamicsFigures& id, const AutotestFigures& a) {
  const double sd0 = sd[0].median;
  std::printf("Machine-independent ratios (medians)\n");
  std::printf("   sd(NullSpaceQR) / sd(LegPartitioned)                 %8.2f\n", sd[1].median / sd0);
  std::printf("   sd(Augmented)   / sd(LegPartitioned)                 %8.2f\n", sd[2].median / sd0);
  std::printf("   ID / sd(LegP): reduced, actuators only, [**]         %8.2f %8.2f %8.2f   (target <= %g, stretch %g)\n",
              id.reduced.median / sd0, id.actuators.median / sd0, id.stages.median / sd0, kInverseTarget,
              kInverseStretch);
  std::printf("   ID general / sd(LegP): cold, warm 0.5 ms             %8.2f %8.2f\n", id.general_cold.median / sd0,
              id.general_warm.median / sd0);
  std::printf("   Jacobians A, B / sd(LegP) (same run, item 1b)        %8.2f   (target <= 3)\n", jac_ratio);
  std::printf("   regressor / ID cold (same run, item 1c)              %8.2f   (target <= 2)\n", reg_ratio);
  std::printf("   RK4 forward run / (8000 x sd(LegP))                  %8.2f   (integrator + input overhead)\n",
              a.rk4_fwd.fig.median / (8000.0 * sd0));
  std::printf("   RK4 bare round trip / forward only                   %8.2f   (~ 1 + ID[**] / sd = %.2f)\n",
              a.rk4_bare.fig.median / a.rk4_fwd.fig.median, 1.0 + id.stages.median / sd0);
  std::printf("   RK4 run_autotest / forward only                      %8.2f\n",
              a.rk4_rt.fig.median / a.rk4_fwd.fig.median);
  std::printf("   CVODE rhs evaluations / RK4's 8000: 1e-12 %.2f, 1e-8 %.2f\n", static_cast<double>(a.cvt_rt.rhs) / 8000.0,
              static_cast<double>(a.cvd_rt.rhs) / 8000.0);
  std::printf("   CVODE run_autotest / RK4 run_autotest: 1e-12 %.2f, 1e-8 %.2f\n",
              a.cvt_rt.fig.median / a.rk4_rt.fig.median, a.cvd_rt.fig.median / a.rk4_rt.fig.median);
  std::printf("   targets: state derivative <= %g us: %s (%s);  2-s RK4 forward run <= 10 ms: %s (%s)\n",
              kDerivativeTarget * 1e6, ok_mark(sd0, kDerivativeTarget), fmt_time(sd0).c_str(), ok_mark(a.rk4_fwd.fig.median, 10e-3),
              fmt_time(a.rk4_fwd.fig.median).c_str());
  rule();
}

}  // namespace

int main(int argc, char** argv) {
  for (int i = 1; i < argc; ++i) {  // --quick: the documentation build's short run (timing.hpp, Effort)
    if (std::string(argv[i]) == "--quick") {
      bench::set_quick();
    } else {
      std::fprintf(stderr, "pkm_bench: unknown option %s (usage: pkm_bench [--quick])\n", argv[i]);
      return 2;
    }
  }
  Bench b;
  if (!set_up(b)) return 1;
  print_header();
  const StateDerivativeFigures sd = state_derivative_section(b);
  const double jac_ratio = derivatives_section(b);
  const double reg_ratio = regressor_section(b);
  const InverseDynamicsFigures id = inverse_dynamics_section(b, sd[0]);
  const AutotestFigures a = autotest_section(b, sd[0]);
  allocations_section(b);
  ratios_section(sd, jac_ratio, reg_ratio, id, a);
  if (b.failures) std::printf("%d measurement(s) FAILED (see the marks above)\n", b.failures);
  return b.failures ? 1 : 0;
}

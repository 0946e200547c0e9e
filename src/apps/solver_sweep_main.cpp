// SPDX-License-Identifier: BSD-2-Clause
// pkm_solver_sweep: every solver against CVODE at tight tolerance over a
// grid of machines that includes the declared extremes (docs/solvers.md
// "Accuracy"). Each case runs the plant in 1-ms communication steps with
// CVODE at the FMU's defaults, RK4 and ROS2 (rk4_step 1 ms), and compares
// every step each answered OK with the reference, CVODE (BDF) at rtol
// 1e-10, atol 1e-12. The error is the largest |velocity - reference| (dx,
// dy, dz, 0.1 m dphi) over the steps compared, relative to the reference's
// top speed over the run (at least 1 um/s: below, every solver's tolerance
// is absolute). The steps compared are those where the reference agrees
// with CVODE at rtol 1e-12, atol 1e-14 within a tenth of the tightest
// bound: beyond (undamped stiff stops after a few impacts: the motion turns
// chaotic) the reference itself is not known to that accuracy. A solver may
// refuse a case (at initialisation, or a step answered with a failure and a
// message); an OK step must be within the solver's bound (RK4 and ROS2;
// CVODE at its defaults promises its local tolerances only). Prints one
// Markdown table, a row per case, and a summary; exit status 1 if an OK
// step exceeds its bound or a refusal comes without a message, 2 on a
// wrong argument.
//
//   pkm_solver_sweep [--quick] [--only TEXT]
//
// --quick: the short sweep of the default test run (a few seconds); the
// docs build runs the full one. --only: the cases whose name contains TEXT.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <limits>
#include <string>
#include <vector>

#include "apps/autotest.hpp"
#include "pkm4puu/kinematics/constraints.hpp"
#include "pkm4puu/sim/fixed_step_stability.hpp"
#include "pkm4puu/sim/parameters.hpp"
#include "pkm4puu/sim/plant.hpp"

namespace {

using pkm::Params;
using pkm::Pose;
using pkm::SolverSettings;
using pkm::Status;

constexpr double kH = 1e-3;  // s, the communication step

/// The bounds an OK step is held to, relative to the run's top speed
/// (docs/solvers.md "Accuracy" says where they come from). CVODE at its
/// defaults promises its local tolerances only: its column is shown, not
/// held to a bound (infinity).
constexpr double kBoundCvode = std::numeric_limits<double>::infinity(), kBoundRk4 = 1e-4, kBoundRosenbrock = 1e-2;
/// The reference is trusted where it agrees with a tighter one this well
/// (a tenth of the tightest bound).
constexpr double kReferenceAgreement = 1e-5;
/// The speed below which errors are absolute (m/s): a machine slower than
/// 1 um/s stands (stuck friction creeps at a fraction of friction_velocity).
constexpr double kSpeedFloor = 1e-6;

enum class Drive { Drop, Autotest };

struct Case {
  std::string name;
  Params p;
  int steps;
  Drive drive = Drive::Drop;
  bool quick = false;  // in the --quick sweep
};

struct Run {
  std::vector<pkm::Vec4> v;  // the velocity after each OK step (dphi times 0.1 m)
  bool refused_at_init = false;
  Status failure = Status::Ok;  // the first failed step's status
  std::string message;
};

SolverSettings cvode_settings(double rtol, double atol) {
  SolverSettings s;
  s.cvode_method = pkm::CvodeMethod::BDF;
  s.rtol = rtol;
  s.atol = atol;
  return s;
}

Run run(const Case& c, const pkm::Model& m, const SolverSettings& s) {
  Run r;
  pkm::Plant plant(m);
  std::string why;
  if (plant.set_solver(s, &why) != Status::Ok) {
    r.refused_at_init = true;
    r.message = why;
    return r;
  }
  pkm::PathForces forces;
  forces.model = &m;
  const pkm::InputSignal input = c.drive == Drive::Autotest ? forces.signal() : pkm::InputSignal{};
  Pose p0(0.0, 0.0, 0.05, 0.0), v0 = Pose::Zero(), a0;
  if (c.drive == Drive::Autotest) forces.path.eval(0.0, p0, v0, a0);
  if (plant.initialize(0.0, p0, v0) != Status::Ok) {
    r.refused_at_init = true;
    r.message = plant.last_error();
    return r;
  }
  r.v.reserve(static_cast<size_t>(c.steps));
  for (int k = 1; k <= c.steps; ++k) {
    const Status st = plant.advance(k * kH, input, k > 1);
    if (st != Status::Ok) {
      r.failure = st;
      r.message = plant.last_error();
      break;
    }
    pkm::Vec4 v = plant.state().tail<4>();
    v[3] *= pkm::kConditionLength;
    r.v.push_back(v);
  }
  return r;
}

/// The reference's top speed over its steps, at least kSpeedFloor.
double speed_scale(const Run& ref) {
  double scale = kSpeedFloor;
  for (const pkm::Vec4& v : ref.v) scale = std::max(scale, v.cwiseAbs().maxCoeff());
  return scale;
}

/// The largest velocity error over the first n steps of r, relative to scale.
double relative_error(const Run& r, const Run& ref, size_t n, double scale) {
  double worst = 0.0;
  n = std::min(n, r.v.size());
  for (size_t k = 0; k < n; ++k) worst = std::max(worst, (r.v[k] - ref.v[k]).cwiseAbs().maxCoeff());
  return worst / scale;
}

std::vector<Case> cases() {
  std::vector<Case> out;
  auto add = [&out](std::string name, Params p, int steps, bool quick = false, Drive d = Drive::Drop) {
    out.push_back({std::move(name), p, steps, d, quick});
  };
  char name[160];
  Params p;
  // Repeated impacts: the default machine dropped onto its stops (F = 0 from
  // the home pose, the stops reached at 95 ms), bouncing until it rests.
  add("default machine, drop (3 impacts)", p, 300, true);
  add("default machine, drop, 1.5 s", p, 1500);
  // Long drops: the lower stops 2.5 m and 5 m below (falls of 0.7 s and
  // 1 s, impacts at 7 m/s and 10 m/s), each followed by a second impact.
  for (double depth : {2.5, 5.0}) {
    p = {};
    p.rho_min = -depth;
    std::snprintf(name, sizeof name, "drop of %g m (rho_min = -%g m), 2.5 s", depth, depth);
    add(name, p, 2500, depth == 2.5);
  }
  // The auto-test's inputs (the forces of the inverse dynamics along its path).
  add("auto-test, 2 s", Params{}, 2000, false, Drive::Autotest);
  add("auto-test, first 0.3 s", Params{}, 300, true, Drive::Autotest);
  // One parameter at a time over its declared range (the parameter table's
  // row: its upper end, its lower one unless that is the default, whose drop
  // is a case above, and points between), the drop.
  struct Axis {
    const char* name;
    std::vector<double> between;
    bool quick_at_hi;  // the run at the upper end is in the --quick sweep
  };
  const Axis axes[] = {
      {"stop_stiffness", {1e3, 1e7}, true},
      {"stop_damping", {1.0, 1e4}, false},
      {"friction_viscous", {1.0, 1e3}, true},
      {"friction_coulomb", {0.1, 5.0}, false},
      {"m_slider", {1e-2, 1e2}, false},
      {"m_platform", {1e2}, false},
      {"rotor_inertia", {1e-6}, false},
      {"payload_mass", {10.0}, false},
  };
  for (const Axis& a : axes) {
    const pkm::Parameter* row = pkm::find_parameter(a.name);
    if (!row) {
      std::fprintf(stderr, "pkm_solver_sweep: no parameter '%s' in the parameter table\n", a.name);
      std::exit(1);
    }
    std::vector<double> values;
    if (row->lo != row->start()) values.push_back(row->lo);
    values.insert(values.end(), a.between.begin(), a.between.end());
    values.push_back(row->hi);
    for (double v : values) {
      pkm::Configuration config;
      row->set(config, v);
      std::snprintf(name, sizeof name, "%s = %g %s", a.name, v, row->unit);
      add(name, config.params, 300, a.quick_at_hi && v == row->hi);
    }
  }
  // Stuck and viscous friction: the regularised Coulomb slope F_c / v_s at
  // its declared extremes, against the default and the lightest slider.
  for (double vs : {1e-9, 1e-6, 10.0}) {
    for (double ms : {Params{}.m_slider, 1e-6}) {
      p = {};
      p.friction_coulomb = 10.0;
      p.friction_velocity = vs;
      p.m_slider = ms;
      std::snprintf(name, sizeof name, "friction_coulomb = 10 N, friction_velocity = %g m/s, m_slider = %g kg%s", vs,
                    ms, vs < 1.0 ? " (stuck)" : "");
      add(name, p, 300, vs == 1e-9 && ms == 1e-6);
    }
  }
  // Breaking away: 1 N of Coulomb friction holds less than a slider's share
  // of the weight, so the machine slides from the first instant.
  for (double vs : {1e-9, 1e-6}) {
    p = {};
    p.friction_coulomb = 1.0;
    p.friction_velocity = vs;
    std::snprintf(name, sizeof name, "friction_coulomb = 1 N, friction_velocity = %g m/s (breaks away)", vs);
    add(name, p, 300, vs == 1e-9);
  }
  p = {};
  p.friction_coulomb = 1e6;
  p.friction_velocity = 1e-9;
  add("friction_coulomb = 1e6 N, friction_velocity = 1e-9 m/s (stuck)", p, 300, true);
  p = {};
  p.friction_viscous = 1e6;
  p.m_slider = 1e-6;
  add("friction_viscous = 1e6 N.s/m, m_slider = 1e-6 kg", p, 300);
  // The stiffest declared stops, overdamped and undamped.
  for (double ms : {Params{}.m_slider, 1e-6}) {
    p = {};
    p.stop_stiffness = 1e9;
    p.stop_damping = 1e6;
    p.m_slider = ms;
    std::snprintf(name, sizeof name, "stops 1e9 N/m, 1e6 N.s/m, m_slider = %g kg", ms);
    add(name, p, 300, true);
    p.stop_damping = 0.0;
    std::snprintf(name, sizeof name, "stops 1e9 N/m, undamped, m_slider = %g kg, 1 s", ms);
    add(name, p, 1000, ms == 1e-6);
  }
  p = {};
  p.stop_stiffness = 1e9;
  p.stop_damping = 1e6;
  p.friction_viscous = 1e6;
  p.m_slider = 1e-6;
  add("stops 1e9 N/m, 1e6 N.s/m, friction_viscous = 1e6 N.s/m, m_slider = 1e-6 kg", p, 300);
  return out;
}

struct Column {
  const char* name;
  SolverSettings s;
  double bound;
};

SolverSettings defaults_with(pkm::Solver solver) {
  SolverSettings s;  // the FMU's defaults
  s.solver = solver;
  return s;
}

/// One cell: the error, or how the run ended.
std::string cell(const Run& r, double err, double bound, int steps) {
  char buf[200];
  if (r.refused_at_init) return "refused at initialisation";
  const int ok = static_cast<int>(r.v.size());
  std::snprintf(buf, sizeof buf, "%.1e%s", err, err <= bound ? "" : " **over its bound**");
  std::string out = buf;
  if (ok < steps) out += std::string(", ") + pkm::status_name(r.failure) + " at step " + std::to_string(ok + 1);
  return out;
}

}  // namespace

int main(int argc, char** argv) {
  bool quick = false;
  const char* only = nullptr;
  for (int i = 1; i < argc; ++i) {
    if (std::strcmp(argv[i], "--quick") == 0) {
      quick = true;
    } else if (std::strcmp(argv[i], "--only") == 0 && i + 1 < argc) {
      only = argv[++i];
    } else {
      std::fprintf(stderr, "pkm_solver_sweep: unknown argument '%s'\nusage: pkm_solver_sweep [--quick] [--only TEXT]\n",
                   argv[i]);
      return 2;
    }
  }
  const Column columns[] = {{"CVODE, defaults", defaults_with(pkm::Solver::Cvode), kBoundCvode},
                            {"RK4, 1 ms", defaults_with(pkm::Solver::Rk4), kBoundRk4},
                            {"ROS2, 1 ms", defaults_with(pkm::Solver::Rosenbrock), kBoundRosenbrock}};
  std::printf("| case | steps compared | top speed (m/s) | ");
  for (const Column& c : columns) {
    if (std::isfinite(c.bound)) {
      std::printf("%s (bound %.0e) | ", c.name, c.bound);
    } else {
      std::printf("%s (no bound) | ", c.name);
    }
  }
  std::printf("\n|---|---|---|---|---|---|\n");
  int violations = 0, silent = 0, runs = 0, cases_run = 0;
  double worst[3] = {0, 0, 0};
  const auto t_start = std::chrono::steady_clock::now();
  for (const Case& c : cases()) {
    if (quick && !c.quick) continue;
    if (only && c.name.find(only) == std::string::npos) continue;
    ++cases_run;
    pkm::Model m;
    std::string why;
    if (pkm::make_model(c.p, m, &why) != Status::Ok) {
      std::fprintf(stderr, "pkm_solver_sweep: case '%s' is outside the declared ranges: %s\n", c.name.c_str(),
                   why.c_str());
      return 1;
    }
    const Run ref = run(c, m, cvode_settings(1e-10, 1e-12));
    const Run tight = run(c, m, cvode_settings(1e-12, 1e-14));
    const double scale = speed_scale(ref);
    // The steps where the two references agree (the first ones, up to the
    // first that does not).
    size_t trusted = 0;
    while (trusted < std::min(ref.v.size(), tight.v.size()) &&
           (ref.v[trusted] - tight.v[trusted]).cwiseAbs().maxCoeff() <= kReferenceAgreement * scale)
      ++trusted;
    std::string compared = std::to_string(trusted) + " of " + std::to_string(c.steps);
    if (ref.v.size() < static_cast<size_t>(c.steps))
      compared += " (the reference: " + std::string(pkm::status_name(ref.failure)) + " at step " +
                  std::to_string(ref.v.size() + 1) + ")";
    else if (trusted < static_cast<size_t>(c.steps))
      compared += " (then the references part)";
    std::printf("| %s | %s | %.2g | ", c.name.c_str(), compared.c_str(), scale);
    for (int j = 0; j < 3; ++j) {
      const Run r = run(c, m, columns[j].s);
      ++runs;
      const double err = relative_error(r, ref, trusted, scale);
      if (!(err <= columns[j].bound)) ++violations;
      if ((r.refused_at_init || r.failure != Status::Ok) && r.message.empty()) ++silent;
      worst[j] = std::max(worst[j], err);
      std::printf("%s | ", cell(r, err, columns[j].bound, c.steps).c_str());
      std::fflush(stdout);
    }
    std::printf("\n");
  }
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t_start).count();
  std::printf("\n%d cases, %d runs besides the references, in %.1f s. Worst over the cases, of the top speed: "
              "CVODE (defaults) %.1e, RK4 %.1e, ROS2 %.1e.\n",
              cases_run, runs, seconds, worst[0], worst[1], worst[2]);
  if (violations || silent) {
    std::printf("FAILED: %d runs with an OK step over its bound, %d refusals without a message\n", violations, silent);
    return 1;
  }
  return 0;
}

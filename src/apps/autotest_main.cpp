// SPDX-License-Identifier: BSD-2-Clause
// pkm_autotest: the paper's auto-test (section 5.1) with the C++ core.
// Inverse dynamics along the spec's rest-to-rest path gives F1..F4(t);
// forward dynamics driven by those forces (open loop, evaluated at the
// integrator's own stage times) must reproduce the path. Writes one CSV per
// solver, prints the largest pose errors and checks them against the
// bounds (kAutotestBounds): one PASS/FAIL line each, also written to
// DIR/autotest_checks.csv in the columns of pkm4puu.cli.checks (the
// main job's verdict reads it); exit status 1 when a check fails.
// A wrong argument (unknown option, missing value, a value that is not a
// number or out of range, an --out that cannot be written) fails at once,
// before anything runs, naming it: exit status 2.
//
//   pkm_autotest [--out DIR] [--solver rk4|cvode|both] [--rk4-step S]
//                [--rtol R] [--atol A] [--formulation 0|1|2]
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <string>
#include <vector>

#include "apps/autotest.hpp"

namespace {

void usage() {
  std::fprintf(stderr,
               "usage: pkm_autotest [--out DIR] [--solver rk4|cvode|both] [--rk4-step S]\n"
               "                    [--rtol R] [--atol A] [--formulation 0|1|2]\n");
}

[[noreturn]] void bad_argument(const std::string& why) {
  std::fprintf(stderr, "pkm_autotest: %s\n", why.c_str());
  usage();
  std::exit(2);
}

/// The value of `option`, a positive finite number, or bad_argument.
double positive_number(const std::string& option, const char* text) {
  errno = 0;
  char* end = nullptr;
  const double v = std::strtod(text, &end);
  if (end == text || *end != '\0' || errno == ERANGE)
    bad_argument(option + ": '" + text + "' is not a number");
  if (!std::isfinite(v) || v <= 0) bad_argument(option + ": '" + text + "' must be a positive number");
  return v;
}

/// Creates `dir` (with its parents) when missing; why it cannot hold the
/// results, or "" when it can.
std::string unwritable(const std::string& dir) {
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  if (ec) return "cannot create the directory: " + ec.message();
  if (!std::filesystem::is_directory(dir, ec)) return "not a directory";
  if (access(dir.c_str(), W_OK | X_OK) != 0) return std::string("not writable: ") + std::strerror(errno);
  return "";
}

void progress(void* user, double t, double t_end) {
  std::fprintf(stderr, "  [%s] t = %5.3f s of %.3f s (%3.0f%%)\n", static_cast<const char*>(user), t, t_end,
               100.0 * t / t_end);
}

/// One line of the verdict: a measured value against its bound
/// (pkm4puu.cli.checks's columns).
struct Check {
  std::string case_name, quantity;
  double measured, bound;
  const char* unit;
  bool passed() const { return measured <= bound; }  // false for NaN
};

bool write_checks(const std::string& path, const std::vector<Check>& checks) {
  FILE* f = std::fopen(path.c_str(), "w");
  if (!f) return false;
  std::fprintf(f, "case,quantity,measured,relation,bound,unit,verdict\n");
  for (const auto& c : checks)
    std::fprintf(f, "%s,%s,%.6e,<=,%g,%s,%s\n", c.case_name.c_str(), c.quantity.c_str(), c.measured, c.bound,
                 c.unit, c.passed() ? "PASS" : "FAIL");
  return std::fclose(f) == 0;
}

bool write_csv(const std::string& path, const pkm::AutotestResult& r) {
  FILE* f = std::fopen(path.c_str(), "w");
  if (!f) return false;
  std::fprintf(f,
               "t_s,x_ref_m,y_ref_m,z_ref_m,phi_ref_rad,x_m,y_m,z_m,phi_rad,"
               "F1_N,F2_N,F3_N,F4_N,F1_static_N,F2_static_N,F3_static_N,F4_static_N,rho1_m,rho2_m,rho3_m,rho4_m,constraint_residual_m,jacobian_condition\n");
  for (const auto& s : r.samples) {
    std::fprintf(f, "%.6f", s.t);
    for (int k = 0; k < 4; ++k) std::fprintf(f, ",%.17g", s.desired[k]);
    for (int k = 0; k < 4; ++k) std::fprintf(f, ",%.17g", s.simulated[k]);
    for (int k = 0; k < 4; ++k) std::fprintf(f, ",%.17g", s.F[k]);
    for (int k = 0; k < 4; ++k) std::fprintf(f, ",%.17g", s.F_static[k]);
    for (int k = 0; k < 4; ++k) std::fprintf(f, ",%.17g", s.rho[k]);
    std::fprintf(f, ",%.6e,%.6f\n", s.constraint_residual, s.jacobian_condition);
  }
  return std::fclose(f) == 0;
}

}  // namespace

int main(int argc, char** argv) {
  std::string out_dir = "results";
  std::string which = "both";
  pkm::SolverSettings base;
  base.rtol = 1e-12;
  base.atol = 1e-14;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    auto next = [&]() -> const char* {
      if (i + 1 >= argc) bad_argument(a + " needs a value");
      return argv[++i];
    };
    if (a == "--out") out_dir = next();
    else if (a == "--solver") which = next();
    else if (a == "--rk4-step") base.rk4_step = positive_number(a, next());
    else if (a == "--rtol") base.rtol = positive_number(a, next());
    else if (a == "--atol") base.atol = positive_number(a, next());
    else if (a == "--formulation") {
      const std::string f = next();
      if (f != "0" && f != "1" && f != "2") bad_argument("--formulation: '" + f + "' is not 0, 1 or 2");
      base.formulation = static_cast<pkm::Formulation>(f[0] - '0');
    } else if (a == "-h" || a == "--help") {
      usage();
      return 0;
    } else {
      bad_argument("unknown option '" + a + "'");
    }
  }
  if (which != "rk4" && which != "cvode" && which != "both")
    bad_argument("--solver: '" + which + "' is not rk4, cvode or both");
  if (const std::string why = unwritable(out_dir); !why.empty()) bad_argument("--out " + out_dir + ": " + why);

  pkm::Model model;
  std::string why;
  if (pkm::make_model(pkm::Params{}, model, &why) != pkm::Status::Ok) {
    std::fprintf(stderr, "pkm_autotest: %s\n", why.c_str());
    return 1;
  }
  std::printf("Auto-test (paper section 5.1): %.0f s rest-to-rest from P0 = (0, 0, 0.05 m, 0) to "
              "P1 = (0.005 m, -0.005 m, 0.07 m, 4 deg), gravity %.2f m/s^2, formulation: %s\n",
              pkm::RestToRest{}.duration, model.p.g, pkm::formulation_name(base.formulation));
  int failures = 0;
  std::vector<Check> checks;
  const pkm::AutotestBounds& bound = pkm::kAutotestBounds;
  for (const char* name : {"rk4", "cvode"}) {
    if (which != "both" && which != name) continue;
    pkm::AutotestOptions opt;
    opt.solver = base;
    opt.solver.solver = std::strcmp(name, "rk4") == 0 ? pkm::Solver::Rk4 : pkm::Solver::Cvode;
    opt.progress = &progress;
    opt.progress_user = const_cast<char*>(name);
    pkm::AutotestResult r;
    const auto t0 = std::chrono::steady_clock::now();
    const pkm::Status s = pkm::run_autotest(model, opt, r);
    const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    // A run that failed is checked too, with nothing measured: its lines fail.
    const std::string case_name = std::string("C++ auto-test ") + (opt.solver.solver == pkm::Solver::Rk4 ? "RK4" : "CVODE");
    const bool ran = s == pkm::Status::Ok;
    const double nan = std::nan("");
    checks.push_back({case_name, "max position error", ran ? r.max_position_error : nan, bound.position, "m"});
    checks.push_back({case_name, "max phi error", ran ? r.max_angle_error : nan, bound.angle, "rad"});
    checks.push_back({case_name, "max ||C(q)||", ran ? r.max_constraint_residual : nan, bound.constraint, "m"});
    if (!ran) {
      std::fprintf(stderr, "pkm_autotest [%s]: %s\n", name, r.error.c_str());
      ++failures;
      continue;
    }
    const std::string csv = out_dir + "/autotest_" + name + ".csv";
    if (!write_csv(csv, r)) {
      std::fprintf(stderr, "pkm_autotest: cannot write %s\n", csv.c_str());
      ++failures;
      continue;
    }
    if (std::strcmp(name, "rk4") == 0)
      std::printf("  RK4, h = %g s:", opt.solver.rk4_step);
    else
      std::printf("  CVODE Adams, rtol = %g, atol = %g:", opt.solver.rtol, opt.solver.atol);
    std::printf(" max |position error| = %.3e m, max |phi error| = %.3e rad, max ||C(q)|| = %.1e m, "
                "max cond(J) = %.2f, max |F - F_static| = %.4f N, %ld derivative evaluations (with inverse dynamics at each), %.2f s wall -> %s\n",
                r.max_position_error, r.max_angle_error, r.max_constraint_residual, r.max_jacobian_condition,
                r.max_dynamic_force, r.rhs_evaluations, wall, csv.c_str());
  }
  std::printf("Checks against the bounds:\n");
  for (const auto& c : checks) {
    std::printf("  %-40s %10.3e %-3s <= %-8g %s\n", (c.case_name + ": " + c.quantity).c_str(), c.measured, c.unit,
                c.bound, c.passed() ? "PASS" : "FAIL");
    if (!c.passed()) ++failures;
  }
  const std::string checks_csv = out_dir + "/autotest_checks.csv";
  if (!write_checks(checks_csv, checks)) {
    std::fprintf(stderr, "pkm_autotest: cannot write %s\n", checks_csv.c_str());
    ++failures;
  }
  return failures == 0 ? 0 : 1;
}

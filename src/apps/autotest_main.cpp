// SPDX-License-Identifier: BSD-2-Clause
// pkm_autotest: the paper's auto-test (section 5.1) with the C++ core.
// Inverse dynamics along the spec's rest-to-rest path gives F1..F4(t);
// forward dynamics driven by those forces (open loop, evaluated at the
// integrator's own stage times) must reproduce the path. Writes one CSV per
// solver and prints the largest pose errors.
//
//   pkm_autotest [--out DIR] [--solver rk4|cvode|both] [--rk4-step S]
//                [--rtol R] [--atol A] [--formulation 0|1|2]
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <sys/stat.h>

#include "apps/autotest.hpp"

namespace {

void usage() {
  std::fprintf(stderr,
               "usage: pkm_autotest [--out DIR] [--solver rk4|cvode|both] [--rk4-step S]\n"
               "                    [--rtol R] [--atol A] [--formulation 0|1|2]\n");
}

void progress(void* user, double t, double t_end) {
  std::fprintf(stderr, "  [%s] t = %5.3f s of %.3f s (%3.0f%%)\n", static_cast<const char*>(user), t, t_end,
               100.0 * t / t_end);
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
      if (i + 1 >= argc) {
        usage();
        std::exit(2);
      }
      return argv[++i];
    };
    if (a == "--out") out_dir = next();
    else if (a == "--solver") which = next();
    else if (a == "--rk4-step") base.rk4_step = std::atof(next());
    else if (a == "--rtol") base.rtol = std::atof(next());
    else if (a == "--atol") base.atol = std::atof(next());
    else if (a == "--formulation") base.formulation = static_cast<pkm::Formulation>(std::atoi(next()));
    else {
      usage();
      return 2;
    }
  }
  if (which != "rk4" && which != "cvode" && which != "both") {
    usage();
    return 2;
  }
  mkdir(out_dir.c_str(), 0755);

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
    if (s != pkm::Status::Ok) {
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
  return failures == 0 ? 0 : 1;
}

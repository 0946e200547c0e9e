// SPDX-License-Identifier: BSD-2-Clause
// The plain C API (pkm.h): creation and parameter errors, pose errors,
// forward and inverse dynamics through it, state save/restore, and that a
// failed call loses nothing.
#include <cmath>
#include <cstring>
#include <string>

#include <gtest/gtest.h>

#include "pkm4puu/pkm.h"

namespace {

struct Handle {
  pkm_model* m = nullptr;
  explicit Handle(const pkm_params* p = nullptr) {
    pkm_params d;
    pkm_default_params(&d);
    char err[256];
    EXPECT_EQ(pkm_create(p ? p : &d, &m, err, sizeof err), PKM_OK) << err;
  }
  ~Handle() { pkm_destroy(m); }
};

const double kHome[4] = {0.0, 0.0, 0.05, 0.0};

}  // namespace

// One version: CMake's project() (PKM_PROJECT_VERSION, set by
// tests/CMakeLists.txt), the header's macros and the library's answer.
TEST(CApi, VersionIsTheProjectVersionInHeaderAndLibrary) {
  const std::string numbers = std::to_string(PKM_VERSION_MAJOR) + "." + std::to_string(PKM_VERSION_MINOR) + "." +
                              std::to_string(PKM_VERSION_PATCH);
  EXPECT_EQ(numbers, PKM_PROJECT_VERSION);
  EXPECT_STREQ(PKM_VERSION_STRING, PKM_PROJECT_VERSION);
  EXPECT_STREQ(pkm_version(), PKM_PROJECT_VERSION);
}

TEST(CApi, CreateRejectsBadParametersWithAMessage) {
  pkm_params p;
  pkm_default_params(&p);
  p.r_b = -1.0;
  pkm_model* m = reinterpret_cast<pkm_model*>(0x1);
  char err[256] = "";
  EXPECT_EQ(pkm_create(&p, &m, err, sizeof err), PKM_ERR_INVALID_PARAMETER);
  EXPECT_EQ(m, nullptr);
  EXPECT_NE(std::string(err).find("r_b"), std::string::npos) << err;
  EXPECT_EQ(pkm_create(nullptr, &m, err, sizeof err), PKM_ERR_INVALID_ARGUMENT);
  EXPECT_EQ(pkm_create(&p, nullptr, nullptr, 0), PKM_ERR_INVALID_ARGUMENT);
}

TEST(CApi, UnreachablePoseIsAnErrorWithAMessage) {
  Handle h;
  const double far[4] = {0.2, 0.0, 0.05, 0.0};
  EXPECT_EQ(pkm_init_pose(h.m, 0.0, far, nullptr), PKM_ERR_UNREACHABLE);
  EXPECT_NE(std::string(pkm_last_error(h.m)).find("unreachable"), std::string::npos) << pkm_last_error(h.m);
  double F[4] = {0, 0, 0, 0};
  EXPECT_EQ(pkm_advance(h.m, 0.01, F, nullptr), PKM_ERR_NOT_INITIALIZED);
}

TEST(CApi, NonFiniteForceIsRejectedAndTheStateKept) {
  Handle h;
  ASSERT_EQ(pkm_init_pose(h.m, 0.0, kHome, nullptr), PKM_OK);
  double t0, y0[8];
  ASSERT_EQ(pkm_get_state(h.m, &t0, y0, nullptr), PKM_OK);
  const double bad[4] = {1.0, NAN, 1.0, 1.0};
  EXPECT_EQ(pkm_advance(h.m, 0.01, bad, nullptr), PKM_ERR_NONFINITE);
  double t1, y1[8];
  ASSERT_EQ(pkm_get_state(h.m, &t1, y1, nullptr), PKM_OK);
  EXPECT_EQ(t0, t1);
  EXPECT_EQ(std::memcmp(y0, y1, sizeof y0), 0);
}

TEST(CApi, StaticForcesHoldTheHomePose) {
  // Inverse dynamics at rest, fed forward for 0.5 s, keeps the platform put.
  Handle h;
  const double zero[4] = {0, 0, 0, 0};
  pkm_inverse_result inv;
  ASSERT_EQ(pkm_inverse_dynamics(h.m, kHome, zero, zero, nullptr, &inv), PKM_OK);
  for (int i = 0; i < 4; ++i) EXPECT_NEAR(inv.F[i], 2.655616050, 1e-9);
  for (int solver : {PKM_SOLVER_CVODE, PKM_SOLVER_RK4, PKM_SOLVER_ROSENBROCK}) {
    pkm_solver_settings s;
    pkm_default_solver_settings(&s);
    s.solver = solver;
    ASSERT_EQ(pkm_set_solver(h.m, &s), PKM_OK);
    ASSERT_EQ(pkm_init_pose(h.m, 0.0, kHome, nullptr), PKM_OK);
    ASSERT_EQ(pkm_advance(h.m, 0.5, inv.F, nullptr), PKM_OK) << pkm_last_error(h.m);
    pkm_outputs out;
    ASSERT_EQ(pkm_get_outputs(h.m, inv.F, nullptr, &out), PKM_OK);
    EXPECT_DOUBLE_EQ(out.t, 0.5);
    for (int k = 0; k < 4; ++k) EXPECT_NEAR(out.pose[k], kHome[k], 1e-12) << "solver " << solver;
    for (int k = 0; k < 12; ++k) EXPECT_NEAR(out.lambda[k], inv.lambda[k], 1e-9);
    EXPECT_LT(out.constraint_residual, 1e-15);
    EXPECT_GT(out.jacobian_condition, 1.0);
    EXPECT_LT(out.jacobian_condition, 26.0);
  }
}

TEST(CApi, SavedStateRestoresABitIdenticalContinuation) {
  for (int solver : {PKM_SOLVER_RK4, PKM_SOLVER_ROSENBROCK}) {
    Handle h;
    pkm_solver_settings s;
    pkm_default_solver_settings(&s);
    s.solver = solver;
    ASSERT_EQ(pkm_set_solver(h.m, &s), PKM_OK);
    const double v0[4] = {0.01, 0.0, 0.0, 0.05};
    ASSERT_EQ(pkm_init_pose(h.m, 0.0, kHome, v0), PKM_OK);
    const double F[4] = {2.7, 2.6, 2.65, 2.66};
    ASSERT_EQ(pkm_advance(h.m, 0.2, F, nullptr), PKM_OK);
    double t, y[8], th[4];
    ASSERT_EQ(pkm_get_state(h.m, &t, y, th), PKM_OK);
    ASSERT_EQ(pkm_advance(h.m, 0.4, F, nullptr), PKM_OK);
    pkm_outputs a, b;
    ASSERT_EQ(pkm_get_outputs(h.m, F, nullptr, &a), PKM_OK);
    ASSERT_EQ(pkm_set_state(h.m, t, y, th), PKM_OK);
    ASSERT_EQ(pkm_advance(h.m, 0.4, F, nullptr), PKM_OK);
    ASSERT_EQ(pkm_get_outputs(h.m, F, nullptr, &b), PKM_OK);
    EXPECT_EQ(std::memcmp(&a, &b, sizeof a), 0) << "solver " << solver;
    EXPECT_NE(a.pose[0], kHome[0]);  // it did move
  }
}

TEST(CApi, StepChecksAreSetCheckedAndKeptBySetSolver) {
  Handle h;
  double budget = 0, tolerance = -1;
  ASSERT_EQ(pkm_get_step_checks(h.m, &budget, &tolerance), PKM_OK);
  EXPECT_EQ(budget, 1000.0);
  EXPECT_EQ(tolerance, 0.0);
  EXPECT_EQ(pkm_set_step_checks(h.m, 0.5, 0.0), PKM_ERR_INVALID_ARGUMENT);  // below 1 inner step
  EXPECT_NE(std::string(pkm_last_error(h.m)).find("work_budget"), std::string::npos);
  EXPECT_EQ(pkm_set_step_checks(h.m, 10.0, -1.0), PKM_ERR_INVALID_ARGUMENT);
  EXPECT_NE(std::string(pkm_last_error(h.m)).find("energy_tolerance"), std::string::npos);
  ASSERT_EQ(pkm_set_step_checks(h.m, 10.0, 1e-3), PKM_OK);
  pkm_solver_settings s;
  pkm_default_solver_settings(&s);
  s.solver = PKM_SOLVER_RK4;
  ASSERT_EQ(pkm_set_solver(h.m, &s), PKM_OK);
  ASSERT_EQ(pkm_get_step_checks(h.m, &budget, &tolerance), PKM_OK);
  EXPECT_EQ(budget, 10.0);
  EXPECT_EQ(tolerance, 1e-3);
  // F = 0 from the home pose: the fall reaches the stops at 95 ms, whose
  // located contact (about 30 bisection trials) does not fit 10 inner steps.
  ASSERT_EQ(pkm_init_pose(h.m, 0.0, kHome, nullptr), PKM_OK);
  const double zero[4] = {0, 0, 0, 0};
  pkm_status st = PKM_OK;
  for (int k = 1; k <= 200 && st == PKM_OK; ++k) st = pkm_advance(h.m, k * 1e-3, zero, nullptr);
  EXPECT_EQ(st, PKM_ERR_SOLVER);
  EXPECT_NE(std::string(pkm_last_error(h.m)).find("work budget"), std::string::npos) << pkm_last_error(h.m);
}

TEST(CApi, CallbackInputsMatchConstantInputs) {
  Handle h1, h2;
  const double F[4] = {2.7, 2.6, 2.65, 2.66};
  ASSERT_EQ(pkm_init_pose(h1.m, 0.0, kHome, nullptr), PKM_OK);
  ASSERT_EQ(pkm_init_pose(h2.m, 0.0, kHome, nullptr), PKM_OK);
  ASSERT_EQ(pkm_advance(h1.m, 0.3, F, nullptr), PKM_OK);
  auto cb = [](void* user, double, double f[4], double w[4]) {
    std::memcpy(f, user, 4 * sizeof(double));
    for (int i = 0; i < 4; ++i) w[i] = 0.0;
  };
  ASSERT_EQ(pkm_advance_fn(h2.m, 0.3, cb, const_cast<double*>(F), 0), PKM_OK);
  double t1, y1[8], t2, y2[8];
  pkm_get_state(h1.m, &t1, y1, nullptr);
  pkm_get_state(h2.m, &t2, y2, nullptr);
  EXPECT_EQ(std::memcmp(y1, y2, sizeof y1), 0);
}

TEST(CApi, BadSolverSettingsAreRejected) {
  Handle h;
  pkm_solver_settings s;
  pkm_default_solver_settings(&s);
  s.rk4_step = -1e-3;
  EXPECT_EQ(pkm_set_solver(h.m, &s), PKM_ERR_INVALID_ARGUMENT);
  EXPECT_NE(std::string(pkm_last_error(h.m)).find("rk4_step"), std::string::npos);
  pkm_default_solver_settings(&s);
  s.solver = 7;
  EXPECT_EQ(pkm_set_solver(h.m, &s), PKM_ERR_INVALID_ARGUMENT);
}

TEST(CApi, EnergyIsAvailable) {
  Handle h;
  const double v0[4] = {0.0, 0.0, 0.1, 0.0};
  ASSERT_EQ(pkm_init_pose(h.m, 0.0, kHome, v0), PKM_OK);
  double T, U;
  ASSERT_EQ(pkm_energy(h.m, &T, &U), PKM_OK);
  // Pure vertical motion: every body moves at 0.1 m/s, nothing rotates.
  EXPECT_NEAR(T, 0.5 * (0.45474 + 4 * (0.09331 + 0.06371)) * 0.01, 1e-15);
}

TEST(CApi, ReadingOutputsChangesNothing) {
  // An FMU state saved after reading outputs equals one saved without.
  Handle h;
  const double v0[4] = {0.01, -0.01, 0.0, 0.1};
  ASSERT_EQ(pkm_init_pose(h.m, 0.0, kHome, v0), PKM_OK);
  const double F[4] = {2.7, 2.6, 2.65, 2.66};
  ASSERT_EQ(pkm_advance(h.m, 0.1, F, nullptr), PKM_OK);
  double t1, y1[8], th1[4], t2, y2[8], th2[4];
  ASSERT_EQ(pkm_get_state(h.m, &t1, y1, th1), PKM_OK);
  pkm_outputs out;
  ASSERT_EQ(pkm_get_outputs(h.m, F, nullptr, &out), PKM_OK);
  ASSERT_EQ(pkm_get_state(h.m, &t2, y2, th2), PKM_OK);
  EXPECT_EQ(std::memcmp(th1, th2, sizeof th1), 0);
  EXPECT_EQ(std::memcmp(y1, y2, sizeof y1), 0);
  for (int i = 0; i < 4; ++i) EXPECT_EQ(out.theta1[i], th1[i]);
}

// The derivatives through the C API: the layout (row-major, the inputs'
// order) against central differences of the accelerations pkm_get_outputs
// reports and of pkm_inverse_dynamics_machine; their accuracy is
// test_derivatives' subject.
namespace {

struct MachineHandle {
  pkm_model* m = nullptr;
  MachineHandle() {
    pkm_params p;
    pkm_default_params(&p);
    pkm_machine_params mp;
    pkm_default_machine_params(&mp);
    mp.friction_viscous = 1.5;
    mp.payload_mass = 0.3;
    mp.payload_com[0] = 0.02;
    char err[256];
    EXPECT_EQ(pkm_create_machine(&p, &mp, &m, err, sizeof err), PKM_OK) << err;
  }
  ~MachineHandle() { pkm_destroy(m); }
};

// Fourth-order central difference of s -> f(s)[0..3] at s = 0.
template <class F>
void d_ds4(F f, double h, double out[4]) {
  double a[4] = {}, b[4] = {}, c[4] = {}, d[4] = {};  // zero if f stops at a failed assertion
  f(-2 * h, a), f(-h, b), f(h, c), f(2 * h, d);
  for (int i = 0; i < 4; ++i) out[i] = (a[i] - 8 * b[i] + 8 * c[i] - d[i]) / (12 * h);
}

}  // namespace

TEST(CApi, ForwardDerivativesAreRowMajorInTheInputsOrder) {
  MachineHandle h;
  const double y[8] = {0.004, -0.003, 0.06, 0.05, 0.1, -0.05, 0.08, 0.7};
  const double u[PKM_PLANT_INPUTS] = {2.7, 2.5, 2.9, 2.6, 0.3, -0.2, 0.5, 0.01, 0, 0, 0, 0};
  double ydot[8], A[64], B[96];
  ASSERT_EQ(pkm_forward_derivatives(h.m, y, u, ydot, A, B), PKM_OK);
  // The accelerations pkm_get_outputs reports at a state for F and wrench = u[4..7].
  auto acc = [&](const double* ys, const double* us, double out[4]) {
    ASSERT_EQ(pkm_init_pose(h.m, 0.0, ys, ys + 4), PKM_OK);
    pkm_outputs o;
    ASSERT_EQ(pkm_get_outputs(h.m, us, us + 4, &o), PKM_OK);
    for (int i = 0; i < 4; ++i) out[i] = o.acceleration[i];
  };
  double a0[4];
  acc(y, u, a0);
  for (int i = 0; i < 4; ++i) {
    EXPECT_EQ(ydot[i], y[4 + i]);
    EXPECT_NEAR(ydot[4 + i], a0[i], 1e-9 * (1 + std::fabs(a0[i])));
  }
  for (int k = 0; k < 16; ++k) {  // 8 state columns, then F and the wrench
    double d[4];
    d_ds4([&](double s, double out[4]) {
      double ys[8], us[PKM_PLANT_INPUTS];
      std::memcpy(ys, y, sizeof ys);
      std::memcpy(us, u, sizeof us);
      if (k < 8) ys[k] += s; else us[k - 8] += s;
      acc(ys, us, out);
    }, k < 8 ? 1e-5 : 1e-2, d);
    for (int i = 0; i < 4; ++i) {
      const double an = k < 8 ? A[8 * (4 + i) + k] : B[12 * (4 + i) + (k - 8)];
      EXPECT_NEAR(an, d[i], 1e-5 * (1 + std::fabs(d[i]))) << "row " << 4 + i << " column " << k;
    }
  }
  // A motor torque acts as (2 pi / screw_lead) times a force (docs/model.md "The machine around the mechanism").
  for (int i = 0; i < 4; ++i)
    for (int j = 0; j < 4; ++j)
      EXPECT_NEAR(B[12 * (4 + i) + 8 + j], 2 * M_PI / 0.004 * B[12 * (4 + i) + j], 1e-12 * std::fabs(B[12 * (4 + i) + 8 + j]));
}

TEST(CApi, InverseDerivativesAreRowMajorOverPoseRatesAccelerationsWrench) {
  MachineHandle h;
  const double x[16] = {0.004, -0.003, 0.06, 0.05, 0.1, -0.05, 0.08, 0.7, 0.8, -0.5, 1.1, 6.0, 0.3, -0.2, 0.5, 0.01};
  double F[4], dF[64];
  ASSERT_EQ(pkm_inverse_derivatives(h.m, x, x + 4, x + 8, x + 12, F, dF), PKM_OK);
  auto forces = [&](const double* xs, double out[4]) {
    pkm_inverse_machine_result r;
    ASSERT_EQ(pkm_inverse_dynamics_machine(h.m, xs, xs + 4, xs + 8, xs + 12, &r), PKM_OK);
    for (int i = 0; i < 4; ++i) out[i] = r.F[i];
  };
  double F0[4];
  forces(x, F0);
  for (int i = 0; i < 4; ++i) EXPECT_NEAR(F[i], F0[i], 1e-11 * std::fabs(F0[i]));
  for (int k = 0; k < 16; ++k) {
    double d[4];
    d_ds4([&](double s, double out[4]) {
      double xs[16];
      std::memcpy(xs, x, sizeof xs);
      xs[k] += s;
      forces(xs, out);
    }, k < 4 ? 1e-5 : 1e-3, d);
    for (int i = 0; i < 4; ++i)
      EXPECT_NEAR(dF[16 * i + k], d[i], 1e-5 * (1 + std::fabs(d[i]))) << "row " << i << " column " << k;
  }
  EXPECT_EQ(pkm_inverse_derivatives(h.m, x, x + 4, x + 8, nullptr, F, nullptr), PKM_ERR_INVALID_ARGUMENT);
}

// Calibration: Y pi + F0 is the machine's inverse dynamics; the batch
// functions give the single sample's Y; a slider position out of reach is
// an error that names the sample.
TEST(CApi, RegressorTimesTheModelsParametersIsTheInverseDynamics) {
  MachineHandle h;
  ASSERT_EQ(pkm_regressor_param_count(), PKM_REGRESSOR_PARAMS);
  EXPECT_STREQ(pkm_regressor_param_name(0), "m_slider");
  EXPECT_STREQ(pkm_regressor_param_unit(PKM_REGRESSOR_PARAMS - 1), "N");
  EXPECT_EQ(pkm_regressor_param_name(PKM_REGRESSOR_PARAMS), nullptr);
  double pi[PKM_REGRESSOR_PARAMS];
  ASSERT_EQ(pkm_regressor_params(h.m, pi), PKM_OK);
  EXPECT_DOUBLE_EQ(pi[8], 0.3 * 0.02);  // payload_mx = payload_mass payload_com[1]
  const double x[16] = {0.004, -0.003, 0.06, 0.05, 0.1, -0.05, 0.08, 0.7, 0.8, -0.5, 1.1, 6.0, 0.3, -0.2, 0.5, 0.01};
  double Y[4 * PKM_REGRESSOR_PARAMS], F0[4];
  ASSERT_EQ(pkm_regressor(h.m, x, x + 4, x + 8, x + 12, Y, F0), PKM_OK);
  pkm_inverse_machine_result r;
  ASSERT_EQ(pkm_inverse_dynamics_machine(h.m, x, x + 4, x + 8, x + 12, &r), PKM_OK);
  for (int i = 0; i < 4; ++i) {
    double F = F0[i];
    for (int j = 0; j < PKM_REGRESSOR_PARAMS; ++j) F += Y[PKM_REGRESSOR_PARAMS * i + j] * pi[j];  // row-major
    EXPECT_NEAR(F, r.F[i], 1e-12 * std::fabs(r.F[i]) + 1e-13) << "leg " << i + 1;
  }
  // The batch over two samples, without wrench, and back from the sliders.
  const double poses[8] = {x[0], x[1], x[2], x[3], 0.0, 0.0, 0.05, 0.0};
  const double vel[8] = {x[4], x[5], x[6], x[7], 0, 0, 0, 0}, acc[8] = {x[8], x[9], x[10], x[11], 0, 0, 0, 0};
  double Yb[8 * PKM_REGRESSOR_PARAMS], rho[8], drho[8], Ys[4 * PKM_REGRESSOR_PARAMS];
  ASSERT_EQ(pkm_regressor_poses(h.m, 2, poses, vel, acc, Yb, nullptr, rho, drho), PKM_OK);
  ASSERT_EQ(pkm_regressor(h.m, poses, vel, acc, nullptr, Ys, nullptr), PKM_OK);
  for (int k = 0; k < 4 * PKM_REGRESSOR_PARAMS; ++k) EXPECT_EQ(Yb[k], Ys[k]);
  double ddrho[8] = {}, Yj[8 * PKM_REGRESSOR_PARAMS], pose[8];
  size_t done = 99;
  ASSERT_EQ(pkm_regressor_joints(h.m, 1, rho + 4, drho + 4, ddrho, nullptr, Yj, nullptr, pose, &done), PKM_OK);
  EXPECT_EQ(done, 1u);
  for (int i = 0; i < 4; ++i) EXPECT_NEAR(pose[i], kHome[i], 1e-14);
  double bad_rho[8] = {rho[0], rho[1], rho[2], rho[3], -0.2, 0.1, 0.1, 0.1};
  EXPECT_NE(pkm_regressor_joints(h.m, 2, bad_rho, drho, drho, nullptr, Yj, nullptr, pose, &done), PKM_OK);
  EXPECT_EQ(done, 1u);
  EXPECT_NE(std::string(pkm_last_error(h.m)).find("sample 1 of 2"), std::string::npos) << pkm_last_error(h.m);
  EXPECT_EQ(pkm_regressor(h.m, x, x + 4, nullptr, nullptr, Y, F0), PKM_ERR_INVALID_ARGUMENT);
}

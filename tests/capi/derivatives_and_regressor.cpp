// SPDX-License-Identifier: BSD-2-Clause
// The derivatives and the regressor through the C API (pkm.h): their
// row-major layouts against central differences of pkm_get_outputs and
// pkm_inverse_dynamics, the regressor times the model's parameters against
// the inverse dynamics, its batch functions and their errors.
#include <cmath>
#include <cstddef>
#include <cstring>

#include <gtest/gtest.h>

#include "capi_support.hpp"
#include "pkm4puu/pkm.h"

using namespace pkm_test;

// The derivatives through the C API: the layout (row-major, the inputs'
// order) against central differences of the accelerations pkm_get_outputs
// reports and of pkm_inverse_dynamics; their accuracy is test_derivatives'
// subject.
namespace {

struct MachineHandle : Handle {
  MachineHandle() {
    const char* names[] = {"friction_viscous", "payload_mass", "payload_com[1]"};
    const double values[] = {1.5, 0.3, 0.02};
    EXPECT_EQ(pkm_set_parameters(m, 3, names, values), PKM_OK) << error();
  }
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
  double ydot[8], A[64], B[8 * PKM_PLANT_INPUTS];
  ASSERT_EQ(pkm_forward_derivatives(h.m, y, u, ydot, A, B), PKM_OK);
  // The accelerations pkm_get_outputs reports at a state for the inputs.
  auto acc = [&](const double* ys, const double* us, double out[4]) {
    ASSERT_EQ(pkm_init_pose(h.m, 0.0, ys, ys + 4), PKM_OK);
    pkm_outputs o = sized<pkm_outputs>();
    ASSERT_EQ(pkm_get_outputs(h.m, us, &o), PKM_OK);
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
      const double an = k < 8 ? A[8 * (4 + i) + k] : B[PKM_PLANT_INPUTS * (4 + i) + (k - 8)];
      EXPECT_NEAR(an, d[i], 1e-5 * (1 + std::fabs(d[i]))) << "row " << 4 + i << " column " << k;
    }
  }
  // A motor torque acts as (2 pi / screw_lead) times a force (docs/model.md "The machine around the mechanism").
  for (int i = 0; i < 4; ++i)
    for (int j = 0; j < 4; ++j)
      EXPECT_NEAR(B[12 * (4 + i) + 8 + j], 2 * kPi / 0.004 * B[12 * (4 + i) + j],
                  1e-12 * std::fabs(B[12 * (4 + i) + 8 + j]));
}

TEST(CApi, InverseDerivativesAreRowMajorOverPoseRatesAccelerationsWrench) {
  MachineHandle h;
  const double x[16] = {0.004, -0.003, 0.06, 0.05, 0.1, -0.05, 0.08, 0.7, 0.8, -0.5, 1.1, 6.0, 0.3, -0.2, 0.5, 0.01};
  double F[4], dF[64];
  ASSERT_EQ(pkm_inverse_derivatives(h.m, x, x + 4, x + 8, x + 12, F, dF), PKM_OK);
  auto forces = [&](const double* xs, double out[4]) {
    pkm_inverse_result r = sized<pkm_inverse_result>();
    ASSERT_EQ(pkm_inverse_dynamics(h.m, xs, xs + 4, xs + 8, xs + 12, &r), PKM_OK);
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
// an error that names the sample and says how many were written.
TEST(CApi, RegressorTimesTheModelsParametersIsTheInverseDynamics) {
  MachineHandle h;
  EXPECT_STREQ(pkm_regressor_param_name(0), "m_slider");
  EXPECT_STREQ(pkm_regressor_param_unit(PKM_REGRESSOR_PARAMS - 1), "N");
  EXPECT_EQ(pkm_regressor_param_name(PKM_REGRESSOR_PARAMS), nullptr);
  double pi[PKM_REGRESSOR_PARAMS];
  ASSERT_EQ(pkm_regressor_params(h.m, pi), PKM_OK);
  EXPECT_DOUBLE_EQ(pi[8], 0.3 * 0.02);  // payload_mx = payload_mass payload_com[1]
  const double x[16] = {0.004, -0.003, 0.06, 0.05, 0.1, -0.05, 0.08, 0.7, 0.8, -0.5, 1.1, 6.0, 0.3, -0.2, 0.5, 0.01};
  double Y[4 * PKM_REGRESSOR_PARAMS], F0[4];
  ASSERT_EQ(pkm_regressor(h.m, x, x + 4, x + 8, x + 12, Y, F0), PKM_OK);
  pkm_inverse_result r = sized<pkm_inverse_result>();
  ASSERT_EQ(pkm_inverse_dynamics(h.m, x, x + 4, x + 8, x + 12, &r), PKM_OK);
  for (int i = 0; i < 4; ++i) {
    double F = F0[i];
    for (int j = 0; j < PKM_REGRESSOR_PARAMS; ++j) F += Y[PKM_REGRESSOR_PARAMS * i + j] * pi[j];  // row-major
    EXPECT_NEAR(F, r.F[i], 1e-12 * std::fabs(r.F[i]) + 1e-13) << "leg " << i + 1;
  }
  // The batch over two samples, without wrench, and back from the sliders.
  const double poses[8] = {x[0], x[1], x[2], x[3], 0.0, 0.0, 0.05, 0.0};
  const double vel[8] = {x[4], x[5], x[6], x[7], 0, 0, 0, 0}, acc[8] = {x[8], x[9], x[10], x[11], 0, 0, 0, 0};
  double Yb[8 * PKM_REGRESSOR_PARAMS], rho[8], drho[8], Ys[4 * PKM_REGRESSOR_PARAMS];
  size_t done = 99;
  ASSERT_EQ(pkm_regressor_poses(h.m, 2, poses, vel, acc, Yb, nullptr, rho, drho, &done), PKM_OK);
  EXPECT_EQ(done, 2u);
  ASSERT_EQ(pkm_regressor(h.m, poses, vel, acc, nullptr, Ys, nullptr), PKM_OK);
  for (int k = 0; k < 4 * PKM_REGRESSOR_PARAMS; ++k) EXPECT_EQ(Yb[k], Ys[k]);
  double ddrho[8] = {}, Yj[8 * PKM_REGRESSOR_PARAMS], pose[8];
  ASSERT_EQ(pkm_regressor_joints(h.m, 1, rho + 4, drho + 4, ddrho, nullptr, Yj, nullptr, pose, &done), PKM_OK);
  EXPECT_EQ(done, 1u);
  for (int i = 0; i < 4; ++i) EXPECT_NEAR(pose[i], kHome[i], 1e-14);
  double bad_rho[8] = {rho[0], rho[1], rho[2], rho[3], -0.2, 0.1, 0.1, 0.1};
  EXPECT_NE(pkm_regressor_joints(h.m, 2, bad_rho, drho, drho, nullptr, Yj, nullptr, pose, &done), PKM_OK);
  EXPECT_EQ(done, 1u);
  EXPECT_TRUE(contains(h.error(), "sample 1 of 2")) << h.error();
  EXPECT_EQ(pkm_regressor(h.m, x, x + 4, nullptr, nullptr, Y, F0), PKM_ERR_INVALID_ARGUMENT);
}

TEST(CApi, RegressorPosesSaysHowManySamplesItWrote) {
  Handle h;
  const double poses[12] = {0.0, 0.0, 0.05, 0.0, 0.2, 0.0, 0.05, 0.0, 0.0, 0.0, 0.05, 0.0};  // sample 1 out of reach
  double Y[3 * 4 * PKM_REGRESSOR_PARAMS];
  for (double& v : Y) v = 1234.5;
  size_t done = 99;
  EXPECT_EQ(pkm_regressor_poses(h.m, 3, poses, poses, poses, Y, nullptr, nullptr, nullptr, &done),
            PKM_ERR_UNREACHABLE);
  EXPECT_EQ(done, 1u);
  EXPECT_TRUE(contains(h.error(), "sample 1 of 3")) << h.error();
  EXPECT_NE(Y[0], 1234.5);  // sample 0 written
  for (int k = 4 * PKM_REGRESSOR_PARAMS; k < 3 * 4 * PKM_REGRESSOR_PARAMS; ++k) ASSERT_EQ(Y[k], 1234.5) << k;
}

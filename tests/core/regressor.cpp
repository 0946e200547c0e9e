// SPDX-License-Identifier: BSD-2-Clause
// The dynamic-parameter regressor (dynamics/regressor.hpp): Y pi + F0
// against the inverse dynamics with the machine (rotor, friction, payload,
// wrench), each column against a difference quotient of the inverse
// dynamics in that parameter, the joint-space path against the pose path,
// and the base parameters from a column-pivoted QR of stacked regressors.
#include <cmath>

#include "pkm4puu/dynamics/inverse_dynamics.hpp"
#include "pkm4puu/dynamics/regressor.hpp"
#include "test_support.hpp"

using namespace pkm_test;

namespace {

// A machine with every term of pi non-zero: every_machine_term() (rotors,
// friction, an off-centre payload).

RegressorSample regressor_at(const Model& m, const Motion& mo) {
  RegressorSample r;
  EXPECT_EQ(regressor(m, mo.pose, mo.vel, mo.acc, mo.we, r), Status::Ok);
  return r;
}

Vec4 inverse_forces(const Model& m, const Motion& mo) { return inverse_dynamics_of(m, mo).F; }

/// The model whose pi is `pi` (the struct's other fields from `base`).
Model model_with(const Params& base, const ParamVector& pi) {
  Params p = base;
  std::string why;
  EXPECT_EQ(apply_parameter_vector(pi, p, &why), Status::Ok) << why;
  return model_of(p);
}

}  // namespace

TEST(Regressor, ParameterVectorRoundTripsThroughTheParameterStruct) {
  const Params p = every_machine_term();
  const ParamVector pi = parameter_vector(p);
  // The payload's entries as the model uses them (model.cpp): m c, I + m |c|^2.
  EXPECT_EQ(pi[kPiPayloadMx], 0.3 * 0.02);  // every_machine_term()'s payload: 0.3 kg at (0.02, -0.012) m
  EXPECT_EQ(pi[kPiPayloadMy], 0.3 * -0.012);
  EXPECT_DOUBLE_EQ(pi[kPiPayloadIzzP], 1.2e-4 + 0.3 * (0.02 * 0.02 + 0.012 * 0.012));
  Params q;
  ASSERT_EQ(apply_parameter_vector(pi, q), Status::Ok);
  EXPECT_LT((parameter_vector(q) - pi).cwiseAbs().maxCoeff(), 1e-18);
  EXPECT_NEAR(q.payload_com[0], 0.02, 1e-17);
  EXPECT_NEAR(q.payload_Izz, 1.2e-4, 1e-19);
  for (int j = 0; j < kParams; ++j) EXPECT_NE(regressor_param_info(j).name, nullptr);
  EXPECT_EQ(regressor_param_info(kParams).name, nullptr);
}

TEST(Regressor, RefusesParameterVectorsThatAreNoParameterSet) {
  ParamVector pi = parameter_vector(Params{});
  pi[kPiPayloadMx] = 1e-3;  // a first moment without a payload mass
  Params p;
  std::string why;
  EXPECT_EQ(apply_parameter_vector(pi, p, &why), Status::InvalidParameter);
  EXPECT_NE(why.find("payload_mass"), std::string::npos) << why;
  pi = parameter_vector(Params{});
  pi[kPiSlider] = -0.1;
  EXPECT_EQ(apply_parameter_vector(pi, p, &why), Status::InvalidParameter);
  EXPECT_NE(why.find("m_slider"), std::string::npos) << why;
  EXPECT_EQ(p.m_slider, Params{}.m_slider);  // untouched on failure
}

TEST(Regressor, TimesTheParametersEqualsInverseDynamicsWithTheMachine) {
  for (const bool machine : {false, true}) {
    const Params p = machine ? every_machine_term() : Params{};
    const Model m = model_of(p);
    const ParamVector pi = parameter_vector(p);
    for (unsigned seed = 1; seed <= 40; ++seed) {
      const Motion mo = random_motion(m, seed);
      const RegressorSample r = regressor_at(m, mo);
      EXPECT_LT(rel_diff(Vec4(r.Y * pi + r.F0), inverse_forces(m, mo)), 1e-12)
          << "seed " << seed << " machine " << machine;
    }
  }
}

TEST(Regressor, EachColumnIsTheInverseDynamicsSlopeInItsParameter) {
  // The forces are linear in pi: a central difference is exact up to
  // rounding, with a step of a hundredth of each parameter's own size.
  const Params p = every_machine_term();
  const ParamVector pi = parameter_vector(p);
  for (unsigned seed = 1; seed <= 6; ++seed) {
    const Motion mo = random_motion(model_of(p), seed);
    const RegressorSample r = regressor_at(model_of(p), mo);
    for (int j = 0; j < kParams; ++j) {
      const double h = 0.01 * std::fabs(pi[j]);  // I_rod keeps its triangle inequality
      ParamVector up = pi, down = pi;
      up[j] += h;
      down[j] -= h;
      const Vec4 fd = (inverse_forces(model_with(p, up), mo) - inverse_forces(model_with(p, down), mo)) / (2 * h);
      const double scale = std::max(r.Y.col(j).cwiseAbs().maxCoeff(), 1e-300);
      EXPECT_GT(scale, 0.0);
      EXPECT_LT((fd - r.Y.col(j)).cwiseAbs().maxCoeff(), 1e-8 * scale + 1e-12 * r.F0.cwiseAbs().maxCoeff() / h)
          << regressor_param_info(j).name << " seed " << seed << "\nY  " << r.Y.col(j).transpose() << "\nfd "
          << fd.transpose();
    }
  }
}

TEST(Regressor, BeyondAStopTheStopForceIsInTheOffset) {
  Params p = every_machine_term();
  p.stop_damping = 0.0;  // the stop pushes with k delta whatever the rate
  const Model m0 = model_of(p);
  const Motion mo = random_motion(m0, 3);
  RegressorSample r0;
  ASSERT_EQ(regressor(m0, mo.pose, mo.vel, mo.acc, mo.we, r0), Status::Ok);
  int top = 0;
  r0.rho.maxCoeff(&top);
  p.rho_max = r0.rho[top] - 1e-4;  // the highest slider is 0.1 mm into its upper stop
  const Model m = model_of(p);
  RegressorSample r;
  ASSERT_EQ(regressor(m, mo.pose, mo.vel, mo.acc, mo.we, r), Status::Ok);
  EXPECT_EQ(r.beyond_stops, 1u << (4 + top));
  EXPECT_LT(rel_diff(Vec4(r.Y * parameter_vector(p) + r.F0), inverse_forces(m, mo)), 1e-12);
  EXPECT_NEAR(r.F0[top] - r0.F0[top], p.stop_stiffness * 1e-4, 1e-9);  // + k delta: it pushes down
}

TEST(Regressor, FromTheSlidersMeasurementsEqualsFromThePlatformMotion) {
  const Params p = every_machine_term();
  const Model m = model_of(p);
  for (unsigned seed = 1; seed <= 10; ++seed) {
    const Motion mo = random_motion(m, seed);
    const InverseDynamicsResult id = inverse_dynamics_of(m, mo);
    Vec4 rho, rhod, rhodd;
    for (int i = 0; i < kLegs; ++i) {
      rho[i] = id.q[leg_offset(i)];
      rhod[i] = id.qd[leg_offset(i)];
      rhodd[i] = id.qdd[leg_offset(i)];
    }
    RegressorSample rp, rj;
    ASSERT_EQ(regressor(m, mo.pose, mo.vel, mo.acc, mo.we, rp), Status::Ok);
    rj.pose = Pose(0.0, 0.0, 0.05, 0.0);  // the home pose as the guess
    ASSERT_EQ(joint_regressor(m, rho, rhod, rhodd, mo.we, rj), Status::Ok);
    EXPECT_LT((rj.pose - mo.pose).cwiseAbs().maxCoeff(), 1e-13) << "seed " << seed;
    EXPECT_LT(rel_diff(rj.pose_d, mo.vel), 1e-12) << "seed " << seed;
    EXPECT_LT(rel_diff(rj.pose_dd, mo.acc), 1e-11) << "seed " << seed;
    EXPECT_LT(rel_diff(rj.Y, rp.Y), 1e-11) << "seed " << seed;
    EXPECT_LT(rel_diff(Vec4(rj.Y * parameter_vector(p) + rj.F0), id.F), 1e-11) << "seed " << seed;
  }
}

TEST(Regressor, RefusesNonFiniteAndUnreachableInput) {
  const Model m = model_of(every_machine_term());
  RegressorSample r;
  const double nan = std::nan("");
  EXPECT_EQ(regressor(m, Pose(0, 0, 0.05, nan), Pose::Zero(), Pose::Zero(), Wrench::Zero(), r), Status::NonFinite);
  EXPECT_EQ(regressor(m, Pose(0.5, 0, 0.05, 0), Pose::Zero(), Pose::Zero(), Wrench::Zero(), r), Status::Unreachable);
  r.pose = Pose(0, 0, 0.05, 0);
  EXPECT_EQ(joint_regressor(m, Vec4(0.1, nan, 0.1, 0.1), Vec4::Zero(), Vec4::Zero(), Wrench::Zero(), r),
            Status::NonFinite);
  // Sliders 1 and 3 (opposite legs) 0.3 m apart: no platform joins them.
  const Status s = joint_regressor(m, Vec4(-0.2, 0.1, 0.1, 0.1), Vec4::Zero(), Vec4::Zero(), Wrench::Zero(), r);
  EXPECT_TRUE(s == Status::Unreachable || s == Status::NotConverged || s == Status::Singular) << status_name(s);
}

TEST(Regressor, BaseParametersFromTheColumnPivotedQrOfStackedRegressors) {
  // docs/calibration.md: of the 14 parameters 12 combinations are
  // identifiable; the platform's and the payload's mass, and their inertias
  // about P, enter only as sums.
  const Params p = every_machine_term();
  const Model m = model_of(p);
  constexpr int kSamples = 60;
  Eigen::MatrixXd W(4 * kSamples, kParams);
  for (int k = 0; k < kSamples; ++k) {
    const Motion mo = random_motion(m, 100 + k);
    RegressorSample r;
    ASSERT_EQ(regressor(m, mo.pose, mo.vel, mo.acc, mo.we, r), Status::Ok);
    W.middleRows<4>(4 * k) = r.Y;
  }
  // Columns scaled to unit norm: the rank does not depend on the units.
  const Eigen::VectorXd norms = W.colwise().norm().transpose();
  const Eigen::MatrixXd Ws = W * norms.cwiseInverse().asDiagonal();
  Eigen::ColPivHouseholderQR<Eigen::MatrixXd> qr(Ws);
  qr.setThreshold(1e-10);
  EXPECT_EQ(qr.rank(), 12);
  const Eigen::VectorXd d = qr.matrixQR().diagonal().cwiseAbs();
  std::printf("|R_ii| / |R_00|: 12th %.2e, 13th %.2e\n", d[11] / d[0], d[12] / d[0]);
  EXPECT_GT(d[11] / d[0], 1e-4);  // well identifiable from random states
  // The null space: exactly the two documented differences.
  EXPECT_EQ((W.col(kPiPlatform) - W.col(kPiPayload)).cwiseAbs().maxCoeff(), 0.0);
  EXPECT_EQ((W.col(kPiPlatformIzz) - W.col(kPiPayloadIzzP)).cwiseAbs().maxCoeff(), 0.0);
  // Without either of the payload's duplicate columns the rest has full rank.
  Eigen::MatrixXd Wb(W.rows(), 12);
  int c = 0;
  for (int j = 0; j < kParams; ++j)
    if (j != kPiPayload && j != kPiPayloadIzzP) Wb.col(c++) = Ws.col(j);
  EXPECT_EQ(Eigen::ColPivHouseholderQR<Eigen::MatrixXd>(Wb).setThreshold(1e-10).rank(), 12);
}

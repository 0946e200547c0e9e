// SPDX-License-Identifier: BSD-2-Clause
// Analytic derivatives of the forward and inverse dynamics
// (reduced_dynamics_derivatives.hpp, inverse_dynamics_derivatives.hpp)
// against central differences of the same model's plain functions
// (state_derivative, inverse_dynamics) with Richardson extrapolation:
// at several poses (home, the auto-test's end pose, off-centre and rotated),
// with nonzero rates and every machine term on, and with an end stop pushing.
#include <cstdio>

#include "pkm4puu/dynamics/inverse_dynamics.hpp"
#include "pkm4puu/dynamics/inverse_dynamics_derivatives.hpp"
#include "pkm4puu/dynamics/lagrangian.hpp"
#include "pkm4puu/machine/passive_force.hpp"
#include "pkm4puu/kinematics/actuator_positions.hpp"
#include "pkm4puu/dynamics/state_derivative.hpp"
#include "pkm4puu/dynamics/reduced_dynamics_derivatives.hpp"
#include "pkm4puu/integrators/rk4.hpp"
#include "test_support.hpp"

using namespace pkm_test;

namespace {

struct Case {
  const char* name;
  Pose pose, vel;
};

// Home, the auto-test's end pose (docs/model.md), off-centre and rotated the
// other way; each with rates in every coordinate.
const Case kCases[] = {
    {"home", Pose(0.0, 0.0, 0.05, 0.0), Pose(0.12, -0.08, 0.10, 0.9)},
    {"autotest end", Pose(0.005, -0.005, 0.07, deg(4)), Pose(-0.05, 0.11, -0.07, -0.6)},
    {"off-centre rotated", Pose(-0.007, 0.006, 0.058, -0.07), Pose(0.09, 0.04, 0.13, 1.3)},
};

const Vec4 kF(2.7, 2.5, 2.9, 2.6);             // N
const Vec4 kTau(1e-3, -2e-3, 1.5e-3, 0.0);     // N*m
const Wrench kWe(0.3, -0.2, 0.5, 0.01);        // N, N*m

/// pdd at y for the inputs u = (F, Fe, Me_z, tau) by the plain state function.
Pose plain_pdd(const Model& m, const Vec8& y, const Eigen::Matrix<double, 12, 1>& u) {
  const Vec16 f = generalized_forces(m, u.head<4>(), u.tail<4>(), u.segment<4>(4));
  Vec8 ydot;
  EXPECT_EQ(state_derivative(m, Formulation::LegPartitioned, y, f, ydot), Status::Ok);
  return ydot.tail<4>();
}

/// The state Jacobians against Richardson differences of state_derivative;
/// `h` scales every step (an end stop's kink must stay out of reach).
void check_forward(const Model& m, const Case& c, double h) {
  SCOPED_TRACE(c.name);
  Vec8 y;
  y << c.pose, c.vel;
  Eigen::Matrix<double, 12, 1> u;
  u << kF, kWe, kTau;
  Vec8 ydot;
  Mat8 A;
  Mat8x12 B;
  JointJacobians joints;
  ASSERT_EQ(state_derivative_jacobians(m, y, kF, kTau, kWe, kStopsFromState, ydot, A, B, &joints), Status::Ok);
  EXPECT_EQ(ydot.tail<4>(), plain_pdd(m, y, u)) << "the value is the plain state function's";
  EXPECT_EQ(ydot.head<4>(), c.vel);
  // dpd/dy: identity on the rates, nothing else; dpd/du = 0.
  Mat8 top = Mat8::Zero();
  top.topRightCorner<4, 4>().setIdentity();
  EXPECT_EQ(A.topRows<4>(), top.topRows<4>());
  EXPECT_EQ(B.topRows<4>(), (Eigen::Matrix<double, 4, 12>::Zero()));

  // Steps: pose 0.3 mm and 3 mrad, rates 5 mm/s and 50 mrad/s, forces 1 N,
  // moments 0.01 N*m, torques 5 mN*m (the dynamics are linear in u).
  const double hy[8] = {3e-4, 3e-4, 3e-4, 3e-3, 5e-3, 5e-3, 5e-3, 5e-2};
  Eigen::MatrixXd fd(4, 8 + 12);
  Eigen::VectorXd err(8 + 12);
  for (int k = 0; k < 8; ++k) {
    fd.col(k) = richardson([&](double s) {
      Vec8 ys = y;
      ys[k] += s;
      return plain_pdd(m, ys, u);
    }, h * hy[k], &err[k]);
  }
  for (int k = 0; k < 12; ++k) {
    const double hu = k < 7 ? 1.0 : (k == 7 ? 1e-2 : 5e-3);
    fd.col(8 + k) = richardson([&](double s) {
      Eigen::Matrix<double, 12, 1> us = u;
      us[k] += s;
      return plain_pdd(m, y, us);
    }, hu, &err[8 + k]);
  }
  Eigen::MatrixXd an(4, 20);
  an << A.bottomRows<4>(), B.bottomRows<4>();
  expect_columns_match("d pdd / d(p, pd)", an.leftCols(8), fd.leftCols(8), err.head(8), 1e-7);
  expect_columns_match("d pdd / du", an.rightCols(12), fd.rightCols(12), err.tail(12), 1e-7);

  // The sliders' rows: d rho/dp, d rhod/dp and d rhod/dpd = d rho/dp, from
  // the joints the plain state function reports.
  Eigen::MatrixXd fd_joints(8, 8), an_joints(8, 8);
  Eigen::VectorXd err_joints(8);
  for (int k = 0; k < 8; ++k) {
    fd_joints.col(k) = richardson([&](double s) {
      Vec8 ys = y, yd;
      ys[k] += s;
      JointMotion jm;
      EXPECT_EQ(state_derivative(m, Formulation::LegPartitioned, ys, Vec16::Zero(), yd, nullptr, &jm), Status::Ok);
      Vec8 out;
      out << jm.rho, jm.rhod;
      return out;
    }, h * hy[k], &err_joints[k]);
  }
  an_joints << joints.J_rho, Mat4::Zero(), joints.drhod_dp, joints.J_rho;
  expect_columns_match("d (rho, rhod) / d(p, pd)", an_joints, fd_joints, err_joints, 1e-7);
}

}  // namespace

TEST(ForwardDerivatives, IdealMechanismMatchesRichardsonDifferences) {
  const Model m = default_model();
  for (const Case& c : kCases) check_forward(m, c, 1.0);
}

TEST(ForwardDerivatives, EveryMachineTermOnMatchesRichardsonDifferences) {
  const Model m = model_of(every_machine_term());
  for (const Case& c : kCases) check_forward(m, c, 1.0);
}

TEST(ForwardDerivatives, PushingEndStopMatchesRichardsonDifferences) {
  // Leg 1's upper stop 1 mm below its joint at the case's pose: the stop
  // pushes (k delta = 100 N dominates d delta_dot), smooth within 1 mm.
  Params p = every_machine_term();
  const Case& c = kCases[2];
  Vec4 rho;
  ASSERT_EQ(actuator_positions(default_model(), c.pose, rho), Status::Ok);
  p.rho_max = rho[0] - 1e-3;
  const Model m = model_of(p);
  ASSERT_GT(std::fabs(stop_force(m.p, rho[0], 0.0)), 0.0);
  check_forward(m, c, 0.05);  // steps of at most 50 um in the pose
}

namespace {

/// The Jacobians leg by leg, as state_derivative_jacobians computed them
/// before the lanes: reduced_terms, the solve and residual_partials (the
/// inverse dynamics' derivatives still use it), an independent assembly of
/// the same formulas.
void leg_by_leg_jacobians(const Model& m, const Vec8& y, const Vec16& f, Pose& pdd, Mat8& A, Mat8x12& B,
                          JointJacobians& joints) {
  ReducedDynamics rd;
  ASSERT_EQ(reduced_terms(m, y, f, kStopsFromState, rd), Status::Ok);
  ASSERT_EQ(rd.solve_platform(m, f.segment<4>(kPlatform), pdd), Status::Ok);
  ResidualPartials P;
  residual_partials(m, rd, y.tail<4>(), pdd, Vec4::Zero(), kStopsFromState, P);
  const Eigen::PartialPivLU<Mat4> lu(P.Mr);
  A.setZero();
  A.topRightCorner<4, 4>().setIdentity();
  A.bottomLeftCorner<4, 4>() = -lu.solve(P.dp);
  A.bottomRightCorner<4, 4>() = -lu.solve(P.dpd);
  B.setZero();
  B.block<4, 4>(4, 0) = lu.solve(P.J_rho.transpose());
  B.block<4, 4>(4, 4) = lu.solve(Mat4::Identity());
  B.block<4, 4>(4, 8) = m.drive_ratio * B.block<4, 4>(4, 0);
  joints.J_rho = P.J_rho;
  joints.drhod_dp = P.drhod_dp;
}

/// Largest |a - b| over the largest |b| (the Jacobians' entries span many
/// orders of magnitude; their scale is the matrix's).
template <class M1, class M2>
double relative_to_largest(const M1& a, const M2& b) {
  return (a - b).cwiseAbs().maxCoeff() / b.cwiseAbs().maxCoeff();
}

}  // namespace

TEST(ForwardDerivatives, LanesMatchTheLegByLegAssemblyToRounding) {
  for (const Model& m : {default_model(), model_of(every_machine_term())}) {
    for (const Case& c : kCases) {
      SCOPED_TRACE(c.name);
      Vec8 y;
      y << c.pose, c.vel;
      Vec8 ydot;
      Mat8 A, A_ref;
      Mat8x12 B, B_ref;
      JointJacobians joints, joints_ref;
      Pose pdd_ref;
      ASSERT_EQ(state_derivative_jacobians(m, y, kF, kTau, kWe, kStopsFromState, ydot, A, B, &joints), Status::Ok);
      leg_by_leg_jacobians(m, y, generalized_forces(m, kF, kTau, kWe), pdd_ref, A_ref, B_ref, joints_ref);
      EXPECT_EQ(ydot.tail<4>(), pdd_ref) << "the reduced system's solve, bit for bit";
      const double eA = relative_to_largest(A.bottomRows<4>(), A_ref.bottomRows<4>());
      const double eB = relative_to_largest(B.bottomRows<4>(), B_ref.bottomRows<4>());
      const double eJ = relative_to_largest(joints.J_rho, joints_ref.J_rho);
      const double eR = relative_to_largest(joints.drhod_dp, joints_ref.drhod_dp);
      std::printf("%s: lanes vs leg by leg, A %.2e, B %.2e, J_rho %.2e, d rhod/dp %.2e\n", c.name, eA, eB, eJ, eR);
      EXPECT_LT(eA, 1e-12);
      EXPECT_LT(eB, 1e-12);
      EXPECT_LT(eJ, 1e-12);
      EXPECT_LT(eR, 1e-12);
    }
  }
}

TEST(InverseDerivatives, MatchRichardsonDifferencesOfTheInverseDynamics) {
  const Model m = model_of(every_machine_term());
  const Pose acc(0.8, -0.5, 1.1, 6.0);
  for (const Case& c : kCases) {
    SCOPED_TRACE(c.name);
    InverseDynamicsPartials d;
    ASSERT_EQ(inverse_dynamics_derivatives(m, c.pose, c.vel, acc, kWe, d), Status::Ok);
    // The force itself against the full Eqs. 10-11 of inverse_dynamics_general,
    // an independent route (Newton, servo Jacobian, 12x12 multipliers); the
    // differences below are of inverse_dynamics (the reduced path).
    InverseDynamicsResult g;
    ASSERT_EQ(inverse_dynamics_general(m, c.pose, c.vel, acc, kWe, g), Status::Ok);
    EXPECT_LT(rel_diff(d.F, g.F), 1e-12) << d.F.transpose() << " vs " << g.F.transpose();
    auto forces = [&](const Pose& p, const Pose& v, const Pose& a, const Wrench& we) {
      InverseDynamicsResult r;
      EXPECT_EQ(inverse_dynamics(m, p, v, a, we, r), Status::Ok);
      return Vec4(r.F);
    };

    const double h[4] = {3e-4, 1e-2, 0.1, 1.0};  // steps for p (phi: 10x), pd, pdd, we
    Eigen::MatrixXd an(4, 16), fd(4, 16);
    Eigen::VectorXd err(16);
    an << d.dp, d.dpd, d.dpdd, d.dwe;
    for (int block = 0; block < 4; ++block)
      for (int k = 0; k < 4; ++k) {
        const double hk = h[block] * (block < 2 && k == 3 ? 10.0 : 1.0);
        fd.col(4 * block + k) = richardson([&](double s) {
          Pose x[4] = {c.pose, c.vel, acc, kWe};
          x[block][k] += s;
          return forces(x[0], x[1], x[2], x[3]);
        }, hk, &err[4 * block + k]);
      }
    expect_columns_match("dF / d(p, pd, pdd, we)", an, fd, err, 1e-7);
  }
}

TEST(MachineDerivatives, PassiveForceAndDissipationSlopesMatchRichardsonDifferences) {
  // Friction alone (within the travel), a pushing stop, a released stop
  // (k delta + d delta_dot < 0: the force is held at 0, the spring's energy
  // flows back), each stop from the state and held on (machine.hpp).
  const Params p = every_machine_term();
  struct Joint { const char* what; double rho, rhod; unsigned stops; };
  const Joint joints[] = {
      {"within the travel", 0.06, 0.03, kStopsFromState},
      {"pushing lower stop", p.rho_min - 1e-3, 0.02, kStopsFromState},
      {"pushing upper stop, held", p.rho_max + 1e-3, -0.02, 1u << 4},
      {"released lower stop", p.rho_min - 1e-4, 0.2, kStopsFromState},
      {"released upper stop, held", p.rho_max + 1e-4, -0.2, 1u << 4},
  };
  for (const Joint& j : joints) {
    SCOPED_TRACE(j.what);
    const PassiveSlopes f = passive_joint_force_slopes(p, 0, j.stops, j.rho, j.rhod);
    const PassiveSlopes d = dissipated_power_slopes(p, 0, j.stops, j.rho, j.rhod);
    Eigen::Matrix2d an, fd;  // fixed size: GCC 12 misreads the dynamic blocks' stores (-Wstringop-overflow)
    Eigen::Vector2d err;
    an << f.drho, f.drhod, d.drho, d.drhod;
    auto both = [&](double rho, double rhod) {
      Eigen::Vector2d v;
      v << passive_joint_force(p, 0, j.stops, rho, rhod), dissipated_power(p, 0, j.stops, rho, rhod);
      return v;
    };
    fd.col(0) = richardson([&](double s) { return both(j.rho + s, j.rhod); }, 2e-5, &err[0]);
    fd.col(1) = richardson([&](double s) { return both(j.rho, j.rhod + s); }, 2e-3, &err[1]);
    expect_columns_match("d(F_passive, P_dissipated)/d(rho, rhod)", an, fd, err, 1e-7);
  }
}

TEST(ForwardDerivatives, LinearisationPredictsAPerturbedMotionToSecondOrder) {
  // The machine held at rest at the home pose (holding forces: an
  // equilibrium), every term on. A perturbation eps (dy0, du) moves the
  // nonlinear plant y' = f(y, u) for 50 ms; the linearisation
  // dy' = A dy + B du at the equilibrium predicts it with an error that
  // shrinks as eps^2 (Taylor): halving eps divides it by about 4.
  const Model m = model_of(every_machine_term());
  Vec16 q;
  ASSERT_EQ(closed_form_position(m, Pose(0.0, 0.0, 0.05, 0.0), q), Status::Ok);
  Vec4 F0;
  ASSERT_EQ(holding_forces(m, q, Wrench::Zero(), F0), Status::Ok);
  Vec8 y0;
  y0 << 0.0, 0.0, 0.05, 0.0, 0.0, 0.0, 0.0, 0.0;
  Vec8 ydot;
  Mat8 A;
  Mat8x12 B;
  ASSERT_EQ(state_derivative_jacobians(m, y0, F0, Vec4::Zero(), Wrench::Zero(), kStopsFromState, ydot, A, B),
            Status::Ok);
  ASSERT_LT(ydot.cwiseAbs().maxCoeff(), 1e-12) << "an equilibrium";
  Vec8 dy0;
  dy0 << 1e-3, -8e-4, 5e-4, 1e-2, 1e-2, 5e-3, -8e-3, 0.1;  // m, rad, m/s, rad/s
  Eigen::Matrix<double, 12, 1> du;
  du << 0.05, -0.03, 0.02, 0.04, 0.1, -0.05, 0.08, 2e-3, 1e-4, 0.0, -1e-4, 5e-5;
  const double h = 1e-4, T = 0.05;
  const int steps = static_cast<int>(std::lround(T / h));
  auto prediction_error = [&](double eps) {
    const Eigen::Matrix<double, 12, 1> u = eps * du;
    auto plant = [&](double, const Vec8& y, Vec8& yd) {
      return state_derivative(m, Formulation::LegPartitioned, y,
                              generalized_forces(m, F0 + u.head<4>(), u.tail<4>(), u.segment<4>(4)), yd);
    };
    auto linear = [&](double, const Vec8& d, Vec8& dd) {
      dd = A * d + B * u;
      return Status::Ok;
    };
    Vec8 y = y0 + eps * dy0, d = eps * dy0;
    for (int k = 0; k < steps; ++k) {
      EXPECT_EQ(rk4_step(plant, k * h, h, y), Status::Ok);
      EXPECT_EQ(rk4_step(linear, k * h, h, d), Status::Ok);
    }
    return (y - y0 - d).cwiseAbs().maxCoeff() / (eps * dy0.cwiseAbs().maxCoeff());
  };
  const double e1 = prediction_error(0.5), e2 = prediction_error(0.25), e3 = prediction_error(0.125);
  std::printf("relative prediction error over 50 ms: eps 1/2: %.2e, 1/4: %.2e, 1/8: %.2e\n", e1, e2, e3);
  // Relative to the perturbation the error is first order in eps: halving
  // eps halves it (the absolute error is second order; a wrong A or B
  // would leave a first-order absolute error, a ratio near 1).
  EXPECT_LT(e1, 0.02) << "the linearisation predicts the motion";
  EXPECT_NEAR(e1 / e2, 2.0, 0.15);
  EXPECT_NEAR(e2 / e3, 2.0, 0.15);
}

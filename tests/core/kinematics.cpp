// SPDX-License-Identifier: BSD-2-Clause
// Kinematics: closed-form inverse kinematics against the spec's golden
// poses, the servo position/velocity/acceleration problems (Eqs. 2-9), and
// the analytic Jacobians against finite differences.
#include <cmath>

#include "pkm4puu/base/sin_cos.hpp"
#include "reference_model.hpp"
#include "test_support.hpp"
#include "apps/trajectory.hpp"

using namespace pkm_test;

namespace {

double wrap_diff(double a, double b) { return std::remainder(a - b, 2.0 * kPi); }

struct GoldenLeg { double rho, theta1, theta2; };

// docs/model.md "Bodies" (10 significant digits).
void expect_golden(const Pose& pose, const GoldenLeg (&legs)[4]) {
  const Model m = default_model();
  Vec16 q;
  ASSERT_EQ(closed_form_position(m, pose, q), Status::Ok);
  for (int i = 0; i < 4; ++i) {
    const int o = leg_offset(i);
    EXPECT_NEAR(q[o], legs[i].rho, 1e-9) << "leg " << i + 1;
    EXPECT_NEAR(wrap_diff(q[o + 1], legs[i].theta1), 0.0, 1e-9) << "leg " << i + 1;
    EXPECT_NEAR(q[o + 2], legs[i].theta2, 1e-9) << "leg " << i + 1;
  }
  EXPECT_LT(constraints(m, q).norm(), 1e-15);
  // The independent DH product agrees that the loops are closed.
  EXPECT_LT(ref::constraints(ref::RefParams{}, q).norm(), 1e-15);
}

}  // namespace

TEST(Kinematics, GoldenPoseHome) {
  const GoldenLeg odd{0.0443193423, 3.2655932943, -0.8606121019};
  const GoldenLeg even{0.0443193423, -1.3393164414, -0.8606121019};
  const GoldenLeg legs[4] = {odd, even, odd, even};
  expect_golden(Pose(0, 0, 0.05, 0), legs);
}

TEST(Kinematics, GoldenPoseEnd) {
  const GoldenLeg legs[4] = {{0.0676488698, 3.3244509641, -0.9270633736},
                             {0.0608871697, -1.3561168385, -0.7971100074},
                             {0.0407700625, 3.1413311322, -0.4823651758},
                             {0.0792527515, -1.0390941300, -1.2373176895}};
  expect_golden(Pose(0.005, -0.005, 0.07, 4.0 * kPi / 180.0), legs);
}

TEST(Kinematics, ConstraintsMatchIndependentDhProduct) {
  const Model m = default_model();
  for (unsigned seed = 1; seed <= 20; ++seed) {
    const Vec16 q = random_vec<16>(seed, 1.0);  // anywhere, not only on the manifold
    EXPECT_LT((constraints(m, q) - ref::constraints(ref::RefParams{}, q)).norm(), 1e-15);
  }
}

TEST(Kinematics, UnreachablePoseIsReported) {
  const Model m = default_model();
  Vec16 q;
  // Far outside: the rods (l = 80 mm) cannot reach.
  EXPECT_EQ(closed_form_position(m, Pose(0.2, 0, 0.05, 0), q), Status::Unreachable);
  // Leg 1's attachment point moved onto its prismatic axis, inside the
  // circle of radius h' that the rod's offset cannot reach.
  EXPECT_EQ(closed_form_position(m, Pose(0.061, -0.068, 0.05, 0), q), Status::Unreachable);
  EXPECT_EQ(closed_form_position(m, Pose(NAN, 0, 0.05, 0), q), Status::NonFinite);
}

TEST(Kinematics, NewtonFromPerturbedGuessConvergesToClosedForm) {
  const Model m = default_model();
  for (unsigned seed = 1; seed <= 10; ++seed) {
    const RandomState s = random_state(m, seed);
    Vec16 q = s.q;
    q.head<12>() += random_vec<12>(100 + seed, 0.05);  // 50 mm / 0.05 rad off
    NewtonReport rep;
    ASSERT_EQ(solve_position(m, s.pose, q, {}, &rep), Status::Ok) << "seed " << seed;
    EXPECT_GE(rep.iterations, 2);
    EXPECT_LE(rep.residual, 1e-14);
    EXPECT_LT((q - s.q).lpNorm<Eigen::Infinity>(), 1e-12) << "seed " << seed;
  }
}

TEST(Kinematics, ConstraintJacobianMatchesFiniteDifferences) {
  const Model m = default_model();
  for (unsigned seed = 1; seed <= 8; ++seed) {
    const Vec16 q = random_state(m, seed).q;
    Mat12x16 Cq;
    constraint_jacobian(m, q, Cq);
    for (int k = 0; k < kN; ++k) {
      const Vec12 fd = d_ds([&](double e) { Vec16 x = q; x[k] += e; return Vec12(constraints(m, x)); }, 1e-4);
      EXPECT_LT((Cq.col(k) - fd).lpNorm<Eigen::Infinity>(), 1e-10) << "column " << k << " seed " << seed;
    }
  }
}

TEST(Kinematics, GammaMatchesFiniteDifferencesOfCqQd) {
  // (C_q qd)_q qd = d/ds [C_q(q + s qd) qd] at s = 0.
  const Model m = default_model();
  for (unsigned seed = 1; seed <= 8; ++seed) {
    const RandomState s = random_state(m, seed);
    const Vec12 fd = d_ds([&](double e) {
      Mat12x16 Cq;
      constraint_jacobian(m, Vec16(s.q + e * s.qd), Cq);
      return Vec12(Cq * s.qd);
    }, 1e-4);
    const Vec12 g = constraint_gamma(m, s.q, s.qd);
    EXPECT_LT(rel_diff(g, fd), 1e-8) << "seed " << seed;
  }
}

TEST(Kinematics, ServoProblemsMatchDerivativesOfThePath) {
  // Along the spec's path, qd and qdd from Eqs. 5-9 equal the time
  // derivatives of the position problem's solution.
  const Model m = default_model();
  const RestToRest path;
  auto q_at = [&](double t) {
    Vec16 q;
    EXPECT_EQ(closed_form_position(m, path_motion(path, t).pose, q), Status::Ok);
    return q;
  };
  for (double t : {0.3, 0.7, 1.0, 1.45}) {
    const Motion x = path_motion(path, t);
    const Vec16 q = q_at(t);
    Vec16 qd, qdd;
    ASSERT_EQ(solve_velocity(m, q, x.vel, qd), Status::Ok);
    ASSERT_EQ(solve_acceleration(m, q, qd, x.acc, qdd), Status::Ok);
    const Vec16 qd_fd = d_ds([&](double e) { return q_at(t + e); }, 1e-4);
    const Vec16 qdd_fd = d_ds([&](double e) {
      Vec16 v;
      EXPECT_EQ(solve_velocity(m, q_at(t + e), path_motion(path, t + e).vel, v), Status::Ok);
      return v;
    }, 1e-4);
    EXPECT_LT((qd - qd_fd).lpNorm<Eigen::Infinity>(), 1e-10) << "t = " << t;
    EXPECT_LT((qdd - qdd_fd).lpNorm<Eigen::Infinity>(), 1e-9) << "t = " << t;
    Mat12x16 Cq;
    constraint_jacobian(m, q, Cq);
    EXPECT_LT((Cq * qd).norm(), 1e-16);
  }
}

TEST(Kinematics, LegBlockDeterminantIsLTimesATimesSinTheta2) {
  // docs/model.md: det(dC_i/d(rho, theta1, theta2)) = l A sin(theta2), with
  // A = sqrt(qx^2 + qy^2 - h'^2) computed here from the geometry.
  const Model m = default_model();
  for (unsigned seed = 1; seed <= 6; ++seed) {
    const RandomState s = random_state(m, seed);
    const PlatformConfig pc = platform_config(s.pose);
    for (int i = 0; i < 4; ++i) {
      const Vec3 qt = rotate_to_leg(m, i, platform_point(m, i, pc) - m.B[i]);
      const double A = std::sqrt(qt.x() * qt.x() + qt.y() * qt.y() - m.p.h_prime * m.p.h_prime);
      const double th2 = s.q[leg_offset(i) + 2];
      EXPECT_NEAR(std::fabs(leg_block(m, i, leg_config_from_q(s.q, i)).determinant()),
                  std::fabs(m.p.l * A * std::sin(th2)), 1e-15);
    }
  }
}

TEST(Kinematics, ActuatorJacobianMatchesFiniteDifferences) {
  const Model m = default_model();
  for (unsigned seed = 1; seed <= 6; ++seed) {
    const RandomState s = random_state(m, seed);
    Mat4 J;
    ASSERT_EQ(actuator_jacobian(m, s.q, J), Status::Ok);
    for (int k = 0; k < 4; ++k) {
      const Vec4 fd = d_ds([&](double e) {
        Pose p = s.pose;
        p[k] += e;
        Vec16 q;
        EXPECT_EQ(closed_form_position(m, p, q), Status::Ok);
        return Vec4(q[0], q[3], q[6], q[9]);
      }, 1e-5);
      EXPECT_LT((J.col(k) - fd).lpNorm<Eigen::Infinity>(), 1e-9) << "column " << k;
    }
  }
}

TEST(Kinematics, AutotestPathIsWellConditioned) {
  // docs/model.md "The paper's two tests": cond < 26 and 27 deg <= |theta2| <= 71 deg.
  const Model m = default_model();
  const RestToRest path;
  double worst = 0;
  for (int k = 0; k <= 200; ++k) {
    Pose p, pd, pdd;
    path.eval(0.01 * k, p, pd, pdd);
    Vec16 q;
    ASSERT_EQ(closed_form_position(m, p, q), Status::Ok);
    Mat4 J;
    ASSERT_EQ(actuator_jacobian(m, q, J), Status::Ok);
    worst = std::max(worst, actuator_jacobian_condition(J));
    for (int i = 0; i < 4; ++i) {
      const double th2 = std::fabs(q[leg_offset(i) + 2]) * 180.0 / kPi;
      EXPECT_GE(th2, 27.0);
      EXPECT_LE(th2, 71.0);
    }
  }
  EXPECT_LT(worst, 26.0);
  EXPECT_GT(worst, 1.0);
}

TEST(Kinematics, SinCosSeriesIsWithinTwoUlpOfLibm) {
  // base/sin_cos.hpp's series (Windows' platform angle) against std::sin and
  // std::cos: the platform's range, many turns, and up to the fallback.
  auto ulps = [](double got, double want) {
    const double ulp = std::nextafter(std::fabs(want), INFINITY) - std::fabs(want);
    return std::fabs(got - want) / ulp;
  };
  double worst = 0.0;
  for (int i = -200000; i <= 200000; ++i) {
    for (const double scale : {1e-5, 1e-3, 0.4}) {  // |x| up to 2 rad, 200 rad, 8e4 rad
      const double x = scale * i + 1e-7 * (i % 7);
      double s, c;
      pkm::sin_cos_series(x, s, c);
      worst = std::max({worst, ulps(s, std::sin(x)), ulps(c, std::cos(x))});
    }
  }
  std::printf("sin_cos_series: largest error %.2f ulp\n", worst);
  EXPECT_LE(worst, 2.0);
  double s, c;
  pkm::sin_cos_series(0.0, s, c);
  EXPECT_EQ(s, 0.0);
  EXPECT_EQ(c, 1.0);
  pkm::sin_cos_series(1e6, s, c);  // the fallback
  EXPECT_EQ(s, std::sin(1e6));
  EXPECT_EQ(c, std::cos(1e6));
}

// SPDX-License-Identifier: BSD-2-Clause
// The Lagrangian terms of Eq. 1 against the independent reference model:
// M as the Hessian of the kinetic energy in qd, V and G from finite
// differences of the Lagrangian (Eq. 14), plus the spec's static check.
#include "pkm4puu/dynamics/inverse_dynamics.hpp"
#include "pkm4puu/dynamics/lagrangian.hpp"
#include "test_support.hpp"

using namespace pkm_test;

namespace {

const ref::RefParams kRef{};

}  // namespace

TEST(Dynamics, MassMatrixIsSymmetricPositiveDefiniteAndTheHessianOfT) {
  const Model m = default_model();
  for (unsigned seed = 1; seed <= 6; ++seed) {
    const Vec16 q = random_state(m, seed).q;
    Mat16 M;
    mass_matrix(m, q, M);
    EXPECT_EQ((M - M.transpose()).cwiseAbs().maxCoeff(), 0.0);
    const Eigen::SelfAdjointEigenSolver<Mat16> eig(M);
    EXPECT_GT(eig.eigenvalues().minCoeff(), 0.0);
    // Hessian of the reference T in qd by polarisation (exact for a quadratic form).
    const Mat16 H = ref_mass_matrix(kRef, q);
    EXPECT_LT((M - H).cwiseAbs().maxCoeff() / M.cwiseAbs().maxCoeff(), 1e-10) << "seed " << seed;
  }
}

TEST(Dynamics, KineticAndPotentialEnergyMatchReference) {
  const Model m = default_model();
  for (unsigned seed = 1; seed <= 6; ++seed) {
    const RandomState s = random_state(m, seed);
    EXPECT_NEAR(kinetic_energy(m, s.q, s.qd), ref::kinetic_energy(kRef, s.q, s.qd),
                1e-10 * ref::kinetic_energy(kRef, s.q, s.qd));
    // The reference places the slider's height at rho + h: a constant offset.
    const double offset = 4 * m.p.m_slider * m.p.g * m.p.h;
    EXPECT_NEAR(potential_energy(m, s.q) + offset, ref::potential_energy(kRef, s.q), 1e-14);
  }
}

TEST(Dynamics, CoriolisTermsMatchFiniteDifferencesOfTheLagrangian) {
  // V = d/dt(dT/dqd) - dT/dq - M qdd = (d/ds dT/dqd(q + s qd, qd)) - dT/dq.
  const Model m = default_model();
  for (unsigned seed = 1; seed <= 6; ++seed) {
    const RandomState s = random_state(m, seed);
    const Vec16 V_ref = ref_coriolis(kRef, s.q, s.qd);
    const Vec16 V = coriolis(m, s.q, s.qd);
    EXPECT_LT((V - V_ref).lpNorm<Eigen::Infinity>(), 1e-9 * std::max(1e-6, V.lpNorm<Eigen::Infinity>()) + 1e-12)
        << "seed " << seed << "\nV  = " << V.transpose() << "\nref= " << V_ref.transpose();
    EXPECT_GT(V.lpNorm<Eigen::Infinity>(), 1e-5);  // the check is not vacuous
  }
}

TEST(Dynamics, GravityTermsMatchFiniteDifferencesOfThePotential) {
  const Model m = default_model();
  for (unsigned seed = 1; seed <= 6; ++seed) {
    const Vec16 q = random_state(m, seed).q;
    EXPECT_LT((gravity(m, q) - ref_gravity(kRef, q)).lpNorm<Eigen::Infinity>(), 1e-12) << "seed " << seed;
  }
}

TEST(Dynamics, StaticForcesAtHomeCarryTheWeight) {
  // docs/model.md "Bodies": 2.655616050 N per actuator,
  // (m_platform + 4 m_slider + 4 m_rod) g = 10.622464200 N in all.
  const Model m = default_model();
  InverseDynamicsResult r;
  ASSERT_EQ(inverse_dynamics(m, Pose(0, 0, 0.05, 0), Pose::Zero(), Pose::Zero(), Wrench::Zero(), r), Status::Ok);
  for (int i = 0; i < 4; ++i) EXPECT_NEAR(r.F[i], 2.655616050, 1e-9);
  EXPECT_NEAR(r.F.sum(), (0.45474 + 4 * 0.09331 + 4 * 0.06371) * 9.81, 1e-12);
}

TEST(Dynamics, InverseDynamicsSatisfiesEquationOneWithExternalWrench) {
  // Every row of Eq. 1 holds with the computed F and lambda, including an
  // external wrench on the platform, at random states and accelerations.
  const Model m = default_model();
  for (unsigned seed = 1; seed <= 6; ++seed) {
    const Motion mo = random_motion(m, seed, 2.0, 0.5);
    const InverseDynamicsResult r = inverse_dynamics_of(m, mo);
    Mat16 M;
    mass_matrix(m, r.q, M);
    Mat12x16 Cq;
    constraint_jacobian(m, r.q, Cq);
    const Vec16 lhs = M * r.qdd + coriolis(m, r.q, r.qd) + gravity(m, r.q) + Cq.transpose() * r.lambda;
    EXPECT_LT((lhs - generalized_forces(r.F, mo.we)).lpNorm<Eigen::Infinity>(), 1e-12);
    EXPECT_LT((r.qdd.segment<4>(kPlatform) - mo.acc).lpNorm<Eigen::Infinity>(), 1e-12);
  }
}

// SPDX-License-Identifier: BSD-2-Clause
// Forward dynamics: the three formulations agree (Eq. 12, Eq. 13 with a QR
// basis, Eq. 13 with the leg-partitioned basis), they invert the inverse
// dynamics, and energy is conserved when nothing does work.
#include <cmath>
#include <vector>

#include "pkm4puu/kinematics/actuator_positions.hpp"
#include "pkm4puu/dynamics/inverse_dynamics.hpp"
#include "pkm4puu/dynamics/lagrangian.hpp"
#include "pkm4puu/sim/plant.hpp"
#include "pkm4puu/dynamics/reduced_dynamics.hpp"
#include "test_support.hpp"

using namespace pkm_test;

TEST(ForwardDynamics, AllFormulationsGiveTheSameAccelerationsAndMultipliers) {
  const Model m = default_model();
  for (unsigned seed = 1; seed <= 12; ++seed) {
    const RandomState s = random_state(m, seed);
    const Vec16 f = generalized_forces(Vec4::Constant(2.65) + random_vec<4>(200 + seed, 1.0),
                                       random_vec<4>(300 + seed, 0.5));
    Vec16 qdd[3];
    Vec12 lam[3];
    for (int k = 0; k < 3; ++k)
      ASSERT_EQ(forward_dynamics(m, static_cast<Formulation>(k), s.q, s.qd, f, qdd[k], lam[k]), Status::Ok);
    for (int k = 1; k < 3; ++k) {
      EXPECT_LT(rel_diff(qdd[k], qdd[0]), 1e-10) << formulation_name(static_cast<Formulation>(k)) << " seed " << seed;
      EXPECT_LT(rel_diff(lam[k], lam[0]), 1e-10) << formulation_name(static_cast<Formulation>(k)) << " seed " << seed;
    }
    // The accelerations keep the state on the manifold: C_q qdd + gamma = 0.
    Mat12x16 Cq;
    constraint_jacobian(m, s.q, Cq);
    EXPECT_LT((Cq * qdd[0] + constraint_gamma(m, s.q, s.qd)).lpNorm<Eigen::Infinity>(), 1e-12);
  }
}

TEST(ForwardDynamics, InvertsInverseDynamics) {
  // Forces from Eqs. 10-11 for a chosen platform acceleration, fed forward,
  // give that acceleration and the same multipliers back.
  const Model m = default_model();
  for (unsigned seed = 1; seed <= 8; ++seed) {
    const Motion mo = random_motion(m, seed, 3.0, 0.3);
    const InverseDynamicsResult r = inverse_dynamics_of(m, mo);
    for (int k = 0; k < 3; ++k) {
      Vec16 qdd;
      Vec12 lam;
      ASSERT_EQ(forward_dynamics(m, static_cast<Formulation>(k), r.q, r.qd, generalized_forces(r.F, mo.we), qdd, lam),
                Status::Ok);
      EXPECT_LT((qdd.segment<4>(kPlatform) - mo.acc).lpNorm<Eigen::Infinity>(),
                1e-10 * mo.acc.lpNorm<Eigen::Infinity>());
      EXPECT_LT(rel_diff(lam, r.lambda), 1e-10);
    }
  }
}

TEST(ForwardDynamics, StateDerivativeHotPathEqualsFullEvaluation) {
  const Model m = default_model();
  for (unsigned seed = 1; seed <= 6; ++seed) {
    const RandomState s = random_state(m, seed);
    Vec8 y;
    y << s.pose, s.vel;
    const Vec16 f = generalized_forces(random_vec<4>(600 + seed, 3.0), Wrench::Zero());
    Vec8 fast, full;
    MechanismState ms;
    ASSERT_EQ(state_derivative(m, Formulation::LegPartitioned, y, f, fast), Status::Ok);
    ASSERT_EQ(state_derivative(m, Formulation::Augmented, y, f, full, &ms), Status::Ok);
    EXPECT_LT(rel_diff(fast, full), 1e-12);
    EXPECT_LT((ms.q - s.q).lpNorm<Eigen::Infinity>(), 1e-15);
    EXPECT_LT((ms.qd - s.qd).lpNorm<Eigen::Infinity>(), 1e-13);
  }
}

namespace {

// The copies of the hot path's legs (ReducedDynamics::platform_derivative)
// that this build and processor run: the scalar instance of the same
// template, the baseline lanes and, where the processor has it, AVX.
std::vector<lanes::Kernel> lane_kernels() {
  using K = lanes::Kernel;
  std::vector<K> k = {K::Best, K::Scalar, K::Baseline};
  if (PKM_LANES_AVX_DISPATCH && lanes::cpu_runs_avx()) k.push_back(K::Avx);
  return k;
}

// The reference: reduced_terms (prepare_leg, leg_velocity, add_leg with the
// legs' terms kept) and solve_platform.
Status reference_derivative(const Model& m, const Vec8& y, const Vec16& f, unsigned stops, Pose& pdd,
                            JointMotion& legs) {
  ReducedDynamics rd;
  const Status s = reduced_terms(m, y, f, stops, rd, &legs);
  if (s != Status::Ok) return s;
  return rd.solve_platform(m, f.segment<4>(kPlatform), pdd);
}

}  // namespace

TEST(ForwardDynamics, HotPathIsBitIdenticalToTheReducedTermsWithTheLegs) {
  // state_derivative's hot path (ReducedDynamics::platform_derivative) writes out
  // the zeros and ones of J_i^-1, A_i and M_i instead of keeping the legs'
  // terms and computes the four legs as lanes: the same products summed in
  // the same order as reduced_terms + solve_platform, so the same bits, for
  // every variant of the lanes. With every machine term acting (rotor,
  // friction, payload) and with the stops held on or off, over many states
  // (some of them fast, for the friction's tanh, and past the stops); and
  // without Coulomb friction, where the lanes take the passive force
  // lane-wise while no stop acts (stops 0 and, within the travel, from the
  // state) instead of the scalar function per lane.
  for (const double coulomb : {0.4, 0.0}) {
    Params p;
    p.rotor_inertia = 2e-5;
    p.friction_viscous = 3.0;
    p.friction_coulomb = coulomb;
    p.payload_mass = 0.3;
    p.payload_com = {0.01, -0.02};
    const Model m = model_of(p);
    const unsigned stops[] = {kStopsFromState, 0u, 0x0Fu, 0xF0u, 0x5Au, 0xA5u, 0x100u};
    const auto kernels = lane_kernels();
    int compared = 0;
    for (unsigned seed = 1; seed <= 300; ++seed) {
      RandomState s = random_state(m, seed);
      if (seed % 3 == 0) s.vel *= 20.0;  // the friction's tanh saturated
      Vec8 y;
      y << s.pose, s.vel;
      const Vec16 f = generalized_forces(random_vec<4>(700 + seed, 3.0), random_vec<4>(800 + seed, 0.5));
      for (unsigned st : stops) {
        Pose ref;
        JointMotion legs;
        ASSERT_EQ(reference_derivative(m, y, f, st, ref, legs), Status::Ok);
        Vec8 ydot;
        JointMotion hot;
        ASSERT_EQ(state_derivative(m, Formulation::LegPartitioned, y, f, ydot, nullptr, &hot, st), Status::Ok);
        for (int k = 0; k < 4; ++k) {
          EXPECT_EQ(ydot[4 + k], ref[k]) << "seed " << seed << " stops " << st << " k " << k;
          EXPECT_EQ(hot.rho[k], legs.rho[k]) << "seed " << seed;
          EXPECT_EQ(hot.rhod[k], legs.rhod[k]) << "seed " << seed;
        }
        for (const auto kernel : kernels) {
          Vec4 rho, rhod;
          Pose pdd;
          ASSERT_EQ(ReducedDynamics::platform_derivative(m, platform_config(s.pose), s.vel, f, st, &rho, &rhod, pdd,
                                                         kernel),
                    Status::Ok);
          for (int k = 0; k < 4; ++k) {
            EXPECT_EQ(pdd[k], ref[k]) << "kernel " << static_cast<int>(kernel) << " seed " << seed << " stops " << st;
            EXPECT_EQ(rho[k], legs.rho[k]) << "kernel " << static_cast<int>(kernel) << " seed " << seed;
            EXPECT_EQ(rhod[k], legs.rhod[k]) << "kernel " << static_cast<int>(kernel) << " seed " << seed;
          }
          ++compared;
        }
      }
    }
    EXPECT_EQ(compared, 300 * 7 * static_cast<int>(kernels.size()));
  }
}

TEST(ForwardDynamics, ActuatorPositionsAreTheLegInverseKinematicsBitForBit) {
  // actuator_positions (lane_actuator_positions: the derivative's
  // legs' inverse kinematics, four lanes) against leg_inverse_kinematics leg
  // by leg: the same rho bits, and off the workspace the same status with
  // rho untouched, for every variant of the lanes. Poses within the
  // workspace and pushed off it (some legs or all out of reach).
  const Model m = default_model();
  const auto kernels = lane_kernels();
  int compared = 0, failing = 0;
  for (unsigned seed = 1; seed <= 400; ++seed) {
    Pose pose = random_state(m, seed).pose;
    if (seed % 4 == 0) pose.head<3>() += random_vec<3>(900 + seed, 0.05);  // often off the workspace
    PlatformConfig pc = platform_config(pose);
    Status expected = Status::Ok;
    Vec4 ref;
    for (int i = 0; i < kLegs && expected == Status::Ok; ++i) {
      LegConfig c;
      expected = leg_inverse_kinematics(m, i, pc, c);
      ref[i] = c.rho;
    }
    if (expected != Status::Ok) ++failing;
    for (const auto kernel : kernels) {
      Vec4 rho = Vec4::Constant(7.0);
      ASSERT_EQ(lane_actuator_positions(m, pc, rho, kernel), expected)
          << "kernel " << static_cast<int>(kernel) << " seed " << seed;
      if (expected != Status::Ok) {
        EXPECT_EQ(rho, Vec4::Constant(7.0));  // untouched on failure
        continue;
      }
      for (int k = 0; k < 4; ++k) EXPECT_EQ(rho[k], ref[k]) << "kernel " << static_cast<int>(kernel) << " seed " << seed;
      ++compared;
    }
    Vec4 rho;
    ASSERT_EQ(actuator_positions(m, pose, rho), expected);
    if (expected == Status::Ok) {
      EXPECT_EQ(rho, ref);
    }
  }
  EXPECT_GT(compared, 300 * static_cast<int>(kernels.size())) << failing;
  EXPECT_GT(failing, 10) << compared;
  Vec4 rho;
  EXPECT_EQ(actuator_positions(m, Pose(0.0, std::nan(""), 0.06, 0.0), rho), Status::NonFinite);
}

TEST(ForwardDynamics, HotPathReportsTheFirstFailingLeg) {
  // One leg (or two) moved off its reach or onto a singularity, the others
  // as they are: every variant of the lanes returns the status of the first
  // failing leg in leg order, as the leg-by-leg reference does. At the pose
  // (0, 0, z, 0) a leg with beta = 0, r_Q = 0 and B = (-h', 0, .) sees
  // q~ = (h', 0, .): A = 0, the link vertical (Singular); B = (1, 0, .) is
  // out of reach.
  const Model m0 = default_model();
  ASSERT_GT(m0.p.h_prime, 0.0);
  const Pose pose(0.0, 0.0, 0.06, 0.0), vel(0.1, -0.05, 0.02, 0.3);
  Vec8 y;
  y << pose, vel;
  const Vec16 f = generalized_forces(Vec4(1.0, 2.0, 3.0, 4.0), Wrench::Zero());
  enum Fault { None, Far, Singular };
  auto with = [&](int leg, Fault fault, Model m) {
    if (fault == None) return m;
    m.cos_beta[leg] = 1.0;
    m.sin_beta[leg] = 0.0;
    m.r_Q[leg] = Vec3::Zero();
    m.B[leg] = fault == Far ? Vec3(1.0, 0.0, m.B[leg].z()) : Vec3(-m.p.h_prime, 0.0, m.B[leg].z());
    return m;
  };
  struct Case {
    Fault faults[kLegs];
    Status expected;
  };
  const Case cases[] = {
      {{None, Far, None, None}, Status::Unreachable},
      {{None, None, Singular, None}, Status::Singular},
      {{None, None, None, Far}, Status::Unreachable},
      {{None, None, None, Singular}, Status::Singular},
      {{None, Singular, None, Far}, Status::Singular},
      {{None, None, Far, Singular}, Status::Unreachable},
      {{Singular, None, None, Far}, Status::Singular},
      {{Far, Singular, None, None}, Status::Unreachable},
  };
  const auto kernels = lane_kernels();
  for (const Case& c : cases) {
    Model m = m0;
    for (int i = 0; i < kLegs; ++i) m = with(i, c.faults[i], m);
    Pose ref;
    JointMotion legs;
    EXPECT_EQ(reference_derivative(m, y, f, kStopsFromState, ref, legs), c.expected);
    Vec8 ydot;
    EXPECT_EQ(state_derivative(m, Formulation::LegPartitioned, y, f, ydot), c.expected);
    for (const auto kernel : kernels) {
      Vec4 rho = Vec4::Constant(7.0), rhod = Vec4::Constant(7.0);
      Pose pdd;
      EXPECT_EQ(ReducedDynamics::platform_derivative(m, platform_config(pose), vel, f, kStopsFromState, &rho, &rhod,
                                                     pdd, kernel),
                c.expected)
          << "kernel " << static_cast<int>(kernel);
      EXPECT_EQ(rho, Vec4::Constant(7.0));  // untouched on failure
      EXPECT_EQ(rhod, Vec4::Constant(7.0));
    }
  }
  // The unmodified model at that pose: every leg fine.
  Vec8 ydot;
  EXPECT_EQ(state_derivative(m0, Formulation::LegPartitioned, y, f, ydot), Status::Ok);
}

namespace {

struct EnergyRun {
  double max_rel_drift = 0;
  double scale = 0;
};

// Integrates with CVODE (tight) from a random state near home with no
// actuator force and records the drift of T + U against the energy scale
// max(T) that the motion reaches.
EnergyRun run_energy(double g, pkm::CvodeMethod method, double duration = 2.0) {
  // The ideal mechanism: in 2 s of free fall the sliders pass any end stop
  // (docs/model.md's default travel ends at rho = 0), so the stops are made
  // inert here (zero stiffness and damping).
  Params p;
  p.g = g;
  p.stop_stiffness = 0.0;
  p.stop_damping = 0.0;
  Model m;
  EXPECT_EQ(make_model(p, m), Status::Ok);
  Plant plant(m);
  SolverSettings st;
  st.solver = Solver::Cvode;
  st.cvode_method = method;
  st.rtol = 1e-12;
  st.atol = 1e-14;
  EXPECT_EQ(plant.set_solver(st), Status::Ok);
  // A slow drift away from home: stays inside the workspace for 2 s.
  EXPECT_EQ(plant.initialize(0.0, Pose(0.0, 0.0, 0.05, 0.0), Pose(0.001, -0.0015, 0.002, 0.01)), Status::Ok);
  LinearInputs none;
  MechanismState ms;
  auto energy = [&](double& T) {
    EXPECT_EQ(plant.mechanism(none.signal(), ms), Status::Ok);
    T = kinetic_energy(m, ms.q, ms.qd);
    return T + potential_energy(m, ms.q);
  };
  double T0;
  const double E0 = energy(T0);
  EnergyRun r;
  r.scale = T0;
  std::vector<double> drift;
  for (int k = 1; k <= 200; ++k) {
    EXPECT_EQ(plant.advance(duration * k / 200.0, none.signal(), true), Status::Ok);
    double T;
    const double E = energy(T);
    r.scale = std::max(r.scale, T);
    drift.push_back(std::fabs(E - E0));
  }
  for (double d : drift) r.max_rel_drift = std::max(r.max_rel_drift, d / r.scale);
  return r;
}

}  // namespace

TEST(ForwardDynamics, KineticEnergyConservedWithoutForcesOrGravity) {
  const EnergyRun r = run_energy(0.0, CvodeMethod::Adams);
  EXPECT_GT(r.scale, 1e-7);
  EXPECT_LE(r.max_rel_drift, 1e-9) << "scale " << r.scale << " J";
  std::printf("  zero gravity, Adams: relative drift of T over 2 s = %.2e (T = %.3e J)\n", r.max_rel_drift, r.scale);
}

TEST(ForwardDynamics, TotalEnergyConservedInFreeFall) {
  // Gravity on, no actuator force: the mechanism falls as a whole while its
  // parts move relative to each other; T + U is conserved.
  for (CvodeMethod method : {CvodeMethod::Adams, CvodeMethod::BDF}) {
    const EnergyRun r = run_energy(9.81, method);
    EXPECT_GT(r.scale, 1.0);
    EXPECT_LE(r.max_rel_drift, 1e-9) << "method " << static_cast<int>(method);
    std::printf("  gravity, %s: relative drift of T + U over 2 s = %.2e (max T = %.3e J)\n",
                method == CvodeMethod::Adams ? "Adams" : "BDF", r.max_rel_drift, r.scale);
  }
}

TEST(ForwardDynamics, WorkOfHeldForcesBalancesTheEnergy) {
  // Constant actuator forces are conservative: T + U - sum F_i rho_i is
  // constant. Near home the held static forces give a bounded oscillation.
  const Model m = default_model();
  InverseDynamicsResult st;
  ASSERT_EQ(inverse_dynamics(m, Pose(0, 0, 0.05, 0), Pose::Zero(), Pose::Zero(), Wrench::Zero(), st), Status::Ok);
  Plant plant(m);
  SolverSettings s;
  s.rtol = 1e-12;
  s.atol = 1e-14;
  ASSERT_EQ(plant.set_solver(s), Status::Ok);
  ASSERT_EQ(plant.initialize(0.0, Pose(0.001, 0.0, 0.05, 0.0), Pose(0.0, 0.002, 0.0, 0.02)), Status::Ok);
  LinearInputs held;
  held.F0 = st.F;
  MechanismState ms;
  auto energy = [&](double& T) {
    EXPECT_EQ(plant.mechanism(held.signal(), ms), Status::Ok);
    T = kinetic_energy(m, ms.q, ms.qd);
    return T + potential_energy(m, ms.q) - st.F.dot(Vec4(ms.q[0], ms.q[3], ms.q[6], ms.q[9]));
  };
  double T;
  const double E0 = energy(T);
  double scale = T, drift = 0;
  for (int k = 1; k <= 200; ++k) {
    ASSERT_EQ(plant.advance(0.01 * k, held.signal(), true), Status::Ok);
    drift = std::max(drift, std::fabs(energy(T) - E0));
    scale = std::max(scale, T);
  }
  EXPECT_LE(drift / scale, 1e-9) << "scale " << scale;
}

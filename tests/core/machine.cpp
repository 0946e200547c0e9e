// SPDX-License-Identifier: BSD-2-Clause
// The machine around the mechanism (docs/model.md "The machine around the
// mechanism: drives, friction, end stops, payload"): parameters, the
// Lagrangian terms of rotors and payload against the independent reference
// model, an analytic fall with viscous friction, holding forces by virtual
// work, the energy audit, the drop onto the end stops and the inverse ->
// forward round trip with every term on.
#include <cmath>
#include <cstdio>
#include <vector>

#include "apps/autotest.hpp"
#include "pkm4puu/dynamics/inverse_dynamics.hpp"
#include "pkm4puu/dynamics/lagrangian.hpp"
#include "pkm4puu/machine/end_stops.hpp"
#include "pkm4puu/sim/plant.hpp"
#include "reference_model.hpp"
#include "test_support.hpp"

using namespace pkm_test;

namespace {

// Every term on, stops far enough not to be hit by the auto-test (its rho
// stay within 0.040..0.080 m, docs/model.md).
Params machine_params() {
  Params p;
  p.screw_lead = 0.004;
  p.rotor_inertia = 2e-7;       // reflected mass 2e-7 (2 pi / 0.004)^2 = 0.4935 kg
  p.friction_viscous = 2.0;
  p.friction_coulomb = 0.05;
  p.friction_velocity = 1e-3;
  p.payload_mass = 0.2;
  p.payload_com = {0.012, -0.007};
  p.payload_Izz = 1.5e-4;
  return p;
}

ref::RefParams ref_params(const Params& p) {
  ref::RefParams r;
  r.g = p.g;
  r.screw_lead = p.screw_lead;
  r.rotor_inertia = p.rotor_inertia;
  r.payload_mass = p.payload_mass;
  r.payload_com = p.payload_com;
  r.payload_Izz = p.payload_Izz;
  return r;
}

}  // namespace

// ---------------------------------------------------------------------------
// Parameters
// ---------------------------------------------------------------------------

TEST(MachineParams, DefaultsAreTheSpecsAndLeaveTheIdealMechanism) {
  const Params p;
  EXPECT_EQ(p.screw_lead, 0.004);
  EXPECT_EQ(p.rotor_inertia, 0.0);
  EXPECT_EQ(p.friction_viscous, 0.0);
  EXPECT_EQ(p.friction_coulomb, 0.0);
  EXPECT_EQ(p.friction_velocity, 1e-3);
  EXPECT_EQ(p.rho_min, 0.0);
  EXPECT_EQ(p.rho_max, 0.15);
  EXPECT_EQ(p.stop_stiffness, 1e5);
  EXPECT_EQ(p.stop_damping, 100.0);
  EXPECT_EQ(p.payload_mass, 0.0);
  EXPECT_EQ(p.payload_com[0], 0.0);
  EXPECT_EQ(p.payload_com[1], 0.0);
  EXPECT_EQ(p.payload_Izz, 0.0);
  const Model m = model_of(p);
  EXPECT_EQ(m.reflected_mass, 0.0);
  EXPECT_EQ(m.platform_mass, p.m_platform);
  EXPECT_EQ(m.platform_Izz, p.Izz_platform);
  EXPECT_NEAR(m.drive_ratio, 2 * kPi / 0.004, 1e-9);
}

// The machine's parameters are validated with the mechanism's (the cases are
// in test_params.cpp); the travel must not be empty.
TEST(MachineParams, TheTravelMustNotBeEmpty) {
  Params p;
  p.rho_max = p.rho_min;
  EXPECT_NE(validate(p).find("must exceed rho_min"), std::string::npos) << validate(p);
}

// ---------------------------------------------------------------------------
// Lagrangian terms against the reference model (rotors and payload)
// ---------------------------------------------------------------------------

TEST(MachineDynamics, MassMatrixIsTheHessianOfTheReferenceKineticEnergy) {
  const Params p = machine_params();
  const Model m = model_of(p);
  const ref::RefParams r = ref_params(p);
  for (unsigned seed = 1; seed <= 4; ++seed) {
    const Vec16 q = random_state(m, seed).q;
    Mat16 M;
    mass_matrix(m, q, M);
    const Mat16 H = ref_mass_matrix(r, q);
    EXPECT_LT((M - H).cwiseAbs().maxCoeff() / M.cwiseAbs().maxCoeff(), 1e-10) << "seed " << seed;
    // The off-centre payload couples x and y with phi.
    EXPECT_GT(std::fabs(M(12, 15)) + std::fabs(M(13, 15)), 1e-3);
    // The rotor's reflected mass is on each rho's diagonal.
    EXPECT_NEAR(M(0, 0), p.m_slider + p.m_rod + 2e-7 * std::pow(2 * kPi / 0.004, 2), 1e-12);
  }
}

TEST(MachineDynamics, VelocityAndGravityTermsMatchFiniteDifferencesOfTheReferenceLagrangian) {
  const Params p = machine_params();
  const Model m = model_of(p);
  const ref::RefParams r = ref_params(p);
  for (unsigned seed = 1; seed <= 4; ++seed) {
    const RandomState s = random_state(m, seed);
    const Vec16 V = coriolis(m, s.q, s.qd);
    const Vec16 V_ref = ref_coriolis(r, s.q, s.qd);
    EXPECT_LT((V - V_ref).lpNorm<Eigen::Infinity>(), 1e-9 * V.lpNorm<Eigen::Infinity>() + 1e-12)
        << "seed " << seed << "\nV  = " << V.transpose() << "\nref= " << V_ref.transpose();
    EXPECT_GT(std::fabs(V[12]) + std::fabs(V[13]), 1e-6);  // the payload's centripetal terms are there
    EXPECT_LT((gravity(m, s.q) - ref_gravity(r, s.q)).lpNorm<Eigen::Infinity>(), 1e-12) << "seed " << seed;
    // Kinetic energy with rotors and payload.
    EXPECT_NEAR(kinetic_energy(m, s.q, s.qd), ref::kinetic_energy(r, s.q, s.qd),
                1e-10 * ref::kinetic_energy(r, s.q, s.qd));
  }
}

TEST(MachineDynamics, AllFormulationsAgreeWithEveryTermOn) {
  const Params p = machine_params();
  const Model m = model_of(p);
  for (unsigned seed = 1; seed <= 6; ++seed) {
    const RandomState s = random_state(m, seed);
    Vec8 y;
    y << s.pose, s.vel;
    const Vec16 f = generalized_forces(m, Vec4::Constant(4.0) + random_vec<4>(200 + seed, 1.0),
                                       random_vec<4>(500 + seed, 1e-3), random_vec<4>(300 + seed, 0.5));
    Vec8 yd[3];
    for (int k = 0; k < 3; ++k)
      ASSERT_EQ(state_derivative(m, static_cast<Formulation>(k), y, f, yd[k]), Status::Ok);
    Vec8 hot;
    ASSERT_EQ(state_derivative(m, Formulation::LegPartitioned, y, f, hot, nullptr), Status::Ok);
    MechanismState full;
    ASSERT_EQ(state_derivative(m, Formulation::LegPartitioned, y, f, yd[2], &full), Status::Ok);
    for (int k = 0; k < 3; ++k) EXPECT_LT(rel_diff(yd[k], hot), 1e-10) << formulation_name(static_cast<Formulation>(k));
  }
}

// ---------------------------------------------------------------------------
// An analytic motion: the whole machine falling against viscous friction
// ---------------------------------------------------------------------------

// From rest at the symmetric home pose with equal forces on every rho (here
// only the friction -b rhod), every body translates vertically together:
// in the frame falling with the platform all loads are a uniform effective
// gravity plus equal forces on the four rho, the loads the spec's static
// check balances at every height. With a centred payload the machine is
// then one body of mass m_tot (mechanism plus payload) whose four screws
// add the reflected mass 4 J (2 pi/p)^2 to its inertia:
//   (m_tot + 4 J (2 pi/p)^2) zdd = -m_tot g - 4 b zd,
//   zd(t) = -v (1 - exp(-t/T)),  z(t) = z0 - v (t - T (1 - exp(-t/T))),
//   v = m_tot g / (4 b),  T = (m_tot + 4 J (2 pi/p)^2) / (4 b).
TEST(MachineDynamics, FallAgainstViscousFrictionMatchesTheClosedForm) {
  Params p;
  p.rotor_inertia = 1e-7;
  p.friction_viscous = 20.0;
  p.payload_mass = 0.3;
  p.payload_Izz = 2e-4;
  const Model m = model_of(p);
  const double m_tot = 0.45474 + 0.3 + 4 * (0.09331 + 0.06371);
  const double inertia = m_tot + 4 * 1e-7 * std::pow(2 * kPi / 0.004, 2);
  const double v = m_tot * 9.81 / (4 * 20.0), T = inertia / (4 * 20.0);
  for (Solver solver : {Solver::Rk4, Solver::Cvode}) {
    Plant plant(m);
    SolverSettings st;
    st.solver = solver;
    st.rtol = 1e-12;
    st.atol = 1e-14;
    ASSERT_EQ(plant.set_solver(st), Status::Ok);
    ASSERT_EQ(plant.initialize(0.0, Pose(0, 0, 0.05, 0), Pose::Zero()), Status::Ok);
    LinearInputs none;
    double worst = 0;
    for (int k = 1; k <= 20; ++k) {
      const double t = 0.01 * k;
      ASSERT_EQ(plant.advance(t, none.signal(), true), Status::Ok) << plant.last_error();
      const double z = 0.05 - v * (t - T * (1 - std::exp(-t / T)));
      const double zd = -v * (1 - std::exp(-t / T));
      const Vec8& y = plant.state();
      worst = std::max({worst, std::fabs(y[2] - z), std::fabs(y[6] - zd) * 1e-2,
                        y.head<2>().lpNorm<Eigen::Infinity>(), std::fabs(y[3]) * 0.1});
    }
    EXPECT_LT(worst, 1e-10) << (solver == Solver::Rk4 ? "RK4" : "CVODE");
    std::printf("  fall with viscous friction, %s: max |z - closed form| = %.2e m (fell %.4f m)\n",
                solver == Solver::Rk4 ? "RK4 1 ms" : "CVODE", worst, 0.05 - plant.state()[2]);
  }
}

// ---------------------------------------------------------------------------
// Holding forces by virtual work
// ---------------------------------------------------------------------------

// At rest the actuator forces balance the potential: for every virtual
// displacement of the pose, sum F_i d rho_i = dU - we . d pose, so
//   J_rho^T F = grad_pose U - we,   J_rho = d rho / d pose,
// with U the reference model's potential (bodies and payload) at the
// configuration of each pose, both gradients by central differences.
TEST(MachineDynamics, HoldingForcesFollowFromVirtualWork) {
  const Params p = machine_params();
  const Model m = model_of(p);
  const ref::RefParams r = ref_params(p);
  const Pose poses[] = {Pose(0, 0, 0.05, 0), Pose(0.005, -0.005, 0.07, 4 * kPi / 180),
                        Pose(-0.004, 0.003, 0.06, -0.05)};
  const Wrench we(0.3, -0.2, 1.5, 0.01);
  for (const Pose& pose : poses) {
    auto config = [&](const Pose& x) {
      Vec16 q;
      EXPECT_EQ(closed_form_position(m, x, q), Status::Ok);
      return q;
    };
    Mat4 J;
    Vec4 gradU;
    const double e = 1e-6;
    for (int k = 0; k < 4; ++k) {
      Pose a = pose, b = pose;
      a[k] += e;
      b[k] -= e;
      const Vec16 qa = config(a), qb = config(b);
      for (int i = 0; i < 4; ++i) J(i, k) = (qa[leg_offset(i)] - qb[leg_offset(i)]) / (2 * e);
      gradU[k] = (ref::potential_energy(r, qa) - ref::potential_energy(r, qb)) / (2 * e);
    }
    const Vec4 F_ref = J.transpose().partialPivLu().solve(gradU - we);
    Vec4 F;
    ASSERT_EQ(holding_forces(m, config(pose), we, F), Status::Ok);
    EXPECT_LT((F - F_ref).lpNorm<Eigen::Infinity>(), 1e-7) << "F    = " << F.transpose() << "\nF_ref= " << F_ref.transpose();
    // The plant reports the same as its output F_hold.
    Plant plant(m);
    ASSERT_EQ(plant.initialize(0.0, pose, Pose::Zero()), Status::Ok);
    LinearInputs in;
    in.we0 = we;
    MachineOutputs out;
    ASSERT_EQ(plant.machine_outputs(in.signal(), out), Status::Ok);
    EXPECT_LT((out.F_hold - F).lpNorm<Eigen::Infinity>(), 1e-12);
    // Held by F_hold (as forces, or half as motor torques), the machine stays at rest.
    LinearInputs hold;
    hold.we0 = we;
    hold.F0 = 0.5 * F;
    hold.tau0 = 0.5 * F / m.drive_ratio;
    Vec8 yd;
    ASSERT_EQ(state_derivative(m, Formulation::LegPartitioned, plant.state(),
                               generalized_forces(m, hold.F0, hold.tau0, we), yd), Status::Ok);
    EXPECT_LT(yd.tail<4>().lpNorm<Eigen::Infinity>(), 1e-10);
  }
}

// ---------------------------------------------------------------------------
// Energy audit along the auto-test with every term on
// ---------------------------------------------------------------------------

namespace {

// The auto-test's path forces, delivered half as actuator forces and half
// as motor torques, with a constant external wrench.
struct SplitPathInputs {
  PathForces path;
  Wrench we = Wrench::Zero();
  static void eval(void* self, double t, Vec4& F, Wrench& we) {
    auto* me = static_cast<SplitPathInputs*>(self);
    Pose p, pd, pdd;
    me->path.path.eval(t, p, pd, pdd);
    if (inverse_dynamics(*me->path.model, p, pd, pdd, me->we, me->path.id) != Status::Ok)
      me->path.status = Status::Singular;
    F = 0.5 * me->path.id.F;
    we = me->we;
  }
  static void eval_tau(void* self, double t, Vec4& tau) {
    auto* me = static_cast<SplitPathInputs*>(self);
    Vec4 F;
    Wrench we;
    eval(self, t, F, we);
    tau = 0.5 * me->path.id.tau;
  }
  InputSignal signal() { return {&eval, this, &eval_tau}; }
};

struct AuditRun {
  double max_drift = 0;       // J
  double max_pose_error = 0;  // m (x, y, z) or rad (phi)
  double work = 0, dissipated = 0;
};

AuditRun audit(const Model& m, Solver solver) {
  SplitPathInputs in;
  in.path.model = &m;
  in.we = Wrench(0.05, -0.03, 0.2, 0.002);
  Plant plant(m);
  SolverSettings st;
  st.solver = solver;
  st.rk4_step = 1e-3;
  st.rtol = 1e-12;
  st.atol = 1e-14;
  EXPECT_EQ(plant.set_solver(st), Status::Ok);
  EXPECT_EQ(plant.initialize(0.0, in.path.path.p0, Pose::Zero()), Status::Ok);
  auto energy = [&]() {
    MachineOutputs o;
    EXPECT_EQ(plant.machine_outputs(in.signal(), o), Status::Ok);
    for (int i = 0; i < 4; ++i) EXPECT_EQ(o.stop_force[i], 0.0);  // the stops are not hit
    return o.kinetic_energy + o.potential_energy - o.actuator_work + o.dissipated_energy;
  };
  const double E0 = energy();
  AuditRun r;
  for (int k = 1; k <= 200; ++k) {
    const double t = 0.01 * k;
    EXPECT_EQ(plant.advance(t, in.signal(), true), Status::Ok) << plant.last_error();
    EXPECT_EQ(in.path.status, Status::Ok);
    r.max_drift = std::max(r.max_drift, std::fabs(energy() - E0));
    Pose want, pd, pdd;
    in.path.path.eval(t, want, pd, pdd);
    r.max_pose_error = std::max(r.max_pose_error, (plant.state().head<4>() - want).lpNorm<Eigen::Infinity>());
  }
  r.work = plant.energy_integrals().actuator_work;
  r.dissipated = plant.energy_integrals().dissipated;
  return r;
}

}  // namespace

TEST(MachineEnergy, AuditIsConstantAlongTheAutotestWithEveryTermOn) {
  const Model m = model_of(machine_params());
  for (Solver solver : {Solver::Rk4, Solver::Cvode}) {
    const AuditRun r = audit(m, solver);
    const char* name = solver == Solver::Rk4 ? "RK4 1 ms" : "CVODE";
    EXPECT_LE(r.max_drift, 1e-9) << name;
    EXPECT_GT(r.dissipated, 1e-3) << name;  // friction really works
    EXPECT_GT(r.work, 0.1) << name;          // lifting 1.25 kg by 20 mm
    std::printf("  energy audit, %s: max |K + U - W + D - E0| = %.2e J (W = %.6f J, D = %.6f J), "
                "max pose error %.2e\n", name, r.max_drift, r.work, r.dissipated, r.max_pose_error);
  }
}

// ---------------------------------------------------------------------------
// Inverse -> forward round trip (the spec's auto-test) with every term on
// ---------------------------------------------------------------------------

TEST(MachineAutotest, RoundTripStaysWithinTheAutotestBounds) {
  const Model m = model_of(machine_params());
  for (Solver solver : {Solver::Rk4, Solver::Cvode}) {
    AutotestOptions opt;
    opt.solver.solver = solver;
    opt.solver.rk4_step = 1e-3;
    opt.solver.rtol = 1e-12;
    opt.solver.atol = 1e-14;
    AutotestResult r;
    ASSERT_EQ(run_autotest(m, opt, r), Status::Ok) << r.error;
    // The bounds of test_autotest.cpp.
    EXPECT_LE(r.max_position_error, 1e-10);
    EXPECT_LE(r.max_angle_error, 1e-10);
    EXPECT_LE(r.max_constraint_residual, 1e-12);
    std::printf("  round trip with every term on, %s: %.2e m, %.2e rad\n",
                solver == Solver::Rk4 ? "RK4 1 ms" : "CVODE", r.max_position_error, r.max_angle_error);
  }
}

TEST(MachineInverse, TorquesAreTheForcesOnTheScrewAndStopsAreReported) {
  const Model m = model_of(machine_params());
  InverseDynamicsResult r;
  ASSERT_EQ(inverse_dynamics(m, Pose(0.001, 0, 0.06, 0.01), Pose(0.01, 0, 0.02, 0.1), Pose(0.1, 0.2, 0.3, 1.0),
                             Wrench::Zero(), r), Status::Ok);
  for (int i = 0; i < 4; ++i) EXPECT_NEAR(r.tau[i], r.F[i] * 0.004 / (2 * kPi), 1e-15);
  EXPECT_EQ(r.beyond_stops, 0u);
  // A pose whose rho lie below rho_min: solved, and reported.
  Params p = machine_params();
  p.rho_min = 0.05;  // home's rho = 0.0443 m
  const Model low = model_of(p);
  ASSERT_EQ(inverse_dynamics(low, Pose(0, 0, 0.05, 0), Pose::Zero(), Pose::Zero(), Wrench::Zero(), r), Status::Ok);
  EXPECT_EQ(r.beyond_stops, 0x0Fu);
}

// ---------------------------------------------------------------------------
// Drop onto the lower end stops
// ---------------------------------------------------------------------------

// From rest at the default pose with F = 0 the machine falls freely (every
// body at g: the constraints carry nothing) through rho0 = 0.0443193423 m
// (docs/model.md golden pose) and lands on the four lower stops at
// v0 = sqrt(2 g rho0) ~ 0.93 m/s. By the symmetry argument of the viscous
// fall above (equal forces on the four rho keep the motion a vertical
// translation; the test checks x, y, phi stay ~0) it is one body of mass
// m_tot on four springs k with dampers d. Energy from the moment of
// contact: damping only removes energy and the release clamp only removes
// force, so at the deepest point
//   1/2 (4k) delta^2 <= 1/2 m_tot v0^2 + m_tot g delta
//   => delta <= delta_s + sqrt(delta_s^2 + m_tot v0^2 / (4k)),
//   delta_s = m_tot g / (4k)   (the static penetration, weight / k per stop).
// At rest it settles at delta_s.
namespace {

struct DropRun {
  std::vector<Pose> samples;  // every 10 ms
  double max_depth = 0;       // m, over all advance() points
  double final_depth = 0;
  double final_speed = 0;
  double max_asymmetry = 0;   // |x|, |y|, |phi| * 0.1 m
  long events = 0;
  Status status = Status::Ok;
  std::string error;
};

DropRun drop(const Model& m, Solver solver, double interval, double duration) {
  DropRun r;
  Plant plant(m);
  SolverSettings st;
  st.solver = solver;
  EXPECT_EQ(plant.set_solver(st), Status::Ok);
  EXPECT_EQ(plant.initialize(0.0, Pose(0, 0, 0.05, 0), Pose::Zero()), Status::Ok);
  LinearInputs none;  // F = 0
  const long n = std::lround(duration / interval);
  const long per_sample = std::lround(0.01 / interval);
  r.samples.push_back(plant.state().head<4>());
  for (long k = 1; k <= n; ++k) {
    r.status = plant.advance(k * interval, none.signal(), true);
    if (r.status != Status::Ok) {
      r.error = plant.last_error();
      return r;
    }
    MachineOutputs o;
    EXPECT_EQ(plant.machine_outputs(none.signal(), o), Status::Ok);
    for (int i = 0; i < 4; ++i) r.max_depth = std::max(r.max_depth, m.p.rho_min - o.rho[i]);
    const Vec8& y = plant.state();
    r.max_asymmetry = std::max({r.max_asymmetry, std::fabs(y[0]), std::fabs(y[1]), 0.1 * std::fabs(y[3])});
    if (k % per_sample == 0) r.samples.push_back(y.head<4>());
    if (k == n) {
      r.final_depth = m.p.rho_min - o.rho.minCoeff();
      r.final_speed = y.tail<4>().lpNorm<Eigen::Infinity>();
      for (int i = 0; i < 4; ++i) EXPECT_GT(o.stop_force[i], 0.0);  // resting on the stops
    }
  }
  r.events = plant.contact_events();
  return r;
}

}  // namespace

TEST(MachineStops, DropOntoTheLowerStopsComesToRestWithinTheDerivedBound) {
  const Model m = default_model();
  const double m_tot = 0.45474 + 4 * (0.09331 + 0.06371), g = 9.81, k = 1e5;
  const double rho0 = 0.0443193423;
  const double v0sq = 2 * g * rho0;
  const double delta_s = m_tot * g / (4 * k);
  const double bound = delta_s + std::sqrt(delta_s * delta_s + m_tot * v0sq / (4 * k));
  for (Solver solver : {Solver::Rk4, Solver::Cvode}) {
    const char* name = solver == Solver::Rk4 ? "RK4" : "CVODE";
    DropRun runs[3];
    const double intervals[3] = {1e-4, 1e-3, 1e-2};
    for (int j = 0; j < 3; ++j) {
      runs[j] = drop(m, solver, intervals[j], 1.0);
      EXPECT_EQ(runs[j].status, Status::Ok) << name << " every " << intervals[j] << " s: " << runs[j].error;
      if (runs[j].status != Status::Ok) continue;
      EXPECT_LE(runs[j].max_depth, bound) << name;
      if (j == 0) {
        EXPECT_GT(runs[j].max_depth, 0.5 * bound) << name;  // it did land hard (seen every 0.1 ms)
      }
      EXPECT_NEAR(runs[j].final_depth, delta_s, 1e-9) << name;
      EXPECT_LT(runs[j].final_speed, 1e-6) << name;
      EXPECT_LT(runs[j].max_asymmetry, 1e-9) << name;
      EXPECT_GT(runs[j].events, 0) << name;
    }
    double worst = 0;
    for (int j = 1; j < 3; ++j)
      for (size_t s = 0; s < runs[0].samples.size(); ++s) {
        const double d = (runs[j].samples[s] - runs[0].samples[s]).head<3>().lpNorm<Eigen::Infinity>();
        worst = std::max(worst, d);
      }
    EXPECT_LT(worst, 1e-6) << name;
    std::printf("  drop, %s: max penetration %.4e m (bound %.4e, static %.4e), final %.6e m, "
                "samples every 10 ms agree within %.2e m across advance() every 0.1/1/10 ms, %ld contact events\n",
                name, runs[0].max_depth, bound, delta_s, runs[0].final_depth, worst, runs[0].events);
  }
}

TEST(MachineStops, IndicatorsAndStopForcesAtAnArbitraryState) {
  const Model m = default_model();
  double g[kStopIndicators];
  ASSERT_EQ(stop_indicators(m, Pose(0, 0, 0.05, 0), kStopsFromState, g), Status::Ok);
  for (int i = 0; i < 4; ++i) {
    EXPECT_NEAR(g[i], 0.0443193423, 1e-10);
    EXPECT_NEAR(g[4 + i], 0.15 - 0.0443193423, 1e-10);
  }
  const Params& p = m.p;
  EXPECT_EQ(stop_force(p, 0.01, -1.0), 0.0);                  // within the travel
  EXPECT_NEAR(stop_force(p, -1e-4, 0.0), 1e5 * 1e-4, 1e-12);  // spring pushes up
  EXPECT_NEAR(stop_force(p, -1e-4, -0.1), 10.0 + 10.0, 1e-12);
  EXPECT_EQ(stop_force(p, -1e-4, 0.2), 0.0);                  // would pull: released
  EXPECT_NEAR(stop_force(p, 0.1501, 0.0), -10.0, 1e-9);       // upper stop pushes down
}

// SPDX-License-Identifier: BSD-2-Clause
// The payload at run time in the core and its C API: a tunable parameter
// (pkm_set_parameter, Plant::retune) keeps the run and the platform's
// velocity, books the grasp's work so that the energy audit holds, restarts
// CVODE, and refuses what is not tunable or not valid, nothing changed.
// The sinking acceleration at the home pose is the spec's (its derivation:
// tests/fmi/payload.cpp), -m g / (M + m + 4 m_r): each slider moves with P
// along z, so each rotor adds its reflected mass m_r = J (2 pi / p)^2 there.
#include <cmath>
#include <cstring>
#include <set>
#include <string>

#include <gtest/gtest.h>

#include "pkm4puu/pkm.h"
#include "pkm4puu/sim/plant.hpp"
#include "test_support.hpp"

namespace {

constexpr double kG = 9.81;
constexpr double kMovingMass = 0.45474 + 4 * (0.09331 + 0.06371);  // kg, Table III
constexpr double kHolding = 2.655616050;  // N: each actuator at home (docs/model.md "A check anyone can derive")
constexpr double kScrewLead = 0.004;      // m, the default
const double kHome[4] = {0.0, 0.0, 0.05, 0.0};
const char* const kPayloadNames[] = {"payload_mass", "payload_com[1]", "payload_com[2]", "payload_Izz"};

/// A C API model with its outputs and state at hand.
struct Machine {
  pkm_model* m = nullptr;
  double u[PKM_PLANT_INPUTS] = {kHolding, kHolding, kHolding, kHolding};  // holds the empty machine at home
  Machine() { EXPECT_EQ(pkm_create(&m), PKM_OK); }
  ~Machine() { pkm_destroy(m); }
  Machine(const Machine&) = delete;
  Machine& operator=(const Machine&) = delete;
  std::string error() const { return pkm_last_error(m); }
  pkm_status set(const char* name, double v) { return pkm_set_parameter(m, name, v); }
  pkm_outputs outputs() {
    pkm_outputs o{};
    o.size = sizeof o;
    EXPECT_EQ(pkm_get_outputs(m, u, &o), PKM_OK) << error();
    return o;
  }
  pkm_state state() {
    pkm_state s{};
    s.size = sizeof s;
    EXPECT_EQ(pkm_get_state(m, &s), PKM_OK) << error();
    return s;
  }
};

double audit(const pkm_outputs& o) {
  return o.kinetic_energy + o.potential_energy - o.actuator_work + o.dissipated_energy;
}

bool same_motion(const pkm_outputs& a, const pkm_outputs& b) {
  return std::memcmp(a.pose, b.pose, sizeof a.pose) == 0 && std::memcmp(a.velocity, b.velocity, sizeof a.velocity) == 0;
}

/// Smooth forces about the holding ones (N), for pkm_advance_fn.
void wobbling_forces(void*, double t, double u[PKM_PLANT_INPUTS]) {
  for (int i = 0; i < 4; ++i) u[i] = kHolding + 0.05 * std::sin(2 * pkm::kPi * (3.0 + i) * t);
}

}  // namespace

// docs/model.md: payload_mass, payload_com[1..2] and payload_Izz "are
// tunable", and only they; a tunable parameter is not a solver setting.
TEST(PayloadAtRunTime, TheTunableParametersAreThePayloads) {
  std::set<std::string> tunable;
  for (std::size_t i = 0; i < pkm_parameter_count(); ++i) {
    pkm_parameter p{};
    p.size = sizeof p;
    ASSERT_EQ(pkm_parameter_info(i, &p), PKM_OK);
    if (!p.is_tunable) continue;
    tunable.insert(p.name);
    EXPECT_EQ(p.is_solver_setting, 0) << p.name;
  }
  EXPECT_EQ(tunable, std::set<std::string>(std::begin(kPayloadNames), std::end(kPayloadNames)));
}

// At rest at home, held by the forces that hold the empty machine: a payload
// at P keeps the state and accelerates the platform straight down at
// -m g / (M + m + 4 m_r); each actuator's holding force grows by m g / 4;
// the fall goes on at that acceleration (CVODE at rtol 1e-12).
TEST(PayloadAtRunTime, APayloadAddedAtRestSinksAtTheSpecsAcceleration) {
  for (double J : {0.0, 2e-7}) {
    SCOPED_TRACE(J);
    Machine h;
    ASSERT_EQ(h.set("rotor_inertia", J), PKM_OK);
    ASSERT_EQ(h.set("rtol", 1e-12), PKM_OK);
    ASSERT_EQ(h.set("atol", 1e-14), PKM_OK);
    ASSERT_EQ(pkm_init_pose(h.m, 0.0, kHome, nullptr), PKM_OK) << h.error();
    ASSERT_EQ(pkm_advance(h.m, 0.01, h.u), PKM_OK) << h.error();
    const pkm_outputs held = h.outputs();
    const double m = 0.25, reflected = J * std::pow(2 * pkm::kPi / kScrewLead, 2);
    ASSERT_EQ(h.set("payload_mass", m), PKM_OK) << h.error();
    ASSERT_EQ(h.set("payload_Izz", 1e-4), PKM_OK) << h.error();  // no turn: no effect
    const pkm_outputs grasped = h.outputs();
    EXPECT_TRUE(same_motion(held, grasped)) << "the pose and the velocity are kept";
    const double a = -m * kG / (kMovingMass + m + 4 * reflected);
    EXPECT_NEAR(grasped.acceleration[2], a, 1e-9 * std::fabs(a));
    for (int k : {0, 1, 3}) EXPECT_NEAR(grasped.acceleration[k], 0.0, 1e-9) << k;
    for (int i = 0; i < 4; ++i) EXPECT_NEAR(grasped.F_hold[i], kHolding + m * kG / 4, 1e-9) << i;
    const double T = 0.05, v0 = grasped.velocity[2];
    ASSERT_EQ(pkm_advance(h.m, 0.01 + T, h.u), PKM_OK) << h.error();
    const pkm_outputs fallen = h.outputs();
    EXPECT_NEAR(fallen.pose[2] - grasped.pose[2], v0 * T + 0.5 * a * T * T, 1e-9 * 0.5 * std::fabs(a) * T * T);
    EXPECT_NEAR(fallen.velocity[2], v0 + a * T, 1e-9 * std::fabs(a) * T);
  }
}

// A grasp while the platform moves: the state is kept bit for bit, and
// actuator_work takes the payload's own energy at that instant, the spec's
// "work done by the grasp": 1/2 m |v_c|^2 + 1/2 I phid^2 + m g z_c, with
// v_c = v_P + phid e_z x R(phi) c its centre's velocity and z_c = z_P its
// height. The audit (kinetic + potential - actuator_work + dissipated) holds
// across it at rounding level, with each solver; a release later gives the
// energy back the same way, and over the run the audit drifts no more than
// the solver's own error.
TEST(PayloadAtRunTime, TheGraspIsBookedAsWorkAndTheAuditHolds) {
  const double values[] = {0.3, 0.012, -0.007, 1.5e-4};
  const double v0[4] = {0.02, -0.01, 0.03, 0.4};
  for (int solver : {PKM_SOLVER_CVODE, PKM_SOLVER_RK4, PKM_SOLVER_ROSENBROCK}) {
    SCOPED_TRACE(solver);
    Machine h;
    ASSERT_EQ(h.set("solver", solver), PKM_OK);
    ASSERT_EQ(h.set("rk4_step", 1e-4), PKM_OK);
    ASSERT_EQ(h.set("rtol", 1e-11), PKM_OK);
    ASSERT_EQ(h.set("atol", 1e-13), PKM_OK);
    ASSERT_EQ(pkm_init_pose(h.m, 0.0, kHome, v0), PKM_OK) << h.error();
    const double start = audit(h.outputs());
    ASSERT_EQ(pkm_advance(h.m, 0.02, h.u), PKM_OK) << h.error();
    const pkm_outputs before = h.outputs();
    ASSERT_EQ(pkm_set_parameters(h.m, 4, kPayloadNames, values), PKM_OK) << h.error();
    const pkm_outputs after = h.outputs();
    EXPECT_TRUE(same_motion(before, after));
    const double m = values[0], I = values[3], phi = after.pose[3], phid = after.velocity[3];
    const double cx = std::cos(phi) * values[1] - std::sin(phi) * values[2];  // R(phi) c
    const double cy = std::sin(phi) * values[1] + std::cos(phi) * values[2];
    const double vx = after.velocity[0] - phid * cy, vy = after.velocity[1] + phid * cx, vz = after.velocity[2];
    const double grasp = 0.5 * m * (vx * vx + vy * vy + vz * vz) + 0.5 * I * phid * phid + m * kG * after.pose[2];
    EXPECT_NEAR(after.actuator_work - before.actuator_work, grasp, 1e-13);
    EXPECT_EQ(after.dissipated_energy, before.dissipated_energy);
    EXPECT_NEAR(audit(after), audit(before), 1e-15) << "the audit across the grasp";
    ASSERT_EQ(pkm_advance(h.m, 0.04, h.u), PKM_OK) << h.error();
    const pkm_outputs held = h.outputs();
    ASSERT_EQ(h.set("payload_mass", 0.0), PKM_OK) << h.error();
    const pkm_outputs released = h.outputs();
    EXPECT_TRUE(same_motion(held, released));
    EXPECT_LT(released.actuator_work, held.actuator_work) << "the release gives the payload's energy back";
    EXPECT_NEAR(audit(released), audit(held), 1e-15) << "the audit across the release";
    ASSERT_EQ(pkm_advance(h.m, 0.06, h.u), PKM_OK) << h.error();
    const double drift = audit(h.outputs()) - start;
    std::printf("solver %d: audit drift over 60 ms with a grasp and a release %.2e J\n", solver, drift);
    EXPECT_LT(std::fabs(drift), 1e-9);
  }
}

// CVODE restarts at a change: the run goes on exactly as a fresh run from
// the same state with the new payload (which restarts it), although the
// caller says its inputs continue (pkm_advance_fn's continuous = 1).
TEST(PayloadAtRunTime, AChangeRestartsCvodeAsAFreshRunWould) {
  Machine a, b;
  const double v0[4] = {0.01, 0.0, -0.02, 0.1};
  ASSERT_EQ(pkm_init_pose(a.m, 0.0, kHome, v0), PKM_OK) << a.error();
  ASSERT_EQ(pkm_advance_fn(a.m, 0.02, wobbling_forces, nullptr, 1), PKM_OK) << a.error();
  ASSERT_EQ(a.set("payload_mass", 0.25), PKM_OK) << a.error();
  ASSERT_EQ(b.set("payload_mass", 0.25), PKM_OK) << b.error();
  const pkm_state grasped = a.state();
  ASSERT_EQ(pkm_set_state(b.m, &grasped), PKM_OK) << b.error();
  ASSERT_EQ(pkm_advance_fn(a.m, 0.04, wobbling_forces, nullptr, 1), PKM_OK) << a.error();
  ASSERT_EQ(pkm_advance_fn(b.m, 0.04, wobbling_forces, nullptr, 0), PKM_OK) << b.error();
  const pkm_state sa = a.state(), sb = b.state();
  EXPECT_EQ(std::memcmp(sa.y, sb.y, sizeof sa.y), 0) << "the run differs from a fresh one: CVODE went on";
  EXPECT_EQ(sa.actuator_work, sb.actuator_work);
}

// Bad values answer as any parameter's do: PKM_ERR_INVALID_PARAMETER naming
// it, nothing changed, and the run goes on as an untouched twin's.
TEST(PayloadAtRunTime, BadValuesAreRefusedAndTheRunGoesOn) {
  Machine h, twin;
  for (Machine* p : {&h, &twin}) {
    ASSERT_EQ(pkm_init_pose(p->m, 0.0, kHome, nullptr), PKM_OK);
    ASSERT_EQ(pkm_advance(p->m, 0.01, p->u), PKM_OK);
  }
  const pkm_state before = h.state();
  const struct {
    const char* name;
    double value;
  } bad[] = {{"payload_mass", -0.1}, {"payload_mass", std::nan("")}, {"payload_mass", 2e4},
             {"payload_com[2]", 11.0}, {"payload_Izz", -1e-6}};
  for (const auto& b : bad) {
    EXPECT_EQ(h.set(b.name, b.value), PKM_ERR_INVALID_PARAMETER) << b.name << " = " << b.value;
    EXPECT_NE(h.error().find(std::string("parameter ") + b.name), std::string::npos) << h.error();
  }
  double mass = -1.0;
  ASSERT_EQ(pkm_get_parameter(h.m, "payload_mass", &mass), PKM_OK);
  EXPECT_EQ(mass, 0.0);
  const pkm_state after = h.state();
  EXPECT_EQ(std::memcmp(&before, &after, sizeof before), 0) << "a refused value changed the state";
  ASSERT_EQ(pkm_advance(h.m, 0.02, h.u), PKM_OK) << h.error();
  ASSERT_EQ(pkm_advance(twin.m, 0.02, twin.u), PKM_OK);
  const pkm_state sh = h.state(), st = twin.state();
  EXPECT_EQ(std::memcmp(&sh, &st, sizeof sh), 0) << "the run after the refusals differs from the twin's";
}

// One set: a tunable parameter with a solver setting keeps the run (both
// applied); with a fixed parameter the run ends, as a fixed parameter alone
// ends it.
TEST(PayloadAtRunTime, WithAFixedParameterTheRunEndsWithASolverSettingItGoesOn) {
  Machine h;
  ASSERT_EQ(pkm_init_pose(h.m, 0.0, kHome, nullptr), PKM_OK);
  const char* with_solver[] = {"payload_mass", "solver"};
  const double v1[] = {0.2, PKM_SOLVER_RK4};
  ASSERT_EQ(pkm_set_parameters(h.m, 2, with_solver, v1), PKM_OK) << h.error();
  EXPECT_EQ(pkm_advance(h.m, 0.01, h.u), PKM_OK) << h.error();
  double solver = -1.0;
  ASSERT_EQ(pkm_get_parameter(h.m, "solver", &solver), PKM_OK);
  EXPECT_EQ(solver, PKM_SOLVER_RK4);
  EXPECT_LT(h.outputs().velocity[2], 0.0) << "the payload sinks the platform";
  const char* with_fixed[] = {"payload_mass", "g"};
  const double v2[] = {0.1, 9.0};
  ASSERT_EQ(pkm_set_parameters(h.m, 2, with_fixed, v2), PKM_OK) << h.error();
  EXPECT_EQ(pkm_advance(h.m, 0.02, h.u), PKM_ERR_NOT_INITIALIZED);
  EXPECT_NE(h.error().find("a parameter of the machine changed"), std::string::npos) << h.error();
}

// Plant::retune itself: new values of a parameter that is not tunable are
// refused (InvalidArgument), invalid ones too (InvalidParameter); nothing
// changes and last_error() names the parameter.
TEST(PayloadAtRunTime, RetuneRefusesWhatIsNotTunableOrNotValid) {
  pkm::Plant p(pkm_test::default_model());
  ASSERT_EQ(p.initialize(0.0, pkm::Pose(0.0, 0.0, 0.05, 0.0), pkm::Pose(0.01, 0.0, 0.0, 0.0)), pkm::Status::Ok);
  const pkm::Vec8 y = p.state();
  const double work = p.energy_integrals().actuator_work;
  pkm::Params q = p.model().p;
  q.payload_mass = 0.3;
  q.g = 9.0;
  EXPECT_EQ(p.retune(q), pkm::Status::InvalidArgument);
  EXPECT_NE(p.last_error().find("parameter g is not tunable"), std::string::npos) << p.last_error();
  q = p.model().p;
  q.payload_Izz = -1.0;
  EXPECT_EQ(p.retune(q), pkm::Status::InvalidParameter);
  EXPECT_NE(p.last_error().find("payload_Izz"), std::string::npos) << p.last_error();
  EXPECT_EQ(p.model().p.payload_mass, 0.0);
  EXPECT_EQ(p.model().p.payload_Izz, 0.0);
  EXPECT_TRUE(p.state() == y);
  EXPECT_EQ(p.energy_integrals().actuator_work, work);
}

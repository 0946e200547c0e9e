// SPDX-License-Identifier: BSD-2-Clause
// The plain C API (pkm.h): versions, parameters by name and their errors,
// the growable structs, pose errors, forward and inverse dynamics through
// it, state save/restore, the machine's inputs and outputs, the derivatives
// and the regressor's layout, and that a failed call writes and changes
// nothing and says why.
#include <cmath>
#include <cstring>
#include <string>

#include <gtest/gtest.h>

#include "pkm4puu/pkm.h"

namespace {

struct Handle {
  pkm_model* m = nullptr;
  Handle() { EXPECT_EQ(pkm_create(&m), PKM_OK); }
  ~Handle() { pkm_destroy(m); }
  std::string error() const { return pkm_last_error(m); }
};

const double kHome[4] = {0.0, 0.0, 0.05, 0.0};
const double kZero[4] = {0.0, 0.0, 0.0, 0.0};
constexpr double kPi = 3.14159265358979323846;

bool contains(const std::string& s, const char* part) { return s.find(part) != std::string::npos; }

// A pkm.h struct zeroed with its size set (C: `pkm_outputs o = {.size = sizeof(pkm_outputs)};`).
template <class T>
T sized() {
  T v{};
  v.size = sizeof(T);
  return v;
}

// u[PKM_PLANT_INPUTS] with the forces F and the rest zero.
struct Inputs {
  double u[PKM_PLANT_INPUTS] = {};
  explicit Inputs(const double F[4], const double tau[4] = nullptr) {
    for (int i = 0; i < 4; ++i) {
      u[i] = F[i];
      u[8 + i] = tau ? tau[i] : 0.0;
    }
  }
};

}  // namespace

// One version: CMake's project() (PKM_PROJECT_VERSION, set by
// tests/CMakeLists.txt), the header's macros and the library's answer; the
// ABI version is the header's and the library's.
TEST(CApi, VersionIsTheProjectVersionInHeaderAndLibrary) {
  const std::string numbers = std::to_string(PKM_VERSION_MAJOR) + "." + std::to_string(PKM_VERSION_MINOR) + "." +
                              std::to_string(PKM_VERSION_PATCH);
  EXPECT_EQ(numbers, PKM_PROJECT_VERSION);
  EXPECT_STREQ(PKM_VERSION_STRING, PKM_PROJECT_VERSION);
  EXPECT_STREQ(pkm_version(), PKM_PROJECT_VERSION);
  EXPECT_EQ(pkm_abi_version(), PKM_ABI_VERSION);
}

TEST(CApi, ParametersAreSetByNameWithTheirRangesAndMessages) {
  Handle h;
  double v = 0;
  ASSERT_EQ(pkm_get_parameter(h.m, "r_b", &v), PKM_OK);
  EXPECT_EQ(v, 0.09273);  // docs/model.md, Table II
  EXPECT_EQ(pkm_set_parameter(h.m, "r_b", -1.0), PKM_ERR_INVALID_PARAMETER);
  EXPECT_TRUE(contains(h.error(), "pkm_set_parameter: parameter r_b = -1 must be positive")) << h.error();
  EXPECT_EQ(pkm_set_parameter(h.m, "payload_mas", 0.25), PKM_ERR_INVALID_ARGUMENT);
  EXPECT_TRUE(contains(h.error(), "no parameter is called \"payload_mas\"")) << h.error();
  EXPECT_EQ(pkm_set_parameter(h.m, "x0", 0.01), PKM_ERR_INVALID_ARGUMENT);  // pkm_init_pose takes the pose
  EXPECT_EQ(pkm_set_parameter(h.m, "solver", 1.5), PKM_ERR_INVALID_PARAMETER);
  EXPECT_TRUE(contains(h.error(), "solver = 1.5 must be a whole number")) << h.error();
  EXPECT_EQ(pkm_set_parameter(h.m, "solver", 7), PKM_ERR_INVALID_PARAMETER);
  EXPECT_TRUE(contains(h.error(), "solver = 7 must be 0 (CVODE), 1 (RK4) or 2 (Rosenbrock)")) << h.error();
  EXPECT_EQ(pkm_set_parameter(h.m, "rk4_step", -1e-3), PKM_ERR_INVALID_PARAMETER);
  EXPECT_TRUE(contains(h.error(), "rk4_step")) << h.error();
  ASSERT_EQ(pkm_get_parameter(h.m, "r_b", &v), PKM_OK);
  EXPECT_EQ(v, 0.09273) << "a refused value changes nothing";
  ASSERT_EQ(pkm_set_parameter(h.m, "payload_mass", 0.25), PKM_OK);
  ASSERT_EQ(pkm_get_parameter(h.m, "payload_mass", &v), PKM_OK);
  EXPECT_EQ(v, 0.25);
}

TEST(CApi, SeveralParametersChangeAsOneSet) {
  // The stops moved up past each other: one at a time the first change
  // leaves rho_min above rho_max; as one set they fit.
  Handle h;
  const char* names[] = {"rho_min", "rho_max"};
  const double values[] = {0.2, 0.3};
  EXPECT_EQ(pkm_set_parameter(h.m, "rho_min", 0.2), PKM_ERR_INVALID_PARAMETER);
  EXPECT_TRUE(contains(h.error(), "rho_max = 0.14999999999999999 must exceed rho_min = 0.20000000000000001"))
      << h.error();
  const double bad[] = {0.2, 20.0};
  EXPECT_EQ(pkm_set_parameters(h.m, 2, names, bad), PKM_ERR_INVALID_PARAMETER);
  double v = 0;
  ASSERT_EQ(pkm_get_parameter(h.m, "rho_min", &v), PKM_OK);
  EXPECT_EQ(v, 0.0) << "all or nothing";
  ASSERT_EQ(pkm_set_parameters(h.m, 2, names, values), PKM_OK) << h.error();
  ASSERT_EQ(pkm_get_parameter(h.m, "rho_max", &v), PKM_OK);
  EXPECT_EQ(v, 0.3);
}

TEST(CApi, AMachineParameterEndsTheRunAndASolverSettingKeepsIt) {
  Handle h;
  ASSERT_EQ(pkm_init_pose(h.m, 0.0, kHome, nullptr), PKM_OK);
  ASSERT_EQ(pkm_set_parameter(h.m, "solver", PKM_SOLVER_RK4), PKM_OK);
  EXPECT_EQ(pkm_advance(h.m, 0.01, nullptr), PKM_OK) << h.error();
  ASSERT_EQ(pkm_set_parameter(h.m, "g", 0.0), PKM_OK);
  EXPECT_EQ(pkm_advance(h.m, 0.02, nullptr), PKM_ERR_NOT_INITIALIZED);
  EXPECT_TRUE(contains(h.error(), "a parameter of the machine changed since pkm_init_pose")) << h.error();
  ASSERT_EQ(pkm_init_pose(h.m, 0.0, kHome, nullptr), PKM_OK);
  EXPECT_EQ(pkm_advance(h.m, 0.01, nullptr), PKM_OK) << h.error();
  pkm_outputs out = sized<pkm_outputs>();
  ASSERT_EQ(pkm_get_outputs(h.m, nullptr, &out), PKM_OK);
  for (int k = 0; k < 4; ++k) EXPECT_EQ(out.pose[k], kHome[k]) << "no gravity, no force: at rest";
}

TEST(CApi, ParameterInfoListsEveryParameterOnce) {
  const size_t n = pkm_parameter_count();
  ASSERT_GE(n, 44u);
  int seen_payload = 0;
  for (size_t i = 0; i < n; ++i) {
    pkm_parameter p = sized<pkm_parameter>();
    ASSERT_EQ(pkm_parameter_info(i, &p), PKM_OK);
    ASSERT_NE(p.name, nullptr);
    EXPECT_LE(p.min, p.start) << p.name;
    EXPECT_LE(p.start, p.max) << p.name;
    double v = 0;
    Handle h;
    ASSERT_EQ(pkm_get_parameter(h.m, p.name, &v), PKM_OK) << p.name;
    EXPECT_EQ(v, p.start) << p.name;
    if (std::strcmp(p.name, "payload_mass") == 0) {
      ++seen_payload;
      EXPECT_STREQ(p.unit, "kg");
      EXPECT_EQ(p.value_reference, 157u);
      EXPECT_EQ(p.fmus, 3u);  // both FMUs
      EXPECT_EQ(p.is_solver_setting, 0);
    }
  }
  EXPECT_EQ(seen_payload, 1);
  pkm_parameter p = sized<pkm_parameter>();
  EXPECT_EQ(pkm_parameter_info(n, &p), PKM_ERR_INVALID_ARGUMENT);
}

// A caller built against a later pkm.h passes a larger struct: the library
// writes the fields it knows and leaves the rest; one whose size is smaller
// than the first version's struct is refused, nothing written.
TEST(CApi, StructsCarryTheirSizeAndOnlyThatMuchIsWritten) {
  struct Later {
    pkm_outputs known;
    double added;  // a field this library does not know
  } later;
  std::memset(&later, 0, sizeof later);
  later.known.size = sizeof later;
  later.added = 1234.5;
  Handle h;
  ASSERT_EQ(pkm_init_pose(h.m, 0.0, kHome, nullptr), PKM_OK);
  ASSERT_EQ(pkm_get_outputs(h.m, nullptr, &later.known), PKM_OK);
  EXPECT_EQ(later.known.size, sizeof later);
  EXPECT_EQ(later.known.pose[2], 0.05);
  EXPECT_EQ(later.added, 1234.5);
  pkm_outputs small;
  std::memset(&small, 0x7f, sizeof small);
  small.size = offsetof(pkm_outputs, stop_indicators);
  const pkm_outputs before = small;
  EXPECT_EQ(pkm_get_outputs(h.m, nullptr, &small), PKM_ERR_INVALID_ARGUMENT);
  EXPECT_TRUE(contains(h.error(), "pkm_outputs.size")) << h.error();
  EXPECT_EQ(std::memcmp(&small, &before, sizeof small), 0);
}

TEST(CApi, UnreachablePoseIsAnErrorWithAMessage) {
  Handle h;
  const double far[4] = {0.2, 0.0, 0.05, 0.0};
  EXPECT_EQ(pkm_init_pose(h.m, 0.0, far, nullptr), PKM_ERR_UNREACHABLE);
  EXPECT_TRUE(contains(h.error(), "unreachable")) << h.error();
  EXPECT_EQ(pkm_advance(h.m, 0.01, nullptr), PKM_ERR_NOT_INITIALIZED);
}

// After a failure with a message, a NULL argument names itself: the message
// is never the previous call's.
TEST(CApi, ANullArgumentReplacesThePreviousMessage) {
  Handle h;
  const double far[4] = {0.2, 0.0, 0.05, 0.0};
  ASSERT_EQ(pkm_init_pose(h.m, 0.0, far, nullptr), PKM_ERR_UNREACHABLE);
  ASSERT_EQ(pkm_init_pose(h.m, 0.0, kHome, nullptr), PKM_OK);
  EXPECT_EQ(pkm_advance_fn(h.m, 0.1, nullptr, nullptr, 0), PKM_ERR_INVALID_ARGUMENT);
  EXPECT_EQ(h.error(), "pkm_advance_fn: inputs is NULL");
  EXPECT_EQ(pkm_init_pose(h.m, 0.0, nullptr, nullptr), PKM_ERR_INVALID_ARGUMENT);
  EXPECT_EQ(h.error(), "pkm_init_pose: pose is NULL");
  EXPECT_EQ(pkm_inverse_dynamics(h.m, kHome, kZero, kZero, nullptr, nullptr), PKM_ERR_INVALID_ARGUMENT);
  EXPECT_EQ(h.error(), "pkm_inverse_dynamics: out is NULL");
  EXPECT_EQ(pkm_get_parameter(h.m, "g", nullptr), PKM_ERR_INVALID_ARGUMENT);
  EXPECT_EQ(h.error(), "pkm_get_parameter: value is NULL");
  EXPECT_EQ(pkm_create(nullptr), PKM_ERR_INVALID_ARGUMENT);
  EXPECT_STREQ(pkm_last_error(nullptr), "NULL handle");
}

TEST(CApi, NonFiniteForceIsRejectedAndTheStateKept) {
  Handle h;
  ASSERT_EQ(pkm_init_pose(h.m, 0.0, kHome, nullptr), PKM_OK);
  pkm_state s0 = sized<pkm_state>(), s1 = sized<pkm_state>();
  ASSERT_EQ(pkm_get_state(h.m, &s0), PKM_OK);
  double u[PKM_PLANT_INPUTS] = {1.0, NAN, 1.0, 1.0};
  EXPECT_EQ(pkm_advance(h.m, 0.01, u), PKM_ERR_NONFINITE);
  ASSERT_EQ(pkm_get_state(h.m, &s1), PKM_OK);
  EXPECT_EQ(std::memcmp(&s0, &s1, sizeof s0), 0);
}

// An advance the integrator cannot take is refused before any work, with
// its reason, the state kept; the FMU's DoStep asks the same question
// (Plant::advance_refusal). CVODE over less than sqrt(DBL_MIN) = 2^-511 s:
// its first-step estimate squares the span; RK4 over more grid steps than one
// call may take (1e5: rk4_step 1e-6 s over 0.2 s is 2e5).
TEST(CApi, AnAdvanceTheIntegratorCannotTakeIsRefusedBeforeAnyWork) {
  const struct {
    int solver;
    double rk4_step, span;
    const char* why;
  } cases[] = {{PKM_SOLVER_CVODE, 1e-3, 1e-200, "shorter than CVODE can start with"},
               {PKM_SOLVER_CVODE, 1e-3, std::ldexp(1.0, -512), "shorter than CVODE can start with"},
               {PKM_SOLVER_RK4, 1e-6, 0.2, "more than the 100000 inner steps one call may take"}};
  const Inputs in(kZero);
  for (const auto& c : cases) {
    Handle h;
    ASSERT_EQ(pkm_set_parameter(h.m, "solver", c.solver), PKM_OK);
    ASSERT_EQ(pkm_set_parameter(h.m, "rk4_step", c.rk4_step), PKM_OK);
    ASSERT_EQ(pkm_init_pose(h.m, 0.0, kHome, nullptr), PKM_OK);
    pkm_state s0 = sized<pkm_state>(), s1 = sized<pkm_state>();
    ASSERT_EQ(pkm_get_state(h.m, &s0), PKM_OK);
    EXPECT_EQ(pkm_advance(h.m, c.span, in.u), PKM_ERR_INVALID_ARGUMENT) << c.why;
    EXPECT_TRUE(contains(h.error(), c.why)) << h.error();
    ASSERT_EQ(pkm_get_state(h.m, &s1), PKM_OK);
    EXPECT_EQ(std::memcmp(&s0, &s1, sizeof s0), 0) << c.why;
  }
  Handle h;  // at the bound CVODE starts
  ASSERT_EQ(pkm_init_pose(h.m, 0.0, kHome, nullptr), PKM_OK);
  EXPECT_EQ(pkm_advance(h.m, std::ldexp(1.0, -511), in.u), PKM_OK) << h.error();
}

TEST(CApi, StaticForcesHoldTheHomePose) {
  // Inverse dynamics at rest, fed forward for 0.5 s, keeps the platform put.
  Handle h;
  pkm_inverse_result inv = sized<pkm_inverse_result>();
  ASSERT_EQ(pkm_inverse_dynamics(h.m, kHome, kZero, kZero, nullptr, &inv), PKM_OK);
  for (int i = 0; i < 4; ++i) EXPECT_NEAR(inv.F[i], 2.655616050, 1e-9);
  const Inputs in(inv.F);
  for (int solver : {PKM_SOLVER_CVODE, PKM_SOLVER_RK4, PKM_SOLVER_ROSENBROCK}) {
    ASSERT_EQ(pkm_set_parameter(h.m, "solver", solver), PKM_OK);
    ASSERT_EQ(pkm_init_pose(h.m, 0.0, kHome, nullptr), PKM_OK);
    ASSERT_EQ(pkm_advance(h.m, 0.5, in.u), PKM_OK) << h.error();
    pkm_outputs out = sized<pkm_outputs>();
    ASSERT_EQ(pkm_get_outputs(h.m, in.u, &out), PKM_OK);
    EXPECT_DOUBLE_EQ(out.t, 0.5);
    for (int k = 0; k < 4; ++k) EXPECT_NEAR(out.pose[k], kHome[k], 1e-12) << "solver " << solver;
    for (int k = 0; k < 12; ++k) EXPECT_NEAR(out.lambda[k], inv.lambda[k], 1e-9);
    EXPECT_LT(out.constraint_residual, 1e-15);
    EXPECT_GT(out.jacobian_condition, 1.0);
    EXPECT_LT(out.jacobian_condition, 26.0);
  }
}

// A run saved and restored, in place and into a fresh model, continues bit
// for bit: the pose, the energy integrals and the contact mode.
TEST(CApi, SavedStateRestoresABitIdenticalContinuation) {
  for (int solver : {PKM_SOLVER_RK4, PKM_SOLVER_ROSENBROCK}) {
    Handle h, fresh;
    ASSERT_EQ(pkm_set_parameter(h.m, "solver", solver), PKM_OK);
    ASSERT_EQ(pkm_set_parameter(fresh.m, "solver", solver), PKM_OK);
    const double v0[4] = {0.01, 0.0, 0.0, 0.05};
    ASSERT_EQ(pkm_init_pose(h.m, 0.0, kHome, v0), PKM_OK);
    const double F[4] = {2.7, 2.6, 2.65, 2.66};
    const Inputs in(F);
    ASSERT_EQ(pkm_advance(h.m, 0.2, in.u), PKM_OK);
    pkm_state saved = sized<pkm_state>();
    ASSERT_EQ(pkm_get_state(h.m, &saved), PKM_OK);
    EXPECT_NE(saved.actuator_work, 0.0);
    ASSERT_EQ(pkm_advance(h.m, 0.4, in.u), PKM_OK);
    pkm_outputs a = sized<pkm_outputs>(), b = sized<pkm_outputs>(), c = sized<pkm_outputs>();
    ASSERT_EQ(pkm_get_outputs(h.m, in.u, &a), PKM_OK);
    ASSERT_EQ(pkm_set_state(h.m, &saved), PKM_OK);
    ASSERT_EQ(pkm_advance(h.m, 0.4, in.u), PKM_OK);
    ASSERT_EQ(pkm_get_outputs(h.m, in.u, &b), PKM_OK);
    EXPECT_EQ(std::memcmp(&a, &b, sizeof a), 0) << "solver " << solver;
    ASSERT_EQ(pkm_set_state(fresh.m, &saved), PKM_OK) << pkm_last_error(fresh.m);
    ASSERT_EQ(pkm_advance(fresh.m, 0.4, in.u), PKM_OK);
    ASSERT_EQ(pkm_get_outputs(fresh.m, in.u, &c), PKM_OK);
    EXPECT_EQ(std::memcmp(&a, &c, sizeof a), 0) << "solver " << solver << ", a fresh model";
    EXPECT_NE(a.pose[0], kHome[0]);  // it did move
  }
}

TEST(CApi, StepChecksAreSolverSettings) {
  Handle h;
  double budget = 0, tolerance = -1;
  ASSERT_EQ(pkm_get_parameter(h.m, "work_budget", &budget), PKM_OK);
  ASSERT_EQ(pkm_get_parameter(h.m, "energy_tolerance", &tolerance), PKM_OK);
  EXPECT_EQ(budget, 1000.0);
  EXPECT_EQ(tolerance, 0.0);
  EXPECT_EQ(pkm_set_parameter(h.m, "work_budget", 0.5), PKM_ERR_INVALID_PARAMETER);  // below 1 inner step
  EXPECT_TRUE(contains(h.error(), "work_budget")) << h.error();
  EXPECT_EQ(pkm_set_parameter(h.m, "energy_tolerance", -1.0), PKM_ERR_INVALID_PARAMETER);
  EXPECT_TRUE(contains(h.error(), "energy_tolerance")) << h.error();
  const char* names[] = {"work_budget", "energy_tolerance", "solver"};
  const double values[] = {10.0, 1e-3, PKM_SOLVER_RK4};
  ASSERT_EQ(pkm_set_parameters(h.m, 3, names, values), PKM_OK);
  // F = 0 from the home pose: the fall reaches the stops at 95 ms, whose
  // located contact (about 30 bisection trials) does not fit 10 inner steps.
  ASSERT_EQ(pkm_init_pose(h.m, 0.0, kHome, nullptr), PKM_OK);
  pkm_status st = PKM_OK;
  for (int k = 1; k <= 200 && st == PKM_OK; ++k) st = pkm_advance(h.m, k * 1e-3, nullptr);
  EXPECT_EQ(st, PKM_ERR_SOLVER);
  EXPECT_TRUE(contains(h.error(), "work budget")) << h.error();
}

TEST(CApi, CallbackInputsMatchConstantInputs) {
  Handle h1, h2;
  const double F[4] = {2.7, 2.6, 2.65, 2.66}, tau[4] = {1e-4, -2e-4, 0.0, 3e-4};
  const Inputs in(F, tau);
  ASSERT_EQ(pkm_init_pose(h1.m, 0.0, kHome, nullptr), PKM_OK);
  ASSERT_EQ(pkm_init_pose(h2.m, 0.0, kHome, nullptr), PKM_OK);
  ASSERT_EQ(pkm_advance(h1.m, 0.3, in.u), PKM_OK);
  auto cb = [](void* user, double, double u[PKM_PLANT_INPUTS]) {
    std::memcpy(u, user, PKM_PLANT_INPUTS * sizeof(double));
  };
  ASSERT_EQ(pkm_advance_fn(h2.m, 0.3, cb, const_cast<double*>(in.u), 0), PKM_OK);
  pkm_state s1 = sized<pkm_state>(), s2 = sized<pkm_state>();
  ASSERT_EQ(pkm_get_state(h1.m, &s1), PKM_OK);
  ASSERT_EQ(pkm_get_state(h2.m, &s2), PKM_OK);
  EXPECT_EQ(std::memcmp(s1.y, s2.y, sizeof s1.y), 0);
}

TEST(CApi, EnergyIsAnOutput) {
  Handle h;
  const double v0[4] = {0.0, 0.0, 0.1, 0.0};
  ASSERT_EQ(pkm_init_pose(h.m, 0.0, kHome, v0), PKM_OK);
  pkm_outputs out = sized<pkm_outputs>();
  ASSERT_EQ(pkm_get_outputs(h.m, nullptr, &out), PKM_OK);
  // Pure vertical motion: every body moves at 0.1 m/s, nothing rotates.
  EXPECT_NEAR(out.kinetic_energy, 0.5 * (0.45474 + 4 * (0.09331 + 0.06371)) * 0.01, 1e-15);
}

TEST(CApi, ReadingOutputsChangesNothing) {
  Handle h;
  const double v0[4] = {0.01, -0.01, 0.0, 0.1};
  ASSERT_EQ(pkm_init_pose(h.m, 0.0, kHome, v0), PKM_OK);
  const double F[4] = {2.7, 2.6, 2.65, 2.66};
  const Inputs in(F);
  ASSERT_EQ(pkm_advance(h.m, 0.1, in.u), PKM_OK);
  pkm_state s1 = sized<pkm_state>(), s2 = sized<pkm_state>();
  ASSERT_EQ(pkm_get_state(h.m, &s1), PKM_OK);
  pkm_outputs out = sized<pkm_outputs>();
  ASSERT_EQ(pkm_get_outputs(h.m, in.u, &out), PKM_OK);
  ASSERT_EQ(pkm_get_state(h.m, &s2), PKM_OK);
  EXPECT_EQ(std::memcmp(&s1, &s2, sizeof s1), 0);
  for (int i = 0; i < 4; ++i) EXPECT_EQ(out.theta1[i], s1.theta1_ref[i]);
}

// The machine: the holding forces with a payload (docs/model.md's check
// plus its weight), held half by forces and half by motor torques.
TEST(CApi, MachineInputsAndOutputs) {
  Handle h;
  EXPECT_EQ(pkm_set_parameter(h.m, "friction_velocity", 0.0), PKM_ERR_INVALID_PARAMETER);
  EXPECT_TRUE(contains(h.error(), "parameter friction_velocity ")) << h.error();
  ASSERT_EQ(pkm_set_parameter(h.m, "payload_mass", 0.1), PKM_OK);
  ASSERT_EQ(pkm_init_pose(h.m, 0.0, kHome, nullptr), PKM_OK);
  pkm_outputs o = sized<pkm_outputs>();
  ASSERT_EQ(pkm_get_outputs(h.m, nullptr, &o), PKM_OK);
  // The spec's check with 0.1 kg more on the platform: (10.622464200 + 0.981) / 4 N each.
  for (int i = 0; i < 4; ++i) EXPECT_NEAR(o.F_hold[i], (10.622464200 + 0.1 * 9.81) / 4, 1e-9);
  for (int i = 0; i < 4; ++i) EXPECT_NEAR(o.stop_indicators[i], 0.0443193423, 1e-10);
  pkm_inverse_result inv = sized<pkm_inverse_result>();
  ASSERT_EQ(pkm_inverse_dynamics(h.m, kHome, kZero, kZero, nullptr, &inv), PKM_OK);
  double F[4], tau[4];
  for (int i = 0; i < 4; ++i) {
    EXPECT_NEAR(inv.F[i], o.F_hold[i], 1e-12);
    EXPECT_NEAR(inv.tau[i], inv.F[i] * 0.004 / (2 * kPi), 1e-15);
    F[i] = 0.5 * inv.F[i];
    tau[i] = 0.5 * inv.tau[i];
  }
  EXPECT_EQ(inv.beyond_stops, 0u);
  const Inputs in(F, tau);
  ASSERT_EQ(pkm_advance(h.m, 0.5, in.u), PKM_OK) << h.error();
  pkm_state s = sized<pkm_state>();
  ASSERT_EQ(pkm_get_state(h.m, &s), PKM_OK);
  EXPECT_LT(std::fabs(s.y[2] - 0.05), 1e-12);
}

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

// Near a leg singularity (leg 2's rod almost horizontal, theta2 -> 0, from
// docs/model.md's closed form) the inverse dynamics, its derivatives and the
// regressor refuse the pose by the guard min_leg_measure, as the inverse FMU
// does, and write nothing.
namespace {

// The pose (x, 0, 0.05, 0) with leg 2 (beta = 90 deg, gamma = -65 deg) at
// A = l (1 - eps): in its leg frame q~ = (r_Q sin 25 deg - r_b, -(x + r_Q cos
// 25 deg)), A^2 = |q~|^2 - h'^2, and its rod's |cos theta2 sin theta2| =
// (1 - eps) sqrt(1 - (1 - eps)^2).
void leg2_nearly_horizontal(double eps, double pose[4]) {
  const double l = 0.080, hp = 0.075, r_b = 0.09273, r_Q = 0.075, a = 25.0 * kPi / 180.0;
  const double qx = r_Q * std::sin(a) - r_b, A = l * (1.0 - eps);
  pose[0] = std::sqrt(A * A + hp * hp - qx * qx) - r_Q * std::cos(a);
  pose[1] = 0.0, pose[2] = 0.05, pose[3] = 0.0;
}

}  // namespace

TEST(CApi, PosesBeyondTheLegGuardAreRefusedAndNothingWritten) {
  Handle h;
  double pose[4];
  leg2_nearly_horizontal(1e-12, pose);  // measure 1.4e-6 < min_leg_measure = 1e-2
  const double v[4] = {0.01, 0.0, 0.0, 0.0};
  pkm_inverse_result r;
  std::memset(&r, 0x7f, sizeof r);
  r.size = sizeof r;
  const pkm_inverse_result before = r;
  EXPECT_EQ(pkm_inverse_dynamics(h.m, pose, v, kZero, nullptr, &r), PKM_ERR_SINGULAR);
  EXPECT_TRUE(contains(h.error(), "min_leg_measure")) << h.error();
  EXPECT_EQ(std::memcmp(&r, &before, sizeof r), 0);
  double Y[4 * PKM_REGRESSOR_PARAMS], F0[4] = {7, 7, 7, 7};
  for (double& y : Y) y = 7.0;
  EXPECT_EQ(pkm_regressor(h.m, pose, v, kZero, nullptr, Y, F0), PKM_ERR_SINGULAR);
  for (double y : Y) ASSERT_EQ(y, 7.0);
  for (double f : F0) ASSERT_EQ(f, 7.0);
  double F[4] = {7, 7, 7, 7}, dF[64];
  EXPECT_EQ(pkm_inverse_derivatives(h.m, pose, v, kZero, nullptr, F, dF), PKM_ERR_SINGULAR);
  for (double f : F) ASSERT_EQ(f, 7.0);
  size_t done = 99;
  EXPECT_EQ(pkm_regressor_poses(h.m, 1, pose, v, kZero, Y, nullptr, nullptr, nullptr, &done), PKM_ERR_SINGULAR);
  EXPECT_EQ(done, 0u);
  // Within the guard (a looser pose of the same leg) every call answers.
  leg2_nearly_horizontal(1e-3, pose);  // measure 0.045
  EXPECT_EQ(pkm_regressor(h.m, pose, v, kZero, nullptr, Y, F0), PKM_OK) << h.error();
  // The guards are the model's: switched off, the pose is computed (its
  // actuator Jacobian is as near singular as the leg: both guards).
  leg2_nearly_horizontal(1e-12, pose);
  const char* guards[] = {"min_leg_measure", "max_jacobian_condition"};
  const double off[] = {0.0, INFINITY};
  ASSERT_EQ(pkm_set_parameters(h.m, 2, guards, off), PKM_OK) << h.error();
  EXPECT_EQ(pkm_inverse_dynamics(h.m, pose, v, kZero, nullptr, &r), PKM_OK) << h.error();
  EXPECT_GT(std::fabs(r.F[1]), 1e6);  // what the guard keeps from a caller
}

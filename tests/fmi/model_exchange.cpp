// SPDX-License-Identifier: BSD-2-Clause
// The plant as FMI 2.0 Model Exchange, driven through the dlopen'd binary by
// an integrator of the test's own: classic RK4 at h = 1 ms with the auto-test's
// forces evaluated exactly at each stage time (in-process inverse dynamics,
// set through fmi2SetReal), as docs/model.md "The paper's two tests" and the paper do.
// The in-process auto-test (pkm::run_autotest, RK4 at 1 ms) integrates the
// same ODE with the same method, so the two trajectories must agree to
// rounding (bound 1e-10 m and rad): a Model Exchange state,
// derivative or time handled differently from the core would show here.
#include <dlfcn.h>

#include <array>
#include <cmath>
#include <string>
#include <vector>

#include "apps/autotest.hpp"
#include "fmi3FunctionTypes.h"
#include "fmu_loader.hpp"
#include "pkm4puu/kinematics/workspace_guard.hpp"
#include "pkm4puu/machine/end_stops.hpp"
#include "test_support.hpp"

namespace {

using pkm_test::PlantFmu;

constexpr int kStates = 10;  // pose, velocity, actuator_work, dissipated_energy
using State = std::array<double, kStates>;

/// One Model Exchange instance at the home pose, in continuous-time mode.
struct MeInstance {
  PlantFmu fmu{"model exchange", false, fmi2ModelExchange};
  std::vector<fmi2ValueReference> force_vrs;

  MeInstance() {
    EXPECT_NE(fmu.c, nullptr) << fmu.log.dump();
    for (int i = 1; i <= 4; ++i) force_vrs.push_back(fmu.vr(pkm_test::force_name(i)));
  }
  void start() {
    ASSERT_EQ(fmu.setup(), fmi2OK) << fmu.log.dump();
    ASSERT_EQ(fmu.enter(), fmi2OK) << fmu.log.dump();
    ASSERT_EQ(fmu.exit(), fmi2OK) << fmu.log.dump();
    fmi2EventInfo info{};
    info.newDiscreteStatesNeeded = fmi2True;
    while (info.newDiscreteStatesNeeded == fmi2True && info.terminateSimulation == fmi2False)
      ASSERT_EQ(fmu.lib.fmi2NewDiscreteStates(fmu.c, &info), fmi2OK) << fmu.log.dump();
    ASSERT_EQ(info.terminateSimulation, fmi2False);
    ASSERT_EQ(fmu.lib.fmi2EnterContinuousTimeMode(fmu.c), fmi2OK) << fmu.log.dump();
  }
  /// Event Mode, its iteration and back to continuous-time mode.
  void event() {
    ASSERT_EQ(fmu.lib.fmi2EnterEventMode(fmu.c), fmi2OK) << fmu.log.dump();
    fmi2EventInfo info{};
    ASSERT_EQ(fmu.lib.fmi2NewDiscreteStates(fmu.c, &info), fmi2OK) << fmu.log.dump();
    EXPECT_EQ(info.newDiscreteStatesNeeded, fmi2False) << "the contact mode is consistent after one iteration";
    ASSERT_EQ(fmu.lib.fmi2EnterContinuousTimeMode(fmu.c), fmi2OK) << fmu.log.dump();
  }
  void set_states(const State& x) {
    ASSERT_EQ(fmu.lib.fmi2SetContinuousStates(fmu.c, x.data(), kStates), fmi2OK) << fmu.log.dump();
  }
  State derivatives() {
    State dx{};
    EXPECT_EQ(fmu.lib.fmi2GetDerivatives(fmu.c, dx.data(), kStates), fmi2OK) << fmu.log.dump();
    return dx;
  }
  /// The end stops' event indicators (after the guards').
  std::vector<double> stop_indicators() {
    std::vector<double> z(fmu.def.n_event_indicators);
    EXPECT_EQ(fmu.lib.fmi2GetEventIndicators(fmu.c, z.data(), z.size()), fmi2OK) << fmu.log.dump();
    return std::vector<double>(z.begin() + pkm::kGuardIndicators, z.end());
  }
  State states() {
    State x{};
    EXPECT_EQ(fmu.lib.fmi2GetContinuousStates(fmu.c, x.data(), kStates), fmi2OK) << fmu.log.dump();
    return x;
  }
  /// dx/dt at (t, x) with the actuator forces F.
  State derivative(double t, const State& x, const pkm::Vec4& F) {
    State dx{};
    EXPECT_EQ(fmu.lib.fmi2SetTime(fmu.c, t), fmi2OK) << fmu.log.dump();
    EXPECT_EQ(fmu.lib.fmi2SetContinuousStates(fmu.c, x.data(), kStates), fmi2OK) << fmu.log.dump();
    EXPECT_EQ(fmu.lib.fmi2SetReal(fmu.c, force_vrs.data(), 4, F.data()), fmi2OK) << fmu.log.dump();
    EXPECT_EQ(fmu.lib.fmi2GetDerivatives(fmu.c, dx.data(), kStates), fmi2OK) << fmu.log.dump();
    return dx;
  }
};

State axpy(const State& x, double a, const State& k) {
  State y;
  for (int i = 0; i < kStates; ++i) y[i] = x[i] + a * k[i];
  return y;
}

TEST(ModelExchange, OwnRk4WithExactStageForcesMatchesTheInProcessAutoTest) {
  const pkm::Model model = pkm_test::default_model();
  pkm::AutotestOptions opt;
  opt.solver.solver = pkm::Solver::Rk4;
  opt.solver.rk4_step = 1e-3;
  opt.sample_dt = 1e-3;
  pkm::AutotestResult in_process;
  ASSERT_EQ(pkm::run_autotest(model, opt, in_process), pkm::Status::Ok) << in_process.error;
  ASSERT_EQ(in_process.samples.size(), 2001u);

  pkm::PathForces forces;
  forces.model = &model;
  forces.path = opt.path;
  const pkm::InputSignal signal = forces.signal();
  auto force_at = [&](double t) {
    pkm::Vec4 F;
    pkm::Wrench we;
    signal.eval(signal.user, t, F, we);
    EXPECT_EQ(forces.status, pkm::Status::Ok);
    EXPECT_TRUE(we.isZero()) << "the auto-test has no external wrench";
    return F;
  };

  MeInstance me;
  me.start();
  State x = me.states();
  const double energy_start = me.fmu.get("kinetic_energy") + me.fmu.get("potential_energy");
  const double h = opt.solver.rk4_step;
  double worst_position = 0.0, worst_angle = 0.0, min_indicator = INFINITY;
  for (std::size_t k = 1; k < in_process.samples.size(); ++k) {
    const double t = static_cast<double>(k - 1) * h;
    const State k1 = me.derivative(t, x, force_at(t));
    const State k2 = me.derivative(t + h / 2, axpy(x, h / 2, k1), force_at(t + h / 2));
    const State k3 = me.derivative(t + h / 2, axpy(x, h / 2, k2), force_at(t + h / 2));
    const State k4 = me.derivative(t + h, axpy(x, h, k3), force_at(t + h));
    for (int i = 0; i < kStates; ++i) x[i] += h / 6 * (k1[i] + 2 * k2[i] + 2 * k3[i] + k4[i]);

    // The step is accepted: time and states at its end, as an importer does.
    const double t_end = static_cast<double>(k) * h;
    ASSERT_EQ(me.fmu.lib.fmi2SetTime(me.fmu.c, t_end), fmi2OK);
    ASSERT_EQ(me.fmu.lib.fmi2SetContinuousStates(me.fmu.c, x.data(), kStates), fmi2OK) << me.fmu.log.dump();
    fmi2Boolean enter_event = fmi2True, terminate = fmi2True;
    ASSERT_EQ(me.fmu.lib.fmi2CompletedIntegratorStep(me.fmu.c, fmi2True, &enter_event, &terminate), fmi2OK);
    EXPECT_EQ(enter_event, fmi2False);
    EXPECT_EQ(terminate, fmi2False);
    std::vector<double> z(me.fmu.def.n_event_indicators);  // guards, then end stops
    ASSERT_EQ(me.fmu.lib.fmi2GetEventIndicators(me.fmu.c, z.data(), z.size()), fmi2OK);
    for (double zi : z) min_indicator = std::min(min_indicator, zi);

    const pkm::Pose& simulated = in_process.samples[k].simulated;
    for (int i = 0; i < 3; ++i) worst_position = std::max(worst_position, std::abs(x[i] - simulated[i]));
    worst_angle = std::max(worst_angle, std::abs(x[3] - simulated[3]));
  }
  std::printf("  Model Exchange + own RK4 vs in-process auto-test: %.2e m, %.2e rad (bound 1e-10); "
              "in-process vs the path: %.2e m, %.2e rad; smallest guard indicator %.3g\n",
              worst_position, worst_angle, in_process.max_position_error, in_process.max_angle_error, min_indicator);
  // The energy audit (the default machine: no friction, the stops never
  // touched): the work done equals the gain in kinetic plus potential energy.
  const double gain = me.fmu.get("kinetic_energy") + me.fmu.get("potential_energy") - energy_start;
  std::printf("  energy audit: actuator_work %.12f J, gain %.12f J, difference %.2e J (bound 1e-9)\n", x[8], gain,
              x[8] - gain);
  EXPECT_NEAR(x[8], gain, 1e-9);
  EXPECT_GT(gain, 0.1) << "the platform is lifted 2 cm: about 10.6 N x 0.02 m of work";
  EXPECT_EQ(x[9], 0.0) << "nothing dissipates in the default machine";
  EXPECT_LE(worst_position, 1e-10);
  EXPECT_LE(worst_angle, 1e-10);
  EXPECT_GT(min_indicator, 0.0) << "the auto-test stays inside both guards and the sliders' travel (docs/model.md)";
  // Not trivially zero: the platform moved 2 cm and 4 degrees.
  EXPECT_NEAR(x[2], 0.07, 1e-7);
  EXPECT_NEAR(x[3], 4.0 * pkm_test::kPi / 180.0, 1e-7);
}


// ---------------------------------------------------------------- states by value reference (issue 27 item 1)

// FMI 2.0.4 state table (section 3.2.3), the footnote on fmi2SetReal (since
// 2.0.1): continuous-time states may be set with fmi2SetReal in Event Mode
// and Continuous-Time Mode. FMI 3.0.2 section 3.2.1 ("set continuous-time
// states: fmi3SetFloat64, fmi3SetContinuousStates") and section 2.3.5 (Event
// Mode). Setting a state by value reference must act as SetContinuousStates
// with the same vector: the same checks, the same derivatives.
TEST(ModelExchange, Fmi2StatesAreSettableByValueReferenceAsBySetContinuousStates) {
  MeInstance by_vr, by_vector;
  by_vr.start();
  by_vector.start();
  State x = by_vr.states();
  x[2] -= 0.01;  // z
  x[6] = -0.1;   // dz
  x[8] = 0.25;   // actuator_work
  const fmi2ValueReference vrs[3] = {by_vr.fmu.vr("z"), by_vr.fmu.vr("dz"), by_vr.fmu.vr("actuator_work")};
  EXPECT_EQ(vrs[0], 12u) << "the issue's value reference";
  const double values[3] = {x[2], x[6], x[8]};
  ASSERT_EQ(by_vr.fmu.lib.fmi2SetReal(by_vr.fmu.c, vrs, 3, values), fmi2OK) << by_vr.fmu.log.dump();
  by_vector.set_states(x);
  EXPECT_EQ(by_vr.states(), x);
  EXPECT_EQ(by_vr.derivatives(), by_vector.derivatives()) << "the same state, bit for bit";
  EXPECT_EQ(by_vr.fmu.get("z"), x[2]);

  // Event Mode: allowed too; the state holds after the event iteration.
  ASSERT_EQ(by_vr.fmu.lib.fmi2EnterEventMode(by_vr.fmu.c), fmi2OK);
  x[2] += 0.002;
  ASSERT_EQ(by_vr.fmu.lib.fmi2SetReal(by_vr.fmu.c, vrs, 1, &x[2]), fmi2OK) << by_vr.fmu.log.dump();
  fmi2EventInfo info{};
  ASSERT_EQ(by_vr.fmu.lib.fmi2NewDiscreteStates(by_vr.fmu.c, &info), fmi2OK);
  ASSERT_EQ(by_vr.fmu.lib.fmi2EnterContinuousTimeMode(by_vr.fmu.c), fmi2OK);
  by_vector.set_states(x);
  EXPECT_EQ(by_vr.states(), x);
  EXPECT_EQ(by_vr.derivatives(), by_vector.derivatives());

  // An unreachable pose answers as SetContinuousStates does (Discard, nothing changed).
  State far = x;
  far[0] = 1.0;  // x = 1 m: beyond the legs' reach
  const fmi2ValueReference x_vr = by_vr.fmu.vr("x");
  const fmi2Status vector_status = by_vector.fmu.lib.fmi2SetContinuousStates(by_vector.fmu.c, far.data(), kStates);
  EXPECT_EQ(vector_status, fmi2Discard);
  EXPECT_EQ(by_vr.fmu.lib.fmi2SetReal(by_vr.fmu.c, &x_vr, 1, &far[0]), vector_status);
  EXPECT_EQ(by_vr.states(), x) << "a refused state changes nothing";
  // Non-finite: Error, as SetContinuousStates.
  const double nan = std::nan("");
  EXPECT_EQ(by_vr.fmu.lib.fmi2SetReal(by_vr.fmu.c, vrs, 1, &nan), fmi2Error);

  // Co-Simulation has no continuous states to set: still refused there.
  PlantFmu cs("co-simulation");
  cs.initialize();
  EXPECT_EQ(cs.lib.fmi2SetReal(cs.c, vrs, 1, &x[2]), fmi2Error);
}

/// The FMI 3.0 entry points of the plant's binary (the same library).
struct Fmi3Me {
#define PKM_FMI3_ME(X)                                                                                              \
  X(fmi3InstantiateModelExchange) X(fmi3EnterInitializationMode) X(fmi3ExitInitializationMode)                     \
  X(fmi3EnterContinuousTimeMode) X(fmi3EnterEventMode) X(fmi3UpdateDiscreteStates) X(fmi3SetFloat64)               \
  X(fmi3GetFloat64) X(fmi3SetContinuousStates) X(fmi3GetContinuousStates) X(fmi3GetContinuousStateDerivatives)     \
  X(fmi3GetEventIndicators) X(fmi3FreeInstance)
#define PKM_DECLARE3(name) name##TYPE* name = nullptr;
  PKM_FMI3_ME(PKM_DECLARE3)
#undef PKM_DECLARE3
  fmi3Instance c = nullptr;

  Fmi3Me() {
    void* lib = pkm_test::plant_library().handle;
#define PKM_LOAD3(name) name = reinterpret_cast<name##TYPE*>(dlsym(lib, #name)); EXPECT_NE(name, nullptr) << #name;
    PKM_FMI3_ME(PKM_LOAD3)
#undef PKM_LOAD3
    c = fmi3InstantiateModelExchange("fmi3 me", PKM_FMU_PLANT_GUID, nullptr, fmi3False, fmi3False, nullptr, nullptr);
    EXPECT_NE(c, nullptr);
  }
  ~Fmi3Me() {
    if (c) fmi3FreeInstance(c);
  }
  void start() {
    ASSERT_EQ(fmi3EnterInitializationMode(c, fmi3False, 0.0, 0.0, fmi3False, 0.0), fmi3OK);
    ASSERT_EQ(fmi3ExitInitializationMode(c), fmi3OK);
    update();
    ASSERT_EQ(fmi3EnterContinuousTimeMode(c), fmi3OK);
  }
  void update() {
    fmi3Boolean b[5];
    fmi3Float64 next;
    ASSERT_EQ(fmi3UpdateDiscreteStates(c, &b[0], &b[1], &b[2], &b[3], &b[4], &next), fmi3OK);
    EXPECT_EQ(b[0], fmi3False) << "the contact mode is consistent after one iteration";
  }
  State states() {
    State x{};
    EXPECT_EQ(fmi3GetContinuousStates(c, x.data(), kStates), fmi3OK);
    return x;
  }
  State derivatives() {
    State dx{};
    EXPECT_EQ(fmi3GetContinuousStateDerivatives(c, dx.data(), kStates), fmi3OK);
    return dx;
  }
};
#undef PKM_FMI3_ME

TEST(ModelExchange, Fmi3StatesAreSettableByValueReferenceAsBySetContinuousStates) {
  const pkm_fmi::ModelDefinition& def = pkm_fmi::pkm4puu_definition();
  Fmi3Me by_vr, by_vector;
  by_vr.start();
  by_vector.start();
  State x = by_vr.states();
  x[2] -= 0.01;
  x[6] = -0.1;
  x[8] = 0.25;
  const fmi3ValueReference vrs[3] = {pkm_test::vr_of(def, "z"), pkm_test::vr_of(def, "dz"),
                                     pkm_test::vr_of(def, "actuator_work")};
  const double values[3] = {x[2], x[6], x[8]};
  ASSERT_EQ(by_vr.fmi3SetFloat64(by_vr.c, vrs, 3, values, 3), fmi3OK);
  ASSERT_EQ(by_vector.fmi3SetContinuousStates(by_vector.c, x.data(), kStates), fmi3OK);
  EXPECT_EQ(by_vr.states(), x);
  EXPECT_EQ(by_vr.derivatives(), by_vector.derivatives());
  double z_read = 0.0;
  ASSERT_EQ(by_vr.fmi3GetFloat64(by_vr.c, vrs, 1, &z_read, 1), fmi3OK);
  EXPECT_EQ(z_read, x[2]);

  ASSERT_EQ(by_vr.fmi3EnterEventMode(by_vr.c), fmi3OK);
  x[2] += 0.002;
  ASSERT_EQ(by_vr.fmi3SetFloat64(by_vr.c, vrs, 1, &x[2], 1), fmi3OK) << "Event Mode (FMI 3.0.2 section 2.3.5)";
  by_vr.update();
  ASSERT_EQ(by_vr.fmi3EnterContinuousTimeMode(by_vr.c), fmi3OK);
  ASSERT_EQ(by_vector.fmi3SetContinuousStates(by_vector.c, x.data(), kStates), fmi3OK);
  EXPECT_EQ(by_vr.states(), x);
  EXPECT_EQ(by_vr.derivatives(), by_vector.derivatives());

  State far = x;
  far[0] = 1.0;  // x = 1 m: beyond the legs' reach
  const fmi3ValueReference x_vr = pkm_test::vr_of(def, "x");
  const fmi3Status vector_status = by_vector.fmi3SetContinuousStates(by_vector.c, far.data(), kStates);
  EXPECT_EQ(vector_status, fmi3Discard);
  EXPECT_EQ(by_vr.fmi3SetFloat64(by_vr.c, &x_vr, 1, &far[0], 1), vector_status);
  EXPECT_EQ(by_vr.states(), x);
}

// ---------------------------------------------------------------- frozen relations (issue 27 item 2)

/// The platform moving down at 0.1 m/s at the home x, y, phi with the
/// sliders 1e-9 m above (`offset` > 0) or below their lower stop: z where
/// rho_i = rho_min (the legs are alike there and rho moves with z one to one).
State at_lower_stops(MeInstance& me, double offset) {
  State x = me.states();
  const double z_contact = x[2] - (me.fmu.get("rho[1]") - me.fmu.get("rho_min"));
  x[2] = z_contact + offset;
  x[6] = -0.1;
  return x;
}

// FMI 2.0.4 section 3.2.2 (and FMI 3.0.2 section 3.1.1): in Continuous-Time
// Mode all relations are frozen; they change only in Event Mode. Crossing
// the lower stops with SetContinuousStates alone must not switch the
// contact on (nor off): the importer sees the crossing in the indicators,
// and the contact changes in Event Mode.
TEST(ModelExchange, EndStopContactsChangeInEventModeOnly) {
  MeInstance me;
  me.start();
  const double k = me.fmu.get("stop_stiffness"), d = me.fmu.get("stop_damping");
  const State above = at_lower_stops(me, 1e-9), below = at_lower_stops(me, -1e-9);
  auto stop_forces = [&me] {
    std::vector<double> f;
    for (int i = 1; i <= 4; ++i) f.push_back(me.fmu.get("stop_force[" + std::to_string(i) + "]"));
    return f;
  };
  const std::vector<double> none(4, 0.0);

  me.set_states(above);
  const double free_above = me.derivatives()[6];
  EXPECT_EQ(stop_forces(), none);
  me.set_states(below);
  const double free_below = me.derivatives()[6];
  EXPECT_EQ(stop_forces(), none) << "passed by 1 nm in Continuous-Time Mode: the contact is frozen off";
  EXPECT_NEAR(free_below, free_above, 1e-6) << "no jump in der(dz) before Event Mode";
  const std::vector<double> crossed = me.stop_indicators();
  for (int i = 0; i < 4; ++i) EXPECT_LT(crossed[i], 0.0) << "the indicators show the crossing to the importer";

  me.event();  // the contact switches on here
  const double rhod = me.fmu.get("drho[1]");
  const double depth = me.fmu.get("rho_min") - me.fmu.get("rho[1]");
  const double expected = k * depth - d * rhod;  // about 10 N: d * 0.1 m/s
  for (double f : stop_forces()) EXPECT_NEAR(f, expected, 1e-9 * expected);
  EXPECT_GT(expected, 9.0);
  const double contact_below = me.derivatives()[6];
  EXPECT_GT(contact_below - free_below, 1.0) << "four stops pushing up at about 10 N each";
  std::printf("  der(dz) across the stops by SetContinuousStates: %.3g m/s^2 (contact frozen); at the event: %.4g "
              "m/s^2, stop_force %.6g N each\n",
              free_below - free_above, contact_below - free_below, expected);
  for (double z : me.stop_indicators()) EXPECT_NE(z, 0.0);

  me.set_states(above);  // back above the stops: still in contact until Event Mode
  for (double f : stop_forces()) EXPECT_GT(f, 0.9 * expected) << "the contact is frozen on";
  EXPECT_NEAR(me.derivatives()[6], contact_below, 1e-3 * std::abs(contact_below - free_below));
  me.event();  // released here
  EXPECT_EQ(stop_forces(), none);
  EXPECT_NEAR(me.derivatives()[6], free_above, 1e-12 * std::abs(free_above) + 1e-12);
  for (double z : me.stop_indicators()) EXPECT_NE(z, 0.0);
}

// FMI 2.0.4 section 3.2.2 / FMI 3.0.2 section 3.1.1: after Event Mode every
// event indicator is nonzero (z_j != 0), so that the importer can tell its
// next crossing. Scanned over the states within a few hundred roundings of
// the stop, where a plain rho_i - rho_min is exactly 0.0 somewhere.
TEST(ModelExchange, NoStopIndicatorIsZeroAfterEventMode) {
  MeInstance me;
  me.start();
  State x = at_lower_stops(me, 0.0);
  x[6] = 0.0;
  for (int step = 0; step < 300; ++step) x[2] = std::nextafter(x[2], 1.0);
  int exact_zeros = 0;
  for (int step = 0; step < 600; ++step) {
    x[2] = std::nextafter(x[2], -1.0);
    me.set_states(x);
    if (me.fmu.get("rho[1]") == me.fmu.get("rho_min")) ++exact_zeros;
    me.event();
    for (double z : me.stop_indicators()) ASSERT_NE(z, 0.0) << "z = " << x[2];
  }
  std::printf("  states scanned: 600 around the lower stops, %d with rho[1] exactly at rho_min\n", exact_zeros);
  EXPECT_GT(exact_zeros, 0) << "the scan covers a state where the plain indicator is exactly 0";
}

}  // namespace

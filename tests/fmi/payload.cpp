// SPDX-License-Identifier: BSD-2-Clause
// The payload at run time through the FMU binaries: payload_mass,
// payload_com[1..2] and payload_Izz are tunable (docs/model.md "The machine
// around the mechanism"), set between communication steps in Co-Simulation
// and in Event Mode in Model Exchange, refused where the standards' state
// tables leave them out, answered like any parameter when out of range, and
// carried by FMU states. FMI 2.0 and 3.0, both FMUs.
//
// The numbers come from the spec. At the home pose a vertical motion of P
// moves every body straight up (each slider by the same amount, the rods
// translate), so the machine's mass along z is its whole moving mass
// M = m_platform + 4 (m_slider + m_rod) (Table III); z is decoupled from x
// and y (the legs' 180 degree symmetry) and from phi (a turn changes the
// distance of Q_i from its slider's axis, which alone sets rho_i, by
// opposite amounts for gamma = +65 and -65 degrees). A payload m at P, held
// by the forces that held the machine without it, therefore accelerates it
// by -m g / (M + m) along z and not otherwise, the same at every z (the
// weight does not depend on z): z(t) = z0 - m g t^2 / (2 (M + m)) exactly.
// By the same symmetry the four actuators share the payload's weight
// equally: each holds m g / 4 more. Grasped at rest, the payload brings its
// potential energy m g z0, which the audit books as work (actuator_work).
#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "any_version.hpp"

namespace {

using namespace pkm_test;

constexpr double kG = 9.81;                                    // docs/model.md "Bodies", gravity
constexpr double kMovingMass = 0.45474 + 4 * (0.09331 + 0.06371);  // kg, Table III
constexpr double kHomeZ = 0.05;                                // m
constexpr double kPayload = 0.25;                              // kg: the standard cycle's

double sink_acceleration(double m) { return -m * kG / (kMovingMass + m); }

/// Whether a and b agree within rel * |b| (or abs for b = 0).
::testing::AssertionResult near(double a, double b, double rel, double abs = 0.0) {
  const double bound = std::max(rel * std::fabs(b), abs);
  if (std::fabs(a - b) <= bound) return ::testing::AssertionSuccess();
  return ::testing::AssertionFailure() << a << " differs from " << b << " by " << std::fabs(a - b) << " (bound "
                                       << bound << ")";
}

/// kinetic + potential - actuator_work + dissipated_energy: the plant's energy audit (J).
double audit(Any& a) {
  return a.value("kinetic_energy") + a.value("potential_energy") - a.value("actuator_work") +
         a.value("dissipated_energy");
}

// FMI 2.0.4 section 4.2.4 (fmi2SetReal in stepComplete, condition 6: "causality
// = parameter and variability = tunable") and section 2.2.7 ("for Co-Simulation
// at every communication point"); FMI 3.0.2 section 4.2.1 (Step Mode:
// fmi3Set{VariableType} for "causality = parameter and variability = tunable")
// and section 2.4.7.4 (tunable: "if Event Mode is not supported, at
// communication points"; this FMU's Co-Simulation has no Event Mode). The
// plant holds still, takes the payload between two steps and sinks at
// -m g / (M + m) (CVODE at its default tolerances: rtol 1e-8, atol 1e-10 m).
// FMI 3.0.2 4.2.1 allows no get between a set and the next DoStep: the tests
// read after the step.
TEST(PayloadTunable, CoSimulationTakesItBetweenStepsAndThePlantSinks) {
  for (int version : {2, 3}) {
    SCOPED_TRACE(version);
    Any a(version, false);
    ASSERT_EQ(a.enter(), fmi2OK) << a.log.dump();
    ASSERT_EQ(a.exit(), fmi2OK) << a.log.dump();
    const double h = 1e-3;
    ASSERT_EQ(a.step(0.0, h), fmi2OK) << a.log.dump();  // the default forces hold the machine at home
    EXPECT_TRUE(near(a.value("z"), kHomeZ, 0.0, 1e-12));
    const double audit0 = audit(a), work0 = a.value("actuator_work");
    ASSERT_EQ(a.set("payload_mass", kPayload), fmi2OK) << a.log.dump();
    const double T = 0.02;
    for (int k = 1; k * h < T + 0.5 * h; ++k) ASSERT_EQ(a.step(k * h, h), fmi2OK) << a.log.dump();
    const double acc = sink_acceleration(kPayload), t = T;
    EXPECT_TRUE(near(a.value("z") - kHomeZ, 0.5 * acc * t * t, 1e-6));
    EXPECT_TRUE(near(a.value("dz"), acc * t, 1e-6));
    for (const char* other : {"x", "y", "phi", "dx", "dy", "dphi"})
      EXPECT_TRUE(near(a.value(other), 0.0, 0.0, 1e-12)) << other;
    for (int i = 1; i <= 4; ++i)
      EXPECT_TRUE(near(a.value(("F_hold[" + std::to_string(i) + "]").c_str()), kStaticForce + kPayload * kG / 4, 0.0,
                       1e-9));
    // The grasp's work, m g z0, then the forces' work on the sinking machine:
    // the audit holds across the change and the steps.
    EXPECT_TRUE(near(audit(a), audit0, 0.0, 1e-9)) << "the energy audit across the grasp";
    EXPECT_GT(a.value("actuator_work") - work0, 0.9 * kPayload * kG * kHomeZ);
  }
}

// FMI 2.0.4 section 3.2.3 (fmi2SetReal in Event Mode, condition 4: "causality
// = parameter and variability = tunable"; in Continuous-Time Mode, condition
// 5: inputs and continuous-time states only); FMI 3.0.2 section 2.3.5 (Event
// Mode: fmi3Set{VariableType} "for variables with causality = parameter and
// variability = tunable"), section 3.2.1 (Continuous-Time Mode: continuous-time
// inputs and states only) and section 2.4.7.4 ("may be changed only in Event
// Mode"). The change shows at once in the state derivatives; the event update
// says valuesOfContinuousStatesChanged (actuator_work took the grasp's work).
TEST(PayloadTunable, ModelExchangeTakesItInEventModeOnly) {
  for (int version : {2, 3}) {
    SCOPED_TRACE(version);
    Any a(version, true);
    ASSERT_EQ(a.enter(), fmi2OK) << a.log.dump();
    ASSERT_EQ(a.exit(), fmi2OK) << a.log.dump();  // Event Mode
    bool changed = true;
    ASSERT_EQ(a.update(&changed), fmi2OK);
    EXPECT_FALSE(changed) << "nothing changed the states yet";
    const std::vector<double> x0 = a.states();
    ASSERT_EQ(a.set("payload_mass", kPayload), fmi2OK) << a.log.dump();
    ASSERT_EQ(a.update(&changed), fmi2OK) << a.log.dump();
    EXPECT_TRUE(changed) << "valuesOfContinuousStatesChanged after the grasp";
    const std::vector<double> x1 = a.states();
    for (int k = 0; k < 8; ++k) EXPECT_EQ(x1[k], x0[k]) << "pose and velocity kept, state " << k;
    EXPECT_TRUE(near(x1[8] - x0[8], kPayload * kG * kHomeZ, 1e-14)) << "actuator_work: the grasp's work m g z0";
    EXPECT_EQ(x1[9], x0[9]) << "dissipated_energy";
    std::vector<double> dx = a.derivatives();
    EXPECT_TRUE(near(dx[6], sink_acceleration(kPayload), 1e-9)) << "der(dz)";
    for (int k : {4, 5, 7}) EXPECT_TRUE(near(dx[k], 0.0, 0.0, 1e-9)) << "der of state " << k;
    ASSERT_EQ(a.update(&changed), fmi2OK);
    EXPECT_FALSE(changed) << "one report per change";
    // Continuous-Time Mode: refused, nothing changed.
    ASSERT_EQ(a.continuous(), fmi2OK) << a.log.dump();
    const std::vector<double> before = a.reals();
    EXPECT_EQ(a.set("payload_mass", 0.5), fmi2Error);
    EXPECT_NE(a.log.last().find("payload_mass is a tunable parameter: in Model Exchange it can be set in Event Mode"),
              std::string::npos)
        << a.log.dump();
    EXPECT_TRUE(bit_identical(a.reals(), before)) << "the refused set changed a variable";
    EXPECT_EQ(a.derivatives()[6], dx[6]);
    // The next event releases it: holding still again, the work given back.
    ASSERT_EQ(a.event(), fmi2OK) << a.log.dump();
    ASSERT_EQ(a.set("payload_mass", 0.0), fmi2OK) << a.log.dump();
    ASSERT_EQ(a.update(&changed), fmi2OK);
    EXPECT_TRUE(changed);
    EXPECT_TRUE(near(a.states()[8], x0[8], 0.0, 1e-15));
    dx = a.derivatives();
    for (int k = 4; k < 8; ++k) EXPECT_TRUE(near(dx[k], 0.0, 0.0, 1e-9)) << "der of state " << k;
  }
}

// Where the state tables leave fmi2SetReal / fmi3SetFloat64 out, a tunable
// parameter is refused like any variable: FMI 2.0.4 section 4.2.4 (not in
// stepFailed or terminated), section 3.2.3 (not in terminated, and in
// Continuous-Time Mode only inputs and states); FMI 3.0.2 section 2.3.8
// (Terminated), 3.2.1 (Continuous-Time Mode). Allowed: Instantiated and
// Initialization Mode (initial = exact: its start value), Event Mode, Step
// Mode. Each instance walks through its states, setting at each.
TEST(PayloadTunable, SetWhereTheStateTablesAllowItAndNowhereElse) {
  for (int version : {2, 3}) {
    for (bool me : {false, true}) {
      SCOPED_TRACE(std::to_string(version) + (me ? " ME" : " CS"));
      Any a(version, me);
      double izz = 1e-5;
      auto settable = [&](const char* where) {
        izz *= 2;
        EXPECT_EQ(a.set("payload_Izz", izz), fmi2OK) << where << "\n" << a.log.dump();
      };
      auto refused = [&](const char* where, const char* says) {
        EXPECT_EQ(a.set("payload_Izz", 7.0), fmi2Error) << where;
        EXPECT_NE(a.log.last().find(says), std::string::npos) << where << "\n" << a.log.dump();
        EXPECT_EQ(a.value("payload_Izz"), izz) << where << ": the refused value was taken";
      };
      settable("Instantiated");
      ASSERT_EQ(a.enter(), fmi2OK) << a.log.dump();
      settable("Initialization Mode");
      ASSERT_EQ(a.exit(), fmi2OK) << a.log.dump();
      settable(me ? "Event Mode" : "Step Mode");
      if (me) {
        ASSERT_EQ(a.update(), fmi2OK);
        ASSERT_EQ(a.continuous(), fmi2OK) << a.log.dump();
        refused("Continuous-Time Mode", "payload_Izz is a tunable parameter");
      } else if (version == 2) {
        ASSERT_EQ(a.set("F[3]", 1e300), fmi2OK);
        ASSERT_EQ(a.step(0.0, 1e-3), fmi2Discard) << a.log.dump();
        refused("stepFailed", "not allowed");
      }
      ASSERT_EQ(a.terminate(), fmi2OK) << a.log.dump();
      refused("Terminated", "not allowed");
    }
  }
}

// Values outside a parameter's range (docs/robustness.md "Error policy"):
// Error with the reason logged, nothing changed, the next step as an
// untouched twin's (FMI 2.0 Co-Simulation, in Step Mode).
TEST(PayloadTunable, BadValuesAreRefusedAndTheRunGoesOnUntouched) {
  on_stepping_instance(
      "fmi2SetReal of a tunable parameter out of its range while stepping (payload_mass = -0.1 kg, NaN, 2e4 kg; "
      "payload_com[1] = 11 m; payload_Izz = -1e-6 kg.m2)",
      fmi2Error, "fmi2Error each, the reason logged (\"lies outside its range\", \"is not finite\")",
      [](PlantFmu& p, double) {
        std::vector<fmi2Status> s;
        for (double m : {-0.1, std::nan(""), 2e4}) s.push_back(p.set("payload_mass", m));
        s.push_back(p.set("payload_com[1]", 11.0));
        s.push_back(p.set("payload_Izz", -1e-6));
        EXPECT_TRUE(p.log.contains("payload_mass = -0.10000000000000001 lies outside its range")) << p.log.dump();
        EXPECT_TRUE(p.log.contains("payload_mass = nan is not finite")) << p.log.dump();
        return s;
      });
}

// The inverse FMU (feed-forward) at the home pose at rest: each actuator
// holds the spec's 2.655616050 N, and a payload m at P adds m g / 4 to each
// (the symmetry above). Co-Simulation (set in Step Mode, read after a step) and Model
// Exchange (set in Event Mode), FMI 2.0 and 3.0: the clauses of the tests above.
TEST(PayloadTunable, InverseForcesChangeByThePayloadsWeightShare) {
  for (int version : {2, 3}) {
    for (bool me : {false, true}) {
      SCOPED_TRACE(std::to_string(version) + (me ? " ME" : " CS"));
      Any inv(version, me, true, /*inverse=*/true);
      ASSERT_EQ(inv.enter(), fmi2OK) << inv.log.dump();
      ASSERT_EQ(inv.exit(), fmi2OK) << inv.log.dump();
      double t = 0.0;
      auto forces = [&] {
        if (!me) {  // FMI 3.0.2 4.2.1: a get follows a set only after a DoStep
          EXPECT_EQ(inv.step(t, 1e-3), fmi2OK) << inv.log.dump();
          t += 1e-3;
        }
        std::vector<double> F;
        for (const char* name : {"F[1]", "F[2]", "F[3]", "F[4]"}) F.push_back(inv.value(name));
        return F;
      };
      const std::vector<double> empty = forces();
      for (double f : empty) EXPECT_TRUE(near(f, kStaticForce, 0.0, 1e-9));
      ASSERT_EQ(inv.set("payload_mass", kPayload), fmi2OK) << inv.log.dump();
      for (double f : forces()) EXPECT_TRUE(near(f, kStaticForce + kPayload * kG / 4, 0.0, 1e-9));
      // Off centre, at rest: the platform cannot tilt, so the weight's moment
      // goes into the joints (lambda), and the weight does the same virtual
      // work as at P: the same forces.
      ASSERT_EQ(inv.set("payload_com[1]", 0.01), fmi2OK) << inv.log.dump();
      ASSERT_EQ(inv.set("payload_com[2]", -0.02), fmi2OK) << inv.log.dump();
      for (double f : forces()) EXPECT_TRUE(near(f, kStaticForce + kPayload * kG / 4, 0.0, 1e-9));
      for (const char* name : {"payload_mass", "payload_com[1]", "payload_com[2]"}) ASSERT_EQ(inv.set(name, 0.0), fmi2OK);
      EXPECT_TRUE(bit_identical(forces(), empty)) << "released: the forces of the empty machine again";
    }
  }
}

/// Ten steps of 1 ms from t; the outputs after them.
std::vector<double> ten_steps(Any& a, double t) {
  for (int k = 0; k < 10; ++k) EXPECT_EQ(a.step(t + k * 1e-3, 1e-3), fmi2OK) << a.log.dump();
  return a.reals();
}

// FMI 2.0.4 section 2.1.8 and FMI 3.0.2 section 2.2.7.4 (getting and setting
// the complete FMU state): the state holds "parameter values", the tunable
// ones among them: restored, a state taken before the grasp goes on
// without the payload, one taken after it with the payload, bit for bit as
// the runs they were taken from.
TEST(PayloadTunable, FmuStatesCarryThePayload) {
  for (int version : {2, 3}) {
    SCOPED_TRACE(version);
    Any a(version, false), twin(version, false);
    ASSERT_NO_FATAL_FAILURE(initialise({&a, &twin}));
    void *before = nullptr, *grasped = nullptr, *saved = nullptr;
    ASSERT_EQ(a.get_state(&before), fmi2OK);
    ASSERT_EQ(a.set("payload_mass", kPayload), fmi2OK);
    ASSERT_EQ(a.set("payload_com[2]", -0.005), fmi2OK);
    ASSERT_EQ(a.get_state(&grasped), fmi2OK);
    const std::vector<double> loaded = ten_steps(a, 0.0);
    ASSERT_EQ(twin.get_state(&saved), fmi2OK);  // as `a` before its run
    twin.free_state(&saved);
    const std::vector<double> empty = ten_steps(twin, 0.0);
    ASSERT_EQ(a.set_state(before), fmi2OK) << a.log.dump();
    EXPECT_EQ(a.value("payload_mass"), 0.0);
    EXPECT_TRUE(bit_identical(ten_steps(a, 0.0), empty)) << "restored before the grasp: the empty machine's run";
    ASSERT_EQ(a.set_state(grasped), fmi2OK) << a.log.dump();
    EXPECT_EQ(a.value("payload_mass"), kPayload);
    EXPECT_EQ(a.value("payload_com[2]"), -0.005);
    EXPECT_TRUE(bit_identical(ten_steps(a, 0.0), loaded)) << "restored after the grasp: the loaded machine's run";
    a.free_state(&before);
    a.free_state(&grasped);
  }
}

}  // namespace

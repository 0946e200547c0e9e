// SPDX-License-Identifier: BSD-2-Clause
// FMU states of the binaries that restore, through the raw FMI 2.0 and 3.0
// functions: get/set and serialised states continue bit-identically (RK4 and
// ROS2 wherever saved; CVODE where its history restarts anyway), in the same
// and in a fresh instance, for both FMUs; taking a state changes no run;
// states left behind are freed with their instance. (The states refused:
// fmu_states_refused.cpp.)
#include <string>
#include <tuple>
#include <vector>

#include <gtest/gtest.h>

#include "any_version.hpp"
#include "fmi2FunctionTypes.h"
#include "fmu_fixture.hpp"
#include "fmu_state_support.hpp"

namespace {

using namespace pkm_test;

class FmuStates : public pkm_test::FmuTest, public ::testing::WithParamInterface<int> {};

TEST_P(FmuStates, GetSetGivesABitIdenticalContinuation) {
  PlantFmu p;
  ASSERT_EQ(p.set_int("solver", GetParam()), fmi2OK);
  ASSERT_EQ(p.set("dx0", 0.01), fmi2OK);
  p.initialize();
  double t = 0.0;
  run_steps(p, lib, t, 30, 1e-3);
  fmi2FMUstate s = nullptr;
  ASSERT_EQ(lib.fmi2GetFMUstate(p.c, &s), fmi2OK);
  ASSERT_NE(s, nullptr);
  const double t_saved = t;
  const std::vector<double> a = run_steps(p, lib, t, 150, 1e-3);
  ASSERT_EQ(lib.fmi2SetFMUstate(p.c, s), fmi2OK) << p.log.dump();
  t = t_saved;
  const std::vector<double> b = run_steps(p, lib, t, 150, 1e-3);
  EXPECT_TRUE(bit_identical(a, b)) << "restored run differs";
  // The state can be overwritten in place and freed.
  ASSERT_EQ(lib.fmi2GetFMUstate(p.c, &s), fmi2OK);
  ASSERT_EQ(lib.fmi2FreeFMUstate(p.c, &s), fmi2OK);
  EXPECT_EQ(s, nullptr);
}

TEST_P(FmuStates, SerializedStateContinuesInAFreshInstance) {
  PlantFmu p;
  ASSERT_EQ(p.set_int("solver", GetParam()), fmi2OK);
  ASSERT_EQ(p.set("m_platform", 0.5), fmi2OK);  // a non-default parameter travels with the state
  ASSERT_EQ(p.set("dphi0", -0.3), fmi2OK);
  p.initialize();
  double t = 0.0;
  run_steps(p, lib, t, 20, 1e-3);
  // Leave derivatives set: they are part of the state too.
  const std::vector<fmi2Byte> bytes = serialized_state(p);
  ASSERT_FALSE(bytes.empty());
  const double t_saved = t;
  const std::vector<double> a = run_steps(p, lib, t, 120, 1e-3);

  PlantFmu fresh("fresh", false);  // only instantiated: no setup, no initialisation
  fmi2FMUstate s2 = nullptr;
  ASSERT_EQ(lib.fmi2DeSerializeFMUstate(fresh.c, bytes.data(), bytes.size(), &s2), fmi2OK) << fresh.log.dump();
  ASSERT_EQ(lib.fmi2SetFMUstate(fresh.c, s2), fmi2OK) << fresh.log.dump();
  ASSERT_EQ(lib.fmi2FreeFMUstate(fresh.c, &s2), fmi2OK);
  EXPECT_EQ(fresh.get("m_platform"), 0.5);
  t = t_saved;
  const std::vector<double> b = run_steps(fresh, lib, t, 120, 1e-3);
  EXPECT_TRUE(bit_identical(a, b)) << "deserialised run differs";
}

INSTANTIATE_TEST_SUITE_P(CvodeAndRk4, FmuStates, ::testing::Values(0, 1),
                         [](const ::testing::TestParamInfo<int>& i) { return i.param == 0 ? "CVODE" : "RK4"; });

TEST_F(FmuState, InverseStateRoundTrip) {
  InverseFmu inv;
  inv.initialize();
  FmuLibrary& ilib = inverse_library();
  ASSERT_EQ(inv.set("ddz", 0.4), fmi2OK);
  const std::vector<double> before = inv.outputs();
  fmi2FMUstate s = nullptr;
  ASSERT_EQ(ilib.fmi2GetFMUstate(inv.c, &s), fmi2OK);
  ASSERT_EQ(inv.set("ddz", -3.0), fmi2OK);
  ASSERT_EQ(ilib.fmi2DoStep(inv.c, 0.0, 0.1, fmi2True), fmi2OK);
  ASSERT_EQ(ilib.fmi2SetFMUstate(inv.c, s), fmi2OK);
  EXPECT_TRUE(bit_identical(inv.outputs(), before));
  ilib.fmi2FreeFMUstate(inv.c, &s);
  EXPECT_EQ(ilib.fmi2DoStep(inv.c, 0.0, 0.1, fmi2True), fmi2OK) << "time restored to 0";
}

TEST_F(FmuState, StatesLeftBehindAreFreedWithTheInstance) {
  // FMI 2.0: fmi2FreeInstance frees everything the instance allocated. The
  // valgrind test (hardening_valgrind) checks that nothing leaks; here: a
  // state freed through another instance of the FMU is forgotten by its creator.
  PlantFmu a("a"), b("b");
  a.initialize();
  b.initialize();
  fmi2FMUstate s1 = nullptr, s2 = nullptr, s3 = nullptr;
  ASSERT_EQ(lib.fmi2GetFMUstate(a.c, &s1), fmi2OK);
  ASSERT_EQ(lib.fmi2GetFMUstate(a.c, &s2), fmi2OK);
  ASSERT_EQ(lib.fmi2GetFMUstate(a.c, &s3), fmi2OK);
  ASSERT_EQ(lib.fmi2FreeFMUstate(b.c, &s2), fmi2OK);  // freed through b
  ASSERT_EQ(lib.fmi2SetFMUstate(b.c, s3), fmi2OK);    // used by b
  EXPECT_EQ(lib.fmi2FreeFMUstate(a.c, &s1), fmi2OK);
  // s3 stays with a, which frees it.
  table_row("FMU states never freed by the importer (fmi2GetFMUstate / fmi2DeSerializeFMUstate, then "
            "fmi2FreeInstance); a state freed or used through another instance of the FMU",
            "fmi2FreeInstance frees them (FMI 2.0: all memory of the instance); fmi2OK for the others",
            "no leak (valgrind: 0 bytes definitely lost)");
}

// ---------------------------------------------------------------- restored runs: RK4 and ROS2 bit for bit

// FMI 2.0 section 2.1.8 and FMI 3.0 section 2.2.6, "Getting and Setting the
// Complete FMU State": SetFMUState makes the saved state the FMU's actual
// state again. The state carries everything the fixed-step solvers keep
// between steps (ROS2's step ladder after a switch of the contact mode,
// pending after initialisation; its step in a contact; its energy
// balance), so a restored run continues bit for bit as the original,
// wherever it was saved -- after initialisation, right after an impact, in
// contact -- in the same instance and in a fresh one.
class RestoredRuns : public FmuTest, public ::testing::WithParamInterface<std::tuple<int, int, int>> {};

TEST_P(RestoredRuns, ContinueBitForBitWhereverTheStateWasSaved) {
  const int version = std::get<0>(GetParam()), solver = std::get<1>(GetParam());
  const Machine& machine = machines()[static_cast<std::size_t>(std::get<2>(GetParam()))];
  constexpr int kSteps = 130;  // past the impact at about 95 ms, into the rebound
  Any a(version, false);
  start_drop(a, solver, machine);
  if (HasFatalFailure()) return;
  struct Saved {
    int k;  // after step k (0: at initialisation)
    const char* where;
    void* state;
    std::vector<unsigned char> bytes;
  };
  std::vector<Saved> saved;
  auto save = [&](int k, const char* where) {
    Saved s{k, where, nullptr, {}};
    ASSERT_EQ(a.get_state(&s.state), fmi2OK) << a.log.dump();
    s.bytes = a.serialize(s.state);
    ASSERT_FALSE(s.bytes.empty()) << a.log.dump();
    saved.push_back(std::move(s));
  };
  std::vector<std::vector<double>> after = {a.reals()};  // every Real after each step (0: at initialisation)
  save(0, "after initialisation");
  int impact = -1;
  for (int k = 0; k < kSteps && !HasFatalFailure(); ++k) {
    ASSERT_EQ(a.step(k * kH, kH), fmi2OK) << "step " << k << "\n" << a.log.dump();
    after.push_back(a.reals());
    double f = 0.0;
    ASSERT_EQ(a.get("stop_force[1]", f), fmi2OK);
    if (impact < 0 && f != 0.0) {
      impact = k + 1;
      save(impact, "right after the impact");
    }
    if (impact > 0 && k + 1 == impact + 5) save(k + 1, "in contact");
  }
  if (std::string(machine.name) != "viscous_friction") {
    ASSERT_GT(impact, 0) << "no impact within " << kSteps << " steps: the checks after it would be missing";
  }
  for (const Saved& s : saved) {
    SCOPED_TRACE(std::string("state saved ") + s.where + " (after step " + std::to_string(s.k) + ")");
    std::vector<double> original;
    for (int k = s.k + 1; k <= kSteps; ++k) original.insert(original.end(), after[k].begin(), after[k].end());
    ASSERT_EQ(a.set_state(s.state), fmi2OK) << a.log.dump();
    EXPECT_EQ(first_difference(a.reals(), after[static_cast<std::size_t>(s.k)]), "") << "right after SetFMUState";
    EXPECT_EQ(first_difference(steps(a, s.k, kSteps), original), "") << "restored in the same instance";
    Any fresh(version, false);  // only instantiated: default parameters
    ASSERT_EQ(fresh.restore(s.bytes), fmi2OK) << fresh.log.dump();
    EXPECT_EQ(first_difference(fresh.reals(), after[static_cast<std::size_t>(s.k)]), "") << "right after restoring";
    EXPECT_EQ(first_difference(steps(fresh, s.k, kSteps), original), "") << "restored in a fresh instance";
  }
  for (Saved& s : saved) EXPECT_EQ(a.free_state(&s.state), fmi2OK);
}

std::string run_name(const ::testing::TestParamInfo<std::tuple<int, int, int>>& i) {
  return std::string("FMI") + std::to_string(std::get<0>(i.param)) + "_" + solver_name(std::get<1>(i.param)) + "_" +
         machines()[static_cast<std::size_t>(std::get<2>(i.param))].name;
}

// RK4 at the stiffest stops runs out of its work budget in contact (the
// stops need ~1e5 sub-steps per millisecond): ROS2's case.
INSTANTIATE_TEST_SUITE_P(Rk4, RestoredRuns,
                         ::testing::Combine(::testing::Values(2, 3), ::testing::Values(kRk4), ::testing::Values(0, 2)),
                         run_name);
INSTANTIATE_TEST_SUITE_P(Ros2, RestoredRuns,
                         ::testing::Combine(::testing::Values(2, 3), ::testing::Values(kRos2),
                                            ::testing::Values(0, 1, 2)),
                         run_name);

// ---------------------------------------------------------------- taking a state is an observation

// FMI 2.0 section 2.1.8 and FMI 3.0 section 2.2.6: GetFMUState copies the
// FMU's state, SerializeFMUState copies that into bytes; neither changes the
// FMU. A master that saves the state before every step, for a rollback it
// may never take, gets the run it gets without: bit for bit, with every
// solver (CVODE keeps its history across the communication points of this
// drop, whose inputs are held). And every state a run saves is one the
// loader takes (a third instance restores each).
class ObservedRuns : public FmuTest, public ::testing::WithParamInterface<std::tuple<int, int, int>> {};

TEST_P(ObservedRuns, SavingTheStateBeforeEveryStepChangesNothing) {
  const int version = std::get<0>(GetParam()), solver = std::get<1>(GetParam());
  const Machine& machine = machines()[static_cast<std::size_t>(std::get<2>(GetParam()))];
  constexpr int kSteps = 200;  // the impact at about 95 ms and the rebound
  Any plain(version, false), saving(version, false), loader(version, false);
  start_drop(plain, solver, machine);
  start_drop(saving, solver, machine);
  if (HasFatalFailure()) return;
  void* s = nullptr;
  std::vector<double> a, b;
  bool impact = false;
  for (int k = 0; k < kSteps; ++k) {
    ASSERT_EQ(saving.get_state(&s), fmi2OK) << saving.log.dump();  // the same state overwritten
    ASSERT_FALSE(saving.serialize(s).empty()) << saving.log.dump();
    ASSERT_EQ(loader.set_state(s), fmi2OK) << "step " << k << "\n" << loader.log.dump();
    const std::vector<double> x = steps(plain, k, k + 1), y = steps(saving, k, k + 1);
    a.insert(a.end(), x.begin(), x.end());
    b.insert(b.end(), y.begin(), y.end());
    double f = 0.0;
    ASSERT_EQ(plain.get("stop_force[1]", f), fmi2OK);
    impact = impact || f != 0.0;
  }
  EXPECT_EQ(saving.free_state(&s), fmi2OK);
  EXPECT_TRUE(impact) << "the run reaches the end stops";
  EXPECT_EQ(first_difference(b, a), "") << "the run with GetFMUState and SerializeFMUState before every step";
}

// CVODE at the stiffest stops takes seconds a run (the solvers' page): the
// default machine for it and RK4, the stiffest stops too for ROS2.
INSTANTIATE_TEST_SUITE_P(CvodeAndRk4, ObservedRuns,
                         ::testing::Combine(::testing::Values(2, 3), ::testing::Values(kCvode, kRk4),
                                            ::testing::Values(0)),
                         run_name);
INSTANTIATE_TEST_SUITE_P(Ros2, ObservedRuns,
                         ::testing::Combine(::testing::Values(2, 3), ::testing::Values(kRos2), ::testing::Values(0, 1)),
                         run_name);

}  // namespace

// SPDX-License-Identifier: BSD-2-Clause
// FMU states of the binaries that are refused, through the raw FMI 2.0 and
// 3.0 functions, the instance unchanged: foreign and broken states, and
// states forged with a valid checksum -- impossible content, the other FMI
// version, a mode or contact mode the instance cannot be in, a plant it
// cannot have; every byte of the integrators' memory restored or refused.
// (The states that restore: fmu_states_restored.cpp.)
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "any_version.hpp"
#include "fmi/instance.hpp"
#include "fmi2FunctionTypes.h"
#include "fmu_fixture.hpp"
#include "fmu_state_support.hpp"
#include "models/PKM4PUU/plant_state.hpp"
#include "models/models.hpp"
#include "pkm4puu/sim/solver_memory.hpp"

namespace {

using namespace pkm_test;

TEST_F(FmuState, ForeignStateDataIsRejected) {
  PlantFmu p;
  p.initialize();
  std::vector<fmi2Byte> good = serialized_state(p);
  ASSERT_FALSE(good.empty());
  const std::size_t size = good.size();
  fmi2FMUstate s = nullptr;
  ASSERT_EQ(lib.fmi2GetFMUstate(p.c, &s), fmi2OK);
  EXPECT_EQ(lib.fmi2SerializeFMUstate(p.c, s, good.data(), good.size() - 1), fmi2Error);  // buffer too small
  lib.fmi2FreeFMUstate(p.c, &s);

  fmi2FMUstate out = nullptr;
  std::vector<fmi2Byte> junk(size, 0x5a);
  EXPECT_EQ(lib.fmi2DeSerializeFMUstate(p.c, junk.data(), junk.size(), &out), fmi2Error);
  EXPECT_EQ(lib.fmi2DeSerializeFMUstate(p.c, good.data(), good.size() - 8, &out), fmi2Error);  // truncated
  EXPECT_EQ(lib.fmi2DeSerializeFMUstate(p.c, good.data(), 3, &out), fmi2Error);
  std::vector<fmi2Byte> flipped = good;
  flipped[size / 2] = static_cast<fmi2Byte>(flipped[size / 2] ^ 0x01);
  EXPECT_EQ(lib.fmi2DeSerializeFMUstate(p.c, flipped.data(), flipped.size(), &out), fmi2Error);  // checksum
  EXPECT_EQ(out, nullptr);
  // A state of the other FMU.
  InverseFmu inv;
  inv.initialize();
  std::vector<fmi2Byte> other = serialized_state(inv);
  ASSERT_FALSE(other.empty());
  EXPECT_EQ(lib.fmi2DeSerializeFMUstate(p.c, other.data(), other.size(), &out), fmi2Error);
  EXPECT_TRUE(p.log.contains("another FMU")) << p.log.dump();
  // Not a state pointer at all.
  double not_a_state[8] = {};
  EXPECT_EQ(lib.fmi2SetFMUstate(p.c, not_a_state), fmi2Error);
  // The good bytes still work, and the instance still steps.
  ASSERT_EQ(lib.fmi2DeSerializeFMUstate(p.c, good.data(), good.size(), &out), fmi2OK);
  ASSERT_EQ(lib.fmi2SetFMUstate(p.c, out), fmi2OK);
  lib.fmi2FreeFMUstate(p.c, &out);
  EXPECT_EQ(lib.fmi2DoStep(p.c, 0.0, 1e-3, fmi2True), fmi2OK);
}

TEST_F(FmuState, ForeignOrBrokenFmuStates) {
  on_stepping_instance(
      "fmi2SetFMUstate / FreeFMUstate / SerializedFMUstateSize / SerializeFMUstate with a pointer that is not an "
      "FMU state; fmi2GetFMUstate into a *FMUstate that is not one; fmi2DeSerializeFMUstate of zeros, of a "
      "truncated, a bit-flipped or an inverse-FMU state; fmi2SerializeFMUstate into a buffer one byte short",
      fmi2Error,
      "fmi2Error each, \"not an FMU state of this FMU\" / \"checksum mismatch\" / \"belongs to another FMU\" / "
      "\"buffer of n bytes, n+1 needed\"",
      [&](PlantFmu& p, double) {
        std::vector<fmi2Status> s;
        alignas(16) unsigned char junk[256] = {};
        void* foreign = junk;
        std::size_t size = 0;
        s.push_back(lib.fmi2SetFMUstate(p.c, foreign));
        fmi2FMUstate f = foreign;
        s.push_back(lib.fmi2FreeFMUstate(p.c, &f));
        s.push_back(lib.fmi2SerializedFMUstateSize(p.c, foreign, &size));
        s.push_back(lib.fmi2SerializeFMUstate(p.c, foreign, reinterpret_cast<fmi2Byte*>(junk), sizeof junk));
        s.push_back(lib.fmi2GetFMUstate(p.c, &f));
        fmi2FMUstate good = nullptr;
        EXPECT_EQ(lib.fmi2GetFMUstate(p.c, &good), fmi2OK);
        EXPECT_EQ(lib.fmi2SerializedFMUstateSize(p.c, good, &size), fmi2OK);
        std::vector<fmi2Byte> bytes(size + 2, 0x11);
        s.push_back(lib.fmi2SerializeFMUstate(p.c, good, bytes.data() + 1, size - 1));
        for (fmi2Byte byte : bytes) EXPECT_EQ(byte, 0x11) << "nothing written into a short buffer";
        EXPECT_EQ(lib.fmi2SerializeFMUstate(p.c, good, bytes.data() + 1, size), fmi2OK);
        EXPECT_EQ(bytes[0], 0x11);
        EXPECT_EQ(bytes[size + 1], 0x11);
        fmi2FMUstate out = nullptr;
        std::vector<fmi2Byte> zeros(size, 0);
        s.push_back(lib.fmi2DeSerializeFMUstate(p.c, zeros.data(), zeros.size(), &out));
        s.push_back(lib.fmi2DeSerializeFMUstate(p.c, bytes.data() + 1, size - 1, &out));
        std::vector<fmi2Byte> flipped(bytes.begin() + 1, bytes.begin() + 1 + static_cast<long>(size));
        flipped[size / 3] = static_cast<fmi2Byte>(flipped[size / 3] ^ 0x40);
        s.push_back(lib.fmi2DeSerializeFMUstate(p.c, flipped.data(), flipped.size(), &out));
        InverseFmu inv;
        inv.initialize();
        fmi2FMUstate is = nullptr;
        EXPECT_EQ(inv.lib.fmi2GetFMUstate(inv.c, &is), fmi2OK);
        std::size_t isize = 0;
        EXPECT_EQ(inv.lib.fmi2SerializedFMUstateSize(inv.c, is, &isize), fmi2OK);
        std::vector<fmi2Byte> other(isize);
        EXPECT_EQ(inv.lib.fmi2SerializeFMUstate(inv.c, is, other.data(), other.size()), fmi2OK);
        s.push_back(lib.fmi2DeSerializeFMUstate(p.c, other.data(), other.size(), &out));
        EXPECT_EQ(out, nullptr);
        // The inverse FMU's in-memory state handed to the plant: a state object, of the other model.
        s.push_back(lib.fmi2SetFMUstate(p.c, is));
        inv.lib.fmi2FreeFMUstate(inv.c, &is);
        EXPECT_EQ(lib.fmi2FreeFMUstate(p.c, &good), fmi2OK);
        for (unsigned char byte : junk) EXPECT_EQ(byte, 0);
        return s;
      });
}

// States with a valid checksum and absurd content. The layout
// (src/fmi/fmu_state.cpp): a 32-byte header; mode (4), three flags (3), startTime,
// stopTime, time, last successful time, time since start (8 each) from byte
// 39; the count (4) and the stored variables (8 each) from byte 83; then the input
// derivatives and the plant's part (PlantPart).
/// Where the fields of the plant's part lie in a serialised state of `size`
/// bytes (plant_state.hpp's layout): it ends before the 8-byte checksum.
struct PlantPart {
  std::size_t t, y, theta1, energy, stops, memory_size, memory;
  explicit PlantPart(std::size_t size) {
    const auto& at = pkm_fmi::pkm4puu_model::kPlantStateLayout;
    const std::size_t start = size - 8 - at.size;
    t = start + at.t;
    y = start + at.y;
    theta1 = start + at.theta1;
    energy = start + at.energy;
    stops = start + at.stops;
    memory_size = start + at.memory_size;
    memory = start + at.memory;
  }
};

TEST_F(FmuState, ForgedFmuStatesWithAValidChecksumAreRefused) {
  on_stepping_instance(
      "fmi2DeSerializeFMUstate + fmi2SetFMUstate of states forged with a recomputed checksum: time = NaN, startTime "
      "after the time, m_platform = -1, the plant's time = NaN, dx = 1e200 m/s, theta1 reference of leg 2 = 1e16 "
      "rad or off by 1 rad, an end-stop record naming no stop",
      fmi2Error,
      "fmi2SetFMUstate: fmi2Error \"malformed FMU state (a time is not finite ...)\" / \"... outside its range\" / "
      "\"beyond the physical bound 1000 m/s\" / \"theta1 reference ... is not the pose's theta1\"",
      [&](PlantFmu& p, double) {
        std::vector<fmi2Status> s;
        const std::vector<fmi2Byte> bytes = serialized_state(p);
        const std::size_t size = bytes.size();
        std::size_t m_platform = 83;
        for (std::size_t i = 0; i < p.def.n_variables; ++i) {
          const pkm_fmi::Variable& v = p.def.variables[i];
          if (std::string(v.name) == "m_platform") break;
          if (v.stored_in_state()) m_platform += 8;
        }
        const PlantPart plant(size);
        double theta1_2 = 0.0;
        std::memcpy(&theta1_2, &bytes[plant.theta1 + 8], 8);
        const double nan = std::numeric_limits<double>::quiet_NaN();
        const struct {
          std::size_t at;
          double value;
          const char* reason;
          bool u32 = false;
        } forgeries[] = {
            {55, nan, "a time is not finite"},
            {39, 1.0, "the time lies before startTime"},
            {71, 5.0, "the time since startTime does not match the time"},
            {m_platform, -1.0, "m_platform = -1, outside its range"},
            {plant.t, nan, "the plant's time nan s differs from the time since startTime"},
            {plant.y + 32, 1e200, "beyond the physical bound"},
            {plant.theta1 + 8, 1e16, "theta1 reference 10000000000000000 rad of leg 2"},
            {plant.theta1 + 8, theta1_2 + 1.0, "of leg 2 is not the pose's theta1"},
            {plant.energy + 8, nan, "energy integrals are not finite"},
            {plant.stops, 0xffff, "end-stop record", true},
        };
        // The control: the same bytes with the checksum recomputed restore.
        {
          double time = 0.0;
          std::memcpy(&time, &bytes[55], 8);
          fmi2FMUstate same = nullptr;
          EXPECT_EQ(lib.fmi2DeSerializeFMUstate(p.c, forge(bytes, 55, time).data(), size, &same), fmi2OK);
          EXPECT_EQ(lib.fmi2SetFMUstate(p.c, same), fmi2OK) << p.log.dump();
          EXPECT_EQ(lib.fmi2FreeFMUstate(p.c, &same), fmi2OK);
        }
        for (const auto& f : forgeries) {
          SCOPED_TRACE(f.reason);
          const std::vector<fmi2Byte> forged = forge(bytes, f.at, f.value, f.u32);
          fmi2FMUstate st = nullptr;
          EXPECT_EQ(lib.fmi2DeSerializeFMUstate(p.c, forged.data(), forged.size(), &st), fmi2OK);
          const std::size_t logged = p.log.messages.size();
          s.push_back(lib.fmi2SetFMUstate(p.c, st));
          bool named = false;
          for (std::size_t k = logged; k < p.log.messages.size(); ++k)
            named = named || p.log.messages[k].text.find(f.reason) != std::string::npos;
          EXPECT_TRUE(named) << p.log.dump();
          EXPECT_EQ(lib.fmi2FreeFMUstate(p.c, &st), fmi2OK);
        }
        return s;
      });
}

// ---------------------------------------------------------------- states the instance cannot be in

/// `a` refused `status` with a logged message naming `reason`, and is as
/// before: every Real bit-identical, and its next step bit-identical to
/// `twin`'s (both at step k of a run).
void refused_unchanged(Any& a, Any& twin, int status, const std::string& reason, const std::vector<double>& before,
                       int k) {
  EXPECT_EQ(status, fmi2Error) << a.log.dump();
  EXPECT_TRUE(a.log.contains(reason)) << "the reason \"" << reason << "\" logged?\n" << a.log.dump();
  EXPECT_EQ(first_difference(a.reals(), before), "") << "every variable as before";
  EXPECT_EQ(first_difference(steps(a, k, k + 1), steps(twin, k, k + 1)), "") << "the next step as an untouched twin's";
}

// FMI 2.0 section 2.1.8 and FMI 3.0 section 2.2.6: a state of this FMU; an
// FMI 2.0 and an FMI 3.0 FMU are two, whose state machines differ (FMI 2.0.4
// section 4.2.4: stepFailed after a Discard; FMI 3.0.2 section 4.2.3: a
// Discard leaves the FMU in Step Mode, there is no stepFailed). An FMI 2.0
// state taken after a Discard would leave an FMI 3.0 instance in a state it
// has no way out of but Reset.
TEST_F(FmuState, AStateOfTheOtherFmiVersionIsRefused) {
  Any failed(2, false);
  start_drop(failed, kCvode, machines()[0]);
  ASSERT_EQ(failed.set("F[3]", 1e300), fmi2OK);
  ASSERT_EQ(failed.step(0.0, kH), fmi2Discard) << failed.log.dump();
  const std::vector<unsigned char> after_discard = failed.serialized_state();
  ASSERT_FALSE(after_discard.empty()) << failed.log.dump();
  for (int version : {3, 2}) {
    SCOPED_TRACE("into an FMI " + std::to_string(version) + ".0 instance");
    Any from(5 - version, false), into(version, false), twin(version, false);
    for (Any* x : {&from, &into, &twin}) start_drop(*x, kCvode, machines()[0]);
    if (HasFatalFailure()) return;
    steps(from, 0, 3);
    steps(into, 0, 2);
    steps(twin, 0, 2);
    const std::vector<double> before = into.reals();
    const std::string reason = "saved by an FMI " + std::to_string(5 - version) + ".0 instance, this one is FMI " +
                               std::to_string(version) + ".0";
    // Serialised, and as a state object handed over in memory.
    refused_unchanged(into, twin, into.restore(from.serialized_state()), reason, before, 2);
    void* s = nullptr;
    ASSERT_EQ(from.get_state(&s), fmi2OK);
    into.log.messages.clear();
    const std::vector<double> now = into.reals();
    refused_unchanged(into, twin, into.set_state(s), reason, now, 3);
    EXPECT_EQ(from.free_state(&s), fmi2OK);
    if (version == 3) {
      into.log.messages.clear();
      const std::vector<double> later = into.reals();
      refused_unchanged(into, twin, into.restore(after_discard), "saved by an FMI 2.0 instance", later, 4);
    }
  }
}

// FMI 2.0 section 2.1.8, FMI 3.0 section 2.2.6 and the state tables (FMI
// 2.0.4 sections 3.2.3, 4.2.4; FMI 3.0.2 sections 2.3, 3.2, 4.2): states
// whose mode or flags (checksum recomputed) no instance of this version and
// interface can be in are refused, the instance as it was.
TEST_F(FmuState, ForgedModesTheInstanceCannotBeInAreRefused) {
  constexpr std::size_t kMode = 32, kTerminated = 37;  // the layout: ForgedFmuStatesWithAValidChecksumAreRefused
  for (int version : {2, 3}) {
    for (bool me : {false, true}) {
      SCOPED_TRACE(std::string("FMI ") + std::to_string(version) + ".0 " + (me ? "Model Exchange" : "Co-Simulation"));
      Any a(version, me);
      ASSERT_EQ(a.enter(), fmi2OK);
      ASSERT_EQ(a.exit(), fmi2OK);
      const std::vector<unsigned char> good = a.serialized_state();
      ASSERT_FALSE(good.empty());
      struct Forgery {
        std::uint32_t mode;
        unsigned char terminated;
        const char* reason;
      };
      std::vector<Forgery> forgeries = {
          {me ? pkm_fmi::kStepMode : pkm_fmi::kEventMode, 0, "a state no instance of this FMI version and interface"},
          {me ? pkm_fmi::kStepFailed : pkm_fmi::kContinuousTimeMode, 0, "a state no instance"},
          {pkm_fmi::kFatal, 0, "malformed FMU state (mode 256"},
          {me ? pkm_fmi::kEventMode : pkm_fmi::kStepMode, 1, "fmi2Terminated set where no Discard can have set it"},
      };
      if (!me) forgeries.push_back({pkm_fmi::kStepFailed, 0, version == 2 ? "stepFailed without fmi2Terminated"
                                                                          : "a state no instance"});
      if (!me && version == 3) forgeries.push_back({pkm_fmi::kStepFailed, 1, "a state no instance"});
      for (const Forgery& f : forgeries) {
        SCOPED_TRACE(f.reason);
        std::vector<unsigned char> forged = forge(good, kMode, f.mode, true);
        forged = forge_bytes(forged, kTerminated, &f.terminated, 1);
        a.log.messages.clear();
        EXPECT_EQ(a.restore(forged), fmi2Error);
        EXPECT_TRUE(a.log.contains(f.reason)) << a.log.dump();
      }
      // The control: the same bytes with the checksum recomputed restore.
      const unsigned char zero = 0;
      EXPECT_EQ(a.restore(forge_bytes(good, kTerminated, &zero, 1)), fmi2OK) << a.log.dump();
    }
  }
}

// A Co-Simulation state after initialisation holds the plant (the instance
// made it at ExitInitializationMode), at the time the instance counts: a
// state from before initialisation forged into Step Mode, or with the
// plant's time off the instance's, is refused.
TEST_F(FmuState, ForgedPlantsTheInstanceCannotHaveAreRefused) {
  for (int version : {2, 3}) {
    SCOPED_TRACE(version);
    Any a(version, false), twin(version, false);
    const std::vector<unsigned char> instantiated = a.serialized_state();
    ASSERT_FALSE(instantiated.empty()) << a.log.dump();
    start_drop(a, kRos2, machines()[0]);
    start_drop(twin, kRos2, machines()[0]);
    steps(a, 0, 3);
    steps(twin, 0, 3);
    const std::vector<double> before = a.reals();
    refused_unchanged(a, twin, a.restore(forge(instantiated, 32, pkm_fmi::kStepMode, true)),
                      "no plant in a state after initialisation", before, 3);
    const std::vector<unsigned char> good = a.serialized_state();
    double t = 0.0;
    std::memcpy(&t, &good[PlantPart(good.size()).t], 8);
    a.log.messages.clear();
    const std::vector<double> now = a.reals();
    refused_unchanged(a, twin, a.restore(forge(good, PlantPart(good.size()).t, t + kH)),
                      "differs from the time since startTime", now, 4);
  }
}

// The contact mode is part of the hybrid state (docs/model.md): in
// Co-Simulation the plant switches it at every event it locates, so every
// state it saves holds the mode the event rule keeps there. A forged "lower
// stop of leg 1 held" at the home pose, 5 cm above the stop, would pull the
// slider down with the stop's spring: refused, the reason logged. In Model
// Exchange the mode changes only in Event Mode (FMI 2.0.4 section 3.2.2,
// FMI 3.0.2 section 3.1.1), and between events the importer's integrator may
// carry the state past a switch: the mode may lag the state there.
TEST_F(FmuState, AHeldStopClearOfItsSliderIsRefusedInCoSimulation) {
  for (int version : {2, 3}) {
    SCOPED_TRACE(version);
    Any a(version, false), twin(version, false);
    ASSERT_NO_FATAL_FAILURE(initialise({&a, &twin}));
    const std::vector<unsigned char> good = a.serialized_state();
    const PlantPart plant(good.size());
    const std::vector<double> before = a.reals();
    refused_unchanged(a, twin, a.restore(forge(good, plant.stops, 1, true)),
                      "the lower stop of leg 1 is held while its slider is", before, 0);
    double f = NAN;
    ASSERT_EQ(a.get("stop_force[1]", f), fmi2OK);
    EXPECT_EQ(f, 0.0) << "no stop acts at the home pose";
    a.log.messages.clear();
    EXPECT_EQ(a.restore(forge(good, plant.stops, 0x11, true)), fmi2Error)
        << "both stops of leg 1";
    Any me(version, true);
    ASSERT_EQ(me.enter(), fmi2OK);
    ASSERT_EQ(me.exit(), fmi2OK);
    const std::vector<unsigned char> me_good = me.serialized_state();
    EXPECT_EQ(me.restore(forge(me_good, PlantPart(me_good.size()).stops, 1, true)), fmi2OK) << me.log.dump();
  }
}

// The integrators' memory (pkm::SolverMemory) travels whole: each of its
// bytes, perturbed in a serialised state with the checksum recomputed, is
// either refused (a memory no run can have, the reason logged) or restored
// exactly -- the state serialised again carries the perturbed byte. A
// member restored by a list of fields that forgot one would fail here.
TEST_F(FmuState, EveryByteOfTheIntegratorsMemoryIsRestored) {
  Any a(2, false);
  start_drop(a, kRos2, machines()[0]);
  int k = 0;
  double f = 0.0;
  for (; k < 200 && f == 0.0; ++k) {
    ASSERT_EQ(a.step(k * kH, kH), fmi2OK) << a.log.dump();
    ASSERT_EQ(a.get("stop_force[1]", f), fmi2OK);
  }
  ASSERT_NE(f, 0.0) << "right after the impact: ROS2's layer and contact step are set";
  const std::vector<unsigned char> good = a.serialized_state();
  const PlantPart plant(good.size());
  std::uint32_t size = 0;
  std::memcpy(&size, &good[plant.memory_size], 4);
  ASSERT_EQ(size, sizeof(pkm::SolverMemory));
  std::size_t restored = 0;
  for (std::size_t i = 0; i < sizeof(pkm::SolverMemory); ++i) {
    SCOPED_TRACE("byte " + std::to_string(i));
    const unsigned char byte = static_cast<unsigned char>(good[plant.memory + i] ^ 0x01u);
    const std::vector<unsigned char> forged = forge_bytes(good, plant.memory + i, &byte, 1);
    a.log.messages.clear();
    if (a.restore(forged) == fmi2OK) {
      ++restored;
      const std::vector<unsigned char> again = a.serialized_state();
      ASSERT_EQ(again.size(), forged.size());
      EXPECT_EQ(std::memcmp(&again[plant.memory], &forged[plant.memory], sizeof(pkm::SolverMemory)), 0);
    } else {
      EXPECT_TRUE(a.log.contains("the integrators' memory is none a run can have")) << a.log.dump();
    }
  }
  EXPECT_GE(restored, sizeof(pkm::SolverMemory) / 2) << "most perturbations are memories a run can have";
  a.log.messages.clear();
  EXPECT_EQ(a.restore(forge(good, plant.memory_size, sizeof(pkm::SolverMemory) + 8, true)), fmi2Error);
  EXPECT_TRUE(a.log.contains("integrators' memory of")) << a.log.dump();
}

}  // namespace

// SPDX-License-Identifier: BSD-2-Clause
// FMU states of the binaries through the raw FMI 2.0 functions: get/set and
// serialised states continue bit-identically (CVODE and RK4), in the same
// and in a fresh instance, for both FMUs; foreign, broken and forged states
// (valid checksum, impossible content) are refused with the instance
// unchanged; states left behind are freed with their instance.
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "fmi2FunctionTypes.h"
#include "fmu_fixture.hpp"
#include "models/models.hpp"

namespace {

using namespace pkm_test;

class FmuState : public FmuTest {};

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
// (fmu_state.cpp): a 32-byte header; mode (4), three flags (3), startTime,
// stopTime, time, last successful time, time since start (8 each) from byte
// 39; the count (4) and the stored variables (8 each) from byte 83; then the input
// derivatives and the plant's part, which ends (before the 8-byte checksum)
// with time (8), [pose; velocity] (64), the theta1 references (32), the
// energy integrals (16) and the end-stop record (4).
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
        const std::size_t size = bytes.size(), end = size - 8;
        std::size_t m_platform = 83;
        for (std::size_t i = 0; i < p.def.n_variables; ++i) {
          const pkm_fmi::Variable& v = p.def.variables[i];
          if (std::string(v.name) == "m_platform") break;
          if (v.stored_in_state()) m_platform += 8;
        }
        double theta1_2 = 0.0;
        std::memcpy(&theta1_2, &bytes[end - 52 + 8], 8);
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
            {end - 124, nan, "not finite"},
            {end - 84, 1e200, "beyond the physical bound"},
            {end - 52 + 8, 1e16, "theta1 reference 10000000000000000 rad of leg 2"},
            {end - 52 + 8, theta1_2 + 1.0, "of leg 2 is not the pose's theta1"},
            {end - 4, 0xffff, "end-stop record", true},
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

}  // namespace

// SPDX-License-Identifier: BSD-2-Clause
// The plant FMU behaves like the machine when nothing is set (docs/model.md
// "The machine around the mechanism"), and its log stays quiet: with logging
// on and no category named only warnings, errors and events are written.
#include <string>

#include "fmu_loader.hpp"

namespace {

using namespace pkm_test;

// Defaults only, logging on: F starts at the holding forces, so the machine
// stays at the home pose; the 2,000 steps write no message (initialisation
// writes its two mode changes, events).
TEST(Machine, DefaultsHoldTheMachineAndTheLogStaysQuiet) {
  PlantFmu p("quiet", /*logging_on=*/true);
  ASSERT_NE(p.c, nullptr);
  p.initialize();
  ASSERT_EQ(p.log.messages.size(), 2u) << p.log.dump();  // entering and leaving initialisation mode
  for (const LogMessage& m : p.log.messages) EXPECT_EQ(m.category, "logEvents") << m.text;
  double worst = 0.0;
  for (int k = 0; k < 2000; ++k) {
    ASSERT_EQ(p.step(k * 1e-3, 1e-3), fmi2OK) << p.log.dump();
    worst = std::max({worst, std::abs(p.get("x")), std::abs(p.get("z") - 0.05), std::abs(p.get("phi"))});
  }
  EXPECT_LT(worst, 1e-9) << "the default inputs hold the default machine at rest (docs/model.md)";
  for (int i = 1; i <= 4; ++i) EXPECT_NEAR(p.get("F_hold[" + std::to_string(i) + "]"), kStaticForce, 1e-9);
  EXPECT_EQ(p.log.messages.size(), 2u) << "the 2,000 steps and their gets wrote:\n" << p.log.dump();
}

// A drop onto the lower stops, logging on: the contacts (and releases, when
// a slider bounces) are logEvents messages at status OK, nothing else.
TEST(Machine, StopContactsAreLoggedAsEvents) {
  PlantFmu p("drop", /*logging_on=*/true);
  ASSERT_NE(p.c, nullptr);
  p.initialize();
  for (int i = 1; i <= 4; ++i) ASSERT_EQ(p.set(force_name(i), 0.0), fmi2OK);
  for (int k = 0; k < 500; ++k) ASSERT_EQ(p.step(k * 1e-3, 1e-3), fmi2OK) << p.log.dump();
  int contacts = 0;
  for (const LogMessage& m : p.log.messages) {
    EXPECT_EQ(m.category, "logEvents") << m.text;
    EXPECT_EQ(m.status, fmi2OK) << m.text;
    contacts += m.text.find("passes its lower end stop") != std::string::npos;
  }
  for (int i = 1; i <= 4; ++i)
    EXPECT_TRUE(p.log.contains("slider " + std::to_string(i) + " passes its lower end stop")) << p.log.dump();
  EXPECT_GE(contacts, 4);
  EXPECT_LT(p.log.messages.size(), 100u) << "events only, not a message per step";
}

}  // namespace

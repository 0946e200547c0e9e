// SPDX-License-Identifier: BSD-2-Clause
// Which states each FMI function may be called in, for each FMI version, in
// one table: the FMI 2.0.4 state tables (section 3.2.3 Model Exchange,
// section 4.2.4 Co-Simulation) and the FMI 3.0.2 state machines (section 2.3
// common states, section 3.2 Model Exchange, section 4.2 Co-Simulation),
// read literally. ME and CS states are distinct bits; a row also says which
// interfaces have the function. Instance::allowed() checks a call against
// its row; tests/fmi/state_table.cpp compares the rows, and the FMU's answer
// to every function in every state, with the standards' tables transcribed
// apart from this one (tests/fmi/fmi_standard_state_tables.hpp).
#pragma once

#include "fmi/instance.hpp"

namespace pkm_fmi {

constexpr std::uint32_t kAlive = kInstantiated | kInitializationMode | kInitializedModes | kError;

/// The interfaces a function belongs to (bits).
constexpr unsigned kForME = 1u, kForCS = 2u, kForBoth = kForME | kForCS;

/// The FMI calls that check the state machine (several C functions may share
/// a row: every getter is Get).
enum class Call : unsigned {
  SetDebugLogging,
  SetupExperiment,  // FMI 2.0 fmi2SetupExperiment; FMI 3.0 fmi3EnterInitializationMode's arguments
  EnterInitializationMode,
  ExitInitializationMode,
  Terminate,
  Reset,
  Get,
  Set,
  SetNonReal,  // the setters of the other types: FMI 2.0 has no Continuous-Time Mode row for them
  FmuState,
  PartialDerivative,
  NotProvided,  // functions this FMU does not provide: Error with the reason, in any state
  InputDerivatives,
  OutputDerivatives,
  DoStep,
  StepStatus,
  EnterEventMode,
  EventUpdate,
  EnterContinuousTimeMode,
  CompletedIntegratorStep,
  SetTime,
  SetContinuousStates,
  GetContinuousStates,
  GetDerivatives,
  GetEventIndicators,
  GetNominals,
  GetNumberOf,
  Count
};

struct CallRule {
  Call call;
  const char* fmi2;     // the FMI 2.0 function (a representative one), nullptr if 2.0 has none
  const char* fmi3;     // the FMI 3.0 function, nullptr if 3.0 has none
  std::uint32_t v2;     // states allowed by FMI 2.0.4
  std::uint32_t v3;     // states allowed by FMI 3.0.2
  unsigned interfaces;  // kForME, kForCS
  const char* clause;   // where the standards say so
};

// clang-format off
inline constexpr CallRule kCallRules[] = {
  {Call::SetDebugLogging, "fmi2SetDebugLogging", "fmi3SetDebugLogging", kAlive, kAlive, kForBoth,
   "2.0.4 3.2.3/4.2.4: every state; 3.0.2 2.3.1: super state FMUStateSettable and after"},
  {Call::SetupExperiment, "fmi2SetupExperiment", "fmi3EnterInitializationMode", kInstantiated, kInstantiated, kForBoth,
   "2.0.4 3.2.3/4.2.4: instantiated; 3.0.2 2.3.2: Instantiated"},
  {Call::EnterInitializationMode, "fmi2EnterInitializationMode", "fmi3EnterInitializationMode", kInstantiated,
   kInstantiated, kForBoth, "2.0.4 3.2.3/4.2.4: instantiated; 3.0.2 2.3.2: Instantiated"},
  {Call::ExitInitializationMode, "fmi2ExitInitializationMode", "fmi3ExitInitializationMode", kInitializationMode,
   kInitializationMode, kForBoth, "2.0.4 3.2.3/4.2.4: Initialization Mode; 3.0.2 2.3.3: Initialization Mode"},
  // FMI 3.0 has no StepFailed: a Discard leaves the FMU in Step Mode (3.0.2 4.2.3).
  {Call::Terminate, "fmi2Terminate", "fmi3Terminate", kRunning | kStepFailed, kRunning, kForBoth,
   "2.0.4 3.2.3: Continuous-Time/Event Mode, 4.2.4: stepComplete, stepFailed; 3.0.2 2.3.4: super state Initialized"},
  {Call::Reset, "fmi2Reset", "fmi3Reset", kAlive, kAlive, kForBoth,
   "2.0.4 3.2.3/4.2.4: every state but fatal; 3.0.2 2.3.1: super state FMUStateSettable"},
  // FMI 3.0 reads start values in Instantiated (3.0.2 2.3.2, table "Get variable start values").
  {Call::Get, "fmi2GetReal", "fmi3GetFloat64", kInitializationMode | kRunning | kStepFailed | kTerminated | kError,
   kInstantiated | kInitializationMode | kRunning | kTerminated | kError, kForBoth,
   "2.0.4 3.2.3/4.2.4: not in instantiated; 3.0.2 2.3.2: Instantiated (start values) and after"},
  {Call::Set, "fmi2SetReal", "fmi3SetFloat64", kInstantiated | kInitializationMode | kRunning,
   kInstantiated | kInitializationMode | kRunning, kForBoth,
   "2.0.4 3.2.3/4.2.4: not after a failed step or termination; 3.0.2 2.3.2-2.3.5, 3.2.1, 4.2.1"},
  // FMI 3.0.2 3.2.1 allows fmi3Set{VariableType} in Continuous-Time Mode for
  // continuous inputs and states, which only Float64 variables can be.
  {Call::SetNonReal, "fmi2SetInteger", "fmi3SetInt32", kInstantiated | kInitializationMode | kEventMode | kStepMode,
   kInstantiated | kInitializationMode | kRunning, kForBoth,
   "2.0.4 3.2.3: fmi2SetInteger/Boolean/String not in Continuous-Time Mode, 4.2.4 as fmi2SetReal; 3.0.2 as "
   "fmi3SetFloat64"},
  {Call::FmuState, "fmi2GetFMUstate", "fmi3GetFMUState", kAlive, kAlive, kForBoth,
   "2.0.4 3.2.3/4.2.4: every state but fatal; 3.0.2 2.3.1: super state FMUStateSettable"},
  {Call::PartialDerivative, "fmi2GetDirectionalDerivative", "fmi3GetDirectionalDerivative",
   kInitializationMode | kRunning | kStepFailed | kTerminated | kError, kInitializationMode | kRunning | kTerminated | kError,
   kForBoth, "2.0.4 3.2.3/4.2.4: not in instantiated; 3.0.2 2.3.3-2.3.5, 4.2.1"},
  {Call::NotProvided, "fmi2CancelStep", "fmi3EnterConfigurationMode", kAlive, kAlive, kForBoth,
   "not provided by this FMU: Error with the reason in every state"},
  {Call::InputDerivatives, "fmi2SetRealInputDerivatives", nullptr, kInstantiated | kInitializationMode | kStepMode, 0,
   kForCS, "2.0.4 4.2.4: instantiated, Initialization Mode, stepComplete"},
  {Call::OutputDerivatives, "fmi2GetRealOutputDerivatives", "fmi3GetOutputDerivatives",
   kStepMode | kStepFailed | kTerminated | kError, kStepMode | kTerminated | kError, kForCS,
   "2.0.4 4.2.4: stepComplete, stepFailed, terminated, error; 3.0.2 2.3.5 (Terminated), 4.2.1 (Step Mode)"},
  {Call::DoStep, "fmi2DoStep", "fmi3DoStep", kStepMode, kStepMode, kForCS,
   "2.0.4 4.2.4: stepComplete; 3.0.2 4.2.1: Step Mode"},
  {Call::StepStatus, "fmi2GetStatus", nullptr, kStepMode | kStepFailed | kTerminated, 0, kForCS,
   "2.0.4 4.2.4: stepComplete, stepFailed, terminated"},
  {Call::EnterEventMode, "fmi2EnterEventMode", "fmi3EnterEventMode", kEventMode | kContinuousTimeMode,
   kContinuousTimeMode, kForME, "2.0.4 3.2.3: Event and Continuous-Time Mode; 3.0.2 3.2.1: Continuous-Time Mode"},
  {Call::EventUpdate, "fmi2NewDiscreteStates", "fmi3UpdateDiscreteStates", kEventMode, kEventMode, kForME,
   "2.0.4 3.2.3: Event Mode; 3.0.2 2.3.4: Event Mode"},
  {Call::EnterContinuousTimeMode, "fmi2EnterContinuousTimeMode", "fmi3EnterContinuousTimeMode", kEventMode,
   kEventMode, kForME, "2.0.4 3.2.3: Event Mode; 3.0.2 2.3.4: Event Mode"},
  {Call::CompletedIntegratorStep, "fmi2CompletedIntegratorStep", "fmi3CompletedIntegratorStep", kContinuousTimeMode,
   kContinuousTimeMode, kForME, "2.0.4 3.2.3: Continuous-Time Mode; 3.0.2 3.2.1: Continuous-Time Mode"},
  // In Event Mode only for a pure discrete-time FMU (Instance::set_time).
  {Call::SetTime, "fmi2SetTime", "fmi3SetTime", kEventMode | kContinuousTimeMode, kContinuousTimeMode, kForME,
   "2.0.4 3.2.3: Continuous-Time Mode, Event Mode (condition 8); 3.0.2 3.2.1: Continuous-Time Mode only"},
  {Call::SetContinuousStates, "fmi2SetContinuousStates", "fmi3SetContinuousStates", kContinuousTimeMode,
   kContinuousTimeMode, kForME, "2.0.4 3.2.3: Continuous-Time Mode; 3.0.2 3.2.1: Continuous-Time Mode"},
  {Call::GetContinuousStates, "fmi2GetContinuousStates", "fmi3GetContinuousStates",
   kInitializationMode | kEventMode | kContinuousTimeMode | kTerminated | kError,
   kInitializationMode | kEventMode | kContinuousTimeMode | kTerminated | kError, kForME,
   "2.0.4 3.2.3: not in instantiated; 3.0.2 2.3.3-2.3.5, 3.2.1"},
  {Call::GetDerivatives, "fmi2GetDerivatives", "fmi3GetContinuousStateDerivatives",
   kInitializationMode | kEventMode | kContinuousTimeMode | kTerminated | kError,
   kInitializationMode | kEventMode | kContinuousTimeMode | kTerminated | kError, kForME,
   "2.0.4 3.2.3: not in instantiated (Initialization Mode since 2.0.1); 3.0.2 2.3.3, 2.3.5, 3.2.1, 2.3.8"},
  {Call::GetEventIndicators, "fmi2GetEventIndicators", "fmi3GetEventIndicators",
   kInitializationMode | kEventMode | kContinuousTimeMode | kTerminated | kError,
   kInitializationMode | kEventMode | kContinuousTimeMode | kTerminated | kError, kForME,
   "2.0.4 3.2.3: not in instantiated; 3.0.2 2.3.3-2.3.5, 3.2.1"},
  {Call::GetNominals, "fmi2GetNominalsOfContinuousStates", "fmi3GetNominalsOfContinuousStates",
   kInstantiated | kInitializationMode | kEventMode | kContinuousTimeMode | kTerminated | kError,
   kInitializationMode | kEventMode | kContinuousTimeMode | kTerminated | kError, kForME,
   "2.0.4 3.2.3: every state but start and fatal; 3.0.2 2.3.3 Initialization Mode, 2.3.4 super state "
   "Initialized, 2.3.8 Terminated"},
  {Call::GetNumberOf, nullptr, "fmi3GetNumberOfContinuousStates", 0, kInstantiated | kEventMode, kForME,
   "3.0.2 2.3.2: Instantiated, \"can only be called in Model Exchange\"; 2.3.5: Event Mode"},
};
// clang-format on

static_assert(sizeof kCallRules / sizeof kCallRules[0] == static_cast<unsigned>(Call::Count),
              "one row per call");

constexpr const CallRule& call_rule(Call c) { return kCallRules[static_cast<unsigned>(c)]; }

constexpr bool rows_in_order() {
  for (unsigned k = 0; k < static_cast<unsigned>(Call::Count); ++k)
    if (static_cast<unsigned>(kCallRules[k].call) != k) return false;
  return true;
}
static_assert(rows_in_order(), "kCallRules is indexed by Call");

/// The states a call is allowed in, for an FMI version.
constexpr std::uint32_t allowed_states(Call c, int fmi_version) {
  return fmi_version == 2 ? call_rule(c).v2 : call_rule(c).v3;
}

/// Continuous states set by value reference (fmi2SetReal, fmi3SetFloat64),
/// a case of Call::Set: in Model Exchange's Event and Continuous-Time Modes
/// (FMI 2.0.4's state table, footnote on fmi2SetReal since 2.0.1; FMI 3.0.2
/// 3.2.1 and 2.3.5).
constexpr std::uint32_t kSetStatesByReference = kEventMode | kContinuousTimeMode;

/// The states an instance of an FMI version and interface can be in, Error
/// included (Fatal is unrecoverable): the FMI 2.0.4 state tables (section
/// 3.2.3 Model Exchange, section 4.2.4 Co-Simulation: stepFailed after a
/// Discard) and the FMI 3.0.2 state machines (section 2.3, 3.2: Event and
/// Continuous-Time Mode; 4.2: Step Mode, a Discard leaves the FMU in it).
/// An FMU state saved in any other is none this instance can be in.
constexpr std::uint32_t reachable_modes(int fmi_version, Interface interface) {
  return kInstantiated | kInitializationMode | kTerminated | kError |
         (interface == Interface::ModelExchange ? kEventMode | kContinuousTimeMode
                                                : kStepMode | (fmi_version == 2 ? kStepFailed : 0u));
}
/// The states an FMI 2.0 Co-Simulation instance can hold fmi2Terminated in:
/// stepFailed, where the Discard that sets it leaves the instance (FMI 2.0.4
/// section 4.2.3), and Terminated or Error, which may follow.
constexpr std::uint32_t kAfterDiscard = kStepFailed | kTerminated | kError;

}  // namespace pkm_fmi

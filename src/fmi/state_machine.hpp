// Which states each FMI function may be called in (FMI 2.0 and 3.0 state
// machines, merged: ME and CS states are distinct bits), in one place.
#pragma once

#include "fmi/instance.hpp"

namespace pkm_fmi {

constexpr std::uint32_t kAlive = kInstantiated | kInitializationMode | kEventMode | kContinuousTimeMode | kStepMode |
                                 kStepFailed | kTerminated | kError;
constexpr std::uint32_t kRunning = kEventMode | kContinuousTimeMode | kStepMode;

constexpr std::uint32_t kMaskSetDebugLogging = kAlive;
constexpr std::uint32_t kMaskSetupExperiment = kInstantiated;
constexpr std::uint32_t kMaskEnterInitialization = kInstantiated;
constexpr std::uint32_t kMaskExitInitialization = kInitializationMode;
constexpr std::uint32_t kMaskTerminate = kRunning | kStepFailed;
constexpr std::uint32_t kMaskReset = kAlive;
constexpr std::uint32_t kMaskGet = kInitializationMode | kRunning | kStepFailed | kTerminated | kError;
constexpr std::uint32_t kMaskSet = kInstantiated | kInitializationMode | kRunning;
constexpr std::uint32_t kMaskFmuState = kAlive;
// Co-Simulation.
constexpr std::uint32_t kMaskInputDerivatives = kInstantiated | kInitializationMode | kStepMode;
constexpr std::uint32_t kMaskOutputDerivatives = kStepMode | kStepFailed | kTerminated | kError;
constexpr std::uint32_t kMaskDoStep = kStepMode;
constexpr std::uint32_t kMaskStatus = kStepMode | kStepFailed | kTerminated;
// Model Exchange.
constexpr std::uint32_t kMaskEnterEventMode = kEventMode | kContinuousTimeMode;
constexpr std::uint32_t kMaskEventUpdate = kEventMode;
constexpr std::uint32_t kMaskEnterContinuousTime = kEventMode;
constexpr std::uint32_t kMaskCompletedStep = kContinuousTimeMode;
constexpr std::uint32_t kMaskSetTime = kEventMode | kContinuousTimeMode;
constexpr std::uint32_t kMaskSetStates = kContinuousTimeMode;
// Continuous states set by value reference (fmi2SetReal, fmi3SetFloat64):
// FMI 2.0.4's state table (footnote on fmi2SetReal, since 2.0.1) and FMI
// 3.0.2 §3.2.1 / §2.3.5.
constexpr std::uint32_t kMaskSetStatesByReference = kEventMode | kContinuousTimeMode;
constexpr std::uint32_t kMaskGetStates = kInitializationMode | kEventMode | kContinuousTimeMode | kTerminated | kError;
// States an FMU state may carry (the others are unrecoverable).
constexpr std::uint32_t kRestorableModes = kAlive;

}  // namespace pkm_fmi

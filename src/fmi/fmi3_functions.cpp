// SPDX-License-Identifier: BSD-2-Clause
// The FMI 3.0 front end (Model Exchange and Co-Simulation) of one FMU: each
// exported function checks its handle and forwards to pkm_fmi::Instance.
// Compiled once per FMU, with PKM_FMI_DEFINITION naming the function that
// returns its ModelDefinition. No exception crosses the C ABI. Every
// variable is a scalar (no Dimension), so nValues equals nValueReferences.
#include <cstdio>
#include <cstring>
#include <exception>

#ifdef PKM_FMI_FUNCTION_PREFIX
#define FMI3_FUNCTION_PREFIX PKM_FMI_FUNCTION_PREFIX
#endif
#include "fmi3Functions.h"
#include "fmi/instance.hpp"

#ifndef PKM_FMI_DEFINITION
#error "PKM_FMI_DEFINITION must name the model's definition, a function in namespace pkm_fmi"
#endif

namespace pkm_fmi {
const ModelDefinition& PKM_FMI_DEFINITION();
}

using pkm_fmi::Instance;
using pkm_fmi::Interface;
using pkm_fmi::Status;

namespace {

const pkm_fmi::ModelDefinition& definition() { return pkm_fmi::PKM_FMI_DEFINITION(); }

fmi3Status to_fmi3(Status s) { return static_cast<fmi3Status>(static_cast<int>(s)); }

void emit(void* callback, void* env, const char*, Status status, const char* category, const char* message) {
  reinterpret_cast<fmi3LogMessageCallback>(callback)(env, static_cast<fmi3Status>(static_cast<int>(status)),
                                                     category, message);
}

template <class Body>
fmi3Status call(fmi3Instance c, const char* function, Body&& body) {
  Instance* inst = Instance::from(c, definition(), 3);
  if (!inst) return fmi3Error;  // no instance of this FMU: nobody to log to
  const Instance::Busy busy(*inst);
  if (!busy) return to_fmi3(inst->concurrent_call(function));
  try {
    return to_fmi3(body(*inst));
  } catch (const std::exception& e) {
    return to_fmi3(inst->internal_error(function, e.what()));
  } catch (...) {
    return to_fmi3(inst->internal_error(function, "unknown exception"));
  }
}

Instance* instantiate(const char* fn, Interface interface, fmi3String name, fmi3String token, fmi3Boolean logging_on,
                      fmi3InstanceEnvironment env, fmi3LogMessageCallback log_message, bool event_mode_used) {
  try {
    pkm_fmi::Logger log(log_message ? &emit : nullptr, reinterpret_cast<void*>(log_message), env,
                        name ? name : "", logging_on, /*categories_only=*/true);
    if (!name) {
      log.error("%s: instanceName is NULL", fn);
      return nullptr;
    }
    if (event_mode_used) {
      log.error("%s: eventModeUsed = true, but this FMU has no event mode in Co-Simulation (hasEventMode = false)",
                fn);
      return nullptr;
    }
    return Instance::create(definition(), 3, interface, token, std::move(log));
  } catch (...) {
    // Out of memory (nothing else throws here): said through the callback
    // directly, the Logger may be what could not be built.
    if (log_message && logging_on) {  // FMI 3.0: no message while logging is off
      char message[160];
      std::snprintf(message, sizeof message, "%s: out of memory; no instance created", fn);
      log_message(env, fmi3Error, "logStatusError", message);
    }
    return nullptr;
  }
}

/// call() for a get or set of scalars: refuses, with no effect, a call whose
/// nValues differs from nValueReferences (every variable here is a scalar).
template <class Body>
fmi3Status scalar_call(fmi3Instance c, const char* fn, size_t nvr, size_t n_values, Body&& body) {
  return call(c, fn, [&](Instance& i) {
    if (nvr == n_values) return body(i);
    i.logger().error("%s: nValues = %llu differs from nValueReferences = %llu (every variable of this FMU is a "
                     "scalar); the call has no effect",
                     fn, static_cast<unsigned long long>(n_values), static_cast<unsigned long long>(nvr));
    return Status::Error;
  });
}

}  // namespace

extern "C" {

const char* fmi3GetVersion(void) { return fmi3Version; }

fmi3Status fmi3SetDebugLogging(fmi3Instance c, fmi3Boolean loggingOn, size_t nCategories,
                               const fmi3String categories[]) {
  return call(c, "fmi3SetDebugLogging",
              [&](Instance& i) { return i.set_debug_logging(loggingOn, nCategories, categories); });
}

fmi3Instance fmi3InstantiateModelExchange(fmi3String instanceName, fmi3String instantiationToken,
                                          fmi3String resourcePath, fmi3Boolean visible, fmi3Boolean loggingOn,
                                          fmi3InstanceEnvironment instanceEnvironment,
                                          fmi3LogMessageCallback logMessage) {
  (void)resourcePath, (void)visible;
  return instantiate("fmi3InstantiateModelExchange", Interface::ModelExchange, instanceName, instantiationToken,
                     loggingOn, instanceEnvironment, logMessage, false);
}

fmi3Instance fmi3InstantiateCoSimulation(fmi3String instanceName, fmi3String instantiationToken,
                                         fmi3String resourcePath, fmi3Boolean visible, fmi3Boolean loggingOn,
                                         fmi3Boolean eventModeUsed, fmi3Boolean earlyReturnAllowed,
                                         const fmi3ValueReference requiredIntermediateVariables[],
                                         size_t nRequiredIntermediateVariables,
                                         fmi3InstanceEnvironment instanceEnvironment,
                                         fmi3LogMessageCallback logMessage,
                                         fmi3IntermediateUpdateCallback intermediateUpdate) {
  (void)resourcePath, (void)visible, (void)earlyReturnAllowed, (void)requiredIntermediateVariables,
      (void)nRequiredIntermediateVariables, (void)intermediateUpdate;  // no intermediate updates, no early return
  return instantiate("fmi3InstantiateCoSimulation", Interface::CoSimulation, instanceName, instantiationToken,
                     loggingOn, instanceEnvironment, logMessage, eventModeUsed);
}

fmi3Instance fmi3InstantiateScheduledExecution(fmi3String instanceName, fmi3String instantiationToken,
                                               fmi3String resourcePath, fmi3Boolean visible, fmi3Boolean loggingOn,
                                               fmi3InstanceEnvironment instanceEnvironment,
                                               fmi3LogMessageCallback logMessage, fmi3ClockUpdateCallback clockUpdate,
                                               fmi3LockPreemptionCallback lockPreemption,
                                               fmi3UnlockPreemptionCallback unlockPreemption) {
  (void)instantiationToken, (void)resourcePath, (void)visible, (void)clockUpdate, (void)lockPreemption,
      (void)unlockPreemption;
  pkm_fmi::Logger log(logMessage ? &emit : nullptr, reinterpret_cast<void*>(logMessage), instanceEnvironment,
                      instanceName ? instanceName : "", loggingOn, /*categories_only=*/true);
  log.error("fmi3InstantiateScheduledExecution: this FMU offers Model Exchange and Co-Simulation only");
  return nullptr;
}

void fmi3FreeInstance(fmi3Instance c) { Instance::free(c, definition(), 3, "fmi3FreeInstance"); }

fmi3Status fmi3EnterInitializationMode(fmi3Instance c, fmi3Boolean toleranceDefined, fmi3Float64 tolerance,
                                       fmi3Float64 startTime, fmi3Boolean stopTimeDefined, fmi3Float64 stopTime) {
  return call(c, "fmi3EnterInitializationMode", [&](Instance& i) {
    const Status s = i.setup_experiment(toleranceDefined, tolerance, startTime, stopTimeDefined, stopTime);
    return s == Status::OK ? i.enter_initialization_mode() : s;
  });
}

fmi3Status fmi3ExitInitializationMode(fmi3Instance c) {
  return call(c, "fmi3ExitInitializationMode", [&](Instance& i) { return i.exit_initialization_mode(); });
}

fmi3Status fmi3EnterEventMode(fmi3Instance c) {
  return call(c, "fmi3EnterEventMode", [&](Instance& i) { return i.enter_event_mode(); });
}

fmi3Status fmi3Terminate(fmi3Instance c) {
  return call(c, "fmi3Terminate", [&](Instance& i) { return i.terminate(); });
}

fmi3Status fmi3Reset(fmi3Instance c) {
  return call(c, "fmi3Reset", [&](Instance& i) { return i.reset(); });
}

// ---------------------------------------------------------------- variables

// Get and set of a type this FMU has variables of (every one a scalar).
#define PKM_FMI3_GET_SET(Type, CType, get, set)                                                                   \
  fmi3Status fmi3Get##Type(fmi3Instance c, const fmi3ValueReference vr[], size_t nvr, CType values[],             \
                           size_t nValues) {                                                                     \
    return scalar_call(c, "fmi3Get" #Type, nvr, nValues, [&](Instance& i) { return i.get(vr, nvr, values); });     \
  }                                                                                                               \
  fmi3Status fmi3Set##Type(fmi3Instance c, const fmi3ValueReference vr[], size_t nvr, const CType values[],       \
                           size_t nValues) {                                                                     \
    return scalar_call(c, "fmi3Set" #Type, nvr, nValues, [&](Instance& i) { return i.set(vr, nvr, values); });     \
  }
PKM_FMI3_GET_SET(Float64, fmi3Float64, get_real, set_real)
PKM_FMI3_GET_SET(Int32, fmi3Int32, get_integer, set_integer)
#undef PKM_FMI3_GET_SET

fmi3Status fmi3GetBoolean(fmi3Instance c, const fmi3ValueReference vr[], size_t nvr, fmi3Boolean values[],
                          size_t nValues) {
  return scalar_call(c, "fmi3GetBoolean", nvr, nValues, [&](Instance& i) {
    if (nvr == 0) return i.get_boolean(vr, 0, nullptr);  // the state check alone
    Status s = Status::OK;
    for (size_t k = 0; k < nvr && pkm_fmi::succeeded(s); ++k) {
      int v = 0;
      s = i.get_boolean(vr + k, 1, &v);
      if (pkm_fmi::succeeded(s) && values) values[k] = v != 0;
    }
    return s;
  });
}

fmi3Status fmi3SetBoolean(fmi3Instance c, const fmi3ValueReference vr[], size_t nvr, const fmi3Boolean values[],
                          size_t nValues) {
  return scalar_call(c, "fmi3SetBoolean", nvr, nValues, [&](Instance& i) {
    if (nvr == 0) return i.set_boolean(vr, 0, nullptr);  // the state check alone
    Status s = Status::OK;
    for (size_t k = 0; k < nvr && pkm_fmi::succeeded(s); ++k) {
      const int v = values && values[k] ? 1 : 0;
      s = i.set_boolean(vr + k, 1, values ? &v : nullptr);
    }
    return s;
  });
}

// Types this FMU has no variables of.
#define PKM_FMI3_NO_GET(Type, CType)                                                                           \
  fmi3Status fmi3Get##Type(fmi3Instance c, const fmi3ValueReference vr[], size_t nvr, CType values[],          \
                           size_t nValues) {                                                                  \
    (void)values, (void)nValues;                                                                               \
    return call(c, "fmi3Get" #Type,                                                                            \
                [&](Instance& i) { return i.no_variables_of_type("fmi3Get" #Type, #Type, vr, nvr, false); }); \
  }                                                                                                            \
  fmi3Status fmi3Set##Type(fmi3Instance c, const fmi3ValueReference vr[], size_t nvr, const CType values[],    \
                           size_t nValues) {                                                                  \
    (void)values, (void)nValues;                                                                               \
    return call(c, "fmi3Set" #Type,                                                                            \
                [&](Instance& i) { return i.no_variables_of_type("fmi3Set" #Type, #Type, vr, nvr, true); });  \
  }
PKM_FMI3_NO_GET(Float32, fmi3Float32)
PKM_FMI3_NO_GET(Int8, fmi3Int8)
PKM_FMI3_NO_GET(UInt8, fmi3UInt8)
PKM_FMI3_NO_GET(Int16, fmi3Int16)
PKM_FMI3_NO_GET(UInt16, fmi3UInt16)
PKM_FMI3_NO_GET(UInt32, fmi3UInt32)
PKM_FMI3_NO_GET(Int64, fmi3Int64)
PKM_FMI3_NO_GET(UInt64, fmi3UInt64)
PKM_FMI3_NO_GET(String, fmi3String)
#undef PKM_FMI3_NO_GET

fmi3Status fmi3GetBinary(fmi3Instance c, const fmi3ValueReference vr[], size_t nvr, size_t valueSizes[],
                         fmi3Binary values[], size_t nValues) {
  (void)valueSizes, (void)values, (void)nValues;
  return call(c, "fmi3GetBinary",
              [&](Instance& i) { return i.no_variables_of_type("fmi3GetBinary", "Binary", vr, nvr, false); });
}

fmi3Status fmi3SetBinary(fmi3Instance c, const fmi3ValueReference vr[], size_t nvr, const size_t valueSizes[],
                         const fmi3Binary values[], size_t nValues) {
  (void)valueSizes, (void)values, (void)nValues;
  return call(c, "fmi3SetBinary",
              [&](Instance& i) { return i.no_variables_of_type("fmi3SetBinary", "Binary", vr, nvr, true); });
}

fmi3Status fmi3GetClock(fmi3Instance c, const fmi3ValueReference vr[], size_t nvr, fmi3Clock values[]) {
  (void)values;
  return call(c, "fmi3GetClock",
              [&](Instance& i) { return i.no_variables_of_type("fmi3GetClock", "Clock", vr, nvr, false); });
}

fmi3Status fmi3SetClock(fmi3Instance c, const fmi3ValueReference vr[], size_t nvr, const fmi3Clock values[]) {
  (void)values;
  return call(c, "fmi3SetClock",
              [&](Instance& i) { return i.no_variables_of_type("fmi3SetClock", "Clock", vr, nvr, true); });
}

fmi3Status fmi3GetNumberOfVariableDependencies(fmi3Instance c, fmi3ValueReference valueReference,
                                               size_t* nDependencies) {
  (void)valueReference, (void)nDependencies;
  return call(c, "fmi3GetNumberOfVariableDependencies", [&](Instance& i) {
    return i.not_supported("fmi3GetNumberOfVariableDependencies",
                           "the dependencies are in modelDescription.xml (providesPerElementDependencies = false)");
  });
}

fmi3Status fmi3GetVariableDependencies(fmi3Instance c, fmi3ValueReference dependent,
                                       size_t elementIndicesOfDependent[], fmi3ValueReference independents[],
                                       size_t elementIndicesOfIndependents[], fmi3DependencyKind dependencyKinds[],
                                       size_t nDependencies) {
  (void)dependent, (void)elementIndicesOfDependent, (void)independents, (void)elementIndicesOfIndependents,
      (void)dependencyKinds, (void)nDependencies;
  return call(c, "fmi3GetVariableDependencies", [&](Instance& i) {
    return i.not_supported("fmi3GetVariableDependencies",
                           "the dependencies are in modelDescription.xml (providesPerElementDependencies = false)");
  });
}

// ---------------------------------------------------------------- FMU states

fmi3Status fmi3GetFMUState(fmi3Instance c, fmi3FMUState* FMUState) {
  return call(c, "fmi3GetFMUState", [&](Instance& i) { return i.get_fmu_state(FMUState); });
}

fmi3Status fmi3SetFMUState(fmi3Instance c, fmi3FMUState FMUState) {
  return call(c, "fmi3SetFMUState", [&](Instance& i) { return i.set_fmu_state(FMUState); });
}

fmi3Status fmi3FreeFMUState(fmi3Instance c, fmi3FMUState* FMUState) {
  return call(c, "fmi3FreeFMUState", [&](Instance& i) { return i.free_fmu_state(FMUState); });
}

fmi3Status fmi3SerializedFMUStateSize(fmi3Instance c, fmi3FMUState FMUState, size_t* size) {
  return call(c, "fmi3SerializedFMUStateSize",
              [&](Instance& i) { return i.serialized_fmu_state_size(FMUState, size); });
}

fmi3Status fmi3SerializeFMUState(fmi3Instance c, fmi3FMUState FMUState, fmi3Byte serializedState[], size_t size) {
  return call(c, "fmi3SerializeFMUState",
              [&](Instance& i) { return i.serialize_fmu_state(FMUState, serializedState, size); });
}

fmi3Status fmi3DeserializeFMUState(fmi3Instance c, const fmi3Byte serializedState[], size_t size,
                                   fmi3FMUState* FMUState) {
  return call(c, "fmi3DeserializeFMUState",
              [&](Instance& i) { return i.deserialize_fmu_state(serializedState, size, FMUState); });
}

// ---------------------------------------------------------------- partial derivatives

fmi3Status fmi3GetDirectionalDerivative(fmi3Instance c, const fmi3ValueReference unknowns[], size_t nUnknowns,
                                        const fmi3ValueReference knowns[], size_t nKnowns, const fmi3Float64 seed[],
                                        size_t nSeed, fmi3Float64 sensitivity[], size_t nSensitivity) {
  return call(c, "fmi3GetDirectionalDerivative", [&](Instance& i) {
    return i.partial_derivative("fmi3GetDirectionalDerivative", false, unknowns, nUnknowns, knowns, nKnowns, seed,
                                nSeed, sensitivity, nSensitivity);
  });
}

fmi3Status fmi3GetAdjointDerivative(fmi3Instance c, const fmi3ValueReference unknowns[], size_t nUnknowns,
                                    const fmi3ValueReference knowns[], size_t nKnowns, const fmi3Float64 seed[],
                                    size_t nSeed, fmi3Float64 sensitivity[], size_t nSensitivity) {
  return call(c, "fmi3GetAdjointDerivative", [&](Instance& i) {
    return i.partial_derivative("fmi3GetAdjointDerivative", true, unknowns, nUnknowns, knowns, nKnowns, seed, nSeed,
                                sensitivity, nSensitivity);
  });
}

// ---------------------------------------------------------------- not provided

fmi3Status fmi3EnterConfigurationMode(fmi3Instance c) {
  return call(c, "fmi3EnterConfigurationMode", [&](Instance& i) {
    return i.not_supported("fmi3EnterConfigurationMode", "it has no structural parameters");
  });
}

fmi3Status fmi3ExitConfigurationMode(fmi3Instance c) {
  return call(c, "fmi3ExitConfigurationMode", [&](Instance& i) {
    return i.not_supported("fmi3ExitConfigurationMode", "it has no structural parameters");
  });
}

#define PKM_FMI3_NO_CLOCKS(Name, ...)                                                                  \
  fmi3Status fmi3##Name(fmi3Instance c, const fmi3ValueReference vr[], size_t nvr, __VA_ARGS__) {     \
    (void)vr, (void)nvr;                                                                               \
    return call(c, "fmi3" #Name, [&](Instance& i) { return i.not_supported("fmi3" #Name, "it has no clocks"); }); \
  }
PKM_FMI3_NO_CLOCKS(GetIntervalDecimal, fmi3Float64[], fmi3IntervalQualifier[])
PKM_FMI3_NO_CLOCKS(GetIntervalFraction, fmi3UInt64[], fmi3UInt64[], fmi3IntervalQualifier[])
PKM_FMI3_NO_CLOCKS(GetShiftDecimal, fmi3Float64[])
PKM_FMI3_NO_CLOCKS(GetShiftFraction, fmi3UInt64[], fmi3UInt64[])
PKM_FMI3_NO_CLOCKS(SetIntervalDecimal, const fmi3Float64[])
PKM_FMI3_NO_CLOCKS(SetIntervalFraction, const fmi3UInt64[], const fmi3UInt64[])
PKM_FMI3_NO_CLOCKS(SetShiftDecimal, const fmi3Float64[])
PKM_FMI3_NO_CLOCKS(SetShiftFraction, const fmi3UInt64[], const fmi3UInt64[])
#undef PKM_FMI3_NO_CLOCKS

fmi3Status fmi3EvaluateDiscreteStates(fmi3Instance c) {
  return call(c, "fmi3EvaluateDiscreteStates", [&](Instance& i) {
    return i.not_supported("fmi3EvaluateDiscreteStates", "providesEvaluateDiscreteStates = false");
  });
}

fmi3Status fmi3ActivateModelPartition(fmi3Instance c, fmi3ValueReference clockReference,
                                      fmi3Float64 activationTime) {
  (void)clockReference, (void)activationTime;
  return call(c, "fmi3ActivateModelPartition", [&](Instance& i) {
    return i.not_supported("fmi3ActivateModelPartition", "it offers no Scheduled Execution");
  });
}

// ---------------------------------------------------------------- Model Exchange

fmi3Status fmi3UpdateDiscreteStates(fmi3Instance c, fmi3Boolean* discreteStatesNeedUpdate,
                                    fmi3Boolean* terminateSimulation, fmi3Boolean* nominalsOfContinuousStatesChanged,
                                    fmi3Boolean* valuesOfContinuousStatesChanged, fmi3Boolean* nextEventTimeDefined,
                                    fmi3Float64* nextEventTime) {
  return call(c, "fmi3UpdateDiscreteStates", [&](Instance& i) {
    bool need = false, terminate = false, nominals = false, values = false, next_defined = false;
    const Status s = i.event_update(&need, &terminate, &nominals, &values, &next_defined, nextEventTime);
    if (discreteStatesNeedUpdate) *discreteStatesNeedUpdate = need;
    if (terminateSimulation) *terminateSimulation = terminate;
    if (nominalsOfContinuousStatesChanged) *nominalsOfContinuousStatesChanged = nominals;
    if (valuesOfContinuousStatesChanged) *valuesOfContinuousStatesChanged = values;
    if (nextEventTimeDefined) *nextEventTimeDefined = next_defined;
    return s;
  });
}

fmi3Status fmi3EnterContinuousTimeMode(fmi3Instance c) {
  return call(c, "fmi3EnterContinuousTimeMode", [&](Instance& i) { return i.enter_continuous_time_mode(); });
}

fmi3Status fmi3CompletedIntegratorStep(fmi3Instance c, fmi3Boolean noSetFMUStatePriorToCurrentPoint,
                                       fmi3Boolean* enterEventMode, fmi3Boolean* terminateSimulation) {
  (void)noSetFMUStatePriorToCurrentPoint;
  return call(c, "fmi3CompletedIntegratorStep", [&](Instance& i) {
    bool event = false, terminate = false;
    const Status s = i.completed_integrator_step(&event, &terminate);
    if (enterEventMode) *enterEventMode = event;
    if (terminateSimulation) *terminateSimulation = terminate;
    return s;
  });
}

fmi3Status fmi3SetTime(fmi3Instance c, fmi3Float64 time) {
  return call(c, "fmi3SetTime", [&](Instance& i) { return i.set_time(time); });
}

fmi3Status fmi3SetContinuousStates(fmi3Instance c, const fmi3Float64 continuousStates[], size_t nContinuousStates) {
  return call(c, "fmi3SetContinuousStates",
              [&](Instance& i) { return i.set_continuous_states(continuousStates, nContinuousStates); });
}

fmi3Status fmi3GetContinuousStateDerivatives(fmi3Instance c, fmi3Float64 derivatives[], size_t nContinuousStates) {
  return call(c, "fmi3GetContinuousStateDerivatives",
              [&](Instance& i) { return i.get_derivatives(derivatives, nContinuousStates); });
}

fmi3Status fmi3GetEventIndicators(fmi3Instance c, fmi3Float64 eventIndicators[], size_t nEventIndicators) {
  return call(c, "fmi3GetEventIndicators",
              [&](Instance& i) { return i.get_event_indicators(eventIndicators, nEventIndicators); });
}

fmi3Status fmi3GetContinuousStates(fmi3Instance c, fmi3Float64 continuousStates[], size_t nContinuousStates) {
  return call(c, "fmi3GetContinuousStates",
              [&](Instance& i) { return i.get_continuous_states(continuousStates, nContinuousStates); });
}

fmi3Status fmi3GetNominalsOfContinuousStates(fmi3Instance c, fmi3Float64 nominals[], size_t nContinuousStates) {
  return call(c, "fmi3GetNominalsOfContinuousStates",
              [&](Instance& i) { return i.get_nominals(nominals, nContinuousStates); });
}

fmi3Status fmi3GetNumberOfEventIndicators(fmi3Instance c, size_t* nEventIndicators) {
  return call(c, "fmi3GetNumberOfEventIndicators", [&](Instance& i) {
    return i.get_number_of("fmi3GetNumberOfEventIndicators", definition().n_event_indicators, nEventIndicators);
  });
}

fmi3Status fmi3GetNumberOfContinuousStates(fmi3Instance c, size_t* nContinuousStates) {
  return call(c, "fmi3GetNumberOfContinuousStates", [&](Instance& i) {
    return i.get_number_of("fmi3GetNumberOfContinuousStates", definition().n_states, nContinuousStates);
  });
}

// ---------------------------------------------------------------- Co-Simulation

fmi3Status fmi3EnterStepMode(fmi3Instance c) {
  return call(c, "fmi3EnterStepMode", [&](Instance& i) {
    return i.not_supported("fmi3EnterStepMode", "no event mode in Co-Simulation (hasEventMode = false): "
                                                "fmi3ExitInitializationMode enters Step Mode");
  });
}

fmi3Status fmi3GetOutputDerivatives(fmi3Instance c, const fmi3ValueReference vr[], size_t nvr,
                                    const fmi3Int32 orders[], fmi3Float64 values[], size_t nValues) {
  (void)vr, (void)nvr, (void)orders, (void)values, (void)nValues;
  return call(c, "fmi3GetOutputDerivatives",
              [&](Instance& i) { return i.get_real_output_derivatives("fmi3GetOutputDerivatives"); });
}

fmi3Status fmi3DoStep(fmi3Instance c, fmi3Float64 currentCommunicationPoint, fmi3Float64 communicationStepSize,
                      fmi3Boolean noSetFMUStatePriorToCurrentPoint, fmi3Boolean* eventHandlingNeeded,
                      fmi3Boolean* terminateSimulation, fmi3Boolean* earlyReturn, fmi3Float64* lastSuccessfulTime) {
  (void)noSetFMUStatePriorToCurrentPoint;
  return call(c, "fmi3DoStep", [&](Instance& i) {
    bool terminate = false;
    const Status s = i.do_step(currentCommunicationPoint, communicationStepSize, &terminate, lastSuccessfulTime);
    if (eventHandlingNeeded) *eventHandlingNeeded = false;
    if (earlyReturn) *earlyReturn = false;
    if (terminateSimulation) *terminateSimulation = terminate;
    return s;
  });
}

}  // extern "C"

// SPDX-License-Identifier: BSD-2-Clause
// The FMI 2.0 front end (Co-Simulation and Model Exchange) of one FMU: each
// exported function checks its handle and forwards to pkm_fmi::Instance.
// Compiled once per FMU, with PKM_FMI_DEFINITION naming the function that
// returns its ModelDefinition. No exception crosses the C ABI.
#include <cstdarg>
#include <cstring>
#include <exception>
#include <string>

#include "fmi2Functions.h"
#include "fmi/instance.hpp"

#ifndef PKM_FMI_DEFINITION
#error "PKM_FMI_DEFINITION must name the model's definition, a function in namespace pkm_fmi"
#endif

namespace pkm_fmi {
const ModelDefinition& PKM_FMI_DEFINITION();
}

// In-process builds of several FMUs into one program (the fuzzer): every
// function is named <prefix>fmi2Xxx. fmi2Functions.h fixes fmi2FullName to
// no prefix; its names expand lazily, so redefining it here renames them.
#ifdef PKM_FMI_FUNCTION_PREFIX
#undef fmi2FullName
#define PKM_FMI2_PASTE2(a, b) a##b
#define PKM_FMI2_PASTE(a, b) PKM_FMI2_PASTE2(a, b)
#define fmi2FullName(name) PKM_FMI2_PASTE(PKM_FMI_FUNCTION_PREFIX, name)
#endif

using pkm_fmi::Instance;
using pkm_fmi::Status;

namespace {

const pkm_fmi::ModelDefinition& definition() { return pkm_fmi::PKM_FMI_DEFINITION(); }

fmi2Status to_fmi2(Status s) { return static_cast<fmi2Status>(static_cast<int>(s)); }

// A C importer may pass any int where FMI 2.0 declares an enum (fmi2Type,
// fmi2StatusKind); such arguments are read as int, never loaded as enums.
template <class E>
int as_int(const E& e) {
  static_assert(sizeof(E) == sizeof(int), "FMI 2.0 enums are int-sized");
  int v;
  std::memcpy(&v, &e, sizeof v);
  return v;
}

// fmi2CallbackLogger treats the message as a printf format: '%' is escaped
// (on the stack when it fits: logging inside a step allocates nothing).
void emit(void* callback, void* env, const char* instance, Status status, const char* category,
          const char* message) {
  char small[2048];
  std::string large;
  std::size_t n = 0;
  for (const char* p = message; *p; ++p) n += (*p == '%') ? 2 : 1;
  char* out = small;
  if (n >= sizeof small) {
    large.resize(n + 1);
    out = &large[0];
  }
  char* q = out;
  for (const char* p = message; *p; ++p) {
    *q++ = *p;
    if (*p == '%') *q++ = '%';
  }
  *q = '\0';
  reinterpret_cast<fmi2CallbackLogger>(callback)(env, instance, static_cast<fmi2Status>(static_cast<int>(status)),
                                                 category, out);
}

template <class Body>
fmi2Status call(fmi2Component c, const char* function, Body&& body) {
  Instance* inst = Instance::from(c, definition(), 2);
  if (!inst) return fmi2Error;  // no instance of this FMU: nobody to log to
  const Instance::Busy busy(*inst);
  if (!busy) return to_fmi2(inst->concurrent_call(function));
  try {
    return to_fmi2(body(*inst));
  } catch (const std::exception& e) {
    return to_fmi2(inst->internal_error(function, e.what()));
  } catch (...) {
    return to_fmi2(inst->internal_error(function, "unknown exception"));
  }
}

}  // namespace

extern "C" {

const char* fmi2GetTypesPlatform(void) { return fmi2TypesPlatform; }

const char* fmi2GetVersion(void) { return fmi2Version; }

fmi2Status fmi2SetDebugLogging(fmi2Component c, fmi2Boolean loggingOn, size_t nCategories,
                               const fmi2String categories[]) {
  return call(c, "fmi2SetDebugLogging",
              [&](Instance& i) { return i.set_debug_logging(loggingOn != fmi2False, nCategories, categories); });
}

fmi2Component fmi2Instantiate(fmi2String instanceName, fmi2Type fmuType, fmi2String fmuGUID,
                              fmi2String fmuResourceLocation, const fmi2CallbackFunctions* functions,
                              fmi2Boolean visible, fmi2Boolean loggingOn) {
  (void)fmuResourceLocation;  // no resources
  (void)visible;              // no user interface
  try {
    fmi2CallbackLogger logger = functions ? functions->logger : nullptr;
    pkm_fmi::Logger log(logger ? &emit : nullptr, reinterpret_cast<void*>(logger),
                        functions ? functions->componentEnvironment : nullptr, instanceName ? instanceName : "",
                        loggingOn != fmi2False);
    if (!instanceName) {
      log.error("fmi2Instantiate: instanceName is NULL");
      return nullptr;
    }
    const int type = as_int(fmuType);
    if (type != fmi2CoSimulation && type != fmi2ModelExchange) {
      log.error("fmi2Instantiate: fmuType = %d is neither fmi2ModelExchange (0) nor fmi2CoSimulation (1)", type);
      return nullptr;
    }
    return Instance::create(definition(), 2,
                            type == fmi2CoSimulation ? pkm_fmi::Interface::CoSimulation
                                                     : pkm_fmi::Interface::ModelExchange,
                            fmuGUID, std::move(log));
  } catch (...) {
    // Out of memory (nothing else throws here): said through the callback
    // directly, the Logger may be what could not be built.
    if (functions && functions->logger)
      functions->logger(functions->componentEnvironment, instanceName ? instanceName : "", fmi2Error,
                        "logStatusError", "fmi2Instantiate: out of memory; no instance created");
    return nullptr;
  }
}

void fmi2FreeInstance(fmi2Component c) { Instance::free(c, definition(), 2, "fmi2FreeInstance"); }

fmi2Status fmi2SetupExperiment(fmi2Component c, fmi2Boolean toleranceDefined, fmi2Real tolerance,
                               fmi2Real startTime, fmi2Boolean stopTimeDefined, fmi2Real stopTime) {
  return call(c, "fmi2SetupExperiment", [&](Instance& i) {
    return i.setup_experiment(toleranceDefined != fmi2False, tolerance, startTime, stopTimeDefined != fmi2False,
                              stopTime);
  });
}

fmi2Status fmi2EnterInitializationMode(fmi2Component c) {
  return call(c, "fmi2EnterInitializationMode", [&](Instance& i) { return i.enter_initialization_mode(); });
}

fmi2Status fmi2ExitInitializationMode(fmi2Component c) {
  return call(c, "fmi2ExitInitializationMode", [&](Instance& i) { return i.exit_initialization_mode(); });
}

fmi2Status fmi2Terminate(fmi2Component c) {
  return call(c, "fmi2Terminate", [&](Instance& i) { return i.terminate(); });
}

fmi2Status fmi2Reset(fmi2Component c) {
  return call(c, "fmi2Reset", [&](Instance& i) { return i.reset(); });
}

fmi2Status fmi2GetReal(fmi2Component c, const fmi2ValueReference vr[], size_t nvr, fmi2Real value[]) {
  return call(c, "fmi2GetReal", [&](Instance& i) { return i.get_real(vr, nvr, value); });
}

fmi2Status fmi2GetInteger(fmi2Component c, const fmi2ValueReference vr[], size_t nvr, fmi2Integer value[]) {
  static_assert(sizeof(fmi2Integer) == sizeof(std::int32_t), "fmi2Integer is 32 bits");
  return call(c, "fmi2GetInteger",
              [&](Instance& i) { return i.get_integer(vr, nvr, reinterpret_cast<std::int32_t*>(value)); });
}

fmi2Status fmi2GetBoolean(fmi2Component c, const fmi2ValueReference vr[], size_t nvr, fmi2Boolean value[]) {
  static_assert(sizeof(fmi2Boolean) == sizeof(int), "fmi2Boolean is an int");
  return call(c, "fmi2GetBoolean", [&](Instance& i) { return i.get_boolean(vr, nvr, value); });
}

fmi2Status fmi2GetString(fmi2Component c, const fmi2ValueReference vr[], size_t nvr, fmi2String value[]) {
  (void)value;
  return call(c, "fmi2GetString",
              [&](Instance& i) { return i.no_variables_of_type("fmi2GetString", "String", vr, nvr, false); });
}

fmi2Status fmi2SetReal(fmi2Component c, const fmi2ValueReference vr[], size_t nvr, const fmi2Real value[]) {
  return call(c, "fmi2SetReal", [&](Instance& i) { return i.set_real(vr, nvr, value); });
}

fmi2Status fmi2SetInteger(fmi2Component c, const fmi2ValueReference vr[], size_t nvr, const fmi2Integer value[]) {
  return call(c, "fmi2SetInteger",
              [&](Instance& i) { return i.set_integer(vr, nvr, reinterpret_cast<const std::int32_t*>(value)); });
}

fmi2Status fmi2SetBoolean(fmi2Component c, const fmi2ValueReference vr[], size_t nvr, const fmi2Boolean value[]) {
  return call(c, "fmi2SetBoolean", [&](Instance& i) { return i.set_boolean(vr, nvr, value); });
}

fmi2Status fmi2SetString(fmi2Component c, const fmi2ValueReference vr[], size_t nvr, const fmi2String value[]) {
  (void)value;
  return call(c, "fmi2SetString",
              [&](Instance& i) { return i.no_variables_of_type("fmi2SetString", "String", vr, nvr, true); });
}

fmi2Status fmi2GetFMUstate(fmi2Component c, fmi2FMUstate* FMUstate) {
  return call(c, "fmi2GetFMUstate", [&](Instance& i) { return i.get_fmu_state(FMUstate); });
}

fmi2Status fmi2SetFMUstate(fmi2Component c, fmi2FMUstate FMUstate) {
  return call(c, "fmi2SetFMUstate", [&](Instance& i) { return i.set_fmu_state(FMUstate); });
}

fmi2Status fmi2FreeFMUstate(fmi2Component c, fmi2FMUstate* FMUstate) {
  return call(c, "fmi2FreeFMUstate", [&](Instance& i) { return i.free_fmu_state(FMUstate); });
}

fmi2Status fmi2SerializedFMUstateSize(fmi2Component c, fmi2FMUstate FMUstate, size_t* size) {
  return call(c, "fmi2SerializedFMUstateSize",
              [&](Instance& i) { return i.serialized_fmu_state_size(FMUstate, size); });
}

fmi2Status fmi2SerializeFMUstate(fmi2Component c, fmi2FMUstate FMUstate, fmi2Byte serializedState[], size_t size) {
  return call(c, "fmi2SerializeFMUstate", [&](Instance& i) {
    return i.serialize_fmu_state(FMUstate, reinterpret_cast<unsigned char*>(serializedState), size);
  });
}

fmi2Status fmi2DeSerializeFMUstate(fmi2Component c, const fmi2Byte serializedState[], size_t size,
                                   fmi2FMUstate* FMUstate) {
  return call(c, "fmi2DeSerializeFMUstate", [&](Instance& i) {
    return i.deserialize_fmu_state(reinterpret_cast<const unsigned char*>(serializedState), size, FMUstate);
  });
}

fmi2Status fmi2GetDirectionalDerivative(fmi2Component c, const fmi2ValueReference vUnknown_ref[], size_t nUnknown,
                                        const fmi2ValueReference vKnown_ref[], size_t nKnown,
                                        const fmi2Real dvKnown[], fmi2Real dvUnknown[]) {
  return call(c, "fmi2GetDirectionalDerivative", [&](Instance& i) {
    return i.partial_derivative("fmi2GetDirectionalDerivative", false, vUnknown_ref, nUnknown, vKnown_ref, nKnown,
                                dvKnown, nKnown, dvUnknown, nUnknown);
  });
}

// ---------------------------------------------------------------- Co-Simulation

fmi2Status fmi2SetRealInputDerivatives(fmi2Component c, const fmi2ValueReference vr[], size_t nvr,
                                       const fmi2Integer order[], const fmi2Real value[]) {
  return call(c, "fmi2SetRealInputDerivatives", [&](Instance& i) {
    return i.set_real_input_derivatives(vr, nvr, reinterpret_cast<const std::int32_t*>(order), value);
  });
}

fmi2Status fmi2GetRealOutputDerivatives(fmi2Component c, const fmi2ValueReference vr[], size_t nvr,
                                        const fmi2Integer order[], fmi2Real value[]) {
  (void)vr, (void)nvr, (void)order, (void)value;
  return call(c, "fmi2GetRealOutputDerivatives",
              [&](Instance& i) { return i.get_real_output_derivatives("fmi2GetRealOutputDerivatives"); });
}

fmi2Status fmi2DoStep(fmi2Component c, fmi2Real currentCommunicationPoint, fmi2Real communicationStepSize,
                      fmi2Boolean noSetFMUStatePriorToCurrentPoint) {
  (void)noSetFMUStatePriorToCurrentPoint;
  return call(c, "fmi2DoStep", [&](Instance& i) {
    return i.do_step(currentCommunicationPoint, communicationStepSize, nullptr, nullptr);
  });
}

fmi2Status fmi2CancelStep(fmi2Component c) {
  return call(c, "fmi2CancelStep", [&](Instance& i) {
    return i.not_supported("fmi2CancelStep", "fmi2DoStep is synchronous and never pending");
  });
}

fmi2Status fmi2GetStatus(fmi2Component c, const fmi2StatusKind s, fmi2Status* value) {
  return call(c, "fmi2GetStatus", [&](Instance& i) {
    bool unused;
    const Status st = i.terminated(&unused);  // the state check
    if (st != Status::OK) return st;
    if (!value) return i.not_supported("fmi2GetStatus", "value is NULL");
    if (as_int(s) != fmi2DoStepStatus) return Status::Discard;
    *value = fmi2OK;  // fmi2DoStep is synchronous: never pending
    return Status::OK;
  });
}

fmi2Status fmi2GetRealStatus(fmi2Component c, const fmi2StatusKind s, fmi2Real* value) {
  return call(c, "fmi2GetRealStatus", [&](Instance& i) {
    if (as_int(s) != fmi2LastSuccessfulTime) return i.not_pending("fmi2GetRealStatus");
    return i.last_successful_time(value);
  });
}

fmi2Status fmi2GetIntegerStatus(fmi2Component c, const fmi2StatusKind s, fmi2Integer* value) {
  (void)s, (void)value;  // no integer status is defined for FMI 2.0 Co-Simulation
  return call(c, "fmi2GetIntegerStatus", [&](Instance& i) { return i.not_pending("fmi2GetIntegerStatus"); });
}

fmi2Status fmi2GetBooleanStatus(fmi2Component c, const fmi2StatusKind s, fmi2Boolean* value) {
  return call(c, "fmi2GetBooleanStatus", [&](Instance& i) {
    if (as_int(s) != fmi2Terminated) return i.not_pending("fmi2GetBooleanStatus");
    bool t = false;
    const Status st = i.terminated(value ? &t : nullptr);
    if (st == Status::OK) *value = t ? fmi2True : fmi2False;
    return st;
  });
}

fmi2Status fmi2GetStringStatus(fmi2Component c, const fmi2StatusKind s, fmi2String* value) {
  (void)s, (void)value;  // fmi2PendingStatus: never pending
  return call(c, "fmi2GetStringStatus", [&](Instance& i) { return i.not_pending("fmi2GetStringStatus"); });
}

// ---------------------------------------------------------------- Model Exchange

fmi2Status fmi2EnterEventMode(fmi2Component c) {
  return call(c, "fmi2EnterEventMode", [&](Instance& i) { return i.enter_event_mode(); });
}

fmi2Status fmi2NewDiscreteStates(fmi2Component c, fmi2EventInfo* info) {
  return call(c, "fmi2NewDiscreteStates", [&](Instance& i) {
    if (!info) return i.not_supported("fmi2NewDiscreteStates", "fmi2EventInfo is NULL");
    bool need = false, terminate = false, nominals = false, values = false, next_defined = false;
    double next = 0.0;
    const Status s = i.event_update(&need, &terminate, &nominals, &values, &next_defined, &next);
    if (pkm_fmi::succeeded(s)) {
      info->newDiscreteStatesNeeded = need ? fmi2True : fmi2False;
      info->terminateSimulation = terminate ? fmi2True : fmi2False;
      info->nominalsOfContinuousStatesChanged = nominals ? fmi2True : fmi2False;
      info->valuesOfContinuousStatesChanged = values ? fmi2True : fmi2False;
      info->nextEventTimeDefined = next_defined ? fmi2True : fmi2False;
      info->nextEventTime = next;
    }
    return s;
  });
}

fmi2Status fmi2EnterContinuousTimeMode(fmi2Component c) {
  return call(c, "fmi2EnterContinuousTimeMode", [&](Instance& i) { return i.enter_continuous_time_mode(); });
}

fmi2Status fmi2CompletedIntegratorStep(fmi2Component c, fmi2Boolean noSetFMUStatePriorToCurrentPoint,
                                       fmi2Boolean* enterEventMode, fmi2Boolean* terminateSimulation) {
  (void)noSetFMUStatePriorToCurrentPoint;
  return call(c, "fmi2CompletedIntegratorStep", [&](Instance& i) {
    bool event = false, terminate = false;
    const Status s = i.completed_integrator_step(&event, &terminate);
    if (enterEventMode) *enterEventMode = event ? fmi2True : fmi2False;
    if (terminateSimulation) *terminateSimulation = terminate ? fmi2True : fmi2False;
    return s;
  });
}

fmi2Status fmi2SetTime(fmi2Component c, fmi2Real time) {
  return call(c, "fmi2SetTime", [&](Instance& i) { return i.set_time(time); });
}

fmi2Status fmi2SetContinuousStates(fmi2Component c, const fmi2Real x[], size_t nx) {
  return call(c, "fmi2SetContinuousStates", [&](Instance& i) { return i.set_continuous_states(x, nx); });
}

fmi2Status fmi2GetDerivatives(fmi2Component c, fmi2Real derivatives[], size_t nx) {
  return call(c, "fmi2GetDerivatives", [&](Instance& i) { return i.get_derivatives(derivatives, nx); });
}

fmi2Status fmi2GetEventIndicators(fmi2Component c, fmi2Real eventIndicators[], size_t ni) {
  return call(c, "fmi2GetEventIndicators", [&](Instance& i) { return i.get_event_indicators(eventIndicators, ni); });
}

fmi2Status fmi2GetContinuousStates(fmi2Component c, fmi2Real x[], size_t nx) {
  return call(c, "fmi2GetContinuousStates", [&](Instance& i) { return i.get_continuous_states(x, nx); });
}

fmi2Status fmi2GetNominalsOfContinuousStates(fmi2Component c, fmi2Real x_nominal[], size_t nx) {
  return call(c, "fmi2GetNominalsOfContinuousStates", [&](Instance& i) { return i.get_nominals(x_nominal, nx); });
}

}  // extern "C"

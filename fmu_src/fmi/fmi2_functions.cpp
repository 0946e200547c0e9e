// The exported FMI 2.0 functions (common and co-simulation) of one FMU: each
// forwards to pkm_fmi::Instance. Compiled once per FMU, with
// PKM_FMI_DEFINITION naming the function that returns its ModelDefinition.
// No exception crosses the C ABI.
#include <exception>

#include "fmi2_cs.hpp"
#include "models.hpp"

#ifndef PKM_FMI_DEFINITION
#error "PKM_FMI_DEFINITION must name the model's definition, e.g. pkm_fmi::pkm4puu_definition"
#endif

using pkm_fmi::Instance;

namespace {

template <class Body>
fmi2Status call(fmi2Component c, const char* function, Body&& body) {
  Instance* inst = Instance::from(c);
  if (!inst) return fmi2Error;  // no instance: nobody to log to
  try {
    return body(*inst);
  } catch (const std::exception& e) {
    return inst->internal_error(function, e.what());
  } catch (...) {
    return inst->internal_error(function, "unknown exception");
  }
}

}  // namespace

extern "C" {

const char* fmi2GetTypesPlatform(void) { return fmi2TypesPlatform; }

const char* fmi2GetVersion(void) { return fmi2Version; }

fmi2Status fmi2SetDebugLogging(fmi2Component c, fmi2Boolean loggingOn, size_t nCategories,
                               const fmi2String categories[]) {
  return call(c, "fmi2SetDebugLogging",
              [&](Instance& i) { return i.set_debug_logging(loggingOn, nCategories, categories); });
}

fmi2Component fmi2Instantiate(fmi2String instanceName, fmi2Type fmuType, fmi2String fmuGUID,
                              fmi2String fmuResourceLocation, const fmi2CallbackFunctions* functions,
                              fmi2Boolean visible, fmi2Boolean loggingOn) {
  try {
    return Instance::instantiate(PKM_FMI_DEFINITION(), instanceName, fmuType, fmuGUID, fmuResourceLocation,
                                 functions, visible, loggingOn);
  } catch (...) {
    return nullptr;
  }
}

void fmi2FreeInstance(fmi2Component c) { delete Instance::from(c); }

fmi2Status fmi2SetupExperiment(fmi2Component c, fmi2Boolean toleranceDefined, fmi2Real tolerance,
                               fmi2Real startTime, fmi2Boolean stopTimeDefined, fmi2Real stopTime) {
  return call(c, "fmi2SetupExperiment", [&](Instance& i) {
    return i.setup_experiment(toleranceDefined, tolerance, startTime, stopTimeDefined, stopTime);
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
  return call(c, "fmi2GetInteger", [&](Instance& i) { return i.get_integer(vr, nvr, value); });
}

fmi2Status fmi2GetBoolean(fmi2Component c, const fmi2ValueReference vr[], size_t nvr, fmi2Boolean value[]) {
  return call(c, "fmi2GetBoolean", [&](Instance& i) { return i.get_boolean(vr, nvr, value); });
}

fmi2Status fmi2GetString(fmi2Component c, const fmi2ValueReference vr[], size_t nvr, fmi2String value[]) {
  return call(c, "fmi2GetString", [&](Instance& i) { return i.get_string(vr, nvr, value); });
}

fmi2Status fmi2SetReal(fmi2Component c, const fmi2ValueReference vr[], size_t nvr, const fmi2Real value[]) {
  return call(c, "fmi2SetReal", [&](Instance& i) { return i.set_real(vr, nvr, value); });
}

fmi2Status fmi2SetInteger(fmi2Component c, const fmi2ValueReference vr[], size_t nvr, const fmi2Integer value[]) {
  return call(c, "fmi2SetInteger", [&](Instance& i) { return i.set_integer(vr, nvr, value); });
}

fmi2Status fmi2SetBoolean(fmi2Component c, const fmi2ValueReference vr[], size_t nvr, const fmi2Boolean value[]) {
  return call(c, "fmi2SetBoolean", [&](Instance& i) { return i.set_boolean(vr, nvr, value); });
}

fmi2Status fmi2SetString(fmi2Component c, const fmi2ValueReference vr[], size_t nvr, const fmi2String value[]) {
  return call(c, "fmi2SetString", [&](Instance& i) { return i.set_string(vr, nvr, value); });
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
  return call(c, "fmi2SerializeFMUstate",
              [&](Instance& i) { return i.serialize_fmu_state(FMUstate, serializedState, size); });
}

fmi2Status fmi2DeSerializeFMUstate(fmi2Component c, const fmi2Byte serializedState[], size_t size,
                                   fmi2FMUstate* FMUstate) {
  return call(c, "fmi2DeSerializeFMUstate",
              [&](Instance& i) { return i.deserialize_fmu_state(serializedState, size, FMUstate); });
}

fmi2Status fmi2GetDirectionalDerivative(fmi2Component c, const fmi2ValueReference vUnknown_ref[], size_t nUnknown,
                                        const fmi2ValueReference vKnown_ref[], size_t nKnown,
                                        const fmi2Real dvKnown[], fmi2Real dvUnknown[]) {
  return call(c, "fmi2GetDirectionalDerivative", [&](Instance& i) {
    return i.get_directional_derivative(vUnknown_ref, nUnknown, vKnown_ref, nKnown, dvKnown, dvUnknown);
  });
}

fmi2Status fmi2SetRealInputDerivatives(fmi2Component c, const fmi2ValueReference vr[], size_t nvr,
                                       const fmi2Integer order[], const fmi2Real value[]) {
  return call(c, "fmi2SetRealInputDerivatives",
              [&](Instance& i) { return i.set_real_input_derivatives(vr, nvr, order, value); });
}

fmi2Status fmi2GetRealOutputDerivatives(fmi2Component c, const fmi2ValueReference vr[], size_t nvr,
                                        const fmi2Integer order[], fmi2Real value[]) {
  return call(c, "fmi2GetRealOutputDerivatives",
              [&](Instance& i) { return i.get_real_output_derivatives(vr, nvr, order, value); });
}

fmi2Status fmi2DoStep(fmi2Component c, fmi2Real currentCommunicationPoint, fmi2Real communicationStepSize,
                      fmi2Boolean noSetFMUStatePriorToCurrentPoint) {
  return call(c, "fmi2DoStep", [&](Instance& i) {
    return i.do_step(currentCommunicationPoint, communicationStepSize, noSetFMUStatePriorToCurrentPoint);
  });
}

fmi2Status fmi2CancelStep(fmi2Component c) {
  return call(c, "fmi2CancelStep", [&](Instance& i) { return i.cancel_step(); });
}

fmi2Status fmi2GetStatus(fmi2Component c, const fmi2StatusKind s, fmi2Status* value) {
  return call(c, "fmi2GetStatus", [&](Instance& i) { return i.get_status(s, value); });
}

fmi2Status fmi2GetRealStatus(fmi2Component c, const fmi2StatusKind s, fmi2Real* value) {
  return call(c, "fmi2GetRealStatus", [&](Instance& i) { return i.get_real_status(s, value); });
}

fmi2Status fmi2GetIntegerStatus(fmi2Component c, const fmi2StatusKind s, fmi2Integer* value) {
  return call(c, "fmi2GetIntegerStatus", [&](Instance& i) { return i.get_integer_status(s, value); });
}

fmi2Status fmi2GetBooleanStatus(fmi2Component c, const fmi2StatusKind s, fmi2Boolean* value) {
  return call(c, "fmi2GetBooleanStatus", [&](Instance& i) { return i.get_boolean_status(s, value); });
}

fmi2Status fmi2GetStringStatus(fmi2Component c, const fmi2StatusKind s, fmi2String* value) {
  return call(c, "fmi2GetStringStatus", [&](Instance& i) { return i.get_string_status(s, value); });
}

}  // extern "C"

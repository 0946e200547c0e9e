// The exported FMI 2.0 functions (common and co-simulation) of one FMU: each
// forwards to pkm_fmi::Instance. Compiled once per FMU, with
// PKM_FMI_DEFINITION naming the function that returns its ModelDefinition.
// No exception crosses the C ABI.
#include <cstring>
#include <exception>

#include "fmi2_cs.hpp"
#include "models.hpp"

#ifndef PKM_FMI_DEFINITION
#error "PKM_FMI_DEFINITION must name the model's definition, e.g. pkm_fmi::pkm4puu_definition"
#endif

// In-process builds of both FMUs into one program (the fuzzer, fuzz/): with
// PKM_FMI_FUNCTION_PREFIX defined, every function below is named
// <prefix>fmi2Xxx (FMI 2.0's FMI2_FUNCTION_PREFIX convention, which the
// fmi2Functions.h in use does not implement). The FMU binaries never define it.
#ifdef PKM_FMI_FUNCTION_PREFIX
#define PKM_FMI_PASTE2(a, b) a##b
#define PKM_FMI_PASTE(a, b) PKM_FMI_PASTE2(a, b)
#define PKM_FMI_RENAME(name) PKM_FMI_PASTE(PKM_FMI_FUNCTION_PREFIX, name)
#undef fmi2GetTypesPlatform
#define fmi2GetTypesPlatform PKM_FMI_RENAME(fmi2GetTypesPlatform)
#undef fmi2GetVersion
#define fmi2GetVersion PKM_FMI_RENAME(fmi2GetVersion)
#undef fmi2SetDebugLogging
#define fmi2SetDebugLogging PKM_FMI_RENAME(fmi2SetDebugLogging)
#undef fmi2Instantiate
#define fmi2Instantiate PKM_FMI_RENAME(fmi2Instantiate)
#undef fmi2FreeInstance
#define fmi2FreeInstance PKM_FMI_RENAME(fmi2FreeInstance)
#undef fmi2SetupExperiment
#define fmi2SetupExperiment PKM_FMI_RENAME(fmi2SetupExperiment)
#undef fmi2EnterInitializationMode
#define fmi2EnterInitializationMode PKM_FMI_RENAME(fmi2EnterInitializationMode)
#undef fmi2ExitInitializationMode
#define fmi2ExitInitializationMode PKM_FMI_RENAME(fmi2ExitInitializationMode)
#undef fmi2Terminate
#define fmi2Terminate PKM_FMI_RENAME(fmi2Terminate)
#undef fmi2Reset
#define fmi2Reset PKM_FMI_RENAME(fmi2Reset)
#undef fmi2GetReal
#define fmi2GetReal PKM_FMI_RENAME(fmi2GetReal)
#undef fmi2GetInteger
#define fmi2GetInteger PKM_FMI_RENAME(fmi2GetInteger)
#undef fmi2GetBoolean
#define fmi2GetBoolean PKM_FMI_RENAME(fmi2GetBoolean)
#undef fmi2GetString
#define fmi2GetString PKM_FMI_RENAME(fmi2GetString)
#undef fmi2SetReal
#define fmi2SetReal PKM_FMI_RENAME(fmi2SetReal)
#undef fmi2SetInteger
#define fmi2SetInteger PKM_FMI_RENAME(fmi2SetInteger)
#undef fmi2SetBoolean
#define fmi2SetBoolean PKM_FMI_RENAME(fmi2SetBoolean)
#undef fmi2SetString
#define fmi2SetString PKM_FMI_RENAME(fmi2SetString)
#undef fmi2GetFMUstate
#define fmi2GetFMUstate PKM_FMI_RENAME(fmi2GetFMUstate)
#undef fmi2SetFMUstate
#define fmi2SetFMUstate PKM_FMI_RENAME(fmi2SetFMUstate)
#undef fmi2FreeFMUstate
#define fmi2FreeFMUstate PKM_FMI_RENAME(fmi2FreeFMUstate)
#undef fmi2SerializedFMUstateSize
#define fmi2SerializedFMUstateSize PKM_FMI_RENAME(fmi2SerializedFMUstateSize)
#undef fmi2SerializeFMUstate
#define fmi2SerializeFMUstate PKM_FMI_RENAME(fmi2SerializeFMUstate)
#undef fmi2DeSerializeFMUstate
#define fmi2DeSerializeFMUstate PKM_FMI_RENAME(fmi2DeSerializeFMUstate)
#undef fmi2GetDirectionalDerivative
#define fmi2GetDirectionalDerivative PKM_FMI_RENAME(fmi2GetDirectionalDerivative)
#undef fmi2SetRealInputDerivatives
#define fmi2SetRealInputDerivatives PKM_FMI_RENAME(fmi2SetRealInputDerivatives)
#undef fmi2GetRealOutputDerivatives
#define fmi2GetRealOutputDerivatives PKM_FMI_RENAME(fmi2GetRealOutputDerivatives)
#undef fmi2DoStep
#define fmi2DoStep PKM_FMI_RENAME(fmi2DoStep)
#undef fmi2CancelStep
#define fmi2CancelStep PKM_FMI_RENAME(fmi2CancelStep)
#undef fmi2GetStatus
#define fmi2GetStatus PKM_FMI_RENAME(fmi2GetStatus)
#undef fmi2GetRealStatus
#define fmi2GetRealStatus PKM_FMI_RENAME(fmi2GetRealStatus)
#undef fmi2GetIntegerStatus
#define fmi2GetIntegerStatus PKM_FMI_RENAME(fmi2GetIntegerStatus)
#undef fmi2GetBooleanStatus
#define fmi2GetBooleanStatus PKM_FMI_RENAME(fmi2GetBooleanStatus)
#undef fmi2GetStringStatus
#define fmi2GetStringStatus PKM_FMI_RENAME(fmi2GetStringStatus)
#endif

using pkm_fmi::Instance;

#if defined(PKM_FMI_FREE_EH_POOL) && defined(__GLIBCXX__)
namespace __gnu_cxx {
void __freeres();  // libstdc++ (eh_alloc.cc): frees the exception-handling emergency pool
}
namespace {
// The FMU binary links libstdc++ statically (-static-libstdc++), and with it
// a private exception-handling emergency pool (72 KiB, malloc'ed when the
// binary is loaded). Nothing would free it: after dlclose it is lost, once
// per load (valgrind: "definitely lost"). Free it when the binary unloads
// (dlclose, or process exit); no code of this binary runs after that.
__attribute__((destructor)) void free_emergency_pool() { __gnu_cxx::__freeres(); }
}  // namespace
#endif

namespace {

// A C importer may pass any int where FMI 2.0 declares an enum (fmi2Type,
// fmi2StatusKind); a C++ enum object must not hold a value outside its
// enumerators' range, so such arguments are read as int, never loaded as enums.
template <class E>
int as_int(const E& e) {
  static_assert(sizeof(E) == sizeof(int), "FMI 2.0 enums are int-sized");
  int v;
  std::memcpy(&v, &e, sizeof v);
  return v;
}

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
    return Instance::instantiate(PKM_FMI_DEFINITION(), instanceName, as_int(fmuType), fmuGUID, fmuResourceLocation,
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
  return call(c, "fmi2GetStatus", [&](Instance& i) { return i.get_status(as_int(s), value); });
}

fmi2Status fmi2GetRealStatus(fmi2Component c, const fmi2StatusKind s, fmi2Real* value) {
  return call(c, "fmi2GetRealStatus", [&](Instance& i) { return i.get_real_status(as_int(s), value); });
}

fmi2Status fmi2GetIntegerStatus(fmi2Component c, const fmi2StatusKind s, fmi2Integer* value) {
  return call(c, "fmi2GetIntegerStatus", [&](Instance& i) { return i.get_integer_status(as_int(s), value); });
}

fmi2Status fmi2GetBooleanStatus(fmi2Component c, const fmi2StatusKind s, fmi2Boolean* value) {
  return call(c, "fmi2GetBooleanStatus", [&](Instance& i) { return i.get_boolean_status(as_int(s), value); });
}

fmi2Status fmi2GetStringStatus(fmi2Component c, const fmi2StatusKind s, fmi2String* value) {
  return call(c, "fmi2GetStringStatus", [&](Instance& i) { return i.get_string_status(as_int(s), value); });
}

}  // extern "C"

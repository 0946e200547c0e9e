// SPDX-License-Identifier: BSD-2-Clause
// The FMI standards' rules of which function may be called in which state,
// transcribed by hand from the standards' own text, one row per function
// with its clause, and kept apart from the FMU's table
// (src/fmi/state_machine.hpp) so that tests/fmi/state_table.cpp can compare
// that table, and the FMU's answers, with them.
//
// FMI 2.0.4 (tag v2.0.4 of github.com/modelica/fmi-standard): the tables of
// section 3.2.3 (Model Exchange) and section 4.2.4 (Co-Simulation), column by
// column. FMI 3.0.2 (tag v3.0.2) has no such table: each state lists its
// "Allowed Function Calls" (section 2.3.1 super state FMU State Settable,
// 2.3.2 Instantiated, 2.3.3 Initialization Mode, 2.3.4 super state
// Initialized, 2.3.5 Event Mode, 2.3.8 Terminated; 3.2.1 Continuous-Time
// Mode; 4.2.1 Step Mode); a row here collects where a function is listed.
//
// A cell is one character: 'x' allowed, '.' not allowed, otherwise allowed
// only under the condition of that name (kConditions), as the standard says.
#pragma once

namespace pkm_test::standard {

struct Row {
  const char* function;  // the C function ("fmi3Get{VariableType}": every getter)
  const char* cells;     // one character per column of its table
  const char* clause;    // where the standard says so
};

/// A condition of a cell. `state_allows`: the state allows the call, for
/// the variables (or with the caveat) the condition names; else a property
/// of the FMU or of its instantiation decides, per FMU.
struct Condition {
  char id;
  bool state_allows;
  const char* text;  // the standard's words
};
/// FMI 2.0's conditions, in the tables they belong to ("2.0": both; 8 is
/// another condition in each).
struct Condition2 {
  const char* table;  // "2.0 ME", "2.0 CS", "2.0"
  Condition condition;
};

// clang-format off
inline constexpr Condition2 kFmi2Conditions[] = {
  // FMI 2.0.4 below the tables of sections 3.2.3 (Model Exchange) and 4.2.4
  // (Co-Simulation): the same words where both tables have a number.
  {"2.0", {'1', true, "for a variable with variability != \"constant\" that has initial = \"exact\" or \"approx\""}},
  {"2.0", {'2', true, "for a variable with causality = \"output\" or variables listed under "
                      "<ModelStructure><InitialUnknowns>"}},
  {"2.0", {'3', true, "for a variable with variability != \"constant\" that has initial = \"exact\", or causality = "
                      "\"input\""}},
  {"2.0 ME", {'4', true, "for a variable with causality = \"input\", or (causality = \"parameter\" and variability = "
                         "\"tunable\")"}},
  {"2.0 ME", {'5', true, "for a variable with causality = \"input\" and variability = \"continuous\", and for a "
                         "continuous-time state variable"}},
  {"2.0 CS", {'6', true, "for a variable with causality = \"input\" or (causality = \"parameter\" and variability = "
                         "\"tunable\")"}},
  {"2.0", {'7', true, "always, but retrieved values are usable for debugging only"}},
  {"2.0 ME", {'8', false, "only for a Pure Discrete-Time FMU. This exits the current event mode and sets the time "
                          "for the next event instant"}},
  {"2.0 CS", {'8', true, "always, but if status is other than fmi2Terminated, retrieved values are useable for "
                         "debugging only"}},
};
inline constexpr Condition kFmi3Conditions[] = {
  // FMI 3.0.2, the text of each state's allowed calls (letters are this file's).
  {'s', true, "Instantiated: get variable start values as defined in modelDescription.xml (2.3.2)"},
  {'a', true, "Instantiated: variables with variability != constant and with initial = exact or approx (2.3.2)"},
  {'b', true, "Initialization Mode: variables with variability != constant and with initial = exact; inputs "
              "included (2.3.3)"},
  {'c', true, "Event Mode: causality = input, causality = parameter and variability = tunable, and "
              "continuous-time states with reinit = false (2.3.5)"},
  {'d', true, "Continuous-Time Mode: only for variables with causality = input and variability = continuous, "
              "and continuous-time states (3.2.1)"},
  {'e', true, "Step Mode: causality = input, or causality = parameter and variability = tunable (4.2.1)"},
  {'v', false, "fmi3EnterEventMode in Step Mode: must not be called if fmi3InstantiateCoSimulation signaled "
               "eventModeUsed = fmi3False, which can be forced by the FMU with hasEventMode = false (4.2.1)"},
  {'z', false, "fmi3EnterConfigurationMode: must not be called if the FMU contains no structural parameters "
               "(2.3.2, 2.3.5, 4.2.1)"},
};

// FMI 2.0.4: the table of section 3.2.3, "FMI 2.0 for Model Exchange", and
// that of section 4.2.4, "FMI 2.0 for Co-Simulation", side by side (nullptr:
// the function is not in that table; the functions marked yellow there are
// in one only). fmi2GetDerivatives in Initialization Mode: the table, as
// its 2.0.1 bugfix note confirms.
// Model Exchange columns: start/end, instantiated, Initialization Mode,
// Event Mode, Continuous-Time Mode, terminated, error, fatal.
inline constexpr const char* kFmi2MeColumns[] = {"start, end", "instantiated", "Initialization Mode", "Event Mode",
                                                 "Continuous-Time Mode", "terminated", "error", "fatal"};
// Co-Simulation columns: start/end, instantiated, Initialization Mode,
// stepComplete, stepInProgress, stepFailed, stepCanceled, terminated, error,
// fatal.
inline constexpr const char* kFmi2CsColumns[] = {"start, end", "instantiated", "Initialization Mode", "stepComplete",
                                                 "stepInProgress", "stepFailed", "stepCanceled", "terminated",
                                                 "error", "fatal"};
struct Row2 {
  const char* function;
  const char* me;  // FMI 2.0.4 3.2.3
  const char* cs;  // FMI 2.0.4 4.2.4
};
inline constexpr Row2 kFmi2[] = {
  {"fmi2GetTypesPlatform",              "xxxxxxx.", "xxxxxxxxx."},
  {"fmi2GetVersion",                    "xxxxxxx.", "xxxxxxxxx."},
  {"fmi2SetDebugLogging",               ".xxxxxx.", ".xxxxxxxx."},
  {"fmi2Instantiate",                   "x.......", "x........."},
  {"fmi2FreeInstance",                  ".xxxxxx.", ".xxx.xxxx."},
  {"fmi2SetupExperiment",               ".x......", ".x........"},
  {"fmi2EnterInitializationMode",       ".x......", ".x........"},
  {"fmi2ExitInitializationMode",        "..x.....", "..x......."},
  {"fmi2Terminate",                     "...xx...", "...x.x...."},
  {"fmi2Reset",                         ".xxxxxx.", ".xxx.xxxx."},
  {"fmi2GetReal",                       "..2xxx7.", "..2x.87x7."},
  {"fmi2GetInteger",                    "..2xxx7.", "..2x.87x7."},
  {"fmi2GetBoolean",                    "..2xxx7.", "..2x.87x7."},
  {"fmi2GetString",                     "..2xxx7.", "..2x.87x7."},
  {"fmi2SetReal",                       ".1345...", ".136......"},
  {"fmi2SetInteger",                    ".134....", ".136......"},
  {"fmi2SetBoolean",                    ".134....", ".136......"},
  {"fmi2SetString",                     ".134....", ".136......"},
  {"fmi2GetFMUstate",                   ".xxxxx7.", ".xxx.87x7."},
  {"fmi2SetFMUstate",                   ".xxxxxx.", ".xxx.xxxx."},
  {"fmi2FreeFMUstate",                  ".xxxxxx.", ".xxx.xxxx."},
  {"fmi2SerializedFMUstateSize",        ".xxxxxx.", ".xxx.xxxx."},
  {"fmi2SerializeFMUstate",             ".xxxxxx.", ".xxx.xxxx."},
  {"fmi2DeSerializeFMUstate",           ".xxxxxx.", ".xxx.xxxx."},
  {"fmi2GetDirectionalDerivative",      "..xxxx7.", "..xx.87x7."},
  {"fmi2EnterEventMode",                "...xx...", nullptr},
  {"fmi2NewDiscreteStates",             "...x....", nullptr},
  {"fmi2EnterContinuousTimeMode",       "...x....", nullptr},
  {"fmi2CompletedIntegratorStep",       "....x...", nullptr},
  {"fmi2SetTime",                       "...8x...", nullptr},
  {"fmi2SetContinuousStates",           "....x...", nullptr},
  {"fmi2GetEventIndicators",            "..xxxx7.", nullptr},
  {"fmi2GetContinuousStates",           "..xxxx7.", nullptr},
  {"fmi2GetDerivatives",                "..xxxx7.", nullptr},
  {"fmi2GetNominalsOfContinuousStates", ".xxxxx7.", nullptr},
  {"fmi2SetRealInputDerivatives",       nullptr,    ".xxx......"},
  {"fmi2GetRealOutputDerivatives",      nullptr,    "...x.8xx7."},
  {"fmi2DoStep",                        nullptr,    "...x......"},
  {"fmi2CancelStep",                    nullptr,    "....x....."},
  {"fmi2GetStatus",                     nullptr,    "...xxx.x.."},
  {"fmi2GetRealStatus",                 nullptr,    "...xxx.x.."},
  {"fmi2GetIntegerStatus",              nullptr,    "...xxx.x.."},
  {"fmi2GetBooleanStatus",              nullptr,    "...xxx.x.."},
  {"fmi2GetStringStatus",               nullptr,    "...xxx.x.."},
};

// FMI 3.0.2, Model Exchange and Co-Simulation in one table: the states are
// distinct (Continuous-Time Mode is Model Exchange's, Step Mode
// Co-Simulation's); "ME"/"CS" in a clause is the standard's "can only be
// called in Model Exchange", "Not allowed in Co-Simulation" (or the
// reverse). Columns: Instantiated, Initialization Mode, Event Mode,
// Continuous-Time Mode, Step Mode, Terminated. FMI 3.0 has no error state:
// "If any function called in super state FMU State Settable returns
// fmi3Error, the FMU enters state Terminated" (2.3.1).
inline constexpr const char* kFmi3Columns[] = {"Instantiated", "Initialization Mode", "Event Mode",
                                               "Continuous-Time Mode", "Step Mode", "Terminated"};
struct Row3 {
  Row row;
  const char* interfaces;  // "ME", "CS" or "ME CS"
};
inline constexpr Row3 kFmi3[] = {
  {{"fmi3SetDebugLogging",               "xxxxxx", "FMI 3.0.2 2.3.1 (FMU State Settable)"}, "ME CS"},
  {{"fmi3Reset",                         "xxxxxx", "FMI 3.0.2 2.3.1 (FMU State Settable)"}, "ME CS"},
  {{"fmi3GetFMUState",                   "xxxxxx", "FMI 3.0.2 2.3.1 (FMU State Settable)"}, "ME CS"},
  {{"fmi3SetFMUState",                   "xxxxxx", "FMI 3.0.2 2.3.1 (FMU State Settable)"}, "ME CS"},
  {{"fmi3FreeFMUState",                  "xxxxxx", "FMI 3.0.2 2.3.1 (FMU State Settable)"}, "ME CS"},
  {{"fmi3SerializedFMUStateSize",        "xxxxxx", "FMI 3.0.2 2.3.1 (FMU State Settable)"}, "ME CS"},
  {{"fmi3SerializeFMUState",             "xxxxxx", "FMI 3.0.2 2.3.1 (FMU State Settable)"}, "ME CS"},
  {{"fmi3DeserializeFMUState",           "xxxxxx", "FMI 3.0.2 2.3.1 (FMU State Settable)"}, "ME CS"},
  {{"fmi3EnterInitializationMode",       "x.....", "FMI 3.0.2 2.3.2"}, "ME CS"},
  {{"fmi3EnterConfigurationMode",        "z.z.z.", "FMI 3.0.2 2.3.2, 2.3.5, 4.2.1"}, "ME CS"},
  {{"fmi3GetNumberOfContinuousStates",   "x.x...", "FMI 3.0.2 2.3.2 (ME only), 2.3.5"}, "ME"},
  {{"fmi3GetNumberOfEventIndicators",    "x.x...", "FMI 3.0.2 2.3.2, 2.3.5 (not in CS)"}, "ME"},
  {{"fmi3Get{VariableType}",             "sxxxxx", "FMI 3.0.2 2.3.2 (start values), 2.3.3, 2.3.5, 3.2.1, 4.2.1, 2.3.8"},
   "ME CS"},
  {{"fmi3Set{VariableType}",             "abcde.", "FMI 3.0.2 2.3.2, 2.3.3, 2.3.5, 3.2.1, 4.2.1"}, "ME CS"},
  {{"fmi3ExitInitializationMode",        ".x....", "FMI 3.0.2 2.3.3"}, "ME CS"},
  {{"fmi3GetContinuousStates",           ".xxx.x", "FMI 3.0.2 2.3.3 (ME only), 2.3.5, 3.2.1, 2.3.8 (not in CS)"}, "ME"},
  {{"fmi3GetContinuousStateDerivatives", ".xxx.x", "FMI 3.0.2 2.3.3 (ME only), 2.3.5, 3.2.1, 2.3.8 (not in CS)"}, "ME"},
  {{"fmi3GetNominalsOfContinuousStates", ".xxx.x", "FMI 3.0.2 2.3.3 (ME only), 2.3.4, 2.3.8 (not in CS)"}, "ME"},
  {{"fmi3GetEventIndicators",            ".xxx.x", "FMI 3.0.2 2.3.3, 2.3.5, 3.2.1, 2.3.8 (not in CS)"}, "ME"},
  {{"fmi3GetDirectionalDerivative",      ".xxxxx", "FMI 3.0.2 2.3.3, 2.3.5, 3.2.1, 4.2.1, 2.3.8"}, "ME CS"},
  {{"fmi3GetAdjointDerivative",          ".xxxxx", "FMI 3.0.2 2.3.3, 2.3.5, 3.2.1, 4.2.1, 2.3.8"}, "ME CS"},
  {{"fmi3Terminate",                     "..xxx.", "FMI 3.0.2 2.3.4 (Initialized)"}, "ME CS"},
  {{"fmi3UpdateDiscreteStates",          "..x...", "FMI 3.0.2 2.3.5"}, "ME CS"},
  {{"fmi3EnterContinuousTimeMode",       "..x...", "FMI 3.0.2 2.3.5 (in Model Exchange)"}, "ME"},
  {{"fmi3EnterStepMode",                 "..x...", "FMI 3.0.2 2.3.5 (in Co-Simulation)"}, "CS"},
  {{"fmi3SetTime",                       "...x..", "FMI 3.0.2 3.2.1"}, "ME"},
  {{"fmi3SetContinuousStates",           "...x..", "FMI 3.0.2 3.2.1"}, "ME"},
  {{"fmi3CompletedIntegratorStep",       "...x..", "FMI 3.0.2 3.2.1"}, "ME"},
  {{"fmi3EnterEventMode",                "...xv.", "FMI 3.0.2 3.2.1, 4.2.1"}, "ME CS"},
  {{"fmi3DoStep",                        "....x.", "FMI 3.0.2 4.2.1"}, "CS"},
  {{"fmi3GetOutputDerivatives",          "....xx", "FMI 3.0.2 4.2.1, 2.3.8 (not in ME)"}, "CS"},
};

/// Where these FMUs read a cell otherwise, on purpose; the test prints each.
struct Deviation {
  const char* standard;  // what the standard says, with its clause
  const char* project;   // what these FMUs do instead
  const char* docs;      // where docs/ says so
  const char* test;      // the test that holds the FMUs to it
};
inline constexpr Deviation kDeviations[] = {
  {"a call that returns Error moves the instance to the state error (FMI 2.0.4 2.1.3, 3.2.3, 4.2.4: then only "
   "fmi2SetFMUstate, fmi2Reset, fmi2FreeInstance) or Terminated (FMI 3.0.2 2.3.1)",
   "a call its state does not allow answers Error with no effect: the instance stays in its state (byte for byte, "
   "as fmi2GetFMUstate/fmi3GetFMUState sees it) and remains usable there; only a failure inside a computation "
   "enters the error state, which allows what the standard's error (2.0) or Terminated (3.0) column allows",
   "docs/importers.md, \"Statuses, version by version\" (Error, no effect) and \"Which call is allowed when\"",
   "StateTable.EveryFunctionInEveryStateAnswersAsTheStandardsSay"},
  {"Continuous-Time Mode allows fmi2/fmi3CompletedIntegratorStep, EnterEventMode and the trial evaluations; \"if "
   "the environment tries to compute past stopTime the FMU has to return Error\" (FMI 2.0.4 2.1.6, FMI 3.0.2 2.3.2)",
   "compute reads as advance: past a defined stopTime, SetTime, SetContinuousStates, GetDerivatives, "
   "GetEventIndicators and the gets are answered (a trial point), CompletedIntegratorStep, EnterEventMode and a "
   "communication step ending there answer Error with no effect",
   "docs/importers.md, \"stopTime\"", "StateTable.PastStopTimeTrialEvaluationsAreAcceptedWhatAdvancesIsRefused"},
};
// clang-format on

}  // namespace pkm_test::standard

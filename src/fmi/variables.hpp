// SPDX-License-Identifier: BSD-2-Clause
// One model's interface as a table: every variable of modelDescription.xml
// (FMI 2.0 and 3.0 are generated from it, model_description.cpp), how to
// reach its value in an instance's data, and what it depends on
// (ModelStructure). A ModelDefinition bundles the table with the model's
// identity and capabilities.
#pragma once

#include <cstddef>
#include <cstdint>
#include <limits>
#include <memory>
#include <string>

namespace pkm_fmi {

class ModelData;

enum class VarType : std::uint8_t { Real, Integer, Boolean };
enum class Causality : std::uint8_t { Parameter, CalculatedParameter, Input, Output, Local, Independent };
enum class Variability : std::uint8_t { Constant, Fixed, Tunable, Discrete, Continuous };
enum class Initial : std::uint8_t { None, Exact, Approx, Calculated };

/// The modelDescription.xml spelling ("parameter", "fixed", "exact"; "" for Initial::None).
const char* xml_name(Causality c);
const char* xml_name(Variability v);
const char* xml_name(Initial i);
/// FMI 2.0 element names ("Real", "Integer", "Boolean").
const char* fmi2_type_name(VarType t);
/// FMI 3.0 element names ("Float64", "Int32", "Boolean").
const char* fmi3_type_name(VarType t);

/// Where a variable lives in an instance's data: returns a pointer to a
/// double (Real), std::int32_t (Integer) or int (Boolean, 0 or 1). `index` is the
/// variable's element index (arrays), 0 for scalars. The address must stay
/// the same for the instance's life: the layer asks once, at instantiation.
using Ref = void* (*)(ModelData& data, int index);

/// What a computed variable depends on, for ModelStructure: a bit set of
/// kinds that the model defines for its states and inputs (`kind`); a
/// computed variable depends on every state and input whose kind shares a
/// bit with its `depends`. One bit is the layer's own: kOnOwnState, an
/// output that is a state depends on that state only.
constexpr std::uint8_t kDependsNothing = 0;
constexpr std::uint8_t kOnOwnState = 1u << 3;

/// Computed variables without a group of their own: every group computes them.
constexpr std::uint8_t kAllGroups = 0xFF;

/// One row of a model's variable table: everything modelDescription.xml
/// says about a variable, plus how to reach its value.
struct Variable {
  std::uint32_t vr;
  const char* name;
  VarType type;
  Causality causality;
  Variability variability;
  Initial initial;  // Initial::None: attribute absent (inputs, independent)
  double start;     // meaningful iff has_start()
  const char* unit;  // "" = no unit attribute
  const char* description;
  Ref value;
  int index;
  Ref derivative;   // first derivative of a continuous Real input (CS input interpolation), nullptr if none
  double min;       // -inf = no min attribute
  double max;       // +inf = no max attribute
  std::uint8_t depends;  // kind bits (outputs, locals); kOnOwnState: that state only
  int state_of;     // der(x) rows: index of the state x in the model's states; -1 otherwise
  int state;        // rows that are continuous states: their index in the states; -1 otherwise
  int indicator = -1;  // rows that are event indicators (Model Exchange): their index; -1 otherwise
  std::uint8_t kind = kDependsNothing;  // inputs and states: the model's kind bits that name them
  double nominal = 1.0;  // continuous states: their scale (nominal attribute, GetNominalsOfContinuousStates)
  // Computed variables: the output group (a bit) that computes them, so that
  // a get pays only for what it reads (ModelData::update_outputs).
  std::uint8_t group = kAllGroups;
  // Parameters that are the initial value of a continuous state: its index
  // (the InitialUnknowns' dependencies); -1 otherwise.
  int initial_of = -1;

  constexpr bool has_start() const {
    return causality == Causality::Input || initial == Initial::Exact || initial == Initial::Approx;
  }
  /// Values the model computes (read through ModelData::update_outputs).
  constexpr bool computed() const {
    return causality == Causality::Output || causality == Causality::Local ||
           causality == Causality::CalculatedParameter;
  }
  /// Values an FMU state carries (the rest is recomputed).
  constexpr bool stored_in_state() const {
    return causality == Causality::Parameter || causality == Causality::Input;
  }
};

constexpr double kNoMin = -std::numeric_limits<double>::infinity();
constexpr double kNoMax = std::numeric_limits<double>::infinity();

/// Table rows of the usual kinds.
/// A continuous Real input; `kind` says what it is for ModelStructure.
constexpr Variable real_input(std::uint32_t vr, const char* name, double start, const char* unit,
                              const char* description, Ref value, int index, Ref derivative, std::uint8_t kind) {
  return {vr,    name,  VarType::Real, Causality::Input, Variability::Continuous, Initial::None, start, unit,
          description, value, index, derivative, kNoMin, kNoMax, kDependsNothing, -1, -1, -1, kind};
}
/// A continuous Real output computed by the model (initial calculated, no start).
constexpr Variable real_output(std::uint32_t vr, const char* name, const char* unit, const char* description,
                               Ref value, int index, std::uint8_t depends, std::uint8_t group = kAllGroups) {
  return {vr,    name,  VarType::Real, Causality::Output, Variability::Continuous, Initial::Calculated, 0.0, unit,
          description, value, index, nullptr, kNoMin, kNoMax, depends, -1, -1, -1, kDependsNothing, 1.0, group};
}
/// A Real output that is continuous state number `state` of the given kind.
constexpr Variable state_output(std::uint32_t vr, const char* name, const char* unit, const char* description,
                                Ref value, int index, int state, std::uint8_t kind, double nominal,
                                std::uint8_t group = kAllGroups) {
  return {vr,    name,  VarType::Real, Causality::Output, Variability::Continuous, Initial::Calculated, 0.0, unit,
          description, value, index, nullptr, kNoMin, kNoMax, kOnOwnState, -1, state, -1, kind, nominal, group};
}
/// der(x) of continuous state number `state_of` (a local variable).
constexpr Variable state_derivative(std::uint32_t vr, const char* name, const char* unit, const char* description,
                                    Ref value, int index, int state_of, std::uint8_t depends,
                                    std::uint8_t group = kAllGroups) {
  return {vr,    name,  VarType::Real, Causality::Local, Variability::Continuous, Initial::Calculated, 0.0, unit,
          description, value, index, nullptr, kNoMin, kNoMax, depends, state_of, -1, -1, kDependsNothing, 1.0, group};
}
/// Event indicator number `k` (a local variable, Model Exchange).
constexpr Variable event_indicator(std::uint32_t vr, const char* name, const char* unit, const char* description,
                                   Ref value, int index, int k, std::uint8_t depends,
                                   std::uint8_t group = kAllGroups) {
  return {vr,    name,  VarType::Real, Causality::Local, Variability::Continuous, Initial::Calculated, 0.0, unit,
          description, value, index, nullptr, kNoMin, kNoMax, depends, -1, -1, k, kDependsNothing, 1.0, group};
}
/// A fixed Real parameter (initial exact): settable before initialisation ends; [min, max] checked.
constexpr Variable real_parameter(std::uint32_t vr, const char* name, double start, const char* unit,
                                  const char* description, Ref value, int index, double min = kNoMin,
                                  double max = kNoMax) {
  return {vr,    name,  VarType::Real, Causality::Parameter, Variability::Fixed, Initial::Exact, start, unit,
          description, value, index, nullptr, min, max, kDependsNothing, -1, -1};
}
/// A fixed Integer parameter (initial exact) with its range.
constexpr Variable integer_parameter(std::uint32_t vr, const char* name, int start, const char* description,
                                     Ref value, int min, int max) {
  return {vr,    name,  VarType::Integer, Causality::Parameter, Variability::Fixed, Initial::Exact,
          static_cast<double>(start), "", description, value, 0, nullptr, static_cast<double>(min),
          static_cast<double>(max), kDependsNothing, -1, -1};
}
/// The independent variable (time).
constexpr Variable time_variable(std::uint32_t vr) {
  return {vr,      "time",  VarType::Real, Causality::Independent, Variability::Continuous, Initial::None, 0.0, "s",
          "Simulation time", nullptr, 0, nullptr, kNoMin, kNoMax, kDependsNothing, -1, -1};
}

/// Everything immutable about one FMU, shared by all its instances.
struct ModelDefinition {
  const char* identifier;     // modelIdentifier (= modelName)
  const char* title;          // one line: the modelDescription's description
  const char* summary;        // a paragraph of HTML, for the documentation
  const Variable* variables;  // sorted by value reference, unique
  std::size_t n_variables;
  std::size_t n_states;            // continuous states (Model Exchange)
  std::size_t n_position_states;   // the first states are positions whose derivatives are the next ones
  std::size_t n_event_indicators;  // Model Exchange
  bool can_interpolate_inputs;     // FMI 2.0 CS: fmi2SetRealInputDerivatives
  double default_step;             // DefaultExperiment stepSize
  double default_stop;             // DefaultExperiment stopTime
  std::unique_ptr<ModelData> (*create)();
  /// Directional and adjoint derivatives (ModelData::partial_derivatives):
  /// providesDirectionalDerivative(s), providesAdjointDerivatives.
  bool provides_derivatives = false;

  /// The variable with this value reference, nullptr if none. Called for
  /// every value of every get and set, so inline: the value references are
  /// unique and increasing and the tables nearly dense (a few gaps), so the
  /// variable sits at index vr - vr_0 or a few steps before it; a binary
  /// search below that (find_sparse) otherwise.
  const Variable* find(std::uint32_t vr) const {
    if (n_variables == 0 || vr < variables[0].vr) return nullptr;
    std::size_t last = vr - variables[0].vr < n_variables ? vr - variables[0].vr : n_variables - 1;
    for (int k = 0; k < 4; ++k) {
      if (variables[last].vr == vr) return &variables[last];
      if (variables[last].vr < vr || last == 0) return nullptr;
      --last;
    }
    return find_sparse(vr, last);
  }
  /// find's binary search in variables[0..last].
  const Variable* find_sparse(std::uint32_t vr, std::size_t last) const;
  const Variable* find(const char* name) const;
  /// The instantiation token (FMI 3.0) = GUID (FMI 2.0): a hash of the
  /// table, so that it changes whenever the interface does. Computed on each
  /// call (the definition holds nothing mutable; instances keep a copy).
  std::string guid() const;
};

/// True if the table is sorted by strictly increasing value reference.
constexpr bool sorted_by_vr(const Variable* v, std::size_t n) {
  for (std::size_t i = 1; i < n; ++i)
    if (!(v[i - 1].vr < v[i].vr)) return false;
  return true;
}

}  // namespace pkm_fmi

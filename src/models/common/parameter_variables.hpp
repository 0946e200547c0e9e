// SPDX-License-Identifier: BSD-2-Clause
// What both FMUs share: their parameters, the rows of the one parameter
// table (pkm::kParameters) that name the FMU, as FMI variables whose values
// an instance keeps by row, and the pkm::Configuration those values set.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>

#include "fmi/model_data.hpp"
#include "fmi/variables.hpp"
#include "pkm4puu/sim/parameters.hpp"

namespace pkm_fmi {

/// Per-instance data of a model of the mechanism: every row's value (a
/// parameter variable points at its row's; rows the FMU lacks keep their
/// defaults).
struct MechanismData : ModelData {
  double real_parameters[pkm::kParameterCount];
  std::int32_t integer_parameters[pkm::kParameterCount];

  MechanismData() {
    const pkm::Configuration defaults{};
    for (std::size_t row = 0; row < pkm::kParameterCount; ++row) {
      real_parameters[row] = pkm::kParameters[row].get(defaults);
      integer_parameters[row] = static_cast<std::int32_t>(real_parameters[row]);
    }
  }
  /// The tunable rows' values back to those of `in_effect` (a change the
  /// running model refused: ModelData::tune).
  void put_back_tunable(const pkm::Params& in_effect) {
    const pkm::Configuration c{in_effect};
    for (std::size_t row = 0; row < pkm::kParameterCount; ++row)
      if (pkm::kParameters[row].variability == pkm::ParameterVariability::Tunable &&
          pkm::kParameters[row].target == pkm::ParameterTarget::Model)
        real_parameters[row] = pkm::kParameters[row].get(c);
  }
  /// What the parameters set now.
  pkm::Configuration parameters() const {
    pkm::Configuration c;
    for (std::size_t row = 0; row < pkm::kParameterCount; ++row) {
      const pkm::Parameter& p = pkm::kParameters[row];
      p.set(c, p.type == pkm::ParameterType::Integer ? integer_parameters[row] : real_parameters[row]);
    }
    return c;
  }
};

inline void* real_parameter_value(ModelData& d, int row) {
  return &static_cast<MechanismData&>(d).real_parameters[row];
}
inline void* integer_parameter_value(ModelData& d, int row) {
  return &static_cast<MechanismData&>(d).integer_parameters[row];
}

/// Row `row` of the table as a parameter variable. `state`: the
/// continuous state whose initial value it is (initial-state rows), else -1.
constexpr Variable parameter_variable(std::size_t row, int state) {
  const pkm::Parameter& p = pkm::kParameters[row];
  const int index = static_cast<int>(row);
  Variable v = p.type == pkm::ParameterType::Integer
                   ? integer_parameter(p.vr, p.name, static_cast<int>(p.start()), p.description,
                                       &integer_parameter_value, static_cast<int>(p.lo), static_cast<int>(p.hi))
                   : real_parameter(p.vr, p.name, p.start(), p.unit, p.description, &real_parameter_value, index,
                                    p.lo, p.hi);
  v.index = index;
  v.initial_of = state;
  if (p.variability == pkm::ParameterVariability::Tunable) v.variability = Variability::Tunable;
  return v;
}

/// How many rows name the FMU `fmu` (pkm::kFmuPlant, pkm::kFmuInverse).
constexpr std::size_t parameter_count(std::uint8_t fmu) {
  std::size_t n = 0;
  for (const pkm::Parameter& p : pkm::kParameters) n += (p.fmus & fmu) != 0;
  return n;
}

/// The parameter variables of the FMU `fmu`, in the table's order (by value
/// reference); the initial-state rows are the initial values of the
/// continuous states 0, 1, ... in their order.
template <std::uint8_t Fmu>
constexpr std::array<Variable, parameter_count(Fmu)> parameter_variables() {
  std::array<Variable, parameter_count(Fmu)> out{};
  std::size_t k = 0;
  int state = 0;
  for (std::size_t row = 0; row < pkm::kParameterCount; ++row) {
    if (!(pkm::kParameters[row].fmus & Fmu)) continue;
    const bool initial = pkm::kParameters[row].target == pkm::ParameterTarget::Initial;
    out[k++] = parameter_variable(row, initial ? state++ : -1);
  }
  return out;
}

/// A model's own variables and its parameter variables, both sorted by
/// value reference, merged into one table sorted by value reference.
template <std::size_t N, std::size_t M>
constexpr std::array<Variable, N + M> merge_by_vr(const Variable (&own)[N], const std::array<Variable, M>& params) {
  std::array<Variable, N + M> out{};
  std::size_t i = 0, j = 0;
  for (std::size_t k = 0; k < N + M; ++k)
    out[k] = j == M || (i < N && own[i].vr < params[j].vr) ? own[i++] : params[j++];
  return out;
}

}  // namespace pkm_fmi

// SPDX-License-Identifier: BSD-2-Clause
// The parameter table (model/parameter_table.hpp) as data: one Parameter
// per row, with its accessors into a Configuration, everything the
// parameters set. The FMUs' parameter variables (models/common), the C
// API's parameters by name (capi/) and the documentation's reference
// (apps/parameter_reference.cpp) are all made from kParameters.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <iterator>
#include <string>
#include <string_view>

#include "pkm4puu/kinematics/constraints.hpp"
#include "pkm4puu/model/parameter_table.hpp"
#include "pkm4puu/model/params.hpp"
#include "pkm4puu/sim/plant.hpp"
#include "pkm4puu/sim/solver_settings.hpp"

namespace pkm {

/// The plant FMU's initial state (its parameters x0..dphi0; the C API takes
/// it as pkm_init_pose's arguments instead).
struct InitialState {
  std::array<double, 4> pose0{0.0, 0.0, 0.05, 0.0};  // x, y, z (m), phi (rad): the home pose
  std::array<double, 4> vel0{0.0, 0.0, 0.0, 0.0};    // m/s, rad/s
};

/// Everything the parameters set; its default is every row's default.
struct Configuration {
  Params params{};
  SolverSettings solver{};  // the guards' limits among them
  InitialState initial{};
};

enum class ParameterTarget : std::uint8_t { Model, Guard, Solver, Initial };
enum class ParameterType : std::uint8_t { Real, Integer };
enum class ParameterVariability : std::uint8_t { Fixed, Tunable };
/// The FMUs that have a parameter, as bits.
enum : std::uint8_t { kFmuPlant = 1u << 0, kFmuInverse = 1u << 1 };
inline constexpr std::uint8_t kFmusPlant = kFmuPlant, kFmusBoth = kFmuPlant | kFmuInverse;

/// One row of the table.
struct Parameter {
  std::uint32_t vr;
  const char* name;
  ParameterTarget target;
  ParameterType type;
  const char* unit;
  double lo, hi;
  ParameterRule rule;
  ParameterVariability variability;
  std::uint8_t fmus;
  const char* description;
  double (*get)(const Configuration&);
  void (*set)(Configuration&, double);

  /// The default (the FMUs' start value).
  constexpr double start() const { return get(Configuration{}); }
  /// "" if the value may be set (within the range; whole for an Integer),
  /// else the message naming the parameter.
  std::string check(double value) const {
    return check_parameter(name, value, lo, hi, unit, rule, type == ParameterType::Integer);
  }
};

// Where a target's members live in a Configuration.
#define PKM_PARAMETER_IN_Model(c) (c).params
#define PKM_PARAMETER_IN_Guard(c) (c).solver
#define PKM_PARAMETER_IN_Solver(c) (c).solver
#define PKM_PARAMETER_IN_Initial(c) (c).initial

inline constexpr Parameter kParameters[] = {
#define PKM_PARAMETER_ROW(vr, name, target, member, type, unit, lo, hi, rule, variability, fmus, description)      \
  {vr, name, ParameterTarget::target, ParameterType::type, unit, lo, hi, rule, ParameterVariability::variability,  \
   kFmus##fmus, description,                                                                                       \
   [](const Configuration& c) -> double { return PKM_PARAMETER_GET_##type(PKM_PARAMETER_IN_##target(c).member); }, \
   [](Configuration& c, double v) { PKM_PARAMETER_SET_##type(PKM_PARAMETER_IN_##target(c).member, v); }},
    PKM_PARAMETER_TABLE(PKM_PARAMETER_ROW)
#undef PKM_PARAMETER_ROW
};

#undef PKM_PARAMETER_IN_Model
#undef PKM_PARAMETER_IN_Guard
#undef PKM_PARAMETER_IN_Solver
#undef PKM_PARAMETER_IN_Initial

inline constexpr std::size_t kParameterCount = std::size(kParameters);

/// The row called `name` ("beta[2]"), nullptr if there is none.
const Parameter* find_parameter(std::string_view name);

namespace parameter_table_checks {

constexpr bool sorted_by_vr() {
  for (std::size_t i = 1; i < kParameterCount; ++i)
    if (!(kParameters[i - 1].vr < kParameters[i].vr)) return false;
  return true;
}

/// No two rows share a member: with every row zero, setting one row to 1
/// changes no other row.
constexpr bool rows_are_distinct() {
  for (const Parameter& p : kParameters) {
    Configuration c{};
    for (const Parameter& q : kParameters) q.set(c, 0.0);
    p.set(c, 1.0);
    for (const Parameter& q : kParameters)
      if (&q != &p && q.get(c) != 0.0) return false;
  }
  return true;
}

/// Every member of Params has a row: as many Model rows as Params has doubles.
constexpr bool model_rows_cover_params() {
  std::size_t rows = 0;
  for (const Parameter& p : kParameters) rows += p.target == ParameterTarget::Model;
  return rows == sizeof(Params) / sizeof(double);
}

}  // namespace parameter_table_checks

static_assert(parameter_table_checks::sorted_by_vr(), "the parameter table must be sorted by value reference");
static_assert(parameter_table_checks::rows_are_distinct(), "two rows of the parameter table share a member");
static_assert(parameter_table_checks::model_rows_cover_params(),
              "every member of Params needs a row in the parameter table");

}  // namespace pkm

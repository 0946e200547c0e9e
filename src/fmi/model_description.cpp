// SPDX-License-Identifier: BSD-2-Clause
#include "fmi/model_description.hpp"

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <map>
#include <set>

#include "fmi/logger.hpp"

namespace pkm_fmi {
namespace {

// SI base-unit exponents of every unit the tables use, and the quantity it
// measures here (the name of its FMI 3.0 type, after Modelica.Units.SI).
struct UnitInfo {
  const char* name;
  int kg, m, s, rad;
  const char* quantity;
};
constexpr UnitInfo kUnits[] = {
    {"s", 0, 0, 1, 0, "Time"},
    {"m", 0, 1, 0, 0, "Length"},
    {"m/s", 0, 1, -1, 0, "Velocity"},
    {"m/s2", 0, 1, -2, 0, "Acceleration"},
    {"rad", 0, 0, 0, 1, "Angle"},
    {"rad/s", 0, 0, -1, 1, "AngularVelocity"},
    {"rad/s2", 0, 0, -2, 1, "AngularAcceleration"},
    {"kg", 1, 0, 0, 0, "Mass"},
    {"kg.m2", 1, 2, 0, 0, "MomentOfInertia"},
    {"N", 1, 1, -2, 0, "Force"},
    {"N.m", 1, 2, -2, 0, "Torque"},
    {"N.s/m", 1, 0, -1, 0, "TranslationalDampingConstant"},
    {"N/m", 1, 0, -2, 0, "TranslationalSpringConstant"},
    {"J", 1, 2, -2, 0, "Energy"},
    {"W", 1, 2, -3, 0, "Power"},
};

const UnitInfo& unit_info(const char* unit) {
  for (const UnitInfo& u : kUnits)
    if (std::strcmp(u.name, unit) == 0) return u;
  std::fprintf(stderr, "model description: unit %s has no UnitDefinition (add it to kUnits)\n", unit);
  std::abort();  // a build tool's programming error, never reached in an FMU
}

std::string unit_definitions(const ModelDefinition& d) {
  std::set<std::string> used;
  for (std::size_t i = 0; i < d.n_variables; ++i)
    if (*d.variables[i].unit) used.insert(d.variables[i].unit);
  for (const std::string& u : used) unit_info(u.c_str());
  std::string out = "  <UnitDefinitions>\n";
  for (const UnitInfo& u : kUnits) {
    if (!used.count(u.name)) continue;
    out += "    <Unit name=\"" + std::string(u.name) + "\">\n      <BaseUnit";
    if (u.kg) out += " kg=\"" + std::to_string(u.kg) + "\"";
    if (u.m) out += " m=\"" + std::to_string(u.m) + "\"";
    if (u.s) out += " s=\"" + std::to_string(u.s) + "\"";
    if (u.rad) out += " rad=\"" + std::to_string(u.rad) + "\"";
    out += "/>\n    </Unit>\n";
  }
  return out + "  </UnitDefinitions>\n";
}

// FMI 3.0: one Float64Type per unit, named for its quantity; the variables
// name it as declaredType. (FMI 3.0 also allows a unit attribute on each
// variable; some importers, e.g. the Rust fmi-schema 0.8 behind fmi-sim,
// read units only through types, as the Reference FMUs declare them.)
std::string type_definitions(const ModelDefinition& d) {
  std::set<std::string> used;
  for (std::size_t i = 0; i < d.n_variables; ++i)
    if (*d.variables[i].unit) used.insert(d.variables[i].unit);
  std::string out = "  <TypeDefinitions>\n";
  for (const UnitInfo& u : kUnits)
    if (used.count(u.name))
      out += "    <Float64Type name=\"" + std::string(u.quantity) + "\" quantity=\"" + u.quantity + "\" unit=\"" +
             u.name + "\"/>\n";
  return out + "  </TypeDefinitions>\n";
}

std::string log_categories() {
  std::string out = "  <LogCategories>\n";
  for (int c = 0; c < kLogCategoryCount; ++c)
    out += "    <Category name=\"" + std::string(kLogCategoryNames[c]) + "\" description=\"" +
           xml_escape(kLogCategoryDescriptions[c]) + "\"/>\n";
  return out + "  </LogCategories>\n";
}

std::string default_experiment(const ModelDefinition& d) {
  return "  <DefaultExperiment startTime=\"0\" stopTime=\"" + exact_text(d.default_stop) + "\" stepSize=\"" +
         exact_text(d.default_step) + "\"/>\n";
}

// The attributes of <fmiModelDescription> both versions share, between
// description and variableNamingConvention: the project's version, licence
// and generator. Per-commit values (the commit in generationTool,
// generationDateAndTime) are added by cmake/pack_fmu.py to the archive's
// copy only: the committed files stay the same from commit to commit.
std::string header_attributes(const std::string& version) {
  return "\n  version=\"" + xml_escape(version.c_str()) + "\"\n  copyright=\"" + kCopyright + "\"\n  license=\"" +
         kLicense + "\"\n  generationTool=\"PKM4PUU " + xml_escape(version.c_str()) + "\"";
}

bool is_state(const Variable& v) { return v.state >= 0; }

const Variable* state_variable(const ModelDefinition& d, int k) {
  for (std::size_t i = 0; i < d.n_variables; ++i)
    if (d.variables[i].state == k) return &d.variables[i];
  return nullptr;
}

// Attributes common to both versions' variable elements.
std::string variable_attributes(const Variable& v) {
  std::string a = " name=\"" + xml_escape(v.name) + "\" valueReference=\"" + std::to_string(v.vr) + "\"";
  if (*v.description) a += " description=\"" + xml_escape(v.description) + "\"";
  a += " causality=\"" + std::string(xml_name(v.causality)) + "\" variability=\"" + xml_name(v.variability) + "\"";
  if (v.initial != Initial::None) a += " initial=\"" + std::string(xml_name(v.initial)) + "\"";
  return a;
}

// Type attributes (unit or declared type, min, max, start, derivative).
std::string type_attributes(const ModelDefinition& d, const Variable& v, int version,
                            const std::map<std::uint32_t, int>& index) {
  std::string a;
  if (*v.unit && version == 2) a += " unit=\"" + std::string(v.unit) + "\"";
  if (*v.unit && version == 3) a += " declaredType=\"" + std::string(unit_info(v.unit).quantity) + "\"";
  if (v.type == VarType::Integer) {
    if (std::isfinite(v.min)) a += " min=\"" + std::to_string(static_cast<long long>(v.min)) + "\"";
    if (std::isfinite(v.max)) a += " max=\"" + std::to_string(static_cast<long long>(v.max)) + "\"";
  } else {
    if (std::isfinite(v.min)) a += " min=\"" + exact_text(v.min) + "\"";
    if (std::isfinite(v.max)) a += " max=\"" + exact_text(v.max) + "\"";
    // The states' scale. FMI 2.0 only: fmi-sim's reader (fmi-schema 0.8)
    // refuses a nominal attribute on an FMI 3.0 Float64, and FMI 3.0
    // importers take the nominals from fmi3GetNominalsOfContinuousStates.
    if (version == 2 && v.state >= 0 && v.nominal != 1.0) a += " nominal=\"" + exact_text(v.nominal) + "\"";
  }
  if (v.has_start()) {
    if (v.type == VarType::Real)
      a += " start=\"" + exact_text(v.start) + "\"";
    else if (v.type == VarType::Integer)
      a += " start=\"" + std::to_string(static_cast<long long>(v.start)) + "\"";
    else
      a += std::string(" start=\"") + (v.start != 0.0 ? "true" : "false") + "\"";
  }
  if (v.state_of >= 0) {
    const Variable* x = state_variable(d, v.state_of);
    a += " derivative=\"" + std::to_string(version == 2 ? index.at(x->vr) : static_cast<int>(x->vr)) + "\"";
  }
  return a;
}

std::string dependencies_attributes(const Dependencies& deps, int version, const std::map<std::uint32_t, int>& index) {
  std::string list, kinds;
  for (std::size_t k = 0; k < deps.knowns.size(); ++k) {
    if (k) {
      list += ' ';
      kinds += ' ';
    }
    list += std::to_string(version == 2 ? index.at(deps.knowns[k]) : static_cast<int>(deps.knowns[k]));
    kinds += deps.constant ? "constant" : "dependent";
  }
  std::string a = " dependencies=\"" + list + "\"";
  if (!deps.knowns.empty()) a += " dependenciesKind=\"" + kinds + "\"";
  return a;
}

std::string unknown_dependencies(const ModelDefinition& d, const Variable& v, int version,
                                 const std::map<std::uint32_t, int>& index) {
  return dependencies_attributes(dependencies_of(d, v), version, index);
}

std::string initial_dependencies(const ModelDefinition& d, const Variable& v, int version,
                                 const std::map<std::uint32_t, int>& index) {
  return dependencies_attributes(initial_dependencies_of(d, v), version, index);
}

std::string fmi2(const ModelDefinition& d, const std::string& version) {
  std::map<std::uint32_t, int> index;  // value reference -> 1-based ScalarVariable index
  for (std::size_t i = 0; i < d.n_variables; ++i) index[d.variables[i].vr] = static_cast<int>(i + 1);
  std::string x = "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n";
  x += "<fmiModelDescription\n  fmiVersion=\"2.0\"\n  modelName=\"" + std::string(d.identifier) + "\"\n  guid=\"" +
       d.guid() + "\"\n  description=\"" + xml_escape(d.title) + "\"" + header_attributes(version) +
       "\n  variableNamingConvention=\"structured\"\n  numberOfEventIndicators=\"" +
       std::to_string(d.n_event_indicators) + "\">\n";
  const std::string derivatives2 =
      d.provides_derivatives ? "\n    providesDirectionalDerivative=\"true\"" : "";
  x += "  <ModelExchange\n    modelIdentifier=\"" + std::string(d.identifier) +
       "\"\n    completedIntegratorStepNotNeeded=\"true\"\n    canGetAndSetFMUstate=\"true\"\n"
       "    canSerializeFMUstate=\"true\"" + derivatives2 + "/>\n";
  x += "  <CoSimulation\n    modelIdentifier=\"" + std::string(d.identifier) +
       "\"\n    canHandleVariableCommunicationStepSize=\"true\"\n    canInterpolateInputs=\"" +
       (d.can_interpolate_inputs ? "true" : "false") +
       "\"\n    maxOutputDerivativeOrder=\"0\"\n    canGetAndSetFMUstate=\"true\"\n    canSerializeFMUstate=\"true\"" +
       derivatives2 + "/>\n";
  x += unit_definitions(d) + log_categories() + default_experiment(d);
  x += "  <ModelVariables>\n";
  for (std::size_t i = 0; i < d.n_variables; ++i) {
    const Variable& v = d.variables[i];
    x += "    <!-- index " + std::to_string(i + 1) + " -->\n";
    x += "    <ScalarVariable" + variable_attributes(v) + ">\n      <" + fmi2_type_name(v.type) +
         type_attributes(d, v, 2, index) + "/>\n    </ScalarVariable>\n";
  }
  x += "  </ModelVariables>\n  <ModelStructure>\n";
  std::string outputs, derivatives, initial;
  for (std::size_t i = 0; i < d.n_variables; ++i) {
    const Variable& v = d.variables[i];
    const std::string idx = std::to_string(i + 1);
    if (v.causality == Causality::Output)
      outputs += "      <Unknown index=\"" + idx + "\"" + unknown_dependencies(d, v, 2, index) + "/>\n";
    if (v.state_of >= 0)
      derivatives += "      <Unknown index=\"" + idx + "\"" + unknown_dependencies(d, v, 2, index) + "/>\n";
    if ((v.causality == Causality::Output && v.initial != Initial::Exact) || v.state_of >= 0 ||
        (is_state(v) && v.initial != Initial::Exact) || v.causality == Causality::CalculatedParameter)
      initial += "      <Unknown index=\"" + idx + "\"" + initial_dependencies(d, v, 2, index) + "/>\n";
  }
  if (!outputs.empty()) x += "    <Outputs>\n" + outputs + "    </Outputs>\n";
  if (!derivatives.empty()) x += "    <Derivatives>\n" + derivatives + "    </Derivatives>\n";
  if (!initial.empty()) x += "    <InitialUnknowns>\n" + initial + "    </InitialUnknowns>\n";
  x += "  </ModelStructure>\n</fmiModelDescription>\n";
  return x;
}

std::string fmi3(const ModelDefinition& d, const std::string& version) {
  const std::map<std::uint32_t, int> none;
  std::string x = "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n";
  x += "<fmiModelDescription\n  fmiVersion=\"3.0\"\n  modelName=\"" + std::string(d.identifier) +
       "\"\n  instantiationToken=\"" + d.guid() + "\"\n  description=\"" + xml_escape(d.title) + "\"" +
       header_attributes(version) + "\n  variableNamingConvention=\"structured\">\n";
  const std::string derivatives3 =
      d.provides_derivatives
          ? "\n    providesDirectionalDerivatives=\"true\"\n    providesAdjointDerivatives=\"true\""
          : "";
  x += "  <ModelExchange\n    modelIdentifier=\"" + std::string(d.identifier) +
       "\"\n    canGetAndSetFMUState=\"true\"\n    canSerializeFMUState=\"true\"\n"
       "    needsCompletedIntegratorStep=\"false\"" + derivatives3 + "/>\n";
  x += "  <CoSimulation\n    modelIdentifier=\"" + std::string(d.identifier) +
       "\"\n    canGetAndSetFMUState=\"true\"\n    canSerializeFMUState=\"true\"\n"
       "    canHandleVariableCommunicationStepSize=\"true\"" + derivatives3 + "/>\n";
  x += unit_definitions(d) + type_definitions(d) + log_categories() + default_experiment(d);
  x += "  <ModelVariables>\n";
  for (std::size_t i = 0; i < d.n_variables; ++i) {
    const Variable& v = d.variables[i];
    x += "    <" + std::string(fmi3_type_name(v.type)) + variable_attributes(v) + type_attributes(d, v, 3, none) +
         "/>\n";
  }
  x += "  </ModelVariables>\n  <ModelStructure>\n";
  for (std::size_t i = 0; i < d.n_variables; ++i) {
    const Variable& v = d.variables[i];
    if (v.causality == Causality::Output)
      x += "    <Output valueReference=\"" + std::to_string(v.vr) + "\"" + unknown_dependencies(d, v, 3, none) +
           "/>\n";
  }
  for (std::size_t i = 0; i < d.n_variables; ++i) {
    const Variable& v = d.variables[i];
    if (v.state_of >= 0)
      x += "    <ContinuousStateDerivative valueReference=\"" + std::to_string(v.vr) + "\"" +
           unknown_dependencies(d, v, 3, none) + "/>\n";
  }
  for (std::size_t i = 0; i < d.n_variables; ++i) {
    const Variable& v = d.variables[i];
    if ((v.causality == Causality::Output && v.initial != Initial::Exact) || v.state_of >= 0 ||
        v.causality == Causality::CalculatedParameter)
      x += "    <InitialUnknown valueReference=\"" + std::to_string(v.vr) + "\"" + initial_dependencies(d, v, 3, none) +
           "/>\n";
  }
  for (std::size_t i = 0; i < d.n_variables; ++i) {
    const Variable& v = d.variables[i];
    if (v.indicator >= 0) x += "    <EventIndicator valueReference=\"" + std::to_string(v.vr) + "\"/>\n";
  }
  x += "  </ModelStructure>\n</fmiModelDescription>\n";
  return x;
}

}  // namespace

std::string xml_escape(const char* s) {
  std::string out;
  for (; *s; ++s) {
    switch (*s) {
      case '<': out += "&lt;"; break;
      case '>': out += "&gt;"; break;
      case '&': out += "&amp;"; break;
      case '"': out += "&quot;"; break;
      default: out += *s;
    }
  }
  return out;
}

std::string exact_text(double v) {
  char buf[40];
  for (int digits = 1; digits <= 17; ++digits) {
    std::snprintf(buf, sizeof buf, "%.*g", digits, v);
    if (std::strtod(buf, nullptr) == v) break;
  }
  return buf;
}

bool is_dependency(const ModelDefinition& d, const Variable& v, const Variable& k) {
  if (v.depends & kOnOwnState) return k.vr == v.vr;
  // der(position) = rate: each depends on its own rate state only, with factor 1.
  const int half = static_cast<int>(d.n_position_states);
  if (v.state_of >= 0 && v.state_of < half) return k.state == v.state_of + half;
  const bool known = k.state >= 0 || k.causality == Causality::Input;
  return known && (k.kind & v.depends) != 0;
}

Dependencies dependencies_of(const ModelDefinition& d, const Variable& v) {
  Dependencies deps;
  if (v.depends & kOnOwnState) {
    deps.knowns.push_back(v.vr);
    deps.constant = true;
    return deps;
  }
  for (std::size_t i = 0; i < d.n_variables; ++i)
    if (is_dependency(d, v, d.variables[i])) deps.knowns.push_back(d.variables[i].vr);
  deps.constant = v.state_of >= 0 && v.state_of < static_cast<int>(d.n_position_states);
  return deps;
}

Dependencies initial_dependencies_of(const ModelDefinition& d, const Variable& v) {
  auto initial_value = [&](int state) -> const Variable* {
    for (std::size_t i = 0; i < d.n_variables; ++i)
      if (d.variables[i].initial_of == state && state >= 0) return &d.variables[i];
    return nullptr;
  };
  Dependencies deps;
  if (v.state >= 0) {
    if (const Variable* p = initial_value(v.state)) deps.knowns.push_back(p->vr);
    return deps;
  }
  std::set<std::uint32_t> knowns;
  for (std::uint32_t r : dependencies_of(d, v).knowns) {
    const Variable* k = d.find(r);
    if (k->state < 0) {
      knowns.insert(r);  // an input
    } else if (const Variable* p = initial_value(k->state)) {
      knowns.insert(p->vr);
    }
  }
  for (std::size_t i = 0; i < d.n_variables; ++i) {
    const Variable& p = d.variables[i];
    if (p.causality == Causality::Parameter && p.initial_of < 0) knowns.insert(p.vr);
  }
  deps.knowns.assign(knowns.begin(), knowns.end());
  return deps;
}

std::string model_description_xml(const ModelDefinition& def, int fmi_version, const std::string& version) {
  return fmi_version == 2 ? fmi2(def, version) : fmi3(def, version);
}

}  // namespace pkm_fmi

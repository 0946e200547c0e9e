// SPDX-License-Identifier: BSD-2-Clause
#include "fmi/variables.hpp"

#include <algorithm>
#include <cstdio>
#include <cstring>
#include <string>

#include "fmi/fmi_status.hpp"
#include "fmi/fnv1a.hpp"

namespace pkm_fmi {

const char* interface_name(Interface i) { return i == Interface::ModelExchange ? "Model Exchange" : "Co-Simulation"; }

const char* xml_name(Causality c) {
  switch (c) {
    case Causality::Parameter: return "parameter";
    case Causality::CalculatedParameter: return "calculatedParameter";
    case Causality::Input: return "input";
    case Causality::Output: return "output";
    case Causality::Local: return "local";
    case Causality::Independent: return "independent";
  }
  return "?";
}

const char* xml_name(Variability v) {
  switch (v) {
    case Variability::Constant: return "constant";
    case Variability::Fixed: return "fixed";
    case Variability::Tunable: return "tunable";
    case Variability::Discrete: return "discrete";
    case Variability::Continuous: return "continuous";
  }
  return "?";
}

const char* xml_name(Initial i) {
  switch (i) {
    case Initial::None: return "";
    case Initial::Exact: return "exact";
    case Initial::Approx: return "approx";
    case Initial::Calculated: return "calculated";
  }
  return "?";
}

const char* fmi2_type_name(VarType t) {
  switch (t) {
    case VarType::Real: return "Real";
    case VarType::Integer: return "Integer";
    case VarType::Boolean: return "Boolean";
  }
  return "?";
}

const char* fmi3_type_name(VarType t) {
  switch (t) {
    case VarType::Real: return "Float64";
    case VarType::Integer: return "Int32";
    case VarType::Boolean: return "Boolean";
  }
  return "?";
}

const Variable* ModelDefinition::find_sparse(std::uint32_t vr, std::size_t last) const {
  const Variable* end = variables + last + 1;
  const Variable* it =
      std::lower_bound(variables, end, vr, [](const Variable& v, std::uint32_t r) { return v.vr < r; });
  return (it != end && it->vr == vr) ? it : nullptr;
}

const Variable* ModelDefinition::find(const char* name) const {
  if (!name) return nullptr;
  for (std::size_t i = 0; i < n_variables; ++i)
    if (std::strcmp(variables[i].name, name) == 0) return &variables[i];
  return nullptr;
}

namespace {

// Everything an importer relies on, in a canonical text: two hashes of it
// make the token.
std::string interface_text(const ModelDefinition& d) {
  std::string s = d.identifier;
  char buf[160];
  std::snprintf(buf, sizeof buf, "|%zu|%zu|%d", d.n_states, d.n_event_indicators, d.can_interpolate_inputs ? 1 : 0);
  s += buf;
  for (std::size_t i = 0; i < d.n_variables; ++i) {
    const Variable& v = d.variables[i];
    std::snprintf(buf, sizeof buf, "|%u:%d%d%d%d:%a:%a:%a:%d:%d:%d:%d:%d:", static_cast<unsigned>(v.vr),
                  static_cast<int>(v.type), static_cast<int>(v.causality), static_cast<int>(v.variability),
                  static_cast<int>(v.initial), v.start, v.min, v.max, static_cast<int>(v.depends), v.state_of,
                  v.state, v.indicator, static_cast<int>(v.kind));
    s += buf;
    s += v.name;
    s += ':';
    s += v.unit;
    s += v.derivative ? ":d" : ":";
  }
  return s;
}

}  // namespace

std::string ModelDefinition::guid() const {
  const std::string text = interface_text(*this);
  const auto* p = reinterpret_cast<const unsigned char*>(text.data());
  const std::uint64_t a = fnv1a(p, text.size());
  const std::uint64_t b = fnv1a(p, text.size(), 0x84222325cbf29ce4ull);
  char buf[40];
  // UUID layout, version 8 (custom), variant 10.
  std::snprintf(buf, sizeof buf, "{%08x-%04x-8%03x-%04x-%012llx}", static_cast<unsigned>(a >> 32),
                static_cast<unsigned>((a >> 16) & 0xffff), static_cast<unsigned>(a & 0xfff),
                static_cast<unsigned>(0x8000 | ((b >> 48) & 0x3fff)), static_cast<unsigned long long>(b & 0xffffffffffffull));
  return buf;
}

}  // namespace pkm_fmi

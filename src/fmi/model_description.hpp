// SPDX-License-Identifier: BSD-2-Clause
// modelDescription.xml of a model, generated from its variable table: FMI
// 2.0 (Co-Simulation and Model Exchange in one file) and FMI 3.0. The
// committed copies under modelDescription/ are these files; a test fails
// when a regeneration differs.
#pragma once

#include <string>
#include <vector>

#include "fmi/variables.hpp"

namespace pkm_fmi {

/// The copyright and license attributes of every model description.
inline constexpr const char* kCopyright = "Copyright (c) 2026 The PKM4PUU authors";
inline constexpr const char* kLicense = "BSD-2-Clause";

/// The model description for FMI version 2 or 3; `version` is the
/// project's (PKM_VERSION_STRING of pkm4puu/version.h).
std::string model_description_xml(const ModelDefinition& def, int fmi_version, const std::string& version);

/// The value references a computed variable depends on (ModelStructure),
/// in table order, and whether every factor is constant (dependenciesKind).
struct Dependencies {
  std::vector<std::uint32_t> knowns;
  bool constant = false;
};
Dependencies dependencies_of(const ModelDefinition& def, const Variable& v);
/// Whether `known` is among dependencies_of(def, v)'s (the same rule,
/// without building the list: the directional derivatives' per-call check).
bool is_dependency(const ModelDefinition& def, const Variable& v, const Variable& known);
/// What an InitialUnknown depends on in Initialization Mode (knowns: inputs
/// and parameters): a state its initial-value parameter (energy integrals,
/// which start at 0, nothing); any other the inputs it depends on, the
/// initial values of the states it depends on and every other parameter
/// (those that do not change it are listed too: an InitialUnknown may list
/// more than it depends on, never less).
Dependencies initial_dependencies_of(const ModelDefinition& def, const Variable& v);

/// The shortest decimal text that reads back as exactly x.
std::string exact_text(double x);

/// Text with <, >, & and " escaped (XML attributes, HTML).
std::string xml_escape(const char* s);

}  // namespace pkm_fmi

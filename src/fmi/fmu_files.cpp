// SPDX-License-Identifier: BSD-2-Clause
// Build tool, compiled per FMU with PKM_FMI_DEFINITION naming its model:
// writes the files an archive ships from the model's variable table, so
// that they always describe the binary.
//   <tool> <modelIdentifier> <output.html>   documentation/index.html
//   <tool> --xml <directory>                 <directory>/fmi2/<id>.xml and fmi3/<id>.xml
//   <tool> --markdown <output.md>            the documentation site's reference page (docs/)
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <string>

#include "fmi/model_description.hpp"
#include "pkm4puu/version.h"

#ifndef PKM_FMI_DEFINITION
#error "PKM_FMI_DEFINITION must name the model's definition (a function in namespace pkm_fmi)"
#endif

namespace pkm_fmi {
const ModelDefinition& PKM_FMI_DEFINITION();
}

namespace {

std::string start_text(const pkm_fmi::Variable& v) {
  if (!v.has_start()) return "";
  return v.type == pkm_fmi::VarType::Real ? pkm_fmi::exact_text(v.start) : std::to_string(static_cast<int>(v.start));
}

void section(std::ofstream& out, const pkm_fmi::ModelDefinition& def, pkm_fmi::Causality c, const char* title) {
  out << "<h2>" << title << "</h2>\n<table>\n<tr><th>name</th><th>type</th><th>unit</th><th>start</th>"
         "<th>value reference</th><th>description</th></tr>\n";
  for (std::size_t i = 0; i < def.n_variables; ++i) {
    const pkm_fmi::Variable& v = def.variables[i];
    if (v.causality != c) continue;
    out << "<tr><td><code>" << pkm_fmi::xml_escape(v.name) << "</code></td><td>" << pkm_fmi::fmi2_type_name(v.type) << "</td><td>"
        << pkm_fmi::xml_escape(v.unit) << "</td><td>" << start_text(v) << "</td><td>" << v.vr << "</td><td>"
        << pkm_fmi::xml_escape(v.description) << "</td></tr>\n";
  }
  out << "</table>\n";
}

/// A table of the variables that `index_of` numbers 0..n-1 (states,
/// event indicators), in that order; `nominal` adds the nominal column.
template <class IndexOf>
void numbered_table(std::ofstream& out, const pkm_fmi::ModelDefinition& def, std::size_t n, const char* what,
                    bool nominal, IndexOf index_of) {
  out << "<table>\n<tr><th>" << what << "</th><th>unit</th>" << (nominal ? "<th>nominal</th>" : "")
      << "<th>description</th></tr>\n";
  for (std::size_t k = 0; k < n; ++k)
    for (std::size_t i = 0; i < def.n_variables; ++i) {
      const pkm_fmi::Variable& v = def.variables[i];
      if (index_of(v) != static_cast<int>(k)) continue;
      out << "<tr><td><code>" << pkm_fmi::xml_escape(v.name) << "</code></td><td>" << pkm_fmi::xml_escape(v.unit)
          << "</td><td>";
      if (nominal) out << pkm_fmi::exact_text(v.nominal) << "</td><td>";
      out << pkm_fmi::xml_escape(v.description) << "</td></tr>\n";
    }
  out << "</table>\n";
}

/// What the variable table says about the interfaces: the continuous states
/// and event indicators that Model Exchange integrates and locates.
void interfaces(std::ofstream& out, const pkm_fmi::ModelDefinition& def) {
  out << "<h2>Interfaces</h2>\n<p>FMI 2.0 and FMI 3.0, each with Co-Simulation and Model Exchange. Model "
         "Exchange has "
      << def.n_states << " continuous state" << (def.n_states == 1 ? "" : "s") << " and " << def.n_event_indicators
      << " event indicator" << (def.n_event_indicators == 1 ? "" : "s") << ".</p>\n";
  if (def.n_states > 0)
    numbered_table(out, def, def.n_states, "state", true, [](const pkm_fmi::Variable& v) { return v.state; });
  if (def.n_event_indicators > 0)
    numbered_table(out, def, def.n_event_indicators, "event indicator", false,
                   [](const pkm_fmi::Variable& v) { return v.indicator; });
}

/// The model descriptions of both FMI versions into <dir>/fmi<v>/<id>.xml.
int write_model_descriptions(const char* prog, const pkm_fmi::ModelDefinition& def, const std::string& dir) {
  for (int version : {2, 3}) {
    const std::string path = dir + "/fmi" + std::to_string(version) + "/" + def.identifier + ".xml";
    std::ofstream out(path, std::ios::binary);
    out << pkm_fmi::model_description_xml(def, version, PKM_VERSION_STRING);
    out.close();
    if (!out) {
      std::fprintf(stderr, "%s: cannot write %s (does the directory exist?)\n", prog, path.c_str());
      return 1;
    }
  }
  return 0;
}

/// Text as Markdown shows it literally: `|` cannot split a table row, `*`, `_`,
/// `<`, `[` and backquotes start no markup.
std::string md_cell(const std::string& s) {
  std::string r;
  for (char c : s) {
    if (std::strchr("\\|*_<>[]`", c)) r += '\\';
    r += c;
  }
  return r;
}

/// "[min, max]" from the attributes the model description carries; "" when it has neither.
std::string range_text(const pkm_fmi::Variable& v) {
  const bool lo = v.min != pkm_fmi::kNoMin, hi = v.max != pkm_fmi::kNoMax;
  if (!lo && !hi) return "";
  return std::string("[") + (lo ? pkm_fmi::exact_text(v.min) : "-inf") + ", " +
         (hi ? pkm_fmi::exact_text(v.max) : "inf") + "]";
}

/// The documentation site's page of one model: every variable of the table
/// with what both model descriptions say about it (one table per causality).
int write_markdown(const char* prog, const pkm_fmi::ModelDefinition& def, const std::string& path) {
  using pkm_fmi::Causality;
  std::ofstream out(path, std::ios::binary);
  out << "<!-- Generated by " << def.identifier << "_files --markdown from src/models/" << def.identifier
      << "/variables.cpp; do not edit. -->\n\n"
      << "(fmu-" << def.identifier << ")=\n### " << def.identifier << "\n\n**" << md_cell(def.title) << "**\n\n"
      << "FMI 2.0 and FMI 3.0, each with Co-Simulation and Model Exchange; version " << PKM_VERSION_STRING
      << ". Both model descriptions declare the same variables with the same names and value references: "
         "the FMI 2.0 type `Real` is FMI 3.0's `Float64`, `Integer` is `Int32`. Units are SI; a range is the "
         "`min`/`max` the model description declares and the FMU checks when the value is set.\n\n"
      << "Model Exchange: " << def.n_states << " continuous state" << (def.n_states == 1 ? "" : "s") << ", "
      << def.n_event_indicators << " event indicator" << (def.n_event_indicators == 1 ? "" : "s") << ".\n";
  const struct {
    Causality c;
    const char* title;
  } groups[] = {{Causality::Input, "Inputs"},
                {Causality::Output, "Outputs"},
                {Causality::Parameter, "Parameters"},
                {Causality::CalculatedParameter, "Calculated parameters"},
                {Causality::Local, "Local variables (state derivatives, event indicators)"},
                {Causality::Independent, "Independent variable"}};
  for (const auto& g : groups) {
    std::size_t n = 0;
    for (std::size_t i = 0; i < def.n_variables; ++i) n += def.variables[i].causality == g.c;
    if (n == 0) continue;
    out << "\n#### " << def.identifier << ": " << g.title << " (" << n << ")\n\n"
        << "| name | value reference | type (FMI 2.0 / 3.0) | causality | variability | unit | start | range | "
           "description |\n|---|---|---|---|---|---|---|---|---|\n";
    for (std::size_t i = 0; i < def.n_variables; ++i) {
      const pkm_fmi::Variable& v = def.variables[i];
      if (v.causality != g.c) continue;
      out << "| `" << v.name << "` | " << v.vr << " | " << pkm_fmi::fmi2_type_name(v.type) << " / "
          << pkm_fmi::fmi3_type_name(v.type) << " | " << pkm_fmi::xml_name(v.causality) << " | "
          << pkm_fmi::xml_name(v.variability) << " | " << md_cell(v.unit) << " | " << start_text(v) << " | "
          << range_text(v) << " | " << md_cell(v.description) << " |\n";
    }
  }
  out.close();
  if (!out) {
    std::fprintf(stderr, "%s: cannot write %s\n", prog, path.c_str());
    return 1;
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  const pkm_fmi::ModelDefinition* def = &pkm_fmi::PKM_FMI_DEFINITION();
  if (argc == 3 && std::strcmp(argv[1], "--xml") == 0) return write_model_descriptions(argv[0], *def, argv[2]);
  if (argc == 3 && std::strcmp(argv[1], "--markdown") == 0) return write_markdown(argv[0], *def, argv[2]);
  if (argc != 3) {
    std::fprintf(stderr, "usage: %s %s <output.html> | --xml <directory> | --markdown <output.md>\n", argv[0],
                 def->identifier);
    return 2;
  }
  if (std::strcmp(def->identifier, argv[1]) != 0) {
    std::fprintf(stderr, "%s: this tool writes %s, not %s\n", argv[0], def->identifier, argv[1]);
    return 2;
  }
  std::ofstream out(argv[2]);
  out << "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n<title>" << def->identifier
      << "</title>\n<style>body{font-family:sans-serif;max-width:60em;margin:auto}"
         "table{border-collapse:collapse}td,th{border:1px solid #bbb;padding:2px 6px;text-align:left}</style>\n"
         "</head>\n<body>\n<h1>"
      << def->identifier << "</h1>\n<p><b>" << pkm_fmi::xml_escape(def->title) << "</b></p>\n"
      << def->summary
      << "\n<p>FMI 2.0 (Co-Simulation and Model Exchange in one archive) and FMI 3.0 (Co-Simulation and Model "
         "Exchange). SI units on every variable (m, kg, s, rad, N, N.m). "
         "Parameters are fixed: they can be set before ExitInitializationMode only. Arrays follow the "
         "<code>name[i]</code> convention, 1-based; leg i = 1..4; the FMI 3.0 names are the FMI 2.0 ones.</p>\n";
  out << "<h2>Platforms</h2>\n<table>\n<tr><th>platform</th><th>binaries/</th><th>built with</th>"
         "<th>tested</th></tr>\n"
         "<tr><td>Linux x86-64</td><td>linux64, x86_64-linux</td><td>gcc</td><td>natively: every C++ and "
         "Python test of the project</td></tr>\n"
         "<tr><td>Windows x64</td><td>win64, x86_64-windows</td><td>mingw-w64 (gcc), static: imports only "
         "KERNEL32 and msvcrt</td><td>under wine: the FMI life-cycle, state and error tests and the auto-test "
         "through both FMUs (equal to Linux x86-64 to 1e-12 relative); through fmpy's remoting: the "
         "auto-test and the state round trip</td></tr>\n"
         "<tr><td>Linux aarch64 (FMI 3.0)</td><td>aarch64-linux</td><td>gcc, no fused multiply-add</td>"
         "<td>under qemu-user: the same FMI tests as Windows</td></tr>\n"
         "<tr><td>any other</td><td>sources/ (buildDescription.xml, SourceFiles)</td><td>any C++17 compiler; "
         "Eigen inside; RK4 only (solver = 1; solver = 0, CVODE, needs SUNDIALS and is refused)</td>"
         "<td><code>fmpy compile</code> on Linux x86-64: the auto-test as the binary</td></tr>\n"
         "</table>\n<p>Every platform is in the archives of <code>build/dist/</code>; "
         "<code>build/*.fmu</code> hold the build machine's binary only.</p>\n";
  interfaces(out, *def);
  section(out, *def, pkm_fmi::Causality::Input, "Inputs");
  section(out, *def, pkm_fmi::Causality::Output, "Outputs");
  section(out, *def, pkm_fmi::Causality::Parameter, "Parameters");
  section(out, *def, pkm_fmi::Causality::Local, "Local variables (state derivatives, event indicators)");
  out << "</body>\n</html>\n";
  out.close();
  if (!out) {
    std::fprintf(stderr, "%s: cannot write %s\n", argv[0], argv[2]);
    return 1;
  }
  return 0;
}

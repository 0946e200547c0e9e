// SPDX-License-Identifier: BSD-2-Clause
// The interface as the variable tables declare it (src/models/<id>), from which
// every modelDescription.xml is generated (the ctest
// model_descriptions_up_to_date checks that the committed files are those):
// every name of docs/model.md "The FMUs' names", start values equal to
// the core's defaults, and a ModelStructure true to the mathematics, checked
// by perturbing each input and each state of a Model Exchange instance and
// watching which outputs and derivatives move.
#include <algorithm>
#include <cmath>
#include <initializer_list>
#include <memory>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include <gtest/gtest.h>

#include "fmi/instance.hpp"
#include "fmi/model_description.hpp"
#include "models/models.hpp"
#include "pkm4puu/model/params.hpp"
#include "pkm4puu/sim/plant.hpp"
#include "pkm4puu/version.h"

namespace {

using pkm_fmi::Causality;
using pkm_fmi::Instance;
using pkm_fmi::ModelDefinition;
using pkm_fmi::Status;
using pkm_fmi::Variable;

std::vector<std::string> indexed(const std::string& name, int n) {
  std::vector<std::string> v;
  for (int i = 1; i <= n; ++i) v.push_back(name + "[" + std::to_string(i) + "]");
  return v;
}

void expect_names(const ModelDefinition& d, Causality c, const std::vector<std::string>& names) {
  for (const auto& n : names) {
    const Variable* v = d.find(n.c_str());
    ASSERT_NE(v, nullptr) << d.identifier << " lacks the contract name " << n;
    EXPECT_EQ(v->causality, c) << n;
  }
}

TEST(InterfaceContract, PlantHasEveryContractName) {
  const ModelDefinition& d = pkm_fmi::pkm4puu_definition();
  std::vector<std::string> in = indexed("F", 4);
  for (const auto& n : indexed("Fe", 3)) in.push_back(n);
  in.push_back("Me_z");
  expect_names(d, Causality::Input, in);
  std::vector<std::string> out = {"x", "y", "z", "phi", "dx", "dy", "dz", "dphi", "constraint_residual",
                                   "jacobian_condition"};
  for (const char* a : {"rho", "drho", "theta1", "theta2"})
    for (const auto& n : indexed(a, 4)) out.push_back(n);
  for (const auto& n : indexed("lambda", 12)) out.push_back(n);
  expect_names(d, Causality::Output, out);
  std::vector<std::string> par = {"h", "l", "h_prime", "r_b", "r_Q", "m_slider", "m_rod", "m_platform", "Izz_platform",
                                  "g", "x0", "y0", "z0", "phi0", "dx0", "dy0", "dz0", "dphi0", "solver", "rk4_step",
                                  "rtol", "atol"};
  for (const char* a : {"beta", "gamma"})
    for (const auto& n : indexed(a, 4)) par.push_back(n);
  for (const auto& n : indexed("I_rod", 3)) par.push_back(n);
  expect_names(d, Causality::Parameter, par);
}

TEST(InterfaceContract, InverseHasEveryContractName) {
  const ModelDefinition& d = pkm_fmi::pkm4puu_inverse_definition();
  std::vector<std::string> in = {"x", "y", "z", "phi", "dx", "dy", "dz", "dphi", "ddx", "ddy", "ddz", "ddphi", "Me_z"};
  for (const auto& n : indexed("Fe", 3)) in.push_back(n);
  expect_names(d, Causality::Input, in);
  std::vector<std::string> out;
  for (const char* a : {"F", "rho", "drho"})
    for (const auto& n : indexed(a, 4)) out.push_back(n);
  for (const auto& n : indexed("lambda", 12)) out.push_back(n);
  expect_names(d, Causality::Output, out);
}

TEST(InterfaceContract, ParameterStartValuesAreTheCoreDefaults) {
  const pkm::Params p{};
  const pkm::SolverSettings s{};
  const std::pair<const char*, double> expected[] = {
      {"h", p.h},           {"l", p.l},           {"h_prime", p.h_prime}, {"r_b", p.r_b},
      {"r_Q", p.r_Q},       {"m_slider", p.m_slider}, {"m_rod", p.m_rod}, {"m_platform", p.m_platform},
      {"Izz_platform", p.Izz_platform}, {"g", p.g}, {"I_rod[1]", p.I_rod[0]}, {"I_rod[2]", p.I_rod[1]},
      {"I_rod[3]", p.I_rod[2]}, {"beta[2]", p.beta[1]}, {"gamma[1]", p.gamma[0]}, {"gamma[2]", p.gamma[1]},
      {"rk4_step", s.rk4_step}, {"rtol", s.rtol}, {"atol", s.atol}};
  for (const ModelDefinition* d : {&pkm_fmi::pkm4puu_definition(), &pkm_fmi::pkm4puu_inverse_definition()}) {
    for (const auto& e : expected) {
      const Variable* v = d->find(e.first);
      if (!v) {
        EXPECT_TRUE(std::string(d->identifier) == "PKM4PUU_Inverse") << e.first;  // solver settings: plant only
        continue;
      }
      EXPECT_EQ(v->start, e.second) << d->identifier << " " << e.first;
    }
  }
}

TEST(InterfaceContract, HeaderCarriesVersionCopyrightAndLicense) {
  // The project's version (CMake's project()), the copyright holder and the
  // SPDX licence; the per-commit attributes are left to the packer.
  for (const ModelDefinition* d : {&pkm_fmi::pkm4puu_definition(), &pkm_fmi::pkm4puu_inverse_definition()}) {
    for (int version : {2, 3}) {
      const std::string xml = pkm_fmi::model_description_xml(*d, version, PKM_VERSION_STRING);
      const std::string header = xml.substr(0, xml.find('>', xml.find("<fmiModelDescription")));
      EXPECT_NE(header.find("\n  version=\"" PKM_VERSION_STRING "\""), std::string::npos) << header;
      EXPECT_NE(header.find("\n  copyright=\"Copyright (c) 2026 The PKM4PUU authors\""), std::string::npos) << header;
      EXPECT_NE(header.find("\n  license=\"BSD-2-Clause\""), std::string::npos) << header;
      EXPECT_NE(header.find("\n  generationTool=\"PKM4PUU " PKM_VERSION_STRING "\""), std::string::npos) << header;
      EXPECT_EQ(header.find("generationDateAndTime"), std::string::npos) << header;
    }
  }
}

TEST(InterfaceContract, EveryUnitHasAnSIBaseUnitDefinition) {
  // The generator aborts on a unit it has no definition for; here the text.
  for (const ModelDefinition* d : {&pkm_fmi::pkm4puu_definition(), &pkm_fmi::pkm4puu_inverse_definition()}) {
    for (int version : {2, 3}) {
      const std::string xml = pkm_fmi::model_description_xml(*d, version, PKM_VERSION_STRING);
      for (std::size_t i = 0; i < d->n_variables; ++i) {
        const std::string unit = d->variables[i].unit;
        if (unit.empty()) continue;
        EXPECT_NE(xml.find("<Unit name=\"" + unit + "\">"), std::string::npos) << unit;
      }
    }
  }
}

// ---------------------------------------------------------------- dependencies

struct Harness {
  std::unique_ptr<Instance> inst;
  const ModelDefinition& d;
  std::vector<std::uint32_t> unknowns;  // outputs and state derivatives, in table order

  Harness(const ModelDefinition& def, pkm_fmi::Interface interface) : d(def) {
    inst.reset(Instance::create(def, 2, interface, def.guid().c_str(), pkm_fmi::Logger()));
    for (std::size_t k = 0; k < d.n_variables; ++k) {
      const Variable& v = d.variables[k];
      if (v.causality == Causality::Output || v.state_of >= 0) unknowns.push_back(v.vr);
    }
  }
  std::vector<double> read() {
    std::vector<double> y(unknowns.size());
    // Warning: the inverse FMU's note on a pose beyond an end stop (once).
    const Status s = inst->get_real(unknowns.data(), unknowns.size(), y.data());
    EXPECT_TRUE(s == Status::OK || s == Status::Warning);
    return y;
  }
  void set(const char* name, double x) {
    const Variable* v = d.find(name);
    ASSERT_NE(v, nullptr) << name;
    ASSERT_EQ(inst->set_real(&v->vr, 1, &x), Status::OK) << name;
  }
  void set(std::initializer_list<std::pair<const char*, double>> values) {
    for (const auto& [name, x] : values) set(name, x);
  }
  /// Initialisation mode and out of it again.
  void initialize() {
    ASSERT_EQ(inst->enter_initialization_mode(), Status::OK);
    ASSERT_EQ(inst->exit_initialization_mode(), Status::OK);
  }
  std::set<std::uint32_t> declared(std::uint32_t unknown) const {
    const pkm_fmi::Dependencies deps = pkm_fmi::dependencies_of(d, *d.find(unknown));
    return {deps.knowns.begin(), deps.knowns.end()};
  }
};

// Every term of the machine on, and the sliders pressed into their lower end
// stops (rho_min above every rho of the points below, a soft stop), so that
// whatever can depend on something does.
void machine_point(Harness& h) {
  h.set({{"rotor_inertia", 2e-6}, {"friction_viscous", 2.0}, {"friction_coulomb", 0.1}, {"payload_mass", 0.2},
         {"payload_com[1]", 0.01}, {"payload_com[2]", -0.005}, {"payload_Izz", 1e-4}, {"rho_min", 0.06}});
  if (h.d.find("stop_stiffness")) h.set("stop_stiffness", 1e3);
}

// A generic point: the platform moving, every input nonzero.
void plant_point(Harness& h) {
  h.set({{"x0", 0.002}, {"y0", -0.001}, {"z0", 0.055}, {"phi0", 0.03}, {"dx0", 0.01}, {"dy0", 0.004}, {"dz0", -0.02},
         {"dphi0", 0.1}});
  for (int i = 1; i <= 4; ++i) h.set(("F[" + std::to_string(i) + "]").c_str(), 2.6 + 0.01 * i);
  h.set({{"Fe[1]", 0.05}, {"Fe[2]", -0.03}, {"Fe[3]", 0.02}, {"Me_z", 0.001}});
  machine_point(h);
  for (int i = 1; i <= 4; ++i) h.set(("tau[" + std::to_string(i) + "]").c_str(), 0.001 * i);
}

// Perturbing an input moves exactly the unknowns that list it: the pose and
// velocity outputs do not depend on F directly (they are states), lambda and
// the accelerations do.
void check_input_dependencies(Harness& h) {
  const std::vector<double> base = h.read();
  for (std::size_t k = 0; k < h.d.n_variables; ++k) {
    const Variable& in = h.d.variables[k];
    if (in.causality != Causality::Input) continue;
    double x0 = 0.0;
    ASSERT_EQ(h.inst->get_real(&in.vr, 1, &x0), Status::OK);
    const double x1 = x0 != 0.0 ? x0 * (1.0 + 1e-3) : 1e-3;
    ASSERT_EQ(h.inst->set_real(&in.vr, 1, &x1), Status::OK);
    const std::vector<double> moved = h.read();
    ASSERT_EQ(h.inst->set_real(&in.vr, 1, &x0), Status::OK);
    for (std::size_t o = 0; o < h.unknowns.size(); ++o) {
      const bool listed = h.declared(h.unknowns[o]).count(in.vr) != 0;
      const bool moves = moved[o] != base[o];
      EXPECT_EQ(listed, moves) << h.d.find(h.unknowns[o])->name << (moves ? " moves with " : " does not move with ")
                               << in.name << " but " << (listed ? "lists" : "does not list") << " it";
    }
  }
  EXPECT_EQ(h.read(), base) << "restoring every input restores every unknown";
}

TEST(ModelStructure, PlantInputDependenciesAreExact) {
  Harness h(pkm_fmi::pkm4puu_definition(), pkm_fmi::Interface::ModelExchange);
  ASSERT_TRUE(h.inst);
  plant_point(h);
  h.initialize();
  check_input_dependencies(h);
}

TEST(ModelStructure, InverseInputDependenciesAreExact) {
  Harness h(pkm_fmi::pkm4puu_inverse_definition(), pkm_fmi::Interface::CoSimulation);
  ASSERT_TRUE(h.inst);
  h.set({{"x", 0.003}, {"y", -0.002}, {"phi", 0.05}, {"dx", 0.01}, {"dy", 0.02}, {"dz", -0.01}, {"dphi", -0.2},
         {"ddx", 0.1}, {"ddy", -0.2}, {"ddz", 0.3}, {"ddphi", 0.4}, {"Fe[1]", 0.1}, {"Fe[2]", 0.1}, {"Fe[3]", 0.1},
         {"Me_z", 0.01}});
  machine_point(h);
  h.initialize();
  check_input_dependencies(h);
}

// Perturbing a state (Model Exchange) moves exactly the unknowns that list
// it. The machine is invariant to a vertical translation except for the
// slider positions: only rho lists z. ||C(q)|| is zero up to rounding
// whatever the state; it lists the pose and is left out of the comparison.
TEST(ModelStructure, PlantStateDependenciesAreExact) {
  Harness h(pkm_fmi::pkm4puu_definition(), pkm_fmi::Interface::ModelExchange);
  ASSERT_TRUE(h.inst);
  plant_point(h);
  h.initialize();
  ASSERT_EQ(h.inst->enter_continuous_time_mode(), Status::OK);
  const int n = static_cast<int>(h.d.n_states);
  std::vector<double> x(n);
  ASSERT_EQ(h.inst->get_continuous_states(x.data(), n), Status::OK);
  const std::vector<double> base = h.read();
  int listed_and_moved = 0;
  for (int k = 0; k < n; ++k) {
    const Variable* state = nullptr;
    for (std::size_t i = 0; i < h.d.n_variables; ++i)
      if (h.d.variables[i].state == k) state = &h.d.variables[i];
    ASSERT_NE(state, nullptr);
    std::vector<double> y = x;
    y[k] += k < 4 ? 1e-5 : 1e-3;
    ASSERT_EQ(h.inst->set_continuous_states(y.data(), n), Status::OK);
    const std::vector<double> moved = h.read();
    for (std::size_t o = 0; o < h.unknowns.size(); ++o) {
      const std::string name = h.d.find(h.unknowns[o])->name;
      if (name == "constraint_residual") continue;
      // The stops' dissipation, d (d delta/dt)^2 while a stop pushes, does
      // not depend on the depth; it does while a stop is released (k delta
      // d delta/dt) and when contact begins or ends: a structural dependence
      // this point cannot show.
      if (name == "der(dissipated_energy)" && std::string(state->name) == "z") continue;
      const bool listed = h.declared(h.unknowns[o]).count(state->vr) != 0;
      const bool moves = moved[o] != base[o];
      listed_and_moved += listed && moves;
      EXPECT_EQ(listed, moves) << name << (moves ? " moves with " : " does not move with ") << "the state "
                               << state->name << " but " << (listed ? "lists" : "does not list") << " it";
    }
  }
  ASSERT_EQ(h.inst->set_continuous_states(x.data(), n), Status::OK);
  EXPECT_EQ(h.read(), base);
  EXPECT_GT(listed_and_moved, 100);  // the check saw real movement
}

}  // namespace

namespace {

// InitialUnknowns (FMI 2.0.4 section 2.2.8, FMI 3.0.2 section 2.4.8): their
// dependencies on the knowns of Initialization Mode, inputs and parameters,
// generated for both versions from the table (initial_dependencies_of).
// Perturbing each input and each Real parameter before
// ExitInitializationMode moves only InitialUnknowns that list it; a state
// lists exactly its initial-value parameter, and moves with it.
void check_initial_dependencies(const ModelDefinition& d, pkm_fmi::Interface interface) {
  std::vector<std::uint32_t> unknowns;
  for (std::size_t k = 0; k < d.n_variables; ++k) {
    const Variable& v = d.variables[k];
    if ((v.causality == Causality::Output && v.initial != pkm_fmi::Initial::Exact) || v.state_of >= 0 ||
        v.causality == Causality::CalculatedParameter)
      unknowns.push_back(v.vr);
  }
  auto initialised = [&](const Variable* changed, double x, std::vector<double>& y) {
    std::unique_ptr<Instance> inst(Instance::create(d, 3, interface, d.guid().c_str(), pkm_fmi::Logger()));
    if (changed) {
      EXPECT_EQ(inst->set_real(&changed->vr, 1, &x), Status::OK) << changed->name;
    }
    if (inst->enter_initialization_mode() != Status::OK || inst->exit_initialization_mode() != Status::OK)
      return false;
    y.assign(unknowns.size(), 0.0);
    const Status s = inst->get_real(unknowns.data(), unknowns.size(), y.data());
    return s == Status::OK || s == Status::Warning;
  };
  std::vector<double> base;
  ASSERT_TRUE(initialised(nullptr, 0.0, base));
  int moved_and_listed = 0;
  for (std::size_t k = 0; k < d.n_variables; ++k) {
    const Variable& known = d.variables[k];
    if (known.type != pkm_fmi::VarType::Real ||
        (known.causality != Causality::Input && known.causality != Causality::Parameter))
      continue;
    const double x = known.start != 0.0 ? known.start * (1.0 + 1e-3) : 1e-4;
    if (!(x >= known.min && x <= known.max)) continue;
    std::vector<double> y;
    if (!initialised(&known, x, y)) continue;  // a value initialisation refuses moves nothing
    for (std::size_t o = 0; o < unknowns.size(); ++o) {
      const Variable* u = d.find(unknowns[o]);
      const pkm_fmi::Dependencies deps = pkm_fmi::initial_dependencies_of(d, *u);
      const bool listed = std::find(deps.knowns.begin(), deps.knowns.end(), known.vr) != deps.knowns.end();
      const bool moves = y[o] != base[o];
      if (u->name == std::string("constraint_residual")) continue;  // zero up to rounding, whatever moves
      EXPECT_TRUE(listed || !moves) << u->name << " moves with " << known.name << " but does not list it";
      if (u->state >= 0) {
        EXPECT_EQ(listed, moves) << u->name << (moves ? " moves" : " does not move") << " with " << known.name;
      }
      moved_and_listed += listed && moves;
    }
  }
  EXPECT_GT(moved_and_listed, 50) << "the check saw real movement";
}

TEST(ModelStructure, PlantInitialUnknownDependenciesHold) {
  check_initial_dependencies(pkm_fmi::pkm4puu_definition(), pkm_fmi::Interface::ModelExchange);
}

TEST(ModelStructure, InverseInitialUnknownDependenciesHold) {
  check_initial_dependencies(pkm_fmi::pkm4puu_inverse_definition(), pkm_fmi::Interface::CoSimulation);
}

// Every Output, ContinuousStateDerivative and InitialUnknown of both versions
// declares its dependencies (issue 27 item 3: without the attribute an
// importer must assume everything, and some refuse such FMUs).
TEST(ModelStructure, EveryUnknownDeclaresItsDependenciesInBothVersions) {
  for (const ModelDefinition* d : {&pkm_fmi::pkm4puu_definition(), &pkm_fmi::pkm4puu_inverse_definition()}) {
    for (int version : {2, 3}) {
      const std::string xml = pkm_fmi::model_description_xml(*d, version, PKM_VERSION_STRING);
      const std::string structure = xml.substr(xml.find("<ModelStructure>"));
      int unknowns = 0;
      for (std::size_t at = structure.find('<'); at != std::string::npos; at = structure.find('<', at + 1)) {
        const std::string element = structure.substr(at, structure.find('>', at) - at);
        const bool unknown = element.rfind("<Unknown ", 0) == 0 || element.rfind("<Output ", 0) == 0 ||
                             element.rfind("<ContinuousStateDerivative ", 0) == 0 ||
                             element.rfind("<InitialUnknown ", 0) == 0;
        if (!unknown) continue;
        ++unknowns;
        EXPECT_NE(element.find(" dependencies=\""), std::string::npos) << d->identifier << " FMI " << version << ": "
                                                                         << element;
      }
      EXPECT_GT(unknowns, 50);
    }
  }
}

}  // namespace

// The model descriptions (modelDescription/*.xml, as configured into the
// FMUs) against the code's variable tables (fmu_src/fmi): same variables,
// value references, causality, variability, initial, start values, units
// and descriptions; every name of MODEL_SPEC's "FMU interface contract";
// the capability flags, units, log categories and ModelStructure; and
// that the declared dependencies are honest (an output that changes when
// an input or parameter changes lists it).
#include <cmath>
#include <cstdarg>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <map>
#include <memory>
#include <set>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "models.hpp"
#include "params.hpp"
#include "plant.hpp"

namespace {

using pkm_fmi::Causality;
using pkm_fmi::Initial;
using pkm_fmi::ModelDefinition;
using pkm_fmi::Variable;
using pkm_fmi::VarType;

// ---------------------------------------------------------------- a small XML reader
// Elements, attributes, comments, the XML declaration and the five
// predefined entities: all a model description uses.

struct Element {
  std::string name;
  std::map<std::string, std::string> attrs;
  std::vector<Element> children;

  const Element* child(const std::string& n) const {
    for (const auto& c : children)
      if (c.name == n) return &c;
    return nullptr;
  }
  std::vector<const Element*> all(const std::string& n) const {
    std::vector<const Element*> out;
    for (const auto& c : children)
      if (c.name == n) out.push_back(&c);
    return out;
  }
  bool has(const std::string& a) const { return attrs.count(a) != 0; }
  std::string attr(const std::string& a) const {
    auto it = attrs.find(a);
    return it == attrs.end() ? std::string() : it->second;
  }
};

class XmlReader {
 public:
  explicit XmlReader(std::string text) : s_(std::move(text)) {}

  Element parse() {
    skip_misc();
    Element root = element();
    skip_misc();
    if (p_ != s_.size()) fail("content after the root element");
    return root;
  }

 private:
  [[noreturn]] void fail(const std::string& why) const {
    throw std::runtime_error("XML: " + why + " at offset " + std::to_string(p_));
  }
  bool starts(const char* t) const { return s_.compare(p_, std::strlen(t), t) == 0; }
  void skip_space() {
    while (p_ < s_.size() && std::isspace(static_cast<unsigned char>(s_[p_]))) ++p_;
  }
  void skip_until(const char* end) {
    const std::size_t q = s_.find(end, p_);
    if (q == std::string::npos) fail(std::string("missing ") + end);
    p_ = q + std::strlen(end);
  }
  // Whitespace, comments, processing instructions, text between elements.
  void skip_misc() {
    for (;;) {
      while (p_ < s_.size() && s_[p_] != '<') {
        if (!std::isspace(static_cast<unsigned char>(s_[p_]))) fail("unexpected text");
        ++p_;
      }
      if (starts("<!--")) {
        skip_until("-->");
      } else if (starts("<?")) {
        skip_until("?>");
      } else {
        return;
      }
    }
  }
  std::string name() {
    const std::size_t b = p_;
    while (p_ < s_.size() && (std::isalnum(static_cast<unsigned char>(s_[p_])) || s_[p_] == '_' || s_[p_] == ':' ||
                              s_[p_] == '-' || s_[p_] == '.'))
      ++p_;
    if (p_ == b) fail("name expected");
    return s_.substr(b, p_ - b);
  }
  static std::string unescape(const std::string& v) {
    static const std::pair<const char*, char> entities[] = {
        {"&lt;", '<'}, {"&gt;", '>'}, {"&amp;", '&'}, {"&quot;", '"'}, {"&apos;", '\''}};
    std::string out;
    for (std::size_t i = 0; i < v.size();) {
      bool done = false;
      if (v[i] == '&') {
        for (const auto& e : entities) {
          if (v.compare(i, std::strlen(e.first), e.first) == 0) {
            out += e.second;
            i += std::strlen(e.first);
            done = true;
            break;
          }
        }
        if (!done) throw std::runtime_error("XML: unknown entity in " + v);
      } else {
        out += v[i++];
      }
    }
    return out;
  }
  Element element() {
    if (!starts("<")) fail("'<' expected");
    ++p_;
    Element e;
    e.name = name();
    for (;;) {
      skip_space();
      if (starts("/>")) {
        p_ += 2;
        return e;
      }
      if (starts(">")) {
        ++p_;
        break;
      }
      const std::string a = name();
      skip_space();
      if (!starts("=")) fail("'=' expected");
      ++p_;
      skip_space();
      const char quote = s_[p_];
      if (quote != '"' && quote != '\'') fail("quote expected");
      const std::size_t end = s_.find(quote, p_ + 1);
      if (end == std::string::npos) fail("unterminated attribute");
      if (e.attrs.count(a)) fail("duplicate attribute " + a);
      e.attrs[a] = unescape(s_.substr(p_ + 1, end - p_ - 1));
      p_ = end + 1;
    }
    for (;;) {
      skip_misc();
      if (starts("</")) {
        p_ += 2;
        if (name() != e.name) fail("mismatched end tag of " + e.name);
        skip_space();
        if (!starts(">")) fail("'>' expected");
        ++p_;
        return e;
      }
      e.children.push_back(element());
    }
  }

  std::string s_;
  std::size_t p_ = 0;
};

Element read_xml(const char* path) {
  std::ifstream in(path);
  if (!in) throw std::runtime_error(std::string("cannot read ") + path);
  std::stringstream ss;
  ss << in.rdbuf();
  return XmlReader(ss.str()).parse();
}

std::vector<int> parse_indices(const std::string& list) {
  std::vector<int> out;
  std::istringstream in(list);
  int k;
  while (in >> k) out.push_back(k);
  return out;
}

// ---------------------------------------------------------------- the two FMUs

struct Fmu {
  const char* xml_path;
  const ModelDefinition& def;
  const char* guid;  // as the build passed it to the tests
};

const Fmu kPlant{PKM_FMU_PLANT_XML, pkm_fmi::pkm4puu_definition(), PKM_FMU_PLANT_GUID};
const Fmu kInverse{PKM_FMU_INVERSE_XML, pkm_fmi::pkm4puu_inverse_definition(), PKM_FMU_INVERSE_GUID};

std::vector<std::string> indexed(const std::string& base, int n) {
  std::vector<std::string> out;
  for (int i = 1; i <= n; ++i) out.push_back(base + "[" + std::to_string(i) + "]");
  return out;
}

std::vector<std::string> concat(std::initializer_list<std::vector<std::string>> parts) {
  std::vector<std::string> out;
  for (const auto& p : parts) out.insert(out.end(), p.begin(), p.end());
  return out;
}

// MODEL_SPEC "FMU interface contract", name by name.
const std::vector<std::string> kMechanismParameters =
    concat({{"h", "l", "h_prime", "r_b", "r_Q"}, indexed("beta", 4), indexed("gamma", 4),
            {"m_slider", "m_rod"}, indexed("I_rod", 3), {"m_platform", "Izz_platform", "g"}});
const std::vector<std::string> kPlantInputs = concat({indexed("F", 4), indexed("Fe", 3), {"Me_z"}});
const std::vector<std::string> kPlantOutputs =
    concat({{"x", "y", "z", "phi", "dx", "dy", "dz", "dphi"}, indexed("rho", 4), indexed("drho", 4),
            indexed("theta1", 4), indexed("theta2", 4), indexed("lambda", 12),
            {"constraint_residual", "jacobian_condition"}});
const std::vector<std::string> kPlantParameters =
    concat({kMechanismParameters,
            {"x0", "y0", "z0", "phi0", "dx0", "dy0", "dz0", "dphi0", "solver", "rk4_step", "rtol", "atol"}});
const std::vector<std::string> kInverseInputs =
    concat({{"x", "y", "z", "phi", "dx", "dy", "dz", "dphi", "ddx", "ddy", "ddz", "ddphi"}, indexed("Fe", 3),
            {"Me_z"}});
const std::vector<std::string> kInverseOutputs =
    concat({indexed("F", 4), indexed("rho", 4), indexed("drho", 4), indexed("lambda", 12)});

const std::set<std::string> kRequiredUnits = {"m",  "rad",   "N", "N.m",  "kg",    "kg.m2",
                                              "m/s", "rad/s", "s", "m/s2", "rad/s2"};

class ModelDescription : public ::testing::TestWithParam<const Fmu*> {
 protected:
  void SetUp() override {
    ASSERT_NO_THROW(root_ = read_xml(GetParam()->xml_path)) << GetParam()->xml_path;
  }
  const ModelDefinition& def() const { return GetParam()->def; }
  std::vector<const Element*> scalar_variables() const {
    const Element* mv = root_.child("ModelVariables");
    return mv ? mv->all("ScalarVariable") : std::vector<const Element*>{};
  }
  Element root_;
};

TEST_P(ModelDescription, RootAttributes) {
  EXPECT_EQ(root_.name, "fmiModelDescription");
  EXPECT_EQ(root_.attr("fmiVersion"), "2.0");
  EXPECT_EQ(root_.attr("modelName"), def().identifier);
  EXPECT_EQ(root_.attr("guid"), def().guid) << "the binary and modelDescription.xml must agree";
  EXPECT_EQ(root_.attr("guid"), GetParam()->guid);
  EXPECT_EQ(root_.attr("guid").find('@'), std::string::npos) << "placeholder not replaced";
  EXPECT_EQ(root_.attr("variableNamingConvention"), "structured");
  EXPECT_EQ(root_.attr("numberOfEventIndicators"), "0");
  EXPECT_FALSE(root_.attr("generationTool").empty());
  EXPECT_EQ(root_.child("ModelExchange"), nullptr);
}

TEST_P(ModelDescription, CoSimulationCapabilities) {
  const Element* cs = root_.child("CoSimulation");
  ASSERT_NE(cs, nullptr);
  EXPECT_EQ(cs->attr("modelIdentifier"), def().identifier);
  const std::map<std::string, std::string> expected = {
      {"needsExecutionTool", "false"},
      {"canHandleVariableCommunicationStepSize", "true"},
      {"canInterpolateInputs", def().can_interpolate_inputs ? "true" : "false"},
      {"maxOutputDerivativeOrder", "0"},
      {"canRunAsynchronuously", "false"},
      {"canBeInstantiatedOnlyOncePerProcess", "false"},
      {"canNotUseMemoryManagementFunctions", "true"},
      {"canGetAndSetFMUstate", "true"},
      {"canSerializeFMUstate", "true"},
      {"providesDirectionalDerivative", "false"},
  };
  for (const auto& [flag, value] : expected) EXPECT_EQ(cs->attr(flag), value) << flag;
}

TEST_P(ModelDescription, UnitsLogCategoriesAndDefaultExperiment) {
  const Element* units = root_.child("UnitDefinitions");
  ASSERT_NE(units, nullptr);
  std::map<std::string, const Element*> by_name;
  for (const Element* u : units->all("Unit")) {
    EXPECT_EQ(by_name.count(u->attr("name")), 0u) << "duplicate unit " << u->attr("name");
    by_name[u->attr("name")] = u;
    EXPECT_NE(u->child("BaseUnit"), nullptr) << u->attr("name");
  }
  for (const auto& u : kRequiredUnits) EXPECT_EQ(by_name.count(u), 1u) << "unit " << u;
  // SI base exponents of a few units.
  const std::map<std::string, std::map<std::string, std::string>> base = {
      {"N", {{"kg", "1"}, {"m", "1"}, {"s", "-2"}}},    {"N.m", {{"kg", "1"}, {"m", "2"}, {"s", "-2"}}},
      {"kg.m2", {{"kg", "1"}, {"m", "2"}}},             {"m/s2", {{"m", "1"}, {"s", "-2"}}},
      {"rad/s", {{"rad", "1"}, {"s", "-1"}}},           {"m", {{"m", "1"}}},
      {"rad/s2", {{"rad", "1"}, {"s", "-2"}}},
  };
  for (const auto& [unit, exps] : base) {
    ASSERT_TRUE(by_name.count(unit)) << unit;
    const Element* b = by_name[unit]->child("BaseUnit");
    ASSERT_NE(b, nullptr);
    EXPECT_EQ(b->attrs, exps) << unit;
  }
  // Every unit a variable uses is defined.
  for (std::size_t i = 0; i < def().n_variables; ++i) {
    const char* u = def().variables[i].unit;
    if (*u) {
      EXPECT_EQ(by_name.count(u), 1u) << def().variables[i].name << " uses undefined unit " << u;
    }
  }

  const Element* cats = root_.child("LogCategories");
  ASSERT_NE(cats, nullptr);
  const auto cs = cats->all("Category");
  ASSERT_EQ(cs.size(), static_cast<std::size_t>(pkm_fmi::kLogCategoryCount));
  for (int k = 0; k < pkm_fmi::kLogCategoryCount; ++k) {
    EXPECT_EQ(cs[static_cast<std::size_t>(k)]->attr("name"), pkm_fmi::kLogCategoryNames[k]);
    EXPECT_EQ(cs[static_cast<std::size_t>(k)]->attr("description"), pkm_fmi::kLogCategoryDescriptions[k]);
  }

  const Element* de = root_.child("DefaultExperiment");
  ASSERT_NE(de, nullptr);
  EXPECT_EQ(std::strtod(de->attr("startTime").c_str(), nullptr), 0.0);
  EXPECT_EQ(std::strtod(de->attr("stopTime").c_str(), nullptr), 2.0);
  EXPECT_EQ(std::strtod(de->attr("stepSize").c_str(), nullptr), 0.001);
}

TEST_P(ModelDescription, EveryScalarVariableMatchesTheTable) {
  const auto svs = scalar_variables();
  ASSERT_EQ(svs.size(), def().n_variables) << "number of ScalarVariables";
  std::set<std::string> names;
  std::set<unsigned> vrs;
  for (std::size_t k = 0; k < svs.size(); ++k) {
    const Element& e = *svs[k];
    const Variable& v = def().variables[k];  // same order: ModelStructure indices rely on it
    SCOPED_TRACE(std::string("ScalarVariable ") + std::to_string(k + 1) + " " + e.attr("name"));
    EXPECT_TRUE(names.insert(e.attr("name")).second) << "duplicate name";
    EXPECT_TRUE(vrs.insert(static_cast<unsigned>(std::stoul(e.attr("valueReference")))).second)
        << "duplicate value reference";
    EXPECT_EQ(e.attr("name"), v.name);
    EXPECT_EQ(std::stoul(e.attr("valueReference")), v.vr);
    EXPECT_EQ(e.attr("description"), v.description);
    EXPECT_EQ(e.attr("causality"), pkm_fmi::xml_name(v.causality));
    EXPECT_EQ(e.attr("variability"), pkm_fmi::xml_name(v.variability));
    if (v.initial == Initial::None) {
      EXPECT_FALSE(e.has("initial"));
    } else {
      EXPECT_EQ(e.attr("initial"), pkm_fmi::xml_name(v.initial));
    }
    ASSERT_EQ(e.children.size(), 1u);
    const Element& t = e.children[0];
    EXPECT_EQ(t.name, pkm_fmi::xml_name(v.type));
    if (*v.unit) {
      EXPECT_EQ(t.attr("unit"), v.unit);
    } else {
      EXPECT_FALSE(t.has("unit"));
    }
    EXPECT_EQ(t.has("start"), v.has_start()) << "start present iff the table has one";
    if (t.has("start") && v.has_start()) {
      if (v.type == VarType::Real) {
        char* end = nullptr;
        const double x = std::strtod(t.attr("start").c_str(), &end);
        EXPECT_EQ(*end, '\0');
        EXPECT_EQ(x, v.start) << "start " << t.attr("start");  // exact: both spell the same double
      } else {
        EXPECT_EQ(std::stol(t.attr("start")), static_cast<long>(v.start));
      }
    }
    // FMI 2.0 rules the table must follow too.
    if (v.causality == Causality::Input) {
      EXPECT_TRUE(v.has_start());
    }
    if (v.causality == Causality::Output) {
      EXPECT_EQ(v.initial, Initial::Calculated);
    }
    if (v.causality == Causality::Parameter) {
      EXPECT_EQ(v.variability, pkm_fmi::Variability::Fixed);
      EXPECT_EQ(v.initial, Initial::Exact);
    }
  }
}

TEST_P(ModelDescription, ModelStructureListsEveryOutput) {
  const auto svs = scalar_variables();
  const Element* ms = root_.child("ModelStructure");
  ASSERT_NE(ms, nullptr);
  std::vector<int> outputs, initial_unknowns;
  for (std::size_t k = 0; k < def().n_variables; ++k) {
    const Variable& v = def().variables[k];
    if (v.causality == Causality::Output) outputs.push_back(static_cast<int>(k + 1));
    if ((v.causality == Causality::Output && v.initial != Initial::Exact) ||
        v.causality == Causality::CalculatedParameter)
      initial_unknowns.push_back(static_cast<int>(k + 1));
  }
  auto check = [&](const char* section, const std::vector<int>& expected, bool parameters_are_known) {
    const Element* s = ms->child(section);
    ASSERT_NE(s, nullptr) << section;
    const auto unknowns = s->all("Unknown");
    std::vector<int> got;
    for (const Element* u : unknowns) {
      const int index = std::stoi(u->attr("index"));
      got.push_back(index);
      if (!u->has("dependencies")) continue;  // depends on everything: always valid
      int last = 0;
      for (int d : parse_indices(u->attr("dependencies"))) {
        ASSERT_GE(d, 1);
        ASSERT_LE(d, static_cast<int>(def().n_variables));
        EXPECT_GT(d, last) << section << " " << index << ": dependencies sorted, unique";
        last = d;
        const Variable& known = def().variables[d - 1];
        const bool ok = known.causality == Causality::Input ||
                        (parameters_are_known && known.causality == Causality::Parameter);
        EXPECT_TRUE(ok) << section << " " << def().variables[index - 1].name << " depends on " << known.name;
      }
    }
    EXPECT_EQ(got, expected) << section;
  };
  check("Outputs", outputs, false);
  check("InitialUnknowns", initial_unknowns, true);
  EXPECT_EQ(ms->child("Derivatives"), nullptr);
}

TEST_P(ModelDescription, TableIsSortedAndRefsDoNotAlias) {
  const ModelDefinition& d = def();
  EXPECT_TRUE(pkm_fmi::sorted_by_vr(d.variables, d.n_variables));
  // Every variable has its own storage: write distinct values, read them back.
  auto data = d.create();
  std::set<void*> places;
  for (std::size_t k = 0; k < d.n_variables; ++k) {
    const Variable& v = d.variables[k];
    EXPECT_TRUE(places.insert(v.value(*data, v.index)).second) << v.name << " shares storage";
    if (v.derivative) {
      EXPECT_TRUE(places.insert(v.derivative(*data, v.index)).second) << v.name << " derivative";
    }
  }
}

TEST(ModelDescriptionContract, PlantHasEveryContractName) {
  const ModelDefinition& d = pkm_fmi::pkm4puu_definition();
  for (const auto& n : kPlantInputs) {
    const Variable* v = d.find(n.c_str());
    ASSERT_NE(v, nullptr) << n;
    EXPECT_EQ(v->causality, Causality::Input) << n;
    EXPECT_EQ(v->start, 0.0) << n << ": inputs default to 0";
  }
  for (const auto& n : kPlantOutputs) {
    const Variable* v = d.find(n.c_str());
    ASSERT_NE(v, nullptr) << n;
    EXPECT_EQ(v->causality, Causality::Output) << n;
  }
  for (const auto& n : kPlantParameters) {
    const Variable* v = d.find(n.c_str());
    ASSERT_NE(v, nullptr) << n;
    EXPECT_EQ(v->causality, Causality::Parameter) << n;
  }
  EXPECT_EQ(d.find("solver")->type, VarType::Integer);
  EXPECT_EQ(d.find("solver")->start, 0.0) << "CVODE by default";
  EXPECT_EQ(d.find("rk4_step")->start, 1e-3);
  EXPECT_EQ(d.find("rtol")->start, 1e-8);
  EXPECT_EQ(d.find("atol")->start, 1e-10);
  // The initial pose: home, at rest.
  EXPECT_EQ(d.find("z0")->start, 0.05);
  for (const char* n : {"x0", "y0", "phi0", "dx0", "dy0", "dz0", "dphi0"}) EXPECT_EQ(d.find(n)->start, 0.0) << n;
}

TEST(ModelDescriptionContract, InverseHasEveryContractName) {
  const ModelDefinition& d = pkm_fmi::pkm4puu_inverse_definition();
  for (const auto& n : kInverseInputs) {
    const Variable* v = d.find(n.c_str());
    ASSERT_NE(v, nullptr) << n;
    EXPECT_EQ(v->causality, Causality::Input) << n;
  }
  for (const auto& n : kInverseOutputs) {
    const Variable* v = d.find(n.c_str());
    ASSERT_NE(v, nullptr) << n;
    EXPECT_EQ(v->causality, Causality::Output) << n;
  }
  for (const auto& n : kMechanismParameters) {
    const Variable* v = d.find(n.c_str());
    ASSERT_NE(v, nullptr) << n;
    EXPECT_EQ(v->causality, Causality::Parameter) << n;
    // Same name, same value reference and start value as in the plant.
    const Variable* p = pkm_fmi::pkm4puu_definition().find(n.c_str());
    ASSERT_NE(p, nullptr);
    EXPECT_EQ(v->vr, p->vr) << n;
    EXPECT_EQ(v->start, p->start) << n;
  }
}

TEST(ModelDescriptionContract, ParameterStartValuesAreTheCoreDefaults) {
  const pkm::Params p;
  const pkm::SolverSettings s;
  std::map<std::string, double> core = {
      {"h", p.h},
      {"l", p.l},
      {"h_prime", p.h_prime},
      {"r_b", p.r_b},
      {"r_Q", p.r_Q},
      {"m_slider", p.m_slider},
      {"m_rod", p.m_rod},
      {"m_platform", p.m_platform},
      {"Izz_platform", p.Izz_platform},
      {"g", p.g},
      {"solver", static_cast<double>(s.solver)},
      {"rk4_step", s.rk4_step},
      {"rtol", s.rtol},
      {"atol", s.atol},
      {"cvode_method", static_cast<double>(s.cvode_method)},
      {"formulation", static_cast<double>(s.formulation)},
  };
  for (int i = 0; i < 4; ++i) {
    core["beta[" + std::to_string(i + 1) + "]"] = p.beta[static_cast<std::size_t>(i)];
    core["gamma[" + std::to_string(i + 1) + "]"] = p.gamma[static_cast<std::size_t>(i)];
  }
  for (int i = 0; i < 3; ++i) core["I_rod[" + std::to_string(i + 1) + "]"] = p.I_rod[static_cast<std::size_t>(i)];
  for (const auto& [name, value] : core) {
    const Variable* v = pkm_fmi::pkm4puu_definition().find(name.c_str());
    ASSERT_NE(v, nullptr) << name;
    EXPECT_EQ(v->start, value) << name;
  }
}

INSTANTIATE_TEST_SUITE_P(BothFmus, ModelDescription, ::testing::Values(&kPlant, &kInverse),
                         [](const ::testing::TestParamInfo<const Fmu*>& info) {
                           return std::string(info.param == &kPlant ? "PKM4PUU" : "PKM4PUU_Inverse");
                         });

// ---------------------------------------------------------------- honest dependencies
// Through the C++ side of the FMI layer (pkm_fmi::Instance), which the
// exported functions forward to.

struct Log {
  std::vector<std::string> lines;
};

void collect(fmi2ComponentEnvironment env, fmi2String, fmi2Status, fmi2String category, fmi2String message, ...) {
  static_cast<Log*>(env)->lines.push_back(std::string(category) + ": " + message);
}

struct InstanceDeleter {
  void operator()(pkm_fmi::Instance* i) const { delete i; }
};
using InstancePtr = std::unique_ptr<pkm_fmi::Instance, InstanceDeleter>;

InstancePtr make_instance(const Fmu& fmu, Log& log) {
  const fmi2CallbackFunctions functions{&collect, nullptr, nullptr, nullptr, &log};  // copied by the instance
  return InstancePtr(pkm_fmi::Instance::instantiate(fmu.def, "test", fmi2CoSimulation, fmu.def.guid, "", &functions,
                                                    fmi2False, fmi2False));
}

std::vector<double> outputs_of(pkm_fmi::Instance& inst, const std::vector<fmi2ValueReference>& vrs) {
  std::vector<double> v(vrs.size());
  EXPECT_EQ(inst.get_real(vrs.data(), vrs.size(), v.data()), fmi2OK);
  return v;
}

// For each input (and, in initialisation mode, each parameter): perturb it,
// and require every output that changes to list it in ModelStructure.
void check_dependencies(const Fmu& fmu, bool initialization_mode) {
  const Element root = read_xml(fmu.xml_path);
  const Element* section = root.child("ModelStructure")->child(initialization_mode ? "InitialUnknowns" : "Outputs");
  ASSERT_NE(section, nullptr);
  const ModelDefinition& d = fmu.def;
  std::map<int, std::set<int>> declared;  // output index -> declared known indices
  std::set<int> all_known;
  for (const Element* u : section->all("Unknown")) {
    const int index = std::stoi(u->attr("index"));
    std::set<int> deps;
    if (u->has("dependencies")) {
      for (int k : parse_indices(u->attr("dependencies"))) deps.insert(k);
    } else {
      for (std::size_t k = 1; k <= d.n_variables; ++k) deps.insert(static_cast<int>(k));
    }
    declared[index] = deps;
  }
  std::vector<fmi2ValueReference> out_vrs;
  std::vector<int> out_index;
  for (std::size_t k = 0; k < d.n_variables; ++k) {
    if (d.variables[k].causality != Causality::Output) continue;
    out_vrs.push_back(d.variables[k].vr);
    out_index.push_back(static_cast<int>(k + 1));
  }

  Log log;
  InstancePtr inst = make_instance(fmu, log);
  ASSERT_TRUE(inst);
  ASSERT_EQ(inst->setup_experiment(fmi2False, 0, 0, fmi2False, 0), fmi2OK);
  // A generic point: moving, with nonzero inputs.
  auto set = [&](const char* name, double value) {
    const Variable* v = d.find(name);
    ASSERT_NE(v, nullptr) << name;
    ASSERT_EQ(inst->set_real(&v->vr, 1, &value), fmi2OK) << name;
  };
  const bool plant = &d == &pkm_fmi::pkm4puu_definition();
  if (plant) {
    set("x0", 0.002);
    set("phi0", 0.03);
    set("dx0", 0.01);
    set("dz0", -0.02);
    set("dphi0", 0.1);
    for (int i = 1; i <= 4; ++i) set(("F[" + std::to_string(i) + "]").c_str(), 2.6 + 0.01 * i);
    set("Fe[1]", 0.05);
    set("Me_z", 0.001);
  } else {
    set("x", 0.003);
    set("y", -0.002);
    set("phi", 0.05);
    set("dx", 0.01);
    set("dphi", -0.2);
    set("ddz", 0.3);
    set("Fe[2]", 0.1);
  }
  ASSERT_EQ(inst->enter_initialization_mode(), fmi2OK);
  if (!initialization_mode) {
    ASSERT_EQ(inst->exit_initialization_mode(), fmi2OK);
    if (plant) {
      for (int k = 0; k < 5; ++k) ASSERT_EQ(inst->do_step(k * 1e-3, 1e-3, fmi2True), fmi2OK);
    }
  }
  const std::vector<double> base = outputs_of(*inst, out_vrs);
  for (std::size_t k = 0; k < d.n_variables; ++k) {
    const Variable& v = d.variables[k];
    const bool known = v.causality == Causality::Input || (initialization_mode && v.causality == Causality::Parameter);
    if (!known) continue;
    SCOPED_TRACE(std::string("perturbing ") + v.name);
    if (v.type == VarType::Real) {
      double x0;
      ASSERT_EQ(inst->get_real(&v.vr, 1, &x0), fmi2OK);
      const double x1 = x0 != 0.0 ? x0 * (1.0 + 1e-4) : 1e-4;
      ASSERT_EQ(inst->set_real(&v.vr, 1, &x1), fmi2OK);
      const std::vector<double> changed = outputs_of(*inst, out_vrs);
      ASSERT_EQ(inst->set_real(&v.vr, 1, &x0), fmi2OK);
      for (std::size_t o = 0; o < out_vrs.size(); ++o) {
        if (changed[o] != base[o]) {
          EXPECT_TRUE(declared[out_index[o]].count(static_cast<int>(k + 1)))
              << d.variables[out_index[o] - 1].name << " changes with " << v.name << " but does not list it";
        }
      }
    } else {
      fmi2Integer x0;
      ASSERT_EQ(inst->get_integer(&v.vr, 1, &x0), fmi2OK);
      const fmi2Integer x1 = x0 == 0 ? 1 : 0;  // every Integer parameter accepts 0 and 1
      ASSERT_EQ(inst->set_integer(&v.vr, 1, &x1), fmi2OK);
      const std::vector<double> changed = outputs_of(*inst, out_vrs);
      ASSERT_EQ(inst->set_integer(&v.vr, 1, &x0), fmi2OK);
      for (std::size_t o = 0; o < out_vrs.size(); ++o) {
        if (changed[o] != base[o]) {
          EXPECT_TRUE(declared[out_index[o]].count(static_cast<int>(k + 1)))
              << d.variables[out_index[o] - 1].name << " changes with " << v.name << " but does not list it";
        }
      }
    }
  }
  // Restoring every value restores every output.
  EXPECT_EQ(outputs_of(*inst, out_vrs), base);
}

TEST(ModelStructure, PlantOutputDependenciesAreHonest) { check_dependencies(kPlant, false); }
TEST(ModelStructure, PlantInitialUnknownDependenciesAreHonest) { check_dependencies(kPlant, true); }
TEST(ModelStructure, InverseOutputDependenciesAreHonest) { check_dependencies(kInverse, false); }
TEST(ModelStructure, InverseInitialUnknownDependenciesAreHonest) { check_dependencies(kInverse, true); }

// The plant's direct feedthrough is real: lambda does change with every input.
TEST(ModelStructure, PlantLambdaDependsOnEveryInput) {
  Log log;
  InstancePtr inst = make_instance(kPlant, log);
  ASSERT_TRUE(inst);
  ASSERT_EQ(inst->enter_initialization_mode(), fmi2OK);
  ASSERT_EQ(inst->exit_initialization_mode(), fmi2OK);
  const ModelDefinition& d = kPlant.def;
  std::vector<fmi2ValueReference> lambda;
  for (int i = 1; i <= 12; ++i) lambda.push_back(d.find(("lambda[" + std::to_string(i) + "]").c_str())->vr);
  const std::vector<double> base = outputs_of(*inst, lambda);
  for (const auto& n : kPlantInputs) {
    const Variable* v = d.find(n.c_str());
    const double one = 1.0, zero = 0.0;
    ASSERT_EQ(inst->set_real(&v->vr, 1, &one), fmi2OK);
    EXPECT_NE(outputs_of(*inst, lambda), base) << n;
    ASSERT_EQ(inst->set_real(&v->vr, 1, &zero), fmi2OK);
  }
}

}  // namespace

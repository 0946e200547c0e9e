// SPDX-License-Identifier: BSD-2-Clause
// pkm.h: the library, a model's life cycle, its error message and its
// parameters by name (the rows of the parameter table, sim/parameters.hpp).
#include <cstdio>
#include <new>
#include <vector>

#include "capi/capi_model.hpp"

namespace pkm_capi {

pkm_status fail(const pkm_model* m, pkm_status s, const std::string& function, const std::string& why) {
  if (m) m->error = function + ": " + why;
  return s;
}

pkm_status fail(const pkm_model* m, pkm::Status s, const std::string& function) {
  std::string why = pkm::status_name(s);
  if (m && m->plant && !m->plant->last_error().empty()) why += " (" + m->plant->last_error() + ")";
  return fail(m, to_c(s), function, why);
}

pkm_status null_argument(const pkm_model* m, const char* function, const char* argument) {
  return fail(m, PKM_ERR_INVALID_ARGUMENT, function, std::string(argument) + " is NULL");
}

pkm_status first_null(const pkm_model* m, const char* function,
                      std::initializer_list<std::pair<const char*, const void*>> args) {
  for (const auto& [name, pointer] : args)
    if (!pointer) return null_argument(m, function, name);
  return PKM_OK;
}

pkm_status bad_size(const pkm_model* m, const char* function, const char* type, std::size_t size,
                    std::size_t first_size) {
  char buf[160];
  std::snprintf(buf, sizeof buf, "%s.size = %zu is less than %zu: set it to sizeof(%s)", type, size, first_size,
                type);
  return fail(m, PKM_ERR_INVALID_ARGUMENT, function, buf);
}

std::string at_pose(const char* function, const double* pose) {
  char buf[200];
  std::snprintf(buf, sizeof buf, "%s(x=%g, y=%g, z=%g, phi=%g)", function, pose[0], pose[1], pose[2], pose[3]);
  return buf;
}

namespace {

/// The rows the C API sets: all but the plant FMU's initial state, which
/// pkm_init_pose takes.
const std::vector<const pkm::Parameter*>& api_rows() {
  static const std::vector<const pkm::Parameter*> rows = [] {
    std::vector<const pkm::Parameter*> r;
    for (const pkm::Parameter& p : pkm::kParameters)
      if (p.target != pkm::ParameterTarget::Initial) r.push_back(&p);
    return r;
  }();
  return rows;
}

const pkm::Parameter* api_row(const char* name) {
  const pkm::Parameter* p = pkm::find_parameter(name);
  return p && p->target != pkm::ParameterTarget::Initial ? p : nullptr;
}

bool is_solver_setting(const pkm::Parameter& p) {
  return p.target == pkm::ParameterTarget::Solver || p.target == pkm::ParameterTarget::Guard;
}

/// A plant of `config`: its model made, its solver set; *why says what failed.
pkm_status make_plant(const pkm::Configuration& config, std::unique_ptr<pkm::Plant>& out, std::string* why) {
  pkm::Model model;
  const pkm::Status s = pkm::make_model(config.params, model, why);
  if (s != pkm::Status::Ok) return to_c(s);
  auto plant = std::unique_ptr<pkm::Plant>(new (std::nothrow) pkm::Plant(model));
  if (!plant) {
    *why = "out of memory";
    return PKM_ERR_OUT_OF_MEMORY;
  }
  if (plant->set_solver(config.solver, why) != pkm::Status::Ok) return PKM_ERR_INVALID_PARAMETER;
  out = std::move(plant);
  return PKM_OK;
}

pkm_status no_such_parameter(const pkm_model* m, const char* fn, const char* name) {
  return fail(m, PKM_ERR_INVALID_ARGUMENT, fn,
              std::string("no parameter is called \"") + name +
                  "\" (pkm_parameter_count and pkm_parameter_info list them)");
}

/// pkm_set_parameters for `fn`.
pkm_status set_parameters(pkm_model* m, const char* fn, size_t n, const char* const names[], const double values[]) {
  pkm::Configuration next = m->config;
  bool fixed_changed = false, tunable_changed = false, solver_changed = false;
  for (size_t k = 0; k < n; ++k) {
    if (!names[k]) return null_argument(m, fn, "a name");
    const pkm::Parameter* p = api_row(names[k]);
    if (!p) return no_such_parameter(m, fn, names[k]);
    const std::string why = p->check(values[k]);
    if (!why.empty()) return fail(m, PKM_ERR_INVALID_PARAMETER, fn, why);
    if (p->get(next) == values[k]) continue;
    p->set(next, values[k]);
    (is_solver_setting(*p) ? solver_changed
     : p->variability == pkm::ParameterVariability::Tunable ? tunable_changed
                                                            : fixed_changed) = true;
  }
  std::string why;
  if (fixed_changed) {
    // A new plant: the run ends (a changed machine has no state to go on from).
    std::unique_ptr<pkm::Plant> plant;
    const pkm_status s = make_plant(next, plant, &why);
    if (s != PKM_OK) return fail(m, s, fn, why);
    if (m->plant->initialized()) m->run_ended = "a parameter of the machine changed since pkm_init_pose";
    m->plant = std::move(plant);
  } else {
    // Solver settings and tunable parameters keep the run: checked first, so
    // that the settings, once taken, are followed by a change that cannot fail.
    if (tunable_changed) {
      why = pkm::validate(next.params);
      if (!why.empty()) return fail(m, PKM_ERR_INVALID_PARAMETER, fn, why);
    }
    if (solver_changed && m->plant->set_solver(next.solver, &why) != pkm::Status::Ok)
      return fail(m, PKM_ERR_INVALID_PARAMETER, fn, why);
    if (tunable_changed) {
      const pkm::Status s = m->plant->retune(next.params);
      if (s != pkm::Status::Ok) {
        if (solver_changed) m->plant->set_solver(m->config.solver);
        return fail(m, s, fn);
      }
    }
  }
  m->config = next;
  return PKM_OK;
}

}  // namespace
}  // namespace pkm_capi

using namespace pkm_capi;

extern "C" {

const char* pkm_version(void) { return PKM_VERSION_STRING; }

int pkm_abi_version(void) { return PKM_ABI_VERSION; }

const char* pkm_status_string(pkm_status s) {
  if (s == PKM_ERR_OUT_OF_MEMORY) return "out of memory";
  return pkm::status_name(static_cast<pkm::Status>(s));
}

pkm_status pkm_create(pkm_model** out) {
  if (!out) return PKM_ERR_INVALID_ARGUMENT;
  *out = nullptr;
  auto m = std::unique_ptr<pkm_model>(new (std::nothrow) pkm_model);
  if (!m) return PKM_ERR_OUT_OF_MEMORY;
  std::string why;
  const pkm_status s = make_plant(m->config, m->plant, &why);
  if (s != PKM_OK) return s;
  *out = m.release();
  return PKM_OK;
}

void pkm_destroy(pkm_model* m) { delete m; }

const char* pkm_last_error(const pkm_model* m) { return m ? m->error.c_str() : "NULL handle"; }

pkm_status pkm_set_parameters(pkm_model* m, size_t n, const char* const names[], const double values[]) {
  const char* fn = "pkm_set_parameters";
  if (!m) return PKM_ERR_INVALID_ARGUMENT;
  if (n > 0 && !names) return null_argument(m, fn, "names");
  if (n > 0 && !values) return null_argument(m, fn, "values");
  return set_parameters(m, fn, n, names, values);
}

pkm_status pkm_set_parameter(pkm_model* m, const char* name, double value) {
  if (!m) return PKM_ERR_INVALID_ARGUMENT;
  if (!name) return null_argument(m, "pkm_set_parameter", "name");
  return set_parameters(m, "pkm_set_parameter", 1, &name, &value);
}

pkm_status pkm_get_parameter(const pkm_model* m, const char* name, double* value) {
  const char* fn = "pkm_get_parameter";
  if (!m) return PKM_ERR_INVALID_ARGUMENT;
  if (!name) return null_argument(m, fn, "name");
  if (!value) return null_argument(m, fn, "value");
  const pkm::Parameter* p = api_row(name);
  if (!p) return no_such_parameter(m, fn, name);
  *value = p->get(m->config);
  return PKM_OK;
}

size_t pkm_parameter_count(void) { return api_rows().size(); }

pkm_status pkm_parameter_info(size_t index, pkm_parameter* info) {
  if (!info || index >= api_rows().size()) return PKM_ERR_INVALID_ARGUMENT;
  if (!size_ok(info, PKM_CAPI_SIZE_THROUGH(pkm_parameter, value_reference))) return PKM_ERR_INVALID_ARGUMENT;
  const pkm::Parameter& p = *api_rows()[index];
  pkm_parameter r{};
  r.name = p.name;
  r.unit = p.unit;
  r.description = p.description;
  r.start = p.start();
  r.min = p.lo;
  r.max = p.hi;
  r.is_integer = p.type == pkm::ParameterType::Integer;
  r.is_solver_setting = is_solver_setting(p);
  r.is_tunable = p.variability == pkm::ParameterVariability::Tunable;
  r.fmus = p.fmus;
  r.value_reference = p.vr;
  deliver(info, r);
  return PKM_OK;
}

}  // extern "C"

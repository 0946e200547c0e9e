// SPDX-License-Identifier: BSD-2-Clause
// Partial derivatives through FMI: fmi2GetDirectionalDerivative,
// fmi3GetDirectionalDerivative and fmi3GetAdjointDerivative. The layer
// checks the call (state, counts, references: in Model Exchange the unknowns
// are outputs and state derivatives and the knowns continuous states and
// inputs; in Co-Simulation outputs and inputs at the current instant), sets
// to zero what the ModelStructure declares independent, asks the model for
// the rest (ModelData::partial_derivatives) and applies the seed.
#include <cmath>

#include "fmi/instance.hpp"
#include "fmi/model_description.hpp"
#include "fmi/state_machine.hpp"

namespace pkm_fmi {
namespace {

bool depends_on(const ModelDefinition& def, const Variable& unknown, const Variable* const knowns[], std::size_t nk) {
  for (std::size_t j = 0; j < nk; ++j)
    if (is_dependency(def, unknown, *knowns[j])) return true;
  return false;
}

}  // namespace

Status Instance::partial_derivative(const char* fn, bool adjoint, const std::uint32_t unknowns[], std::size_t nu,
                                    const std::uint32_t knowns[], std::size_t nk, const double seed[],
                                    std::size_t n_seed, double sensitivity[], std::size_t n_sensitivity) {
  if (!allowed(Call::PartialDerivative, fn)) return Status::Error;
  if (!def_.provides_derivatives)
    return not_supported(fn, version_ == 2 ? "providesDirectionalDerivative = false"
                                           : "providesDirectionalDerivatives = false");
  const std::size_t want_seed = adjoint ? nu : nk, want_sensitivity = adjoint ? nk : nu;
  if ((nu > 0 && !unknowns) || (nk > 0 && !knowns) || (want_seed > 0 && !seed) ||
      (want_sensitivity > 0 && !sensitivity)) {
    log_.error("%s: NULL array; the call has no effect", fn);
    return Status::Error;
  }
  if (n_seed != want_seed || n_sensitivity != want_sensitivity) {
    log_.error("%s: nSeed = %llu and nSensitivity = %llu, expected %llu and %llu (the numbers of %s and %s); the "
               "call has no effect",
               fn, static_cast<unsigned long long>(n_seed), static_cast<unsigned long long>(n_sensitivity),
               static_cast<unsigned long long>(want_seed), static_cast<unsigned long long>(want_sensitivity),
               adjoint ? "unknowns" : "knowns", adjoint ? "knowns" : "unknowns");
    return Status::Error;
  }
  const bool me = interface_ == Interface::ModelExchange;
  // Each reference must name a Real variable of the role `fits` says.
  auto resolve = [&](const std::uint32_t vrs[], std::size_t n, bool (*fits)(const Variable&, bool),
                     const char* role, const char* rule, std::vector<const Variable*>& out) {
    out.clear();
    for (std::size_t i = 0; i < n; ++i) {
      const Variable* v = def_.find(vrs[i]);
      if (!v || v->type != VarType::Real || !fits(*v, me)) {
        log_.error("%s: value reference %u is not %s of this FMU (%s); the call has no effect", fn,
                   static_cast<unsigned>(vrs[i]), role, rule);
        return false;
      }
      out.push_back(v);
    }
    return true;
  };
  auto is_unknown = [](const Variable& v, bool me) {
    return v.causality == Causality::Output || (me && v.state_of >= 0);
  };
  auto is_known = [](const Variable& v, bool me) { return v.causality == Causality::Input || (me && v.state >= 0); };
  if (!resolve(unknowns, nu, is_unknown, "an unknown",
               me ? "Model Exchange: an output or a state derivative" : "Co-Simulation: an output", d_unknowns_) ||
      !resolve(knowns, nk, is_known, "a known",
               me ? "Model Exchange: a continuous state or an input" : "Co-Simulation: an input", d_knowns_))
    return Status::Error;
  for (std::size_t k = 0; k < want_seed; ++k) {
    if (!std::isfinite(seed[k])) {
      log_.error("%s: seed[%llu] = %g is not finite; the call has no effect", fn, static_cast<unsigned long long>(k),
                 seed[k]);
      return Status::Error;
    }
  }
  // The structural zeros, then the model for the unknowns that depend on a known.
  d_jacobian_.assign(nu * nk, 0.0);
  d_asked_.clear();
  d_rows_.clear();
  for (std::size_t i = 0; i < nu; ++i) {
    if (depends_on(def_, *d_unknowns_[i], d_knowns_.data(), nk)) {
      d_asked_.push_back(d_unknowns_[i]);
      d_rows_.push_back(i);
    }
  }
  if (!d_asked_.empty()) {
    d_asked_jacobian_.assign(d_asked_.size() * nk, 0.0);
    Context ctx = context();
    const Status s =
        data_->partial_derivatives(ctx, d_asked_.data(), d_asked_.size(), d_knowns_.data(), nk, d_asked_jacobian_.data());
    if (s != Status::OK) {
      log_.call("%s: derivatives not available; the call has no effect", fn);
      return s;
    }
    for (std::size_t r = 0; r < d_rows_.size(); ++r)
      for (std::size_t j = 0; j < nk; ++j) d_jacobian_[d_rows_[r] * nk + j] = d_asked_jacobian_[r * nk + j];
  }
  if (adjoint) {
    for (std::size_t j = 0; j < nk; ++j) {
      double sum = 0.0;
      for (std::size_t i = 0; i < nu; ++i) sum += d_jacobian_[i * nk + j] * seed[i];
      sensitivity[j] = sum;
    }
  } else {
    for (std::size_t i = 0; i < nu; ++i) {
      double sum = 0.0;
      for (std::size_t j = 0; j < nk; ++j) sum += d_jacobian_[i * nk + j] * seed[j];
      sensitivity[i] = sum;
    }
  }
  return Status::OK;
}

}  // namespace pkm_fmi

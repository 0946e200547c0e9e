// SPDX-License-Identifier: BSD-2-Clause
#include "fmi/fmu_state.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <memory>

#include "fmi/fnv1a.hpp"
#include "fmi/instance.hpp"
#include "fmi/state_machine.hpp"

namespace pkm_fmi {
namespace {

constexpr std::uint64_t kStateTag = 0x53324d464d4b5002ull;  // marks a live SavedState
constexpr unsigned char kMagic[8] = {'P', 'K', 'M', 'F', 'M', 'U', 'S', 'T'};
constexpr std::uint32_t kFormatVersion = 6;  // 3: the plant's energy integrals and end-stop contacts; 4: elapsed
// time; 5: the plant's end-stop record is its contact mode (held between events, hysteresis); 6: the FMI version
// in the header, the plant's integrators' memory
constexpr std::size_t kHeaderSize = 32;
constexpr std::size_t kTrailerSize = 8;

double read_as_double(ModelData& d, const Variable& v) {
  void* p = v.value(d, v.index);
  switch (v.type) {
    case VarType::Real: return *static_cast<double*>(p);
    case VarType::Integer: return static_cast<double>(*static_cast<std::int32_t*>(p));
    case VarType::Boolean: return *static_cast<int*>(p) ? 1.0 : 0.0;
  }
  return 0.0;
}

std::uint32_t stored_count(const ModelDefinition& d) {
  std::uint32_t n = 0;
  for (std::size_t i = 0; i < d.n_variables; ++i)
    n += (d.variables[i].stored_in_state() ? 1u : 0u) + (d.variables[i].derivative ? 1u : 0u);
  return n;
}

}  // namespace

void write_from_double(ModelData& d, const Variable& v, double x) {
  void* p = v.value(d, v.index);
  switch (v.type) {
    case VarType::Real: *static_cast<double*>(p) = x; break;
    case VarType::Integer: *static_cast<std::int32_t*>(p) = static_cast<std::int32_t>(x); break;
    case VarType::Boolean: *static_cast<int*>(p) = x != 0.0 ? 1 : 0; break;
  }
}

SavedState* as_state(void* handle) {
  auto* p = static_cast<SavedState*>(handle);
  return (p && p->tag == kStateTag) ? p : nullptr;
}

SavedState* make_state(Instance* owner) {
  auto* s = new SavedState{kStateTag, {}, owner};
  return s;
}

void destroy_state(SavedState* s) {
  *static_cast<volatile std::uint64_t*>(&s->tag) = 0;
  delete s;
}

SavedState* Instance::new_state() {
  std::unique_ptr<SavedState> owned(make_state(this));
  states_.insert(owned.get());  // may throw: then nothing leaks
  return owned.release();
}

void Instance::save(std::vector<unsigned char>& out) const {
  out.clear();
  StateWriter w(out);
  for (unsigned char c : kMagic) w.u8(c);
  w.u32(kFormatVersion);
  w.u32(static_cast<std::uint32_t>(version_));
  w.u64(0);  // total size, patched below
  w.u64(fnv1a(token_.c_str()));
  // Generic part.
  w.u32(mode_);
  w.u8(stop_time_defined_ ? 1 : 0);
  w.u8(terminated_ ? 1 : 0);
  w.u8(static_cast<std::uint8_t>(interface_));
  w.f64(start_time_);
  w.f64(stop_time_);
  w.f64(time_);
  w.f64(last_successful_time_);
  w.f64(elapsed_);
  w.u32(stored_count(def_));
  for (std::size_t i = 0; i < def_.n_variables; ++i) {
    const Variable& v = def_.variables[i];
    if (!v.stored_in_state()) continue;
    if (v.type == VarType::Real) {
      w.f64(*static_cast<double*>(v.value(*data_, v.index)));
    } else {
      w.i64(static_cast<std::int64_t>(read_as_double(*data_, v)));
    }
  }
  for (std::size_t i = 0; i < def_.n_variables; ++i) {
    const Variable& v = def_.variables[i];
    if (v.derivative) w.f64(*static_cast<double*>(v.derivative(*data_, v.index)));
  }
  data_->save(w);  // the model's part
  write_le64(out.data() + 16, out.size() + kTrailerSize);
  w.u64(fnv1a(out.data(), out.size()));
}

void Instance::reserve_state_buffers() {
  load_values_.reserve(stored_count(def_));
  save(load_backup_);  // an initialised model's state has its final size
  if (version_ == 3 && interface_ == Interface::CoSimulation) step_start_.reserve(load_backup_.size());
}

bool Instance::check_header(const unsigned char* bytes, std::size_t size, const char* function) {
  if (!bytes || size < kHeaderSize + kTrailerSize || std::memcmp(bytes, kMagic, sizeof kMagic) != 0) {
    log_.error("%s: not a serialised FMU state of this FMU (size %llu, no magic number)", function,
               static_cast<unsigned long long>(size));
    return false;
  }
  const std::uint32_t version = read_le32(bytes + 8);
  if (version != kFormatVersion) {
    log_.error("%s: FMU state format version %u, this FMU reads version %u", function, version, kFormatVersion);
    return false;
  }
  // FMI 2.0.4 section 2.1.8, FMI 3.0.2 section 2.2.6: a state of this FMU,
  // and an FMI 2.0 and an FMI 3.0 FMU are two, with states of their own.
  const std::uint32_t fmi_version = read_le32(bytes + 12);
  if (fmi_version != static_cast<std::uint32_t>(version_)) {
    log_.error("%s: the FMU state was saved by an FMI %u.0 instance, this one is FMI %d.0 (each version's FMU "
               "takes its own states only)",
               function, fmi_version, version_);
    return false;
  }
  if (read_le64(bytes + 16) != size) {
    log_.error("%s: FMU state of %llu bytes says it has %llu", function, static_cast<unsigned long long>(size),
               static_cast<unsigned long long>(read_le64(bytes + 16)));
    return false;
  }
  if (read_le64(bytes + 24) != fnv1a(token_.c_str())) {
    log_.error("%s: the FMU state belongs to another FMU (instantiation token differs from %s)", function,
               token_.c_str());
    return false;
  }
  if (read_le64(bytes + size - kTrailerSize) != fnv1a(bytes, size - kTrailerSize)) {
    log_.error("%s: FMU state corrupted (checksum mismatch)", function);
    return false;
  }
  return true;
}

bool Instance::times_consistent(std::uint32_t mode, double start, bool stop_defined, double stop, double time,
                                double last_successful, double elapsed, const char* function) {
  const char* why = nullptr;
  if (!std::isfinite(start) || !std::isfinite(stop) || !std::isfinite(time) || !std::isfinite(last_successful) ||
      !std::isfinite(elapsed))
    why = "a time is not finite";
  else if (stop_defined && !(stop >= start))
    why = "stopTime lies before startTime";
  else if (interface_ == Interface::CoSimulation && !(time >= start && last_successful >= start))
    why = "the time lies before startTime";
  else if (interface_ == Interface::CoSimulation && stop_defined &&
           time > stop + 1e-9 * std::max(1.0, std::abs(stop)))
    why = "the time lies past stopTime";
  else if (interface_ == Interface::CoSimulation &&
           !(std::abs(start + elapsed - time) <= 1e-9 * std::max(1.0, std::abs(time))))
    why = "the time since startTime does not match the time";
  else if (interface_ == Interface::CoSimulation && mode != kError && last_successful != time)
    why = "the last successful time differs from the time, as only an Error leaves it";
  if (!why) return true;
  log_.error("%s: malformed FMU state (%s: startTime = %.17g, stopTime = %.17g%s, time = %.17g, last successful "
             "time = %.17g); nothing changed",
             function, why, start, stop, stop_defined ? "" : " (undefined)", time, last_successful);
  return false;
}

bool Instance::modes_consistent(std::uint32_t mode, bool terminated, const char* function) {
  const bool cs2 = interface_ == Interface::CoSimulation && version_ == 2;
  const char* why = nullptr;
  if (!(mode & reachable_modes(version_, interface_)))
    why = "a state no instance of this FMI version and interface enters";
  else if (terminated && !(cs2 && (mode & kAfterDiscard)))
    why = "fmi2Terminated set where no Discard can have set it";
  else if (!terminated && (mode & kStepFailed))
    why = "stepFailed without fmi2Terminated, which its Discard sets";
  if (!why) return true;
  log_.error("%s: malformed FMU state (%s: %s in an FMI %d.0 %s instance); nothing changed", function, why,
             mode_name(mode), version_, interface_name(interface_));
  return false;
}

bool Instance::load(const unsigned char* bytes, std::size_t size, const char* function, bool keep_backup) {
  if (!check_header(bytes, size, function)) return false;
  StateReader r(bytes + kHeaderSize, size - kHeaderSize - kTrailerSize);
  const std::uint32_t mode = r.u32();
  const bool stop_defined = r.u8() != 0;
  const bool terminated = r.u8() != 0;
  const std::uint8_t interface = r.u8();
  const double start_time = r.f64();
  const double stop_time = r.f64();
  const double time = r.f64();
  const double last_time = r.f64();
  const double elapsed = r.f64();
  const std::uint32_t count = r.u32();
  const std::uint32_t expected = stored_count(def_);
  if (!r.ok() || count != expected || !(mode & kAlive) || (mode & (mode - 1)) != 0) {
    log_.error("%s: malformed FMU state (mode %u, %u values where %u expected)", function, mode, count, expected);
    return false;
  }
  if (interface != static_cast<std::uint8_t>(interface_)) {
    log_.error("%s: the FMU state was saved by a %s instance, this one is %s", function,
               interface == 0 ? "Model Exchange" : "Co-Simulation", interface_name(interface_));
    return false;
  }
  if (!modes_consistent(mode, terminated, function)) return false;
  // Read every value before changing anything (into a buffer reserved at
  // instantiation: restoring a state allocates nothing).
  std::size_t k = 0;
  std::vector<double>& values = load_values_;
  values.clear();
  values.reserve(count);
  for (std::size_t i = 0; i < def_.n_variables; ++i) {
    const Variable& v = def_.variables[i];
    if (!v.stored_in_state()) continue;
    if (v.type == VarType::Real) {
      values.push_back(r.f64());
    } else {
      const std::int64_t x = r.i64();
      if (x < INT32_MIN || x > INT32_MAX) {
        log_.error("%s: malformed FMU state (%s = %lld)", function, v.name, static_cast<long long>(x));
        return false;
      }
      values.push_back(static_cast<double>(x));
    }
  }
  for (std::size_t i = 0; i < def_.n_variables; ++i)
    if (def_.variables[i].derivative) values.push_back(r.f64());
  if (!r.ok()) {
    log_.error("%s: malformed FMU state (truncated)", function);
    return false;
  }
  // Every field as a setter or a step would have checked it: a state with a
  // valid checksum may still have been forged.
  if (!times_consistent(mode, start_time, stop_defined, stop_time, time, last_time, elapsed, function)) return false;
  k = 0;
  for (std::size_t i = 0; i < def_.n_variables; ++i) {
    const Variable& v = def_.variables[i];
    if (!v.stored_in_state()) continue;
    const double x = values[k++];
    if (!std::isfinite(x) || !(x >= v.min && x <= v.max)) {
      log_.error("%s: malformed FMU state (%s = %.17g, outside its range [%.17g, %.17g]); nothing changed",
                 function, v.name, x, v.min, v.max);
      return false;
    }
  }
  for (; k < values.size(); ++k) {
    if (!std::isfinite(values[k])) {
      log_.error("%s: malformed FMU state (a non-finite input derivative); nothing changed", function);
      return false;
    }
  }
  // Commit, keeping a copy of the current state to fall back to (its buffer
  // sized once initialised, reused).
  if (keep_backup) save(load_backup_);
  k = 0;
  for (std::size_t i = 0; i < def_.n_variables; ++i) {
    const Variable& v = def_.variables[i];
    if (v.stored_in_state()) write_from_double(*data_, v, values[k++]);
  }
  for (std::size_t i = 0; i < def_.n_variables; ++i) {
    const Variable& v = def_.variables[i];
    if (v.derivative) *static_cast<double*>(v.derivative(*data_, v.index)) = values[k++];
  }
  input_derivatives_set_ = true;  // the restored state may carry derivatives
  mode_ = mode;
  stop_time_defined_ = stop_defined;
  terminated_ = terminated;
  start_time_ = start_time;
  stop_time_ = stop_time;
  time_ = time;
  last_successful_time_ = last_time;
  elapsed_ = elapsed;
  time_floor_ = time;  // ME: a restored state starts its own history
  valid_groups_ = 0;
  Context ctx = context();
  // The model replaces what it derived (its solver restarts); it may keep
  // its objects when the parameters are unchanged.
  const bool ok = data_->load(r, ctx) && r.ok() && r.at_end();
  if (ok) return true;
  log_.error("%s: the FMU state cannot be restored; the previous state is kept", function);
  // Cannot fail: the backup was just written.
  if (!keep_backup || !load(load_backup_.data(), load_backup_.size(), function, false)) mode_ = kError;
  return false;
}

Status Instance::get_fmu_state(void** state) {
  const char* fn = PKM_FN2(fmi2GetFMUstate, fmi3GetFMUState);
  if (!allowed(Call::FmuState, fn)) return Status::Error;
  if (!state) {
    log_.error("%s: FMUState is NULL", fn);
    return Status::Error;
  }
  SavedState* s = nullptr;
  if (*state) {
    s = as_state(*state);
    if (!s) {
      log_.error("%s: *FMUState is neither NULL nor an FMU state of this FMU", fn);
      return Status::Error;
    }
  } else {
    s = new_state();
    *state = s;
  }
  save(s->bytes);  // an observation: the run goes on as without it
  log_.event("%s: state saved at t = %.17g (%llu bytes)", fn, time_,
             static_cast<unsigned long long>(s->bytes.size()));
  return Status::OK;
}

SavedState* Instance::state_argument(const char* fn, void* state, const void* out, const char* out_name) {
  if (!allowed(Call::FmuState, fn)) return nullptr;
  SavedState* s = as_state(state);
  if (!s || (out_name && !out)) {
    if (out_name && !out) log_.error("%s: %s is NULL", fn, out_name);
    else log_.error("%s: not an FMU state of this FMU", fn);
    return nullptr;
  }
  return s;
}

Status Instance::set_fmu_state(void* state) {
  const char* fn = PKM_FN2(fmi2SetFMUstate, fmi3SetFMUState);
  SavedState* s = state_argument(fn, state);
  if (!s) return Status::Error;
  if (!load(s->bytes.data(), s->bytes.size(), fn, true)) return Status::Error;
  log_.event("%s: state restored at t = %.17g (%s)", fn, time_, mode_name(mode_));
  return Status::OK;
}

Status Instance::free_fmu_state(void** state) {
  const char* fn = PKM_FN2(fmi2FreeFMUstate, fmi3FreeFMUState);
  if (!allowed(Call::FmuState, fn)) return Status::Error;
  if (!state || !*state) return Status::OK;
  SavedState* s = as_state(*state);
  if (!s) {
    log_.error("%s: not an FMU state of this FMU", fn);
    return Status::Error;
  }
  if (s->owner) s->owner->forget_state(s);  // freed through another instance of this FMU: its creator forgets it
  destroy_state(s);
  *state = nullptr;
  return Status::OK;
}

Status Instance::serialized_fmu_state_size(void* state, std::size_t* size) {
  const char* fn = PKM_FN2(fmi2SerializedFMUstateSize, fmi3SerializedFMUStateSize);
  SavedState* s = state_argument(fn, state, size, "size");
  if (!s) return Status::Error;
  *size = s->bytes.size();
  return Status::OK;
}

Status Instance::serialize_fmu_state(void* state, unsigned char bytes[], std::size_t size) {
  const char* fn = PKM_FN2(fmi2SerializeFMUstate, fmi3SerializeFMUState);
  SavedState* s = state_argument(fn, state, bytes, "serializedState");
  if (!s) return Status::Error;
  if (size < s->bytes.size()) {
    log_.error("%s: buffer of %llu bytes, %llu needed (SerializedFMUStateSize)", fn,
               static_cast<unsigned long long>(size), static_cast<unsigned long long>(s->bytes.size()));
    return Status::Error;
  }
  std::memcpy(bytes, s->bytes.data(), s->bytes.size());
  return Status::OK;
}

Status Instance::deserialize_fmu_state(const unsigned char bytes[], std::size_t size, void** state) {
  const char* fn = PKM_FN2(fmi2DeSerializeFMUstate, fmi3DeserializeFMUState);
  if (!allowed(Call::FmuState, fn)) return Status::Error;
  if (!state) {
    log_.error("%s: FMUState is NULL", fn);
    return Status::Error;
  }
  if (!check_header(bytes, size, fn)) return Status::Error;
  std::vector<unsigned char> copy(bytes, bytes + size);
  SavedState* s = new_state();
  s->bytes.swap(copy);
  *state = s;
  return Status::OK;
}

}  // namespace pkm_fmi

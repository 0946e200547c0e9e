// SPDX-License-Identifier: BSD-2-Clause
// The plant FMU's part of an FMU state: what it saves, and what it checks
// before it restores (fmu_state.cpp holds the layer's part).
#include <cstdint>
#include <cstring>

#include "models/PKM4PUU/plant_data.hpp"
#include "models/PKM4PUU/plant_state.hpp"

namespace pkm_fmi {
namespace pkm4puu_model {

// The plant's part of an FMU state: its snapshot (plant.hpp), the
// integrators' memory whole, as its bytes after their count (a state of a
// build whose memory differs in size is refused); kPlantStateLayout says
// where each field lies.
constexpr PlantStateLayout kAt = kPlantStateLayout;
static_assert(kAt.y - kAt.t == sizeof(pkm::PlantSnapshot::t) && kAt.theta1 - kAt.y == sizeof(pkm::PlantSnapshot::y) &&
                  kAt.energy - kAt.theta1 == sizeof(pkm::PlantSnapshot::theta1_ref) &&
                  kAt.memory - kAt.stops == 2 * sizeof(std::uint32_t) &&
                  kAt.size - kAt.memory == sizeof(pkm::PlantSnapshot::memory),
              "kPlantStateLayout is the snapshot's fields as save() writes them");

void PlantData::save(StateWriter& w) const {
  const bool has = plant && plant->initialized();
  w.u8(has ? 1 : 0);
  if (!has) return;
  const pkm::PlantSnapshot s = plant->snapshot();
  w.f64(s.t);
  w.f64s(s.y.data(), s.y.data() + 8);
  w.f64s(s.theta1_ref.data(), s.theta1_ref.data() + 4);
  w.f64(s.energy.actuator_work);
  w.f64(s.energy.dissipated);
  w.u32(s.stops);  // the contact mode: part of the hybrid state
  w.u32(static_cast<std::uint32_t>(sizeof s.memory));
  w.bytes(&s.memory, sizeof s.memory);
}

bool PlantData::load(StateReader& r, Context& ctx) {
  const char* fn = "SetFMUState";
  if (r.u8() == 0) {
    if (!r.ok()) return false;
    if (ctx.initialized) {  // Step Mode, Event Mode, ...: only after ExitInitializationMode built the plant
      ctx.log.error("%s: malformed FMU state (no plant in a state after initialisation)", fn);
      return false;
    }
    plant.reset();
    jacobian_cache.valid = false;
    return true;
  }
  pkm::PlantSnapshot snap;
  snap.t = r.f64();
  r.f64s(snap.y.data(), snap.y.data() + 8);
  r.f64s(snap.theta1_ref.data(), snap.theta1_ref.data() + 4);
  snap.energy.actuator_work = r.f64();
  snap.energy.dissipated = r.f64();
  snap.stops = r.u32();
  const std::uint32_t memory_size = r.u32();
  if (!r.ok()) return false;
  if (memory_size != sizeof snap.memory) {
    ctx.log.error("%s: malformed FMU state (integrators' memory of %u bytes, this FMU keeps %u)", fn, memory_size,
                  static_cast<unsigned>(sizeof snap.memory));
    return false;
  }
  r.bytes(&snap.memory, sizeof snap.memory);
  if (!r.ok()) return false;
  if (snap.stops & ~pkm::kContactModeBits) {  // the rest of its consistency: Plant::restore
    ctx.log.error("%s: malformed FMU state (end-stop record %#x: no contact mode)", fn, snap.stops);
    return false;
  }
  // Co-Simulation: the model's time is the time since startTime, as the
  // layer counts it (they part only in the Error state).
  if (ctx.interface == Interface::CoSimulation && ctx.initialized && snap.t != ctx.model_time) {
    ctx.log.error("%s: malformed FMU state (the plant's time %.17g s differs from the time since startTime %.17g s)",
                  fn, snap.t, ctx.model_time);
    return false;
  }
  // The plant, with its solver's objects, is kept when the restored
  // parameters are those it was built with (restore() restarts CVODE): a
  // restore allocates nothing. Otherwise a new one.
  pkm::Model model;
  pkm::SolverSettings settings;
  if (configuration(ctx, fn, model, settings) != Status::OK) return false;
  std::unique_ptr<pkm::Plant> fresh;
  if (!built_from(model, settings) && make_plant(ctx, fn, fresh) != Status::OK) return false;
  pkm::Plant& p = fresh ? *fresh : *plant;
  // Co-Simulation locates every switch of the contact mode itself: each of
  // its states holds the mode the event rule keeps there. Model Exchange
  // switches it in Event Mode only, so between events it may lag the state
  // the importer's integrator reached.
  const pkm::Status s = p.restore(snap, ctx.interface == Interface::CoSimulation);
  if (s != pkm::Status::Ok) {
    ctx.log.error("%s: the saved state at t = %.17g cannot be restored: %s%s%s", fn, snap.t, pkm::status_name(s),
                  p.last_error().empty() ? "" : ": ", p.last_error().c_str());
    return false;
  }
  if (fresh) plant = std::move(fresh);
  jacobian_cache.valid = false;
  contact_events = plant->contact_events();  // the count continues from here
  logged_stops = plant->stops();
  may_continue = false;  // CVODE restarts here: its history is not part of the state
  return true;
}

}  // namespace pkm4puu_model
}  // namespace pkm_fmi

// SPDX-License-Identifier: BSD-2-Clause
// What the fixed-step integrators carry from one Plant::advance to the next
// besides the state (time, pose and velocity, energy integrals, contact
// mode): a run continues bit for bit from a snapshot only with it. ROS2's
// step control lives within one advance and keeps nothing here.
#pragma once

#include <cmath>
#include <cstdint>
#include <string>
#include <type_traits>

namespace pkm {

/// Everything an integrator keeps between advances lives here, and nowhere
/// else in the Plant: a snapshot (Plant::snapshot) and an FMU state carry
/// the struct whole, as its bytes, so that a member added here travels with
/// them without further code. Members of 8 bytes only (double,
/// std::int64_t for flags and counts): no padding, and the same bytes on
/// every platform the FMUs are built for (all little-endian). The default,
/// SolverMemory{}, is a restarted run's: its energy balance exact.
struct SolverMemory {
  // ROS2's dissipated energy is the energy audit's balance, brought up to
  // date when read (Plant::settle_energy): pending (1) or not (0), and the
  // energies (J) where it was last exact.
  std::int64_t balance_pending = 0;
  double balance_mech = 0.0, balance_work = 0.0, balance_dissipated = 0.0;
};
static_assert(std::is_trivially_copyable<SolverMemory>::value, "SolverMemory travels as its bytes");
static_assert(sizeof(SolverMemory) % 8 == 0 && alignof(SolverMemory) == 8, "SolverMemory: 8-byte members only");

/// "" if `m` is a memory some run can have, else why not (a restored
/// snapshot is checked with it: a forged one is refused).
inline std::string solver_memory_fault(const SolverMemory& m) {
  if (m.balance_pending != 0 && m.balance_pending != 1) return "the energy balance flag is neither 0 nor 1";
  if (!std::isfinite(m.balance_mech) || !std::isfinite(m.balance_work) || !std::isfinite(m.balance_dissipated))
    return "an energy of the balance is not finite";
  return "";
}

}  // namespace pkm

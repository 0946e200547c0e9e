// SPDX-License-Identifier: BSD-2-Clause
// The byte layout of the plant's part of a serialised FMU state, which
// plant_state.cpp writes and reads: the last bytes of the state, before the
// layer's 8-byte checksum (the tests and the fuzzer forge its fields).
#pragma once

#include <cstddef>

#include "pkm4puu/sim/solver_memory.hpp"

namespace pkm_fmi {
namespace pkm4puu_model {

/// Offsets of the fields from the start of the plant's part (after save()'s
/// flag byte) and the part's size. The part of a state of `n` bytes starts
/// at n - 8 - kPlantStateLayout.size.
struct PlantStateLayout {
  std::size_t t = 0;                     // the plant's time (f64)
  std::size_t y = t + 8;                 // [pose; velocity] (8 f64)
  std::size_t theta1 = y + 64;           // the theta1 references (4 f64)
  std::size_t energy = theta1 + 32;      // actuator_work, dissipated energy (2 f64)
  std::size_t stops = energy + 16;       // the contact mode (u32)
  std::size_t memory_size = stops + 4;   // the size of the integrators' memory (u32)
  std::size_t memory = memory_size + 4;  // pkm::SolverMemory, whole
  std::size_t size = memory + sizeof(pkm::SolverMemory);
};
inline constexpr PlantStateLayout kPlantStateLayout{};

}  // namespace pkm4puu_model
}  // namespace pkm_fmi

// SPDX-License-Identifier: BSD-2-Clause
// The kinds of states and inputs this project's FMUs declare for their
// ModelStructure (fmi/variables.hpp: a computed variable depends on every
// state and input whose kind shares a bit with its `depends`). The
// continuous states split into a position half (pose) and a rate half
// (velocity); inputs are position-, rate- or force-like.
#pragma once

#include <cstdint>

#include "fmi/variables.hpp"

namespace pkm_fmi {

enum : std::uint8_t {
  kOnPositions = 1u << 0,  // position states and pose inputs
  kOnRates = 1u << 1,      // rate states and velocity inputs
  kOnInputs = 1u << 2,     // force-like inputs (forces, wrenches, accelerations)
  // 1u << 3 is the FMI layer's kOnOwnState.
  kOnHeight = 1u << 4,     // the vertical position (state or input): the machine is otherwise invariant to it
  kOnHeightRate = 1u << 5, // its rate: only the slider velocities follow it
  kOnWrench = 1u << 6,     // the external wrench inputs (a kind of kOnInputs)
  kOnEnergy = 1u << 7,     // running-integral states (energy audit): nothing else depends on them
};
static_assert(kOnOwnState == 1u << 3, "the model's kinds leave the FMI layer's bit free");

}  // namespace pkm_fmi

// SPDX-License-Identifier: BSD-2-Clause
// The two FMUs of the project (docs/model.md "The FMUs' names").
#pragma once

#include "fmi/variables.hpp"

namespace pkm_fmi {

/// PKM4PUU: forward dynamics, the plant.
const ModelDefinition& pkm4puu_definition();
/// PKM4PUU_Inverse: algebraic inverse dynamics (computed-force feed-forward).
const ModelDefinition& pkm4puu_inverse_definition();

}  // namespace pkm_fmi

// SPDX-License-Identifier: BSD-2-Clause
#include "pkm4puu/sim/parameters.hpp"

namespace pkm {

const Parameter* find_parameter(std::string_view name) {
  for (const Parameter& p : kParameters)
    if (name == p.name) return &p;
  return nullptr;
}

}  // namespace pkm

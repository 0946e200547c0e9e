// SPDX-License-Identifier: BSD-2-Clause
// What every FMI flavour shares: the status codes (fmi2Status and
// fmi3Status have the same values 0..4) and the interface types.
#pragma once

#include <cstdint>

namespace pkm_fmi {

enum class Status : int { OK = 0, Warning = 1, Discard = 2, Error = 3, Fatal = 4 };

/// True for OK and Warning: the call did what was asked.
constexpr bool succeeded(Status s) { return s == Status::OK || s == Status::Warning; }

/// The worse of two statuses (Fatal > Error > Discard > Warning > OK).
constexpr Status worst(Status a, Status b) { return static_cast<int>(a) > static_cast<int>(b) ? a : b; }

enum class Interface : std::uint8_t { ModelExchange, CoSimulation };

const char* interface_name(Interface i);

}  // namespace pkm_fmi

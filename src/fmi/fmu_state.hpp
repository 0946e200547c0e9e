// SPDX-License-Identifier: BSD-2-Clause
// FMU states: an in-memory state is its serialised form, so that get/set
// and serialise/deserialise share one code path and one format.
//
// Serialised FMU state (all fields little-endian):
//   [0, 8)    magic "PKMFMUST"
//   [8, 12)   format version
//   [12, 16)  the FMI version of the instance that saved it (2 or 3: an FMI
//             2.0 and an FMI 3.0 FMU are two FMUs, whose states differ)
//   [16, 24)  total size in bytes, this header and the checksum included
//   [24, 32)  FNV-1a 64 of the model's instantiation token (a state of another FMU is rejected)
//   [32, n-8) the body: the generic part (Instance::save), then the model's
//   [n-8, n)  FNV-1a 64 of bytes [0, n-8)
#pragma once

#include <cstdint>
#include <vector>

namespace pkm_fmi {

class Instance;

struct SavedState {
  std::uint64_t tag;
  std::vector<unsigned char> bytes;
  Instance* owner = nullptr;  // FreeInstance frees the states it created
};

class ModelData;
struct Variable;
/// Writes a variable's value given as a double (start values, FMU states).
void write_from_double(ModelData& d, const Variable& v, double x);

/// The state behind a handle, nullptr if it is not a live one.
SavedState* as_state(void* handle);
SavedState* make_state(Instance* owner);
void destroy_state(SavedState* s);

}  // namespace pkm_fmi

// SPDX-License-Identifier: BSD-2-Clause
// FNV-1a 64-bit hash: FMU-state checksums and the instantiation token.
#pragma once

#include <cstddef>
#include <cstdint>
#include <cstring>

namespace pkm_fmi {

inline std::uint64_t fnv1a(const unsigned char* p, std::size_t n, std::uint64_t h = 14695981039346656037ull) {
  for (std::size_t i = 0; i < n; ++i) {
    h ^= p[i];
    h *= 1099511628211ull;
  }
  return h;
}

inline std::uint64_t fnv1a(const char* s) { return fnv1a(reinterpret_cast<const unsigned char*>(s), std::strlen(s)); }

}  // namespace pkm_fmi

// SPDX-License-Identifier: BSD-2-Clause
#include "fmi/state_bytes.hpp"

#include <cstring>

namespace pkm_fmi {

std::uint64_t read_le64(const unsigned char* p) {
  std::uint64_t v = 0;
  for (int i = 7; i >= 0; --i) v = (v << 8) | p[i];
  return v;
}

std::uint32_t read_le32(const unsigned char* p) {
  std::uint32_t v = 0;
  for (int i = 3; i >= 0; --i) v = (v << 8) | p[i];
  return v;
}

void write_le64(unsigned char* p, std::uint64_t v) {
  for (int i = 0; i < 8; ++i) p[i] = static_cast<unsigned char>(v >> (8 * i));
}

void StateWriter::u32(std::uint32_t v) {
  for (int i = 0; i < 4; ++i) out_.push_back(static_cast<unsigned char>(v >> (8 * i)));
}

void StateWriter::u64(std::uint64_t v) {
  for (int i = 0; i < 8; ++i) out_.push_back(static_cast<unsigned char>(v >> (8 * i)));
}

void StateWriter::f64(double v) {
  static_assert(sizeof(double) == 8, "IEEE 754 binary64 expected");
  std::uint64_t bits;
  std::memcpy(&bits, &v, 8);
  u64(bits);
}

// StateWriter::bytes keeps the host's byte order: the format says little-endian.
#if defined(__BYTE_ORDER__) && __BYTE_ORDER__ != __ORDER_LITTLE_ENDIAN__
#error "serialised FMU states are little-endian: StateWriter::bytes needs a byte swap on this platform"
#endif

void StateWriter::bytes(const void* p, std::size_t n) {
  const auto* b = static_cast<const unsigned char*>(p);
  out_.insert(out_.end(), b, b + n);
}

bool StateReader::take(std::size_t n) {
  if (!ok_ || static_cast<std::size_t>(end_ - p_) < n) {
    ok_ = false;
    return false;
  }
  return true;
}

std::uint8_t StateReader::u8() {
  if (!take(1)) return 0;
  return *p_++;
}

std::uint32_t StateReader::u32() {
  if (!take(4)) return 0;
  const std::uint32_t v = read_le32(p_);
  p_ += 4;
  return v;
}

std::uint64_t StateReader::u64() {
  if (!take(8)) return 0;
  const std::uint64_t v = read_le64(p_);
  p_ += 8;
  return v;
}

double StateReader::f64() {
  const std::uint64_t bits = u64();
  double v;
  std::memcpy(&v, &bits, 8);
  return v;
}

void StateReader::bytes(void* p, std::size_t n) {
  if (!take(n)) return;
  std::memcpy(p, p_, n);
  p_ += n;
}

}  // namespace pkm_fmi

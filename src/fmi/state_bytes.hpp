// SPDX-License-Identifier: BSD-2-Clause
// Little-endian fixed-size fields of a serialised FMU state.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

namespace pkm_fmi {

/// Appends little-endian fixed-size fields to a byte vector.
class StateWriter {
 public:
  explicit StateWriter(std::vector<unsigned char>& out) : out_(out) {}
  void u8(std::uint8_t v) { out_.push_back(v); }
  void u32(std::uint32_t v);
  void u64(std::uint64_t v);
  void i64(std::int64_t v) { u64(static_cast<std::uint64_t>(v)); }
  void f64(double v);
  template <class It>
  void f64s(It first, It last) {
    for (; first != last; ++first) f64(*first);
  }
  /// n bytes as they are (an object serialised whole: the host's
  /// representation, little-endian on every platform the FMUs are built for).
  void bytes(const void* p, std::size_t n);

 private:
  std::vector<unsigned char>& out_;
};

/// Reads what StateWriter wrote; never reads past the end (ok() turns false).
class StateReader {
 public:
  StateReader(const unsigned char* data, std::size_t size) : p_(data), end_(data + size) {}
  std::uint8_t u8();
  std::uint32_t u32();
  std::uint64_t u64();
  std::int64_t i64() { return static_cast<std::int64_t>(u64()); }
  double f64();
  template <class It>
  void f64s(It first, It last) {
    for (; first != last; ++first) *first = f64();
  }
  /// What StateWriter::bytes wrote, into p (left unchanged when short).
  void bytes(void* p, std::size_t n);
  bool ok() const { return ok_; }
  bool at_end() const { return p_ == end_; }

 private:
  bool take(std::size_t n);
  const unsigned char* p_;
  const unsigned char* end_;
  bool ok_ = true;
};

std::uint64_t read_le64(const unsigned char* p);
std::uint32_t read_le32(const unsigned char* p);
void write_le64(unsigned char* p, std::uint64_t v);

}  // namespace pkm_fmi

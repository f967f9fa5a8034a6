// Test helpers for drivers/openni2: the room.oni fixture (tests/data/oni_kinect), byte-level
// edits of it, and an independent walk over its records (written from the format description,
// not from the driver's code) so that tests can aim edits at named records.
#pragma once

#include <cstdint>
#include <cstring>
#include <fstream>
#include <iterator>
#include <stdexcept>
#include <string>
#include <vector>

namespace pliant::test_support::oni {

inline std::string fixture_path() { return PLIANT_ONI_FIXTURE; }

inline std::vector<std::uint8_t> read_bytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw std::runtime_error("cannot read " + path);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

inline void write_bytes(const std::string& path, const std::vector<std::uint8_t>& bytes) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(reinterpret_cast<const char*>(bytes.data()), static_cast<std::streamsize>(bytes.size()));
  if (!out) throw std::runtime_error("cannot write " + path);
}

inline std::uint32_t get32(const std::vector<std::uint8_t>& b, std::size_t at) {
  std::uint32_t v = 0;
  std::memcpy(&v, b.data() + at, 4);
  return v;
}
inline std::uint64_t get64(const std::vector<std::uint8_t>& b, std::size_t at) {
  std::uint64_t v = 0;
  std::memcpy(&v, b.data() + at, 8);
  return v;
}
inline void put32(std::vector<std::uint8_t>& b, std::size_t at, std::uint32_t v) { std::memcpy(b.data() + at, &v, 4); }
inline void put64(std::vector<std::uint8_t>& b, std::size_t at, std::uint64_t v) { std::memcpy(b.data() + at, &v, 8); }

/// One record of a 1.0.1.0 file (28-byte headers).
struct Record {
  std::size_t offset = 0;
  std::uint32_t type = 0, node = 0, fields = 0, payload = 0;
  std::uint64_t undo = 0;
};

inline std::vector<Record> records(const std::vector<std::uint8_t>& b) {
  std::vector<Record> out;
  std::size_t at = 24;
  while (at + 28 <= b.size()) {
    Record r;
    r.offset = at;
    r.type = get32(b, at + 4);
    r.node = get32(b, at + 8);
    r.fields = get32(b, at + 12);
    r.payload = get32(b, at + 16);
    r.undo = get64(b, at + 20);
    out.push_back(r);
    if (r.type == 0x0B || r.fields < 28) break;
    at += std::size_t{r.fields} + r.payload;
  }
  return out;
}

/// Offset of the first occurrence of `text` (with its NUL when `with_nul`), or npos.
inline std::size_t find_text(const std::vector<std::uint8_t>& b, const std::string& text, bool with_nul) {
  const std::size_t n = text.size() + (with_nul ? 1 : 0);
  for (std::size_t i = 0; i + n <= b.size(); ++i) {
    if (std::memcmp(b.data() + i, text.c_str(), n) == 0) return i;
  }
  return std::string::npos;
}

}  // namespace pliant::test_support::oni

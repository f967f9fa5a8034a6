// libFuzzer target for the compression-test CSV parser and its conversion into a recording.
//
// Input: the text of one CSV file. The parser must either succeed or throw RecordingError with
// a one-line message; any other exception escapes and is reported by libFuzzer, and sanitizer
// findings abort. A successful parse is checked for the invariants the converter relies on, then
// converted on a small mesh (which may refuse with RecordingError or std::invalid_argument, never
// otherwise) and its meta serialised, as write_recording would.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <stdexcept>
#include <string>
#include <string_view>

#include "pliant/host/fem/compression_test.hpp"

namespace {

using pliant::host::CompressionTest;
using pliant::host::RecordingError;

void check_message(const char* message) {
  if (std::strchr(message, '\n') != nullptr || message[0] == '\0') __builtin_trap();
}

void check_parsed(const CompressionTest& t) {
  const std::size_t n = t.row_count();
  if (n < 2 || t.compression_m.size() != n || t.load_n.size() != n) __builtin_trap();
  if (!(t.diameter_m >= 1e-4 && t.diameter_m <= 10.0 && t.height_m >= 1e-4 && t.height_m <= 10.0)) __builtin_trap();
  for (const auto* column : {&t.engineering_strain, &t.engineering_stress_pa, &t.true_strain, &t.true_stress_pa}) {
    if (!column->empty() && column->size() != n) __builtin_trap();
    for (const double v : *column) {
      if (!std::isfinite(v)) __builtin_trap();
    }
  }
  for (std::size_t i = 0; i < n; ++i) {
    if (!std::isfinite(t.time_s[i]) || !std::isfinite(t.load_n[i])) __builtin_trap();
    if (!(std::fabs(t.compression_m[i]) < t.height_m)) __builtin_trap();
    if (i > 0 && !(t.time_s[i] > t.time_s[i - 1])) __builtin_trap();
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  CompressionTest test;
  try {
    test = pliant::host::parse_compression_csv(text, "fuzz.csv");
  } catch (const RecordingError& error) {
    check_message(error.what());
    return 0;
  }
  check_parsed(test);

  try {
    const pliant::host::LinearModulusFit fit = pliant::host::fit_linear_modulus(test, 0.02, 0.10);
    if (fit.rows < 2) __builtin_trap();
  } catch (const std::invalid_argument&) {
  }

  pliant::host::CompressionRecordingOptions options;
  options.mesh = {1, 8, 1};
  options.frame_count = 2 + static_cast<int>(size % 5);
  if (size % 3 == 0) options.max_strain = 0.1;
  if (size % 2 == 0) options.platen_contact = pliant::host::PlatenContact::bonded;
  try {
    const pliant::host::Recording r = pliant::host::compression_test_recording(test, options);
    if (r.frame_count() < 2 || r.wrench.size() != static_cast<std::size_t>(r.frame_count())) __builtin_trap();
    // recording.json must be writable: meta holds text from the file.
    (void)r.meta.dump();
  } catch (const RecordingError& error) {
    check_message(error.what());
  } catch (const std::invalid_argument& error) {
    check_message(error.what());
  }
  return 0;
}

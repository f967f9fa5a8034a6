// libFuzzer target for the recording v1 readers.
//
// Input: recording.json, particles.csv, mesh.vtk, wrench.csv and gripper.csv texts separated by
// NUL bytes (missing parts are empty). Every parser must either succeed or throw RecordingError
// with a one-line message; any other exception escapes and is reported by libFuzzer, and
// sanitizer findings abort. Successful reads are checked for the invariants the estimators rely
// on.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <string>
#include <string_view>

#include "pliant/host/recording.hpp"

namespace {

using pliant::host::Recording;
using pliant::host::RecordingError;

// Each frame stores particle_count * dimension doubles, whatever the CSV holds, so a count near
// the reader's limit (10 million) costs hundreds of MB per frame by design. The fuzzer explores
// parsing, not that allocation, so it skips the CSV stage above this count.
constexpr int kMaxFuzzParticles = 4096;

std::string_view next_part(std::string_view& rest) {
  const std::size_t separator = rest.find('\0');
  const std::string_view part = rest.substr(0, separator);
  rest = separator == std::string_view::npos ? std::string_view() : rest.substr(separator + 1);
  return part;
}

void check_message(const RecordingError& error) {
  const char* message = error.what();
  if (std::strchr(message, '\n') != nullptr || message[0] == '\0') __builtin_trap();
}

template <typename Parse>
bool attempt(Parse&& parse) {
  try {
    parse();
    return true;
  } catch (const RecordingError& error) {
    check_message(error);
    return false;
  }
}

void check_finalized(const Recording& r) {
  const auto n = static_cast<std::size_t>(r.particle_count);
  const auto dimension = static_cast<std::size_t>(r.dimension);
  if (r.frame_times_s.empty() || r.masses.size() != n || r.positions.size() != r.frame_times_s.size() * n * dimension ||
      r.rest_positions.size() != n * dimension) {
    __builtin_trap();
  }
  for (std::size_t f = 1; f < r.frame_times_s.size(); ++f) {
    if (!(r.frame_times_s[f] > r.frame_times_s[f - 1])) __builtin_trap();
  }
  for (const double value : r.rest_positions) {
    if (!std::isfinite(value)) __builtin_trap();
  }
  for (const double value : r.positions) {
    if (std::isinf(value)) __builtin_trap();
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  std::string_view rest(reinterpret_cast<const char*>(data), size);
  const std::string_view json = next_part(rest);
  const std::string_view particles = next_part(rest);
  const std::string_view mesh = next_part(rest);
  const std::string_view wrench = next_part(rest);
  const std::string_view gripper = next_part(rest);

  attempt([&] { pliant::host::parse_wrench_csv(wrench, "wrench.csv"); });
  attempt([&] { pliant::host::parse_gripper_csv(gripper, "gripper.csv"); });

  Recording recording;
  if (!attempt([&] { pliant::host::parse_recording_json(json, "recording.json", recording); })) {
    // Still exercise the CSV reader, with a shape chosen by the input.
    recording = Recording();
    recording.dimension = 2 + static_cast<int>(size % 2);
    recording.particle_count = 1 + static_cast<int>(size % 7);
    recording.masses.assign(static_cast<std::size_t>(recording.particle_count), 1.0);
    attempt([&] { pliant::host::parse_vtk_tet_mesh(mesh, "mesh.vtk"); });
    attempt([&] { pliant::host::parse_particles_csv(particles, "particles.csv", recording); });
    return 0;
  }
  if (recording.particle_count > kMaxFuzzParticles) {
    attempt([&] { pliant::host::parse_vtk_tet_mesh(mesh, "mesh.vtk"); });
    return 0;
  }
  const bool read = attempt([&] {
    pliant::host::parse_particles_csv(particles, "particles.csv", recording);
    if (!mesh.empty()) recording.mesh = pliant::host::parse_vtk_tet_mesh(mesh, "mesh.vtk");
    pliant::host::finalize_recording(recording);
  });
  if (read) check_finalized(recording);
  return 0;
}

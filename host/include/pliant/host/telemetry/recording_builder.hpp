// A recording (recording format v1) from the particles messages of a telemetry stream.
//
// Chunks are assembled per tracker frame (the `frame` field); a frame is kept when its chunks
// cover every particle exactly once, one after another (chunks of another frame in between end
// it). Each kept frame becomes one recording frame at t = stamp_us of its first chunk x 1e-6 s;
// an observed particle keeps its position, a predicted or lost one (or a non-finite position)
// is unobserved (NaN, written as a missing row). The rest shape is the first kept frame, which
// therefore must observe every particle: complete frames before the first such frame are
// skipped. Later frames must have the same dimension and particle count and a later stamp.
// Every frame not kept is counted under one reason. Memory: 8 x dim x particles bytes per kept
// frame.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "pliant/host/recording.hpp"
#include "pliant_telemetry.h"

namespace pliant::host::telemetry {

struct ParticleFrameCounts {
  std::uint64_t kept = 0;
  std::uint64_t incomplete = 0;   ///< chunks missing (lost packets, cut stream) or overlapping
  std::uint64_t before_rest = 0;  ///< before the first frame observing every particle
  std::uint64_t shape = 0;        ///< no particles, or dimension / count unlike the first kept frame
  std::uint64_t time = 0;         ///< stamp not after the previous kept frame's
  std::uint64_t dropped() const { return incomplete + before_rest + shape + time; }
};

class RecordingBuilder {
 public:
  /// One decoded particles chunk with its packet's stamp. Its items are copied.
  void add(const pliant_tm_particles_t& chunk, std::uint64_t stamp_us);
  /// End of the stream: a frame still missing chunks is counted as incomplete.
  void finish();

  const ParticleFrameCounts& counts() const { return counts_; }
  bool has_frames() const { return counts_.kept > 0; }

  /// The recording of the kept frames: dimension and particle count of the first, unit masses,
  /// no constraints, `length_unit` ("m" or "px"), meta.source "pliant telemetry". Throws
  /// std::runtime_error when no frame was kept.
  Recording recording(const std::string& name, const std::string& length_unit) const;

 private:
  struct Pending {
    std::uint32_t frame = 0;
    std::uint8_t dim = 0;
    std::uint16_t total = 0;
    std::uint64_t stamp_us = 0;
    std::vector<float> positions;  // total * dim
    std::vector<std::uint8_t> status;
    std::vector<bool> covered;
    std::size_t covered_count = 0;
    bool overlap = false;
  };
  void complete(const Pending& frame);

  std::optional<Pending> pending_;
  ParticleFrameCounts counts_;
  int dimension_ = 0;
  int particle_count_ = 0;
  std::uint64_t last_stamp_us_ = 0;
  std::vector<double> frame_times_s_;
  std::vector<double> positions_;
};

}  // namespace pliant::host::telemetry

// pliant hal mocks: a camera front end observing the particles of a SimulatedGrasp.
//
// Every period_s (default 30 Hz) a frame is captured: the plant's true particle positions plus
// Gaussian noise (noise_m per coordinate, world frame, m), with the fraction
// occlusion_fraction of the particles (those with the largest rest y: the side facing an
// occluder) unobserved (NaN). It is delivered latency_s after capture, stamped with the capture
// time. Frames are 3D (dimension 3).
// Capture happens at the first read at or after the capture time (read at least once per
// period, e.g. every control cycle); a frame whose capture was missed is lost (sequence gap).
// Faults: every common kind plus `occlude` (value: the fraction hidden, default 0.5). nan makes
//   every coordinate NaN; fault_bits sets `value` (default kFrameDeviceFault).
// Memory: configure() sizes (latency / period + 2) capture slots and the delivered frame; the
//   frame's positions point into the mock, valid until the next read or stop.
// Real-time safety: read is bounded (one plant sync, O(particles)), allocation-free, noexcept.
#pragma once

#include <cstdint>
#include <random>
#include <vector>

#include "pliant/hal/camera.hpp"
#include "pliant/hal/clock.hpp"
#include "pliant/hal/mock/mock_stream.hpp"
#include "pliant/hal/mock/simulated_grasp.hpp"

namespace pliant::hal {

struct MockParticleObserverConfig {
  double period_s = 1.0 / 30;
  double latency_s = 0;           ///< >= 0
  double noise_m = 5e-5;          ///< sd per coordinate, >= 0
  double occlusion_fraction = 0;  ///< [0, 1)
  std::uint32_t fault_bits = kFrameDeviceFault;
  std::uint64_t seed = 3;
};

class MockParticleObserver final : public ParticleObserver {
 public:
  MockParticleObserver(SimulatedGrasp& plant, const Clock& clock,
                       const MockParticleObserverConfig& config = {}) noexcept
      : plant_(plant), clock_(clock), config_(config) {}

  HalStatus set_fault_schedule(const FaultSchedule& schedule) noexcept { return stream_.set_schedule(schedule); }
  HalStatus add_fault(const FaultEvent& event) noexcept { return stream_.add_fault(event); }
  const FaultCounters& fault_counters() const noexcept { return stream_.fault_counters(); }

 protected:
  HalStatus on_configure() override;
  HalStatus on_start() noexcept override;
  HalStatus on_read(ParticleFrame& out) noexcept override;

 private:
  void capture(double now_s) noexcept;

  SimulatedGrasp& plant_;
  const Clock& clock_;
  MockParticleObserverConfig config_;
  MockStream stream_;
  std::mt19937_64 rng_;
  std::normal_distribution<double> normal_{0.0, 1.0};
  int n_ = 0;
  int slots_ = 0;
  std::vector<double> captured_;          ///< [slots][n * 3] true positions
  std::vector<std::int64_t> slot_index_;  ///< capture index held by each slot, -1: none
  std::int64_t next_capture_ = 0;
  std::vector<double> frame_;         ///< the delivered frame
  std::vector<int> occlusion_order_;  ///< particles by descending rest y
  SampleHeader last_header_;
  int last_observed_ = 0;
  bool has_last_ = false;
};

}  // namespace pliant::hal

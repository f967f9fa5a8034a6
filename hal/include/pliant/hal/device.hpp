// pliant hal: the lifecycle, sample header and counters shared by every device category.
//
// Lifecycle (after ros2_control's hardware components)
//
//   unconfigured --configure()--> inactive --start()--> active --stop()--> inactive
//        ^                           |
//        +-------cleanup()-----------+
//
//   configure  validates the device's configuration, opens it and sizes every buffer. It may
//              allocate and may fail (the device stays unconfigured, the status says why). It
//              never throws: an allocation failure becomes capacity_exceeded, any other
//              std::exception from the implementation io_error.
//   start      begins streaming; sequence numbers continue from the last configure.
//   read/write only while active; bounded and non-blocking: they return what is there (or
//              no_data) and never wait for the device. No allocation, no exceptions.
//   stop       always succeeds from active; the device stays configured.
//   cleanup    releases what configure acquired.
// A call in the wrong state returns wrong_state, changes nothing and is counted in
// DeviceCounters::lifecycle_errors.
//
// Samples: every sample carries a SampleHeader: its stamp on the device's injected Clock
// (capture time where known), a sequence number (+1 per sample the device produced, so a gap
// means samples were dropped on the way) and the device's status bits (meaning per category).
//
// Counters: each device counts reads, delivered samples, empty reads, dropped samples (from
// sequence gaps, computed here for every implementation), samples with fault status bits, and
// failed reads and writes by status. They are monotonic (reset only by configure) and readable
// at any time from the thread that drives the device.
//
// Implementing a device: derive from a category class (Gripper, ForceTorqueSensor, ...) and
// override the protected on_* hooks; the public calls enforce the lifecycle and count.
// Thread safety: a device is driven from one thread; no internal locking.
#pragma once

#include <cstdint>
#include <limits>

#include "pliant/hal/status.hpp"

namespace pliant::hal {

enum class LifecycleState : std::uint8_t { unconfigured, inactive, active };

const char* lifecycle_state_name(LifecycleState state) noexcept;

struct SampleHeader {
  double stamp_s = std::numeric_limits<double>::quiet_NaN();  ///< on the device's Clock, s
  std::uint64_t sequence = 0;     ///< 1 for the first sample after configure, +1 per sample produced
  std::uint32_t status_bits = 0;  ///< device status word (see the category's header)
};

struct DeviceCounters {
  std::uint64_t reads = 0;             ///< read calls while active
  std::uint64_t samples = 0;           ///< reads that delivered a sample
  std::uint64_t no_data = 0;           ///< reads that found nothing new
  std::uint64_t dropped = 0;           ///< samples lost: gaps in the delivered sequence numbers (from 1)
  std::uint64_t fault_samples = 0;     ///< delivered samples with a status bit in the category's fault mask
  std::uint64_t timeouts = 0;          ///< reads or writes that returned timeout
  std::uint64_t bus_off = 0;           ///< ... bus_off
  std::uint64_t disconnected = 0;      ///< ... disconnected
  std::uint64_t device_faults = 0;     ///< ... device_fault
  std::uint64_t io_errors = 0;         ///< ... io_error
  std::uint64_t disconnects = 0;       ///< transitions from reachable to disconnected
  std::uint64_t reconnects = 0;        ///< first delivered sample or accepted write after a disconnect
  std::uint64_t writes = 0;            ///< write calls while active
  std::uint64_t rejected_writes = 0;   ///< writes refused (invalid_argument, unsupported or a fault)
  std::uint64_t lifecycle_errors = 0;  ///< calls refused with wrong_state
  /// Every failed read or write (the five transport/device statuses).
  std::uint64_t faults() const noexcept { return timeouts + bus_off + disconnected + device_faults + io_errors; }
};

class Device {
 public:
  virtual ~Device() = default;
  Device(const Device&) = delete;
  Device& operator=(const Device&) = delete;

  /// unconfigured -> inactive. Resets the counters. May allocate; never throws.
  HalStatus configure() noexcept;
  /// inactive -> active.
  HalStatus start() noexcept;
  /// active -> inactive.
  HalStatus stop() noexcept;
  /// inactive -> unconfigured.
  HalStatus cleanup() noexcept;

  LifecycleState state() const noexcept { return state_; }
  const DeviceCounters& counters() const noexcept { return counters_; }
  /// Status bits that mean a fault in this category's samples (counted in fault_samples).
  std::uint32_t fault_mask() const noexcept { return fault_mask_; }

 protected:
  explicit Device(std::uint32_t fault_mask) noexcept : fault_mask_(fault_mask) {}

  virtual HalStatus on_configure() = 0;  ///< may allocate and throw (see configure())
  virtual HalStatus on_start() noexcept = 0;
  virtual HalStatus on_stop() noexcept { return HalStatus::ok; }
  virtual HalStatus on_cleanup() noexcept { return HalStatus::ok; }

  /// For the category's read/write wrappers: true while active, else counts a lifecycle error.
  bool admit() noexcept;
  /// Counts one read's outcome; `header` is the delivered sample's (when status is ok).
  void account_read(HalStatus status, const SampleHeader& header) noexcept;
  /// Counts one write's outcome.
  void account_write(HalStatus status) noexcept;

 private:
  void account_fault(HalStatus status) noexcept;

  std::uint32_t fault_mask_;
  LifecycleState state_ = LifecycleState::unconfigured;
  DeviceCounters counters_;
  std::uint64_t last_sequence_ = 0;  ///< highest sequence delivered since configure
  bool unreachable_ = false;
};

}  // namespace pliant::hal

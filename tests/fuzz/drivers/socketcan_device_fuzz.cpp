// libFuzzer target over the socketcan sensors' read path: AtiNetCanForceTorque or
// RobotousRftForceTorque on a scripted transport that plays the fuzz input as the bus.
//
// Input: byte 0 options (bit 0: Robotous instead of ATI; bit 1: ATI calibration from the config
// instead of the device; bit 2: tare 3 samples on start; bit 3: bias on start; bits 4-5: samples
// withheld after a restart; bit 6: receive timestamps; bit 7: set the output rate), byte 1 the
// ATI base ID (low 7 bits). Then operations, one byte each plus arguments, consumed by the
// transport whenever the device receives:
//   0 b d0..d7   a frame for the device: ATI base ID with opcode b & 15, dlc (b >> 4) % 9; or
//                Robotous response ID 1 or 2 (b & 1), dlc 8 (or (b >> 4) & 7 when b & 0x80)
//   1 i0..i3 l d0..d7  any frame: id (little-endian, flags included), raw dlc byte, data
//   2 c0 c1 d0..d7    an error frame with classes c0 | c1 << 8
//   3            a malformed record          4   the queue is empty (ends this read)
//   5 n          the clock moves n ticks     6   the link drops (open() later takes a byte:
//   7 n          the next n % 4 sends fail                odd = the peer is back)
// Any other value of op % 8 cannot occur. Each read also moves the clock one tick. Checks
// (abort()): every status is one a read may return, a delivered wrench is finite, stamps are
// finite and not in the future, sequence numbers increase.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <cstring>

#include "pliant/drivers/socketcan/ati_netcanoem_sensor.hpp"
#include "pliant/drivers/socketcan/robotous_rft_sensor.hpp"

namespace sc = pliant::drivers::socketcan;
namespace hal = pliant::hal;

namespace {

constexpr double kTick = 1.0 / 1024.0;

void check(bool condition) {
  if (!condition) std::abort();
}

class ScriptedTransport final : public sc::CanTransport {
 public:
  ScriptedTransport(const std::uint8_t* data, std::size_t size, hal::ManualClock& clock, bool rft, std::uint8_t base)
      : data_(data), size_(size), clock_(clock), rft_(rft), base_(base) {}

  hal::HalStatus open() noexcept override {
    if (open_) return hal::HalStatus::ok;
    if (!first_open_ && (at_ >= size_ || (data_[at_++] & 1u) == 0)) return hal::HalStatus::disconnected;
    first_open_ = false;
    open_ = true;
    return hal::HalStatus::ok;
  }
  void close() noexcept override { open_ = false; }
  bool is_open() const noexcept override { return open_; }
  sc::CanIo send(const sc::CanFrame& frame) noexcept override {
    check(frame.dlc <= 8);
    if (!open_) return sc::CanIo::disconnected;
    if (busy_ > 0) {
      --busy_;
      return sc::CanIo::busy;
    }
    return sc::CanIo::ok;
  }
  sc::CanIo receive(sc::CanFrame& frame, sc::CanRxInfo& info) noexcept override {
    check(open_);
    for (;;) {
      if (at_ >= size_) return sc::CanIo::empty;
      const std::uint8_t op = data_[at_++] % 8;
      switch (op) {
        case 0: {
          const std::uint8_t b = take();
          frame = sc::CanFrame{};
          if (rft_) {
            frame.id = (b & 1u) != 0 ? 0x02u : 0x01u;
            frame.dlc = (b & 0x80u) != 0 ? static_cast<std::uint8_t>((b >> 4) & 7u) : 8;
          } else {
            frame.id = (static_cast<std::uint32_t>(base_) << 4) | (b & 0xfu);
            frame.dlc = static_cast<std::uint8_t>((b >> 4) % 9);
          }
          take_data(frame, frame.dlc);
          info.realtime_ns = -1;
          return sc::CanIo::ok;
        }
        case 1: {
          frame = sc::CanFrame{};
          for (int i = 0; i < 4; ++i) frame.id |= static_cast<std::uint32_t>(take()) << (8 * i);
          frame.dlc = take();
          // A transport never delivers dlc > 8 (its contract); clamp like the kernel would refuse.
          if (frame.dlc > 8) frame.dlc = 8;
          take_data(frame, frame.dlc);
          info.realtime_ns = -1;
          return sc::CanIo::ok;
        }
        case 2: {
          const std::uint32_t classes = take() | (static_cast<std::uint32_t>(take()) << 8);
          std::uint8_t d[8];
          for (std::uint8_t& x : d) x = take();
          frame = sc::make_can_error_frame(classes, d);
          info.realtime_ns = -1;
          return sc::CanIo::ok;
        }
        case 3: return sc::CanIo::malformed;
        case 4: return sc::CanIo::empty;
        case 5: (void)clock_.advance(take() * kTick); break;
        case 6: open_ = false; return sc::CanIo::disconnected;
        case 7: busy_ = take() % 4; break;
        default: std::abort();
      }
    }
  }
  bool exhausted() const noexcept { return at_ >= size_; }

 private:
  std::uint8_t take() noexcept { return at_ < size_ ? data_[at_++] : 0; }
  void take_data(sc::CanFrame& f, std::uint8_t dlc) noexcept {
    for (std::uint8_t i = 0; i < 8; ++i) {
      const std::uint8_t v = take();
      if (i < dlc) f.data[i] = v;
    }
  }

  const std::uint8_t* data_;
  std::size_t size_;
  std::size_t at_ = 2;
  hal::ManualClock& clock_;
  bool rft_;
  std::uint8_t base_;
  bool open_ = false;
  bool first_open_ = true;
  int busy_ = 0;
};

bool read_status_allowed(hal::HalStatus s) {
  switch (s) {
    case hal::HalStatus::ok:
    case hal::HalStatus::no_data:
    case hal::HalStatus::timeout:
    case hal::HalStatus::bus_off:
    case hal::HalStatus::disconnected:
    case hal::HalStatus::io_error:
    case hal::HalStatus::device_fault: return true;
    default: return false;
  }
}

void run(hal::ForceTorqueSensor& ft, ScriptedTransport& bus, hal::ManualClock& clock) {
  check(ft.configure() == hal::HalStatus::ok);
  check(ft.start() == hal::HalStatus::ok);
  std::uint64_t last_sequence = 0;
  for (int reads = 0; reads < 20000 && !bus.exhausted(); ++reads) {
    (void)clock.advance(kTick);
    hal::WrenchReading w;
    const hal::HalStatus s = ft.read(w);
    check(read_status_allowed(s));
    if (s != hal::HalStatus::ok) continue;
    for (double v : w.wrench) check(std::isfinite(v));
    check(std::isfinite(w.header.stamp_s) && w.header.stamp_s <= clock.now_s());
    check(w.header.sequence > last_sequence);
    last_sequence = w.header.sequence;
  }
  check(ft.stop() == hal::HalStatus::ok);
  check(ft.cleanup() == hal::HalStatus::ok);
  const hal::DeviceCounters& c = ft.counters();
  check(c.samples + c.no_data + c.faults() == c.reads);
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size < 2) return 0;
  const std::uint8_t options = data[0];
  const bool rft = (options & 1u) != 0;
  const std::uint8_t base = data[1] & 0x7fu;
  hal::ManualClock clock(100.0);
  ScriptedTransport bus(data, size, clock, rft, base);
  sc::CanLinkConfig link;
  link.reconnect_interval_s = 4 * kTick;
  link.max_frames_per_read = 16;
  link.samples_after_restart = (options >> 4) & 3;
  link.use_receive_timestamps = (options & 0x40u) != 0;
  if (rft) {
    sc::RobotousRftConfig c;
    c.link = link;
    c.timeout_s = 20 * kTick;
    c.bias_on_start = (options & 8u) != 0;
    c.output_rate_code = (options & 0x80u) != 0 ? 8 : -1;
    sc::RobotousRftForceTorque ft(bus, clock, c);
    run(ft, bus, clock);
    // The commands it sent are counted, and the overload flag matches the last packet.
    check((ft.last_overload() != 0) == (ft.last_packet().overload != 0));
  } else {
    sc::AtiNetCanConfig c;
    c.link = link;
    c.base_id = base;
    c.response_timeout_s = 3 * kTick;
    c.timeout_s = 20 * kTick;
    c.calibration_from_device = (options & 2u) == 0;
    for (int k = 0; k < 6; ++k) c.calibration.matrix[7 * k] = 1.0f;
    c.calibration.counts_per_force = 1000;
    c.calibration.counts_per_torque = 1000;
    c.tare_samples_on_start = (options & 4u) != 0 ? 3 : 0;
    sc::AtiNetCanForceTorque ft(bus, clock, c);
    run(ft, bus, clock);
    const sc::AtiCounters& p = ft.protocol_counters();
    check(p.complete_samples <= p.polls_sent);
  }
  return 0;
}

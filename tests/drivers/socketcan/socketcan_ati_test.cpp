// AtiNetCanForceTorque against the NETCANOEM emulator over a socketpair, on a manual clock:
// setup, the hand-computed wrench, reassembly faults, tare, status bits, malformed frames,
// error frames, bus-off and recovery, timeouts, disconnect and reconnect, setup failures.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <limits>

#include "socketcan_fixture.hpp"

namespace pliant::drivers::socketcan {
namespace {

using hal::HalStatus;
using hal::WrenchReading;
using test::AtiRig;

TEST(SocketCanAti, SetupReadsCalibrationAndDeviceInfo) {
  AtiRig rig;
  ASSERT_TRUE(rig.pair());
  ASSERT_EQ(rig.make(), HalStatus::ok);
  WrenchReading w;
  // Setup: one request per read, answered by the emulator before the next read; the reads
  // meanwhile find nothing new.
  EXPECT_EQ(rig.cycle(w), HalStatus::no_data);
  ASSERT_TRUE(rig.run_setup());
  EXPECT_EQ(rig.emulator->active_calibration(), 3);
  EXPECT_EQ(rig.emulator->counters().matrix_requests, 6u);
  EXPECT_EQ(rig.emulator->counters().calibration_requests, 1u);
  const AtiDeviceInfo& info = rig.ft->info();
  EXPECT_STREQ(info.serial, "FT004217");
  EXPECT_EQ(info.firmware_major, 2);
  EXPECT_EQ(info.firmware_minor, 1);
  EXPECT_EQ(info.firmware_build, 300);
  const ati::Calibration expected = test::hand_calibration();
  for (int i = 0; i < 36; ++i) EXPECT_EQ(info.calibration.matrix[i], expected.matrix[i]) << i;
  EXPECT_EQ(info.calibration.counts_per_force, 1000u);
  EXPECT_EQ(info.calibration.counts_per_torque, 2000u);
  EXPECT_EQ(rig.ft->protocol_counters().setups_completed, 1u);
  EXPECT_EQ(rig.ft->protocol_counters().setup_retries, 0u);
  EXPECT_EQ(rig.ft->protocol_counters().dropped_frames(), 0u);
}

TEST(SocketCanAti, SamplesCarryTheHandComputedWrench) {
  AtiRig rig;
  ASSERT_TRUE(rig.pair());
  ASSERT_EQ(rig.make(), HalStatus::ok);
  ASSERT_TRUE(rig.run_setup());
  WrenchReading w;
  ASSERT_EQ(rig.next_sample(w), HalStatus::ok);
  test::expect_hand(w);
  EXPECT_EQ(w.header.sequence, 1u);
  EXPECT_EQ(w.header.status_bits, 0u);
  EXPECT_DOUBLE_EQ(w.header.stamp_s, rig.clock.now_s());  // receive stamps off: the read's time
  // Steady state: one poll per read, one sample per read.
  for (int i = 0; i < 20; ++i) {
    ASSERT_EQ(rig.cycle(w), HalStatus::ok) << i;
    EXPECT_EQ(w.header.sequence, static_cast<std::uint64_t>(i + 2));
  }
  EXPECT_EQ(rig.ft->counters().dropped, 0u);
  EXPECT_EQ(rig.ft->protocol_counters().polls_sent, 22u);  // one more is in flight
  EXPECT_EQ(rig.ft->protocol_counters().complete_samples, 21u);
  const std::int16_t g[6] = {100, -200, 300, 50, -400, 20};
  EXPECT_EQ(std::memcmp(rig.ft->last_gauges().gauges, g, sizeof g), 0);
}

TEST(SocketCanAti, PollPeriodLimitsTheRequestRate) {
  AtiRig rig;
  rig.config.poll_period_s = 5 * test::kTick;
  ASSERT_TRUE(rig.pair());
  ASSERT_EQ(rig.make(), HalStatus::ok);
  ASSERT_TRUE(rig.run_setup());
  WrenchReading w;
  int ok = 0;
  int empty = 0;
  for (int i = 0; i < 50; ++i) {
    const HalStatus s = rig.cycle(w);
    ok += s == HalStatus::ok ? 1 : 0;
    empty += s == HalStatus::no_data ? 1 : 0;
  }
  // The first poll went out when setup finished; then one every 5 reads, answered in the next.
  EXPECT_EQ(ok, 10);
  EXPECT_EQ(empty, 40);
  EXPECT_EQ(rig.ft->protocol_counters().polls_sent, 11u);
}

TEST(SocketCanAti, HalvesInEitherOrderGiveTheSameSample) {
  AtiRig rig;
  ASSERT_TRUE(rig.pair());
  rig.emulator->faults().swap_halves = true;
  ASSERT_EQ(rig.make(), HalStatus::ok);
  ASSERT_TRUE(rig.run_setup());
  WrenchReading w;
  ASSERT_EQ(rig.next_sample(w), HalStatus::ok);
  test::expect_hand(w);
  ASSERT_EQ(rig.cycle(w), HalStatus::ok);
  EXPECT_EQ(rig.ft->protocol_counters().incomplete_samples, 0u);
}

TEST(SocketCanAti, MissingHalfAbandonsThePollAfterTheResponseTimeout) {
  for (const bool drop_first : {false, true}) {
    SCOPED_TRACE(drop_first ? "first half lost" : "second half lost");
    AtiRig rig;
    rig.config.response_timeout_s = 5 * test::kTick;
    ASSERT_TRUE(rig.pair());
    ASSERT_EQ(rig.make(), HalStatus::ok);
    ASSERT_TRUE(rig.run_setup());
    WrenchReading w;
    ASSERT_EQ(rig.next_sample(w), HalStatus::ok);
    (drop_first ? rig.emulator->faults().drop_first_halves : rig.emulator->faults().drop_second_halves) = 1;
    ASSERT_EQ(rig.cycle(w), HalStatus::ok);  // this read sends the poll the emulator half-answers
    // 5 ms without the other half: the poll is abandoned, the half discarded, a new poll sent.
    int empty = 0;
    HalStatus s = HalStatus::no_data;
    while ((s = rig.cycle(w)) == HalStatus::no_data && empty < 20) ++empty;
    ASSERT_EQ(s, HalStatus::ok);
    EXPECT_EQ(empty, 5);
    test::expect_hand(w);
    const AtiCounters& c = rig.ft->protocol_counters();
    EXPECT_EQ(c.unanswered_polls, 1u);
    EXPECT_EQ(c.incomplete_samples, 1u);
    // Only delivered samples have sequence numbers: no gap.
    EXPECT_EQ(rig.ft->counters().dropped, 0u);
  }
}

TEST(SocketCanAti, DuplicatedFirstHalfIsCountedAndTheSampleStillCompletes) {
  AtiRig rig;
  ASSERT_TRUE(rig.pair());
  ASSERT_EQ(rig.make(), HalStatus::ok);
  ASSERT_TRUE(rig.run_setup());
  rig.emulator->faults().duplicate_first_halves = 1;
  WrenchReading w;
  ASSERT_EQ(rig.cycle(w), HalStatus::ok);  // the answer already sent; the next one has the fault
  EXPECT_EQ(rig.ft->protocol_counters().incomplete_samples, 0u);
  ASSERT_EQ(rig.cycle(w), HalStatus::ok);
  test::expect_hand(w);
  EXPECT_EQ(rig.ft->protocol_counters().incomplete_samples, 1u);
}

TEST(SocketCanAti, TareAveragesGoodSamplesOnly) {
  AtiRig rig;
  ASSERT_TRUE(rig.pair());
  ASSERT_EQ(rig.make(), HalStatus::ok);
  ASSERT_TRUE(rig.run_setup());
  WrenchReading w;
  ASSERT_EQ(rig.next_sample(w), HalStatus::ok);
  EXPECT_EQ(rig.ft->tare(0), HalStatus::invalid_argument);
  ASSERT_EQ(rig.ft->tare(4), HalStatus::ok);
  EXPECT_TRUE(rig.ft->tare_pending());
  rig.emulator->set_status(0x0020);
  ASSERT_EQ(rig.cycle(w), HalStatus::ok);     // the answer sent before the change: status 0, counts
  ASSERT_EQ(rig.ft->tare(4), HalStatus::ok);  // start over
  // Samples with a status bit do not count toward the tare. (An answer is read one cycle after
  // the emulator sends it, so a change to the emulator shows one cycle later.)
  for (int i = 0; i < 6; ++i) ASSERT_EQ(rig.cycle(w), HalStatus::ok);
  EXPECT_TRUE(rig.ft->tare_pending());
  test::expect_hand(w);  // the old (zero) bias meanwhile
  // Two gauge vectors alternate: the bias is their mean.
  const std::int16_t a[6] = {10, 20, 30, 40, 50, 60};
  const std::int16_t b[6] = {12, 18, 34, 36, 50, 64};
  rig.emulator->set_status(0);
  rig.emulator->set_gauges(a);
  ASSERT_EQ(rig.cycle(w), HalStatus::ok);  // the last answer with the status bit; a is sent next
  for (int i = 0; i < 4; ++i) {
    EXPECT_TRUE(rig.ft->tare_pending()) << i;
    rig.emulator->set_gauges(i % 2 == 0 ? b : a);
    ASSERT_EQ(rig.cycle(w), HalStatus::ok);  // reads a, b, a, b
  }
  EXPECT_FALSE(rig.ft->tare_pending());
  const double mean[6] = {11, 19, 32, 38, 50, 62};
  for (int k = 0; k < 6; ++k) EXPECT_DOUBLE_EQ(rig.ft->gauge_bias()[k], mean[k]) << k;
  EXPECT_EQ(rig.ft->protocol_counters().tares_completed, 1u);
  // Gauges at the mean read zero.
  const std::int16_t m[6] = {11, 19, 32, 38, 50, 62};
  rig.emulator->set_gauges(m);
  ASSERT_EQ(rig.cycle(w), HalStatus::ok);
  ASSERT_EQ(rig.cycle(w), HalStatus::ok);
  for (int k = 0; k < 6; ++k) EXPECT_NEAR(w.wrench[k], 0.0, 1e-12) << k;
  // set_gauge_bias replaces it; non-finite values are refused.
  const double zero[6] = {0, 0, 0, 0, 0, 0};
  ASSERT_EQ(rig.ft->set_gauge_bias(zero), HalStatus::ok);
  double nan_bias[6] = {0, 0, 0, 0, 0, 0};
  nan_bias[2] = std::numeric_limits<double>::quiet_NaN();
  EXPECT_EQ(rig.ft->set_gauge_bias(nan_bias), HalStatus::invalid_argument);
  EXPECT_DOUBLE_EQ(rig.ft->gauge_bias()[2], 0.0);
}

TEST(SocketCanAti, TareOnStartWithholdsSamplesUntilZeroed) {
  AtiRig rig;
  rig.config.tare_samples_on_start = 3;
  ASSERT_TRUE(rig.pair());
  ASSERT_EQ(rig.make(), HalStatus::ok);
  ASSERT_TRUE(rig.run_setup());
  WrenchReading w;
  EXPECT_EQ(rig.cycle(w), HalStatus::no_data);  // tare sample 1 (the first poll went out with setup)
  EXPECT_EQ(rig.cycle(w), HalStatus::no_data);  // tare sample 2
  ASSERT_EQ(rig.cycle(w), HalStatus::ok);       // tare sample 3 completes it and is delivered
  for (int k = 0; k < 6; ++k) EXPECT_NEAR(w.wrench[k], 0.0, 1e-12) << k;
  EXPECT_EQ(w.header.sequence, 1u);  // withheld samples are not drops
  EXPECT_EQ(rig.ft->counters().dropped, 0u);
  EXPECT_EQ(rig.ft->tare(100001), HalStatus::invalid_argument);
}

TEST(SocketCanAti, StatusWordTravelsInTheStatusBits) {
  AtiRig rig;
  ASSERT_TRUE(rig.pair());
  ASSERT_EQ(rig.make(), HalStatus::ok);
  ASSERT_TRUE(rig.run_setup());
  WrenchReading w;
  ASSERT_EQ(rig.next_sample(w), HalStatus::ok);
  struct Case {
    std::uint16_t status;
    bool fault;
  };
  // Watchdog reset and config-invalid are informational; supply-low, bad calibration and
  // temperature-high are faults (kFtFaultMask); the CAN-bus-error bit is "degraded".
  const Case cases[] = {{0x0001, false}, {0x0100, false}, {0x8020, true},
                        {0x0040, true},  {0x0800, true},  {0x4000, false}};
  for (const Case& c : cases) {
    rig.emulator->set_status(c.status);
    ASSERT_EQ(rig.cycle(w), HalStatus::ok);  // the answer to the poll sent before the change
    const std::uint64_t faults_before = rig.ft->counters().fault_samples;
    ASSERT_EQ(rig.cycle(w), HalStatus::ok);
    EXPECT_EQ(w.header.status_bits, c.status);
    EXPECT_EQ((w.header.status_bits & hal::kFtFaultMask) != 0, c.fault) << std::hex << c.status;
    EXPECT_EQ(rig.ft->counters().fault_samples - faults_before, c.fault ? 1u : 0u);
  }
}

TEST(SocketCanAti, MalformedAndForeignFramesAreCountedDrops) {
  AtiRig rig;
  rig.config.response_timeout_s = 3 * test::kTick;
  ASSERT_TRUE(rig.pair());
  ASSERT_EQ(rig.make(), HalStatus::ok);
  ASSERT_TRUE(rig.run_setup());
  WrenchReading w;
  ASSERT_EQ(rig.next_sample(w), HalStatus::ok);
  const std::uint8_t eight[8] = {1, 2, 3, 4, 5, 6, 7, 8};
  CanFrame foreign = make_standard_frame(0x310, eight, 8);  // another base ID
  CanFrame extended = make_standard_frame(0x200, eight, 8);
  extended.id |= kCanEffFlag;
  CanFrame remote = make_standard_frame(0x200, nullptr, 0);
  remote.id |= kCanRtrFlag;
  const CanFrame unused_op = make_standard_frame(0x20a, eight, 2);
  const CanFrame short_gauges = make_standard_frame(0x200, eight, 7);
  const CanFrame late_gauges = make_standard_frame(0x201, eight, 6);  // no poll waits for it
  for (const CanFrame& f : {foreign, extended, remote, unused_op, short_gauges})
    ASSERT_EQ(rig.emulator->send_raw(f), CanIo::ok);
  const unsigned char junk[5] = {9, 9, 9, 9, 9};
  ASSERT_EQ(rig.sensor_end.send_record(junk, sizeof junk), CanIo::ok);
  // They arrive after the answer to the poll in flight: the sample still completes.
  ASSERT_EQ(rig.cycle(w), HalStatus::ok);
  test::expect_hand(w);
  const AtiCounters& c = rig.ft->protocol_counters();
  EXPECT_EQ(c.foreign_frames, 3u);
  EXPECT_EQ(c.unknown_opcodes, 1u);
  EXPECT_EQ(c.wrong_dlc, 1u);
  EXPECT_EQ(rig.ft->link_counters().malformed_records, 1u);
  // A second half with the wrong DLC leaves the poll incomplete until the response timeout.
  rig.emulator->faults().wrong_dlc_answers = 1;
  ASSERT_EQ(rig.cycle(w), HalStatus::ok);  // reads the good answer; the emulator sends the bad one
  int reads = 0;
  HalStatus s = HalStatus::no_data;
  while ((s = rig.cycle(w)) != HalStatus::ok && reads < 20) ++reads;
  ASSERT_EQ(s, HalStatus::ok);
  EXPECT_EQ(reads, 3);  // 3 ticks of response timeout, then a new poll answered in the next read
  EXPECT_EQ(c.wrong_dlc, 2u);
  EXPECT_EQ(c.unanswered_polls, 1u);
  EXPECT_EQ(c.incomplete_samples, 1u);
  // A gauge frame behind a complete answer finds no poll waiting for it: unexpected.
  ASSERT_EQ(rig.emulator->send_raw(late_gauges), CanIo::ok);
  ASSERT_EQ(rig.cycle(w), HalStatus::ok);
  EXPECT_EQ(c.unexpected_frames, 1u);
  EXPECT_EQ(c.dropped_frames(), 3u + 1u + 2u + 1u);
}

TEST(SocketCanAti, ErrorFramesMarkTheNextSampleDegraded) {
  AtiRig rig;
  ASSERT_TRUE(rig.pair());
  ASSERT_EQ(rig.make(), HalStatus::ok);
  ASSERT_TRUE(rig.run_setup());
  WrenchReading w;
  ASSERT_EQ(rig.next_sample(w), HalStatus::ok);
  const std::uint8_t warning[8] = {0, kCanCtrlRxWarning, 0, 0, 0, 0, 0, 97};
  ASSERT_EQ(rig.emulator->send_error(kCanErrController | kCanErrCounters, warning), CanIo::ok);
  ASSERT_EQ(rig.cycle(w), HalStatus::ok);
  test::expect_hand(w);
  EXPECT_EQ(w.header.status_bits, hal::kFtCanBusError);
  EXPECT_EQ(w.header.status_bits & hal::kFtFaultMask, 0u);  // degraded, not invalid
  ASSERT_EQ(rig.cycle(w), HalStatus::ok);
  EXPECT_EQ(w.header.status_bits, 0u);
  EXPECT_EQ(rig.ft->link_counters().error_frames, 1u);
  EXPECT_EQ(rig.ft->last_can_error().rx_errors, 97);
  EXPECT_EQ(rig.ft->last_can_error().controller, kCanCtrlRxWarning);
}

}  // namespace
}  // namespace pliant::drivers::socketcan

namespace pliant::drivers::socketcan {
namespace {

using hal::HalStatus;
using hal::WrenchReading;
using test::AtiRig;
using test::kTick;

TEST(SocketCanAti, BusOffStopsPollingUntilTheControllerRestarts) {
  AtiRig rig;
  rig.config.link.samples_after_restart = 2;
  ASSERT_TRUE(rig.pair());
  ASSERT_EQ(rig.make(), HalStatus::ok);
  ASSERT_TRUE(rig.run_setup());
  WrenchReading w;
  ASSERT_EQ(rig.next_sample(w), HalStatus::ok);
  ASSERT_EQ(rig.emulator->send_error(kCanErrBusOff), CanIo::ok);
  // The answer queued before the bus-off completes a sample, but bus-off is the newer news.
  EXPECT_EQ(rig.cycle(w), HalStatus::bus_off);
  EXPECT_TRUE(rig.ft->bus_off());
  const std::uint64_t polls = rig.ft->protocol_counters().polls_sent;
  for (int i = 0; i < 10; ++i) EXPECT_EQ(rig.cycle(w), HalStatus::bus_off);
  EXPECT_EQ(rig.ft->protocol_counters().polls_sent, polls);  // nothing sent while bus-off
  EXPECT_EQ(rig.ft->counters().bus_off, 11u);
  EXPECT_EQ(rig.ft->link_counters().bus_off_events, 1u);
  // The controller restarts (ip link ... restart-ms): polling resumes; the first two samples
  // after the restart are withheld.
  ASSERT_EQ(rig.emulator->send_error(kCanErrRestarted), CanIo::ok);
  EXPECT_EQ(rig.cycle(w), HalStatus::no_data);  // restart seen, poll sent
  EXPECT_FALSE(rig.ft->bus_off());
  EXPECT_EQ(rig.cycle(w), HalStatus::no_data);  // held 1
  EXPECT_EQ(rig.cycle(w), HalStatus::no_data);  // held 2
  ASSERT_EQ(rig.cycle(w), HalStatus::ok);
  EXPECT_EQ(rig.ft->link_counters().bus_restarts, 1u);
  EXPECT_EQ(rig.ft->link_counters().held_samples, 2u);
  // The sample lost to the bus-off shows as one dropped sample.
  EXPECT_EQ(rig.ft->counters().dropped, 1u);
  EXPECT_EQ(w.header.status_bits, hal::kFtCanBusError);  // error frames since the last sample
}

TEST(SocketCanAti, AFrameFromTheSensorEndsBusOff) {
  AtiRig rig;
  ASSERT_TRUE(rig.pair());
  ASSERT_EQ(rig.make(), HalStatus::ok);
  ASSERT_TRUE(rig.run_setup());
  WrenchReading w;
  ASSERT_EQ(rig.next_sample(w), HalStatus::ok);
  ASSERT_EQ(rig.cycle(w), HalStatus::ok);
  ASSERT_EQ(rig.emulator->send_error(kCanErrBusOff), CanIo::ok);
  ASSERT_EQ(rig.cycle(w), HalStatus::bus_off);
  // No restart error frame (e.g. not subscribed), but the sensor is heard again.
  const std::uint8_t payload[8] = {0, 0, 0, 1, 0, 2, 0, 3};
  ASSERT_EQ(rig.emulator->send_raw(make_standard_frame(0x200, payload, 8)), CanIo::ok);
  EXPECT_EQ(rig.cycle(w), HalStatus::no_data);
  EXPECT_FALSE(rig.ft->bus_off());
  EXPECT_EQ(rig.ft->link_counters().bus_restarts, 1u);
  ASSERT_EQ(rig.cycle(w), HalStatus::ok);
}

TEST(SocketCanAti, SilentSensorTimesOutAndRecovers) {
  AtiRig rig;
  rig.config.response_timeout_s = 5 * kTick;
  rig.config.timeout_s = 20 * kTick;
  ASSERT_TRUE(rig.pair());
  ASSERT_EQ(rig.make(), HalStatus::ok);
  ASSERT_TRUE(rig.run_setup());
  WrenchReading w;
  ASSERT_EQ(rig.next_sample(w), HalStatus::ok);
  rig.emulator->faults().mute = true;
  ASSERT_EQ(rig.cycle(w), HalStatus::ok);  // the answer sent before the sensor went quiet
  int empty = 0;
  HalStatus s = HalStatus::no_data;
  while ((s = rig.cycle(w)) == HalStatus::no_data && empty < 100) ++empty;
  EXPECT_EQ(s, HalStatus::timeout);
  EXPECT_EQ(empty, 20);  // timeout once more than 20 ticks passed without a sample
  for (int i = 0; i < 4; ++i) EXPECT_EQ(rig.cycle(w), HalStatus::timeout);
  EXPECT_EQ(rig.ft->counters().timeouts, 5u);
  EXPECT_EQ(rig.ft->protocol_counters().unanswered_polls, 5u);  // one per response timeout
  rig.emulator->faults().mute = false;
  ASSERT_EQ(rig.next_sample(w), HalStatus::ok);
  test::expect_no_nan(w);
}

TEST(SocketCanAti, PeerCloseIsDisconnectedAndASocketpairCannotReconnect) {
  AtiRig rig;
  rig.config.link.reconnect_interval_s = 10 * kTick;
  ASSERT_TRUE(rig.pair());
  ASSERT_EQ(rig.make(), HalStatus::ok);
  ASSERT_TRUE(rig.run_setup());
  WrenchReading w;
  ASSERT_EQ(rig.next_sample(w), HalStatus::ok);
  rig.emulator->disconnect();
  // The answer already queued is still read, then the end of stream.
  ASSERT_EQ(rig.cycle(w), HalStatus::ok);
  EXPECT_EQ(rig.cycle(w), HalStatus::disconnected);
  for (int i = 0; i < 25; ++i) EXPECT_EQ(rig.cycle(w), HalStatus::disconnected);
  EXPECT_EQ(rig.ft->counters().disconnects, 1u);
  EXPECT_EQ(rig.ft->counters().disconnected, 26u);
  EXPECT_EQ(rig.ft->link_counters().reconnect_attempts, 2u);  // at +10 and +20 ticks
  EXPECT_EQ(rig.ft->link_counters().reconnects, 0u);
}

TEST(SocketCanAti, ReconnectsThroughTheListenerAndSetsUpAgain) {
  AtiRig rig;
  rig.config.link.reconnect_interval_s = 10 * kTick;
  const std::string address = test::unique_address("ati");
  SeqpacketCanListener listener;
  ASSERT_EQ(listener.listen(address.c_str()), HalStatus::ok);
  ASSERT_EQ(rig.device_end.set_address(address.c_str()), HalStatus::ok);
  rig.emulator = std::make_unique<AtiNetCanEmulator>(rig.sensor_end, rig.emulator_config);
  rig.emulator->set_gauges(test::kHandGauges);
  ASSERT_EQ(rig.make(), HalStatus::ok);  // configure connects
  ASSERT_EQ(listener.accept(rig.sensor_end), HalStatus::ok);
  ASSERT_TRUE(rig.run_setup());
  WrenchReading w;
  ASSERT_EQ(rig.next_sample(w), HalStatus::ok);
  rig.emulator->disconnect();
  ASSERT_EQ(rig.cycle(w), HalStatus::ok);
  ASSERT_EQ(rig.cycle(w), HalStatus::disconnected);
  int waiting = 0;
  HalStatus s = HalStatus::disconnected;
  while ((s = rig.cycle(w)) == HalStatus::disconnected && waiting < 50) ++waiting;
  EXPECT_EQ(waiting, 8);             // the reopen waits one reconnect interval (10 ticks)
  EXPECT_EQ(s, HalStatus::no_data);  // reconnected; setup starts again
  EXPECT_FALSE(rig.ft->ready());
  ASSERT_EQ(listener.accept(rig.sensor_end), HalStatus::ok);  // the emulator's side of it
  ASSERT_TRUE(rig.run_setup());
  ASSERT_EQ(rig.next_sample(w), HalStatus::ok);
  test::expect_hand(w);
  EXPECT_EQ(rig.ft->counters().reconnects, 1u);
  EXPECT_EQ(rig.ft->link_counters().reconnects, 1u);
  EXPECT_EQ(rig.ft->protocol_counters().setups_completed, 2u);
  EXPECT_EQ(rig.emulator->counters().calibration_requests, 2u);
}

TEST(SocketCanAti, SetupFailuresAreDeviceFaultsAndAreRetried) {
  AtiRig rig;
  rig.config.link.reconnect_interval_s = 10 * kTick;
  rig.emulator_config.calibration.force_unit = 9;  // no such unit code
  ASSERT_TRUE(rig.pair());
  ASSERT_EQ(rig.make(), HalStatus::ok);
  WrenchReading w;
  HalStatus s = HalStatus::no_data;
  for (int i = 0; i < 30 && s != HalStatus::device_fault; ++i) s = rig.cycle(w);
  ASSERT_EQ(s, HalStatus::device_fault);
  EXPECT_EQ(rig.ft->setup_error(), AtiSetupError::bad_calibration);
  EXPECT_EQ(rig.ft->calibration_error(), ati::CalibrationError::unknown_force_unit);
  EXPECT_EQ(rig.cycle(w), HalStatus::device_fault);
  // The board gets fixed (e.g. recalibrated); the retry after the interval succeeds.
  rig.emulator->config().calibration.force_unit = 2;
  ASSERT_TRUE(rig.run_setup());
  ASSERT_EQ(rig.next_sample(w), HalStatus::ok);
  test::expect_hand(w);
  EXPECT_EQ(rig.ft->protocol_counters().setup_failures, 1u);
  EXPECT_GE(rig.ft->counters().device_faults, 2u);

  AtiRig refused;
  refused.emulator_config.calibration_slots = 2;  // index 3 does not exist on this board
  ASSERT_TRUE(refused.pair());
  ASSERT_EQ(refused.make(), HalStatus::ok);
  s = HalStatus::no_data;
  for (int i = 0; i < 10 && s != HalStatus::device_fault; ++i) s = refused.cycle(w);
  EXPECT_EQ(s, HalStatus::device_fault);
  EXPECT_EQ(refused.ft->setup_error(), AtiSetupError::calibration_refused);
  EXPECT_EQ(refused.emulator->counters().matrix_requests, 0u);
}

TEST(SocketCanAti, SetupRequestsAreRepeatedWhenUnanswered) {
  AtiRig rig;
  rig.config.response_timeout_s = 4 * kTick;
  ASSERT_TRUE(rig.pair());
  rig.emulator->faults().mute = true;
  ASSERT_EQ(rig.make(), HalStatus::ok);
  WrenchReading w;
  for (int i = 0; i < 9; ++i) EXPECT_EQ(rig.cycle(w), HalStatus::no_data);
  EXPECT_EQ(rig.ft->protocol_counters().setup_requests, 3u);  // at 1, 5 and 9 ticks
  EXPECT_EQ(rig.ft->protocol_counters().setup_retries, 2u);
  rig.emulator->faults().mute = false;
  ASSERT_TRUE(rig.run_setup());
}

TEST(SocketCanAti, CalibrationFromTheConfigSkipsTheMatrixReads) {
  AtiRig rig;
  rig.config.calibration_from_device = false;
  rig.config.calibration = test::hand_calibration();
  for (float& v : rig.emulator_config.calibration.matrix) v = 7.0f;  // must not be used
  ASSERT_TRUE(rig.pair());
  ASSERT_EQ(rig.make(), HalStatus::ok);
  ASSERT_TRUE(rig.run_setup());
  EXPECT_EQ(rig.emulator->counters().matrix_requests, 0u);
  EXPECT_EQ(rig.emulator->active_calibration(), 3);
  WrenchReading w;
  ASSERT_EQ(rig.next_sample(w), HalStatus::ok);
  test::expect_hand(w);
  EXPECT_EQ(rig.ft->info().calibration.counts_per_force, 1000u);
}

TEST(SocketCanAti, BadConfigurationsAreRefused) {
  auto refused = [](void (*edit)(AtiNetCanConfig&)) {
    AtiRig rig;
    edit(rig.config);
    if (!rig.pair()) return false;
    AtiNetCanForceTorque ft(rig.device_end, rig.clock, rig.config);
    const bool r = ft.configure() == HalStatus::invalid_argument && ft.state() == hal::LifecycleState::unconfigured;
    return r;
  };
  EXPECT_TRUE(refused([](AtiNetCanConfig& c) { c.base_id = 0x80; }));
  EXPECT_TRUE(refused([](AtiNetCanConfig& c) { c.calibration_index = 16; }));
  EXPECT_TRUE(refused([](AtiNetCanConfig& c) { c.poll_period_s = -1; }));
  EXPECT_TRUE(refused([](AtiNetCanConfig& c) { c.response_timeout_s = 0; }));
  EXPECT_TRUE(refused([](AtiNetCanConfig& c) { c.timeout_s = std::numeric_limits<double>::infinity(); }));
  EXPECT_TRUE(refused([](AtiNetCanConfig& c) { c.gauge_bias[4] = std::numeric_limits<double>::quiet_NaN(); }));
  EXPECT_TRUE(refused([](AtiNetCanConfig& c) { c.tare_samples_on_start = -1; }));
  EXPECT_TRUE(refused([](AtiNetCanConfig& c) { c.link.max_frames_per_read = 0; }));
  EXPECT_TRUE(refused([](AtiNetCanConfig& c) {
    c.calibration_from_device = false;
    c.calibration = test::hand_calibration();
    c.calibration.counts_per_force = 0;
  }));
  // A transport that cannot open fails configure with its reason.
  hal::ManualClock clock;
  SeqpacketCanTransport nowhere;
  AtiNetCanForceTorque ft(nowhere, clock, AtiNetCanConfig{});
  EXPECT_EQ(ft.configure(), HalStatus::disconnected);
  EXPECT_EQ(ft.state(), hal::LifecycleState::unconfigured);
  WrenchReading w;
  EXPECT_EQ(ft.read(w), HalStatus::wrong_state);
  EXPECT_EQ(ft.tare(3), HalStatus::wrong_state);
}

TEST(SocketCanAti, StopStartFlushesStaleFramesAndKeepsTheSequence) {
  AtiRig rig;
  ASSERT_TRUE(rig.pair());
  ASSERT_EQ(rig.make(), HalStatus::ok);
  ASSERT_TRUE(rig.run_setup());
  WrenchReading w;
  ASSERT_EQ(rig.next_sample(w), HalStatus::ok);
  ASSERT_EQ(rig.cycle(w), HalStatus::ok);
  EXPECT_EQ(w.header.sequence, 2u);
  ASSERT_EQ(rig.ft->stop(), HalStatus::ok);
  EXPECT_EQ(rig.ft->read(w), HalStatus::wrong_state);
  // Frames queued while stopped (the answer in flight, and two more) are stale at start.
  const std::uint8_t payload[8] = {};
  ASSERT_EQ(rig.emulator->send_raw(make_standard_frame(0x200, payload, 8)), CanIo::ok);
  ASSERT_EQ(rig.emulator->send_raw(make_standard_frame(0x201, payload, 6)), CanIo::ok);
  ASSERT_EQ(rig.ft->start(), HalStatus::ok);
  EXPECT_EQ(rig.ft->link_counters().flushed_frames, 4u);
  ASSERT_TRUE(rig.run_setup());
  ASSERT_EQ(rig.next_sample(w), HalStatus::ok);
  test::expect_hand(w);
  EXPECT_EQ(w.header.sequence, 3u);
  EXPECT_EQ(rig.ft->protocol_counters().setups_completed, 2u);
  ASSERT_EQ(rig.ft->stop(), HalStatus::ok);
  ASSERT_EQ(rig.ft->cleanup(), HalStatus::ok);
  EXPECT_TRUE(rig.device_end.is_open());  // configure did not open it, so cleanup leaves it
}

TEST(SocketCanAti, ReadIsBoundedWhenTheBusFloods) {
  AtiRig rig;
  rig.config.link.max_frames_per_read = 4;
  ASSERT_TRUE(rig.pair());
  ASSERT_EQ(rig.make(), HalStatus::ok);
  ASSERT_TRUE(rig.run_setup());
  WrenchReading w;
  ASSERT_EQ(rig.next_sample(w), HalStatus::ok);
  // Ten foreign frames queue behind the answer to the poll in flight.
  const std::uint8_t payload[8] = {};
  for (int i = 0; i < 10; ++i) ASSERT_EQ(rig.emulator->send_raw(make_standard_frame(0x555, payload, 8)), CanIo::ok);
  ASSERT_EQ(rig.cycle(w), HalStatus::ok);  // answer (2) + 2 foreign
  EXPECT_EQ(rig.ft->protocol_counters().foreign_frames, 2u);
  EXPECT_EQ(rig.cycle(w), HalStatus::no_data);  // 4 foreign
  EXPECT_EQ(rig.cycle(w), HalStatus::no_data);  // 4 foreign
  EXPECT_EQ(rig.ft->protocol_counters().foreign_frames, 10u);
  EXPECT_EQ(rig.ft->link_counters().budget_exhausted, 3u);
  // The poll sent in the first of these reads is still within its response timeout (20 ms).
  ASSERT_EQ(rig.cycle(w), HalStatus::ok);
}

TEST(SocketCanAti, ReceiveTimestampsStampTheSample) {
  AtiRig rig;
  rig.config.link.use_receive_timestamps = true;
  ASSERT_TRUE(rig.pair());
  ASSERT_EQ(rig.make(), HalStatus::ok);
  ASSERT_TRUE(rig.run_setup());
  WrenchReading w;
  ASSERT_EQ(rig.next_sample(w), HalStatus::ok);
  // The stamp is the read's clock time minus the frame's age (micro- to milliseconds here).
  EXPECT_LE(w.header.stamp_s, rig.clock.now_s());
  EXPECT_GE(w.header.stamp_s, rig.clock.now_s() - 1.0);
  EXPECT_EQ(rig.ft->link_counters().untrusted_stamps, 0u);
}

}  // namespace
}  // namespace pliant::drivers::socketcan

// drivers/openni2 oni_file: the structural check of .oni recordings, on the room.oni fixture, on
// every truncation of it, on aimed corruptions (including the two that crash OpenNI2's player),
// on random ones, and on a small recording built here.
#include <gtest/gtest.h>

#include <functional>
#include <random>
#include <string>
#include <vector>

#include "oni_test_support.hpp"
#include "pliant/drivers/openni2/oni_file.hpp"
#include "support/temp_dir.hpp"

namespace {

using namespace pliant::drivers::openni2;
namespace oni = pliant::test_support::oni;

const std::vector<std::uint8_t>& fixture() {
  static const std::vector<std::uint8_t> bytes = oni::read_bytes(oni::fixture_path());
  return bytes;
}

OniCheckResult check(const std::vector<std::uint8_t>& bytes, OniFileInfo& info) {
  return check_oni_bytes(bytes.data(), bytes.size(), info);
}

OniCheck status_of(const std::vector<std::uint8_t>& bytes) {
  OniFileInfo info;
  return check(bytes, info).status;
}

const oni::Record& first_record(const std::vector<oni::Record>& list, std::uint32_t type, std::uint32_t node) {
  for (const oni::Record& r : list) {
    if (r.type == type && r.node == node) return r;
  }
  throw std::runtime_error("record not found");
}

TEST(Openni2OniFile, DescribesTheFixture) {
  ASSERT_EQ(fixture().size(), 2124474u) << "tests/data/oni_kinect/room.oni changed";
  OniFileInfo info;
  const OniCheckResult result = check(fixture(), info);
  ASSERT_TRUE(result.ok()) << result.message;
  EXPECT_TRUE(result.message.empty());
  EXPECT_EQ(info.version_major, 1);
  EXPECT_EQ(info.version_minor, 0);
  EXPECT_EQ(info.version_maintenance, 1);
  EXPECT_EQ(info.version_build, 0u);
  EXPECT_EQ(info.max_timestamp_us, 378742u);
  EXPECT_EQ(info.max_node_id, 3u);
  EXPECT_EQ(info.records, 151u);
  EXPECT_EQ(info.trailing_bytes, 0u);
  ASSERT_EQ(info.nodes.size(), 3u);
  EXPECT_EQ(info.nodes[0].name, "Device1");
  EXPECT_EQ(info.nodes[0].type, kOniNodeDevice);
  const OniNodeInfo* depth = info.first_node_of_type(kOniNodeDepth);
  ASSERT_NE(depth, nullptr);
  EXPECT_EQ(depth->name, "Depth1");
  EXPECT_EQ(depth->codec, "16zT");
  EXPECT_EQ(depth->frames_declared, 12u);
  EXPECT_EQ(depth->data_records, 12u);
  EXPECT_EQ(depth->first_frame, 1u);
  EXPECT_EQ(depth->last_frame, 12u);
  EXPECT_EQ(depth->first_timestamp_us, 11680u);
  EXPECT_EQ(depth->last_timestamp_us, 378742u);
  EXPECT_GT(depth->max_timestamp_step_us, 33000u);
  EXPECT_LT(depth->max_timestamp_step_us, 34000u);
  EXPECT_NE(depth->seek_table_offset, 0u);
  const OniNodeInfo* image = info.first_node_of_type(kOniNodeImage);
  ASSERT_NE(image, nullptr);
  EXPECT_EQ(image->codec, "JPEG");
  EXPECT_EQ(image->data_records, 12u);
  EXPECT_EQ(info.first_node_of_type(kOniNodeIr), nullptr);
}

TEST(Openni2OniFile, ReadsTheFixtureFromDisk) {
  OniFileInfo info;
  EXPECT_TRUE(check_oni_file(oni::fixture_path(), info).ok());
  EXPECT_EQ(info.file_bytes, 2124474u);

  const OniCheckResult missing = check_oni_file("/nonexistent/room.oni", info);
  EXPECT_EQ(missing.status, OniCheck::io_error);
  EXPECT_NE(missing.message.find("/nonexistent/room.oni"), std::string::npos) << missing.message;
  pliant::test_support::TempDir dir("pliant_oni_");
  EXPECT_EQ(check_oni_file(dir.path().string(), info).status, OniCheck::io_error) << "a directory";
  oni::write_bytes(dir / "text.oni", {'h', 'e', 'l', 'l', 'o', '\n'});
  EXPECT_EQ(check_oni_file(dir / "text.oni", info).status, OniCheck::too_short);
}

TEST(Openni2OniFile, RefusesEveryTruncation) {
  const std::vector<std::uint8_t>& full = fixture();
  const std::vector<oni::Record> list = oni::records(full);
  ASSERT_EQ(list.size(), 151u);
  std::vector<std::size_t> cuts = {0, 3, 23, 24, 25, 51, 52};
  for (const oni::Record& r : list) {
    cuts.push_back(r.offset);       // at a record boundary: the rest is missing
    cuts.push_back(r.offset + 13);  // inside a header
    cuts.push_back(r.offset + r.fields - 1 + (r.payload > 0 ? r.payload / 2 : 0));  // inside fields or payload
  }
  for (std::size_t cut : cuts) {
    if (cut >= full.size()) continue;
    const std::vector<std::uint8_t> part(full.begin(), full.begin() + static_cast<std::ptrdiff_t>(cut));
    OniFileInfo info;
    const OniCheckResult result = check(part, info);
    EXPECT_FALSE(result.ok()) << "cut at " << cut;
    if (cut < 24) {
      EXPECT_EQ(result.status, OniCheck::too_short) << cut;
    } else {
      EXPECT_EQ(result.status, OniCheck::truncated) << cut << ": " << result.message;
    }
  }
  // Only the End record missing (OpenNI2 would play this, but spin at the end): refused too.
  const std::vector<std::uint8_t> no_end(full.begin(), full.end() - 28);
  OniFileInfo info;
  const OniCheckResult result = check(no_end, info);
  EXPECT_EQ(result.status, OniCheck::truncated);
  EXPECT_NE(result.message.find("End record"), std::string::npos) << result.message;
}

// The two single-byte changes that made OpenNI2 2.2's player crash (SIGSEGV) in experiments:
// a property name without its NUL, and a name with a byte above 0x7F.
TEST(Openni2OniFile, RefusesTheNamesThatCrashOpenNi2) {
  std::vector<std::uint8_t> bytes = fixture();
  const std::size_t at = oni::find_text(bytes, "LowLightCompensation", true);
  ASSERT_NE(at, std::string::npos);
  bytes[at + 20] = 0xAE;
  OniFileInfo info;
  OniCheckResult result = check(bytes, info);
  EXPECT_EQ(result.status, OniCheck::bad_string) << result.message;
  EXPECT_NE(result.message.find("property name"), std::string::npos) << result.message;

  bytes = fixture();
  const std::size_t user = oni::find_text(bytes, "xnUserPositions", true);
  ASSERT_NE(user, std::string::npos);
  bytes[user + 9] = 0xDA;
  result = check(bytes, info);
  EXPECT_EQ(result.status, OniCheck::bad_string) << result.message;
}

TEST(Openni2OniFile, RefusesAimedCorruptions) {
  const std::vector<std::uint8_t>& full = fixture();
  const std::vector<oni::Record> list = oni::records(full);
  const oni::Record& depth_added = first_record(list, 0x0D, 2);
  const oni::Record& int_prop = first_record(list, 0x03, 1);
  const oni::Record& depth_data = first_record(list, 0x0A, 2);
  const oni::Record& seek_table = first_record(list, 0x0E, 2);
  std::vector<oni::Record> depth_frames;
  for (const oni::Record& r : list) {
    if (r.type == 0x0A && r.node == 2) depth_frames.push_back(r);
  }
  ASSERT_EQ(depth_frames.size(), 12u);

  struct Case {
    const char* what;
    OniCheck expected;
    std::function<void(std::vector<std::uint8_t>&)> edit;
  };
  const std::vector<Case> cases = {
      {"file magic", OniCheck::bad_magic, [](auto& b) { b[1] = 'X'; }},
      {"version 1.0.2.0", OniCheck::unsupported_version, [](auto& b) { b[6] = 2; }},
      {"version 1.0.0.3", OniCheck::unsupported_version,
       [](auto& b) {
         b[6] = 0;
         oni::put32(b, 8, 3);
       }},
      {"1000 nodes", OniCheck::bad_node_count, [](auto& b) { oni::put32(b, 20, 999); }},
      {"record magic", OniCheck::bad_record, [&](auto& b) { b[int_prop.offset] = 'M'; }},
      {"record type 1", OniCheck::bad_record, [&](auto& b) { oni::put32(b, int_prop.offset + 4, 1); }},
      {"record type 99", OniCheck::bad_record, [&](auto& b) { oni::put32(b, int_prop.offset + 4, 99); }},
      {"fields under the header", OniCheck::bad_record, [&](auto& b) { oni::put32(b, int_prop.offset + 12, 20); }},
      {"fields beyond the player's buffer", OniCheck::bad_record,
       [&](auto& b) { oni::put32(b, int_prop.offset + 12, 6000000); }},
      {"fields beyond the file", OniCheck::truncated, [&](auto& b) { oni::put32(b, int_prop.offset + 12, 3000000); }},
      {"payload on a property", OniCheck::bad_record, [&](auto& b) { oni::put32(b, int_prop.offset + 16, 4); }},
      {"int property of 4 bytes", OniCheck::bad_record,
       [&](auto& b) {
         const std::uint32_t name_len = oni::get32(b, int_prop.offset + 28);
         oni::put32(b, int_prop.offset + 32 + name_len, 4);
       }},
      {"name length beyond the fields", OniCheck::bad_string,
       [&](auto& b) { oni::put32(b, int_prop.offset + 28, 500); }},
      {"empty name", OniCheck::bad_string, [&](auto& b) { oni::put32(b, int_prop.offset + 28, 0); }},
      {"node id above the header's", OniCheck::bad_node, [&](auto& b) { oni::put32(b, int_prop.offset + 8, 7); }},
      {"property of a node not added yet", OniCheck::bad_node, [&](auto& b) { oni::put32(b, int_prop.offset + 8, 3); }},
      {"node added twice", OniCheck::bad_node, [&](auto& b) { oni::put32(b, depth_added.offset + 8, 1); }},
      {"frame number 0", OniCheck::bad_frame, [&](auto& b) { oni::put32(b, depth_data.offset + 36, 0); }},
      {"frame number above the declared 12", OniCheck::bad_frame,
       [&](auto& b) { oni::put32(b, depth_frames[11].offset + 36, 13); }},
      {"frame number repeated", OniCheck::bad_frame, [&](auto& b) { oni::put32(b, depth_frames[5].offset + 36, 5); }},
      {"timestamp above the largest", OniCheck::bad_timestamp,
       [&](auto& b) { oni::put64(b, depth_frames[3].offset + 28, 378743); }},
      {"undo position forward", OniCheck::bad_position,
       [&](auto& b) { oni::put64(b, depth_frames[3].offset + 20, depth_frames[4].offset); }},
      {"undo position inside a record", OniCheck::bad_position,
       [&](auto& b) { oni::put64(b, depth_frames[3].offset + 20, depth_frames[1].offset + 4); }},
      {"seek table position elsewhere", OniCheck::bad_position,
       [&](auto& b) { oni::put64(b, depth_added.offset + 28 + 4 + 7 + 4 + 4 + 4 + 8 + 8, int_prop.offset); }},
      {"seek table position beyond the file", OniCheck::bad_position,
       [&](auto& b) { oni::put64(b, depth_added.offset + 28 + 4 + 7 + 4 + 4 + 4 + 8 + 8, 1u << 30); }},
      {"seek table of the wrong size", OniCheck::bad_record,
       [&](auto& b) {
         // Shrink the table by one entry and move the End record up behind it.
         const std::size_t end_of_table = seek_table.offset + seek_table.fields + seek_table.payload;
         oni::put32(b, seek_table.offset + 16, seek_table.payload - 20);
         b.erase(b.begin() + static_cast<std::ptrdiff_t>(end_of_table - 20),
                 b.begin() + static_cast<std::ptrdiff_t>(end_of_table));
       }},
      {"new data without payload", OniCheck::bad_record,
       [&](auto& b) {
         const std::size_t payload_at = depth_frames[11].offset + depth_frames[11].fields;
         oni::put32(b, depth_frames[11].offset + 16, 0);
         b.erase(b.begin() + static_cast<std::ptrdiff_t>(payload_at),
                 b.begin() + static_cast<std::ptrdiff_t>(payload_at + depth_frames[11].payload));
       }},
  };
  for (const Case& c : cases) {
    std::vector<std::uint8_t> bytes = full;
    c.edit(bytes);
    OniFileInfo info;
    const OniCheckResult result = check(bytes, info);
    EXPECT_EQ(result.status, c.expected) << c.what << ": " << oni_check_name(result.status) << " " << result.message;
    EXPECT_FALSE(result.message.empty()) << c.what;
    EXPECT_LT(result.offset, bytes.size()) << c.what << ": the offset names a place in the file";
  }
}

TEST(Openni2OniFile, SurvivesRandomDamage) {
  std::mt19937 rng(20240611);
  const std::vector<std::uint8_t>& full = fixture();
  const std::vector<oni::Record> list = oni::records(full);
  int refused = 0;
  for (int trial = 0; trial < 300; ++trial) {
    std::vector<std::uint8_t> bytes = full;
    // Aim most changes at record headers and fields, where the walk looks.
    for (int k = 0; k < 4; ++k) {
      const oni::Record& r = list[std::uniform_int_distribution<std::size_t>(0, list.size() - 1)(rng)];
      const std::size_t at = r.offset + std::uniform_int_distribution<std::size_t>(0, r.fields - 1)(rng);
      bytes[at] = static_cast<std::uint8_t>(rng());
    }
    OniFileInfo info;
    const OniCheckResult result = check(bytes, info);
    if (!result.ok()) {
      ++refused;
      EXPECT_FALSE(result.message.empty());
    }
  }
  EXPECT_GT(refused, 100) << "most header damage must be noticed";
}

// A recording built here: one depth node, two frames, no seek table.
std::vector<std::uint8_t> tiny_recording(bool wide) {
  std::vector<std::uint8_t> b = {
      'N', 'I', '1', '0', 1, 0, static_cast<std::uint8_t>(wide ? 1 : 0), 0, static_cast<std::uint8_t>(wide ? 0 : 9),
      0,   0,   0};
  const auto u32 = [&](std::uint32_t v) {
    for (int i = 0; i < 4; ++i) b.push_back(static_cast<std::uint8_t>(v >> (8 * i)));
  };
  const auto u64 = [&](std::uint64_t v) {
    for (int i = 0; i < 8; ++i) b.push_back(static_cast<std::uint8_t>(v >> (8 * i)));
  };
  u64(66000);  // largest timestamp
  u32(1);      // largest node id
  const auto record = [&](std::uint32_t type, std::uint32_t node, const std::vector<std::uint8_t>& fields,
                          std::uint32_t payload) {
    const std::uint32_t header = wide ? 28 : 24;
    b.insert(b.end(), {'N', 'I', 'R', 0});
    u32(type);
    u32(node);
    u32(header + static_cast<std::uint32_t>(fields.size()));
    u32(payload);
    if (wide)
      u64(0);
    else
      u32(0);
    b.insert(b.end(), fields.begin(), fields.end());
    b.insert(b.end(), payload, 0x11);
  };
  std::vector<std::uint8_t> added = {7, 0, 0, 0, 'D', 'e', 'p', 't', 'h', '1', 0, 2, 0, 0, 0, 'N', 'O', 'N', 'E'};
  const std::vector<std::uint8_t> counts = {2, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0xD0, 0x01, 1, 0, 0, 0, 0, 0};
  added.insert(added.end(), counts.begin(), counts.end());  // 2 frames, min 0, max 66000 (0x101D0)
  record(0x0C, 1, added, 0);
  record(0x09, 1, {}, 0);
  record(0x08, 1, {2, 0, 0, 0, 0xD0, 0x01, 1, 0, 0, 0, 0, 0}, 0);
  record(0x0A, 1, {0xE8, 0x80, 0, 0, 0, 0, 0, 0, 1, 0, 0, 0}, 8);  // 33000 us, frame 1
  record(0x0A, 1, {0xD0, 0x01, 1, 0, 0, 0, 0, 0, 2, 0, 0, 0}, 8);  // 66000 us, frame 2
  record(0x07, 1, {}, 0);
  record(0x0B, 0xFFFFFFFFu, {}, 0);
  return b;
}

TEST(Openni2OniFile, AcceptsABuiltRecordingInBothHeaderSizes) {
  for (bool wide : {true, false}) {
    const std::vector<std::uint8_t> bytes = tiny_recording(wide);
    OniFileInfo info;
    const OniCheckResult result = check(bytes, info);
    ASSERT_TRUE(result.ok()) << (wide ? "1.0.1.0: " : "1.0.0.9: ") << result.message;
    const OniNodeInfo* depth = info.first_node_of_type(kOniNodeDepth);
    ASSERT_NE(depth, nullptr);
    EXPECT_EQ(depth->data_records, 2u);
    EXPECT_EQ(depth->max_timestamp_step_us, 33000u);
    EXPECT_EQ(info.records, 7u);
    std::vector<std::uint8_t> trailing = bytes;
    trailing.push_back(0);
    ASSERT_TRUE(check(trailing, info).ok());
    EXPECT_EQ(info.trailing_bytes, 1u);
  }
  // Without its data records: nothing to play.
  std::vector<std::uint8_t> bytes = tiny_recording(true);
  const std::vector<oni::Record> list = oni::records(bytes);
  std::vector<std::uint8_t> no_data(bytes.begin(), bytes.begin() + static_cast<std::ptrdiff_t>(list[3].offset));
  no_data.insert(no_data.end(), bytes.begin() + static_cast<std::ptrdiff_t>(list[5].offset), bytes.end());
  EXPECT_EQ(status_of(no_data), OniCheck::no_data);
}

}  // namespace

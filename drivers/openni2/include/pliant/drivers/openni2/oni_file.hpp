// pliant drivers/openni2: structural check of an OpenNI .oni recording before OpenNI2 sees it.
//
// Why: OpenNI2 2.2's file player (libOniFile) trusts the file. Tests here found inputs that
// crash it (SIGSEGV) when a property name loses its terminating NUL or holds a non-ASCII byte,
// and its code reads record fields into a fixed buffer without bounding them by that buffer,
// follows seek-table and undo positions without checking them, and skips a payload only for
// the record types that are supposed to have one. check_oni walks every record the way the
// player will and refuses a file with a clear reason (and the byte offset) instead. It does not
// decode frame payloads (16-bit depth codecs, JPEG): OpenNI2's decoders are left to cope with
// damaged pixels, which they did in the tests (a bad payload gives a bad image, not a crash).
//
// Format (OpenNI's file format 1.0.0.4 .. 1.0.1.0, little-endian, packed):
//   file header, 24 bytes: "NI10", version {u8 major, u8 minor, u16 maintenance, u32 build},
//     u64 largest timestamp (us), u32 largest node id
//   records from byte 24 to an End record: header {u32 "NIR\0", u32 type, u32 node id,
//     u32 fields size (header included), u32 payload size, undo position (u64 from version
//     1.0.1.0 on: a 28-byte header; u32 before: 24 bytes)}, then the fields, then the payload.
//   Types: 0x02/0x0C/0x0D node added (three generations), 0x03 int, 0x04 real, 0x05 string,
//     0x06 general property, 0x07 node removed, 0x08 data begin, 0x09 state ready, 0x0A new
//     data (u64 timestamp us, u32 frame number; payload: one compressed frame), 0x0B end,
//     0x0E seek table (payload: (frames + 1) entries of 20 bytes, 16 before 1.0.1.0).
//   Strings: u32 size including the NUL, then the characters.
//
// Checks (any failure refuses the whole file): header magic, a supported version, at most
// kOniMaxNodes nodes; every record complete inside the file, with its magic, a known type, a
// fields size at least the header and a total at most kOniRecordMaxBytes (the player's buffer),
// a payload only on new-data and seek-table records, fields that hold what their type needs;
// names NUL-terminated printable ASCII of at most kOniMaxNameBytes bytes; int and real
// properties of 8 bytes, a field of view ("xnFOV") of 16 and an output mode of at least 12;
// node ids below the header's count, records only for nodes that were added (and not removed,
// except seek tables), no node added twice; frame numbers from 1, strictly increasing per node
// and at most the node's declared frame count; timestamps at most the header's largest; undo
// positions pointing back at a record start; a node's seek-table position 0 or the start of a
// seek-table record of that node, with the size its frame count implies; an End record; at least
// one data record; at most kOniMaxRecords records.
//
// Not real-time code: check_oni allocates (names, the record index) and reads the file once.
// Thread safety: pure; separate calls may run concurrently.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace pliant::drivers::openni2 {

inline constexpr std::uint32_t kOniMaxNodes = 256;            ///< largest node id + 1 accepted
inline constexpr std::uint64_t kOniRecordMaxBytes = 5760121;  ///< OpenNI2's record buffer, bytes
inline constexpr std::uint32_t kOniMaxNameBytes = 80;         ///< name length limit, NUL included
inline constexpr std::uint64_t kOniMaxRecords = 10000000;     ///< records per file
inline constexpr std::uint32_t kOniMaxFrames = 50000000;      ///< declared frames per node

enum class OniCheck : std::uint8_t {
  ok,
  io_error,             ///< the file could not be opened or read
  too_short,            ///< smaller than the 24-byte file header
  bad_magic,            ///< the file does not start with "NI10"
  unsupported_version,  ///< version outside 1.0.0.4 .. 1.0.1.0
  bad_node_count,       ///< largest node id >= kOniMaxNodes
  truncated,            ///< a record runs past the end of the file, or there is no End record
  bad_record,           ///< bad record magic, type, sizes or fields
  bad_string,           ///< a string not NUL-terminated, too long, or a name not printable ASCII
  bad_node,             ///< node id out of range, unknown, removed, or added twice
  bad_frame,            ///< frame number 0, not increasing, or above the declared count
  bad_timestamp,        ///< a data timestamp above the header's largest
  bad_position,         ///< an undo or seek-table position that is not a fitting record start
  no_data,              ///< no data record at all
  too_many_records,     ///< more than kOniMaxRecords
};

/// Short stable name ("ok", "truncated", ...).
const char* oni_check_name(OniCheck check) noexcept;

/// OpenNI production node types as stored in the file.
inline constexpr std::uint32_t kOniNodeDevice = 1;
inline constexpr std::uint32_t kOniNodeDepth = 2;
inline constexpr std::uint32_t kOniNodeImage = 3;
inline constexpr std::uint32_t kOniNodeIr = 5;

struct OniNodeInfo {
  std::uint32_t id = 0;
  std::string name;                               ///< e.g. "Depth1"
  std::uint32_t type = 0;                         ///< kOniNodeDepth, ...
  std::string codec;                              ///< four characters, e.g. "16zT", "JPEG", "NONE"
  std::uint32_t frames_declared = 0;              ///< from the node-added (or data-begin) record
  std::uint64_t seek_table_offset = 0;            ///< 0: none
  std::uint32_t data_records = 0;                 ///< new-data records in the file
  std::uint32_t first_frame = 0, last_frame = 0;  ///< frame numbers of the first and last
  std::uint64_t first_timestamp_us = 0, last_timestamp_us = 0;
  std::uint64_t max_timestamp_step_us = 0;  ///< largest increase between consecutive records
};

struct OniFileInfo {
  std::uint8_t version_major = 0, version_minor = 0;
  std::uint16_t version_maintenance = 0;
  std::uint32_t version_build = 0;
  std::uint64_t file_bytes = 0;
  std::uint64_t max_timestamp_us = 0;  ///< from the file header
  std::uint32_t max_node_id = 0;
  std::uint64_t records = 0;         ///< records up to and including End
  std::uint64_t trailing_bytes = 0;  ///< bytes after the End record (ignored by OpenNI2)
  std::vector<OniNodeInfo> nodes;    ///< in the order they were first added
  /// The first node of `type` with at least one data record, or nullptr.
  const OniNodeInfo* first_node_of_type(std::uint32_t type) const noexcept;
};

struct OniCheckResult {
  OniCheck status = OniCheck::ok;
  std::uint64_t offset = 0;  ///< byte offset of the offending header or record
  std::string message;       ///< one line: what is wrong and where (empty when ok)
  bool ok() const noexcept { return status == OniCheck::ok; }
};

/// Random access to the bytes of a recording.
class OniByteSource {
 public:
  virtual ~OniByteSource() = default;
  virtual std::uint64_t size() const noexcept = 0;
  /// Reads exactly `count` bytes at `offset`; false on any failure (short read, I/O error).
  virtual bool read(std::uint64_t offset, void* out, std::size_t count) const noexcept = 0;

 protected:
  OniByteSource() = default;
  OniByteSource(const OniByteSource&) = default;
  OniByteSource& operator=(const OniByteSource&) = default;
};

/// Checks a recording; `info` describes it (also filled as far as the walk got on failure).
OniCheckResult check_oni(const OniByteSource& source, OniFileInfo& info);
/// Same over bytes in memory.
OniCheckResult check_oni_bytes(const std::uint8_t* data, std::size_t size, OniFileInfo& info);
/// Same over a file (io_error when it cannot be opened, is not a regular file, or a read fails).
OniCheckResult check_oni_file(const std::string& path, OniFileInfo& info);

}  // namespace pliant::drivers::openni2

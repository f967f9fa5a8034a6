#include "pliant/drivers/openni2/oni_file.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <utility>

namespace pliant::drivers::openni2 {
namespace {

constexpr std::uint32_t kRecordMagic = 0x0052494Eu;  // "NIR\0"
constexpr std::size_t kFileHeaderBytes = 24;

enum RecordType : std::uint32_t {
  kNodeAdded1004 = 0x02,
  kIntProperty = 0x03,
  kRealProperty = 0x04,
  kStringProperty = 0x05,
  kGeneralProperty = 0x06,
  kNodeRemoved = 0x07,
  kDataBegin = 0x08,
  kStateReady = 0x09,
  kNewData = 0x0A,
  kEnd = 0x0B,
  kNodeAdded1005 = 0x0C,
  kNodeAdded = 0x0D,
  kSeekTable = 0x0E,
};

bool known_type(std::uint32_t type) noexcept { return type >= kNodeAdded1004 && type <= kSeekTable; }

std::uint32_t le32(const std::uint8_t* p) noexcept {
  return static_cast<std::uint32_t>(p[0]) | static_cast<std::uint32_t>(p[1]) << 8 |
         static_cast<std::uint32_t>(p[2]) << 16 | static_cast<std::uint32_t>(p[3]) << 24;
}

std::uint64_t le64(const std::uint8_t* p) noexcept {
  return static_cast<std::uint64_t>(le32(p)) | static_cast<std::uint64_t>(le32(p + 4)) << 32;
}

// Versions compare as (major, minor, maintenance, build), like the player does.
std::uint64_t version_key(std::uint8_t major, std::uint8_t minor, std::uint16_t maintenance,
                          std::uint32_t build) noexcept {
  return static_cast<std::uint64_t>(major) << 56 | static_cast<std::uint64_t>(minor) << 48 |
         static_cast<std::uint64_t>(maintenance) << 32 | build;
}
constexpr std::uint64_t kOldestVersion = std::uint64_t{1} << 56 | 4;                           // 1.0.0.4
constexpr std::uint64_t kWideHeaderVersion = std::uint64_t{1} << 56 | std::uint64_t{1} << 32;  // 1.0.1.0

// Bounded reading of one record's fields.
class Fields {
 public:
  Fields(const std::uint8_t* data, std::size_t size) noexcept : data_(data), size_(size) {}
  bool u32(std::uint32_t& out) noexcept {
    if (size_ - pos_ < 4) return false;
    out = le32(data_ + pos_);
    pos_ += 4;
    return true;
  }
  bool u64(std::uint64_t& out) noexcept {
    if (size_ - pos_ < 8) return false;
    out = le64(data_ + pos_);
    pos_ += 8;
    return true;
  }
  bool skip(std::size_t count) noexcept {
    if (size_ - pos_ < count) return false;
    pos_ += count;
    return true;
  }
  const std::uint8_t* here() const noexcept { return data_ + pos_; }
  std::size_t left() const noexcept { return size_ - pos_; }

 private:
  const std::uint8_t* data_;
  std::size_t size_;
  std::size_t pos_ = 0;
};

struct NodeState {
  std::uint64_t added_at = 0;  // offset of the latest node-added record
  bool ever_added = false;
  bool active = false;
  std::size_t index = 0;  // into OniFileInfo::nodes
  std::uint32_t last_frame = 0;
  bool has_data = false;
};

class Walker {
 public:
  Walker(const OniByteSource& source, OniFileInfo& info) : source_(source), info_(info) {}

  OniCheckResult run() {
    info_ = OniFileInfo{};
    const std::uint64_t size = source_.size();
    info_.file_bytes = size;
    if (size < kFileHeaderBytes) {
      return fail(OniCheck::too_short, 0,
                  "file of " + std::to_string(size) + " bytes is shorter than the 24-byte .oni header");
    }
    std::uint8_t header[kFileHeaderBytes];
    if (!source_.read(0, header, sizeof header)) return fail(OniCheck::io_error, 0, "cannot read the file header");
    if (std::memcmp(header, "NI10", 4) != 0)
      return fail(OniCheck::bad_magic, 0, "not an .oni recording (no \"NI10\" magic)");
    info_.version_major = header[4];
    info_.version_minor = header[5];
    info_.version_maintenance = static_cast<std::uint16_t>(header[6] | header[7] << 8);
    info_.version_build = le32(header + 8);
    info_.max_timestamp_us = le64(header + 12);
    info_.max_node_id = le32(header + 20);
    const std::uint64_t version =
        version_key(info_.version_major, info_.version_minor, info_.version_maintenance, info_.version_build);
    if (version < kOldestVersion || version > kWideHeaderVersion) {
      return fail(OniCheck::unsupported_version, 4,
                  "file format version " + std::to_string(info_.version_major) + "." +
                      std::to_string(info_.version_minor) + "." + std::to_string(info_.version_maintenance) + "." +
                      std::to_string(info_.version_build) + " is outside the supported 1.0.0.4 .. 1.0.1.0");
    }
    wide_ = version >= kWideHeaderVersion;
    header_bytes_ = wide_ ? 28 : 24;
    if (info_.max_node_id >= kOniMaxNodes) {
      return fail(
          OniCheck::bad_node_count, 20,
          "largest node id " + std::to_string(info_.max_node_id) + " is not below " + std::to_string(kOniMaxNodes));
    }
    nodes_.assign(static_cast<std::size_t>(info_.max_node_id) + 1, NodeState{});

    std::uint64_t offset = kFileHeaderBytes;
    while (true) {
      if (offset == size) return fail(OniCheck::truncated, offset, "the file ends without an End record (truncated?)");
      OniCheckResult result = record(offset, size);
      if (!result.ok()) return result;
      if (ended_) break;
    }
    info_.trailing_bytes = size - offset;

    for (const OniNodeInfo& node : info_.nodes) {
      if (node.seek_table_offset == 0) continue;
      const auto match =
          std::find(seek_tables_.begin(), seek_tables_.end(), std::make_pair(node.id, node.seek_table_offset));
      if (match == seek_tables_.end()) {
        return fail(OniCheck::bad_position, nodes_[node.id].added_at,
                    "node \"" + node.name + "\" names a seek table at byte " + std::to_string(node.seek_table_offset) +
                        " where there is no seek-table record of that node");
      }
    }
    if (!any_data_) return fail(OniCheck::no_data, 0, "the recording holds no frame (no new-data record)");
    return {};
  }

 private:
  OniCheckResult fail(OniCheck status, std::uint64_t offset, std::string what) const {
    OniCheckResult result;
    result.status = status;
    result.offset = offset;
    result.message = std::move(what);
    return result;
  }

  OniCheckResult fail_record(OniCheck status, std::uint64_t offset, const std::string& what) const {
    return fail(status, offset,
                "record " + std::to_string(info_.records + 1) + " at byte " + std::to_string(offset) + ": " + what);
  }

  // One record at `offset`; advances `offset` past it.
  OniCheckResult record(std::uint64_t& offset, std::uint64_t size) {
    if (size - offset < header_bytes_)
      return fail_record(OniCheck::truncated, offset, "header cut off by the end of the file");
    std::uint8_t header[28];
    if (!source_.read(offset, header, header_bytes_)) return fail_record(OniCheck::io_error, offset, "read failed");
    const std::uint32_t magic = le32(header);
    const std::uint32_t type = le32(header + 4);
    const std::uint32_t node_id = le32(header + 8);
    const std::uint32_t fields_size = le32(header + 12);
    const std::uint32_t payload_size = le32(header + 16);
    const std::uint64_t undo = wide_ ? le64(header + 20) : le32(header + 20);
    if (magic != kRecordMagic) return fail_record(OniCheck::bad_record, offset, "no \"NIR\" record magic");
    if (!known_type(type))
      return fail_record(OniCheck::bad_record, offset, "unknown record type " + std::to_string(type));
    if (fields_size < header_bytes_)
      return fail_record(OniCheck::bad_record, offset, "fields size smaller than the record header");
    const std::uint64_t total = std::uint64_t{fields_size} + payload_size;
    if (total > kOniRecordMaxBytes) {
      return fail_record(
          OniCheck::bad_record, offset,
          std::to_string(total) + " bytes exceed the player's record buffer of " + std::to_string(kOniRecordMaxBytes));
    }
    if (total > size - offset) {
      return fail_record(
          OniCheck::truncated, offset,
          "needs " + std::to_string(total) + " bytes, the file has " + std::to_string(size - offset) + " left");
    }
    if (payload_size != 0 && type != kNewData && type != kSeekTable) {
      return fail_record(OniCheck::bad_record, offset,
                         "payload on a record type " + std::to_string(type) + " that has none");
    }
    if (undo != 0 && (undo >= offset || !std::binary_search(record_offsets_.begin(), record_offsets_.end(), undo))) {
      return fail_record(OniCheck::bad_position, offset,
                         "undo position " + std::to_string(undo) + " is not an earlier record");
    }
    if (type != kEnd && node_id >= nodes_.size()) {
      return fail_record(
          OniCheck::bad_node, offset,
          "node id " + std::to_string(node_id) + " above the header's largest " + std::to_string(info_.max_node_id));
    }
    if (info_.records + 1 > kOniMaxRecords) return fail_record(OniCheck::too_many_records, offset, "too many records");

    fields_.resize(fields_size - header_bytes_);
    if (!fields_.empty() && !source_.read(offset + header_bytes_, fields_.data(), fields_.size())) {
      return fail_record(OniCheck::io_error, offset, "read failed");
    }
    OniCheckResult result = body(type, node_id, payload_size, offset);
    if (!result.ok()) return result;
    record_offsets_.push_back(offset);
    ++info_.records;
    if (type == kEnd) ended_ = true;
    offset += total;
    return {};
  }

  // A string field; names must be printable ASCII within kOniMaxNameBytes.
  bool string(Fields& in, bool is_name, std::string& out) const {
    std::uint32_t length = 0;
    if (!in.u32(length) || length == 0 || length > in.left()) return false;
    if (is_name && length > kOniMaxNameBytes) return false;
    const std::uint8_t* chars = in.here();
    if (chars[length - 1] != 0) return false;
    for (std::uint32_t i = 0; i + 1 < length; ++i) {
      if (chars[i] == 0) return false;
      if (is_name && (chars[i] < 0x20 || chars[i] > 0x7E)) return false;
    }
    out.assign(reinterpret_cast<const char*>(chars), length - 1);
    return in.skip(length);
  }

  NodeState* active_node(std::uint32_t node_id) noexcept {
    NodeState& node = nodes_[node_id];
    return node.active ? &node : nullptr;
  }

  OniCheckResult body(std::uint32_t type, std::uint32_t node_id, std::uint32_t payload_size, std::uint64_t offset) {
    Fields in(fields_.data(), fields_.size());
    const auto short_fields = [&](const char* what) {
      return fail_record(OniCheck::bad_record, offset, std::string("fields too short for ") + what);
    };
    switch (type) {
      case kNodeAdded1004:
      case kNodeAdded1005:
      case kNodeAdded: {
        OniNodeInfo node;
        node.id = node_id;
        if (!string(in, true, node.name)) return fail_record(OniCheck::bad_string, offset, "bad node name");
        std::uint32_t codec = 0;
        if (!in.u32(node.type) || !in.u32(codec)) return short_fields("a node");
        for (int i = 0; i < 4; ++i) {
          const char c = static_cast<char>((codec >> (8 * i)) & 0xFFu);
          node.codec.push_back(c >= 0x20 && c <= 0x7E ? c : '?');
        }
        if (type != kNodeAdded1004) {
          std::uint64_t min_ts = 0, max_ts = 0;
          if (!in.u32(node.frames_declared) || !in.u64(min_ts) || !in.u64(max_ts)) return short_fields("a node");
        }
        if (type == kNodeAdded && !in.u64(node.seek_table_offset)) return short_fields("a node");
        if (node.frames_declared > kOniMaxFrames)
          return fail_record(OniCheck::bad_frame, offset, "declared frame count too large");
        NodeState& state = nodes_[node_id];
        if (state.active)
          return fail_record(OniCheck::bad_node, offset, "node " + std::to_string(node_id) + " added twice");
        if (state.ever_added) {
          // Added again after a removal: the same node, continue its bookkeeping.
          OniNodeInfo& known = info_.nodes[state.index];
          known.name = node.name;
          known.type = node.type;
          known.codec = node.codec;
          known.frames_declared = node.frames_declared;
          known.seek_table_offset = node.seek_table_offset;
        } else {
          state.index = info_.nodes.size();
          info_.nodes.push_back(node);
        }
        state.ever_added = state.active = true;
        state.added_at = offset;
        return {};
      }
      case kIntProperty:
      case kRealProperty:
      case kStringProperty:
      case kGeneralProperty: {
        if (active_node(node_id) == nullptr)
          return fail_record(OniCheck::bad_node, offset, "property of an unknown node");
        std::string name;
        if (!string(in, true, name)) return fail_record(OniCheck::bad_string, offset, "bad property name");
        std::uint32_t data_size = 0;
        if (!in.u32(data_size) || data_size > in.left()) return short_fields("the property value");
        if ((type == kIntProperty || type == kRealProperty) && data_size != 8) {
          return fail_record(OniCheck::bad_record, offset, "property \"" + name + "\" is not 8 bytes");
        }
        if (type == kStringProperty) {
          const std::uint8_t* value = in.here();
          if (data_size == 0 || value[data_size - 1] != 0 ||
              std::memchr(value, 0, data_size) != value + data_size - 1) {
            return fail_record(OniCheck::bad_string, offset,
                               "property \"" + name + "\" is not one NUL-terminated string");
          }
        }
        if (type == kGeneralProperty) {
          if (name == "xnFOV" && data_size != 16) {
            return fail_record(OniCheck::bad_record, offset,
                               "field of view of " + std::to_string(data_size) + " bytes, not 16");
          }
          if (name == "xnMapOutputMode" && data_size < 12) {
            return fail_record(OniCheck::bad_record, offset,
                               "output mode of " + std::to_string(data_size) + " bytes, under 12");
          }
        }
        return {};
      }
      case kNodeRemoved:
      case kStateReady: {
        NodeState* node = active_node(node_id);
        if (node == nullptr) return fail_record(OniCheck::bad_node, offset, "record of an unknown node");
        if (type == kNodeRemoved) node->active = false;
        return {};
      }
      case kDataBegin: {
        NodeState* node = active_node(node_id);
        if (node == nullptr) return fail_record(OniCheck::bad_node, offset, "data begin of an unknown node");
        std::uint32_t frames = 0;
        std::uint64_t max_ts = 0;
        if (!in.u32(frames) || !in.u64(max_ts)) return short_fields("data begin");
        if (frames > kOniMaxFrames) return fail_record(OniCheck::bad_frame, offset, "declared frame count too large");
        OniNodeInfo& info = info_.nodes[node->index];
        if (info.frames_declared == 0) info.frames_declared = frames;  // 1.0.0.4 files declare frames here
        return {};
      }
      case kNewData: {
        NodeState* node = active_node(node_id);
        if (node == nullptr) return fail_record(OniCheck::bad_node, offset, "data of an unknown node");
        std::uint64_t timestamp = 0;
        std::uint32_t frame = 0;
        if (!in.u64(timestamp) || !in.u32(frame)) return short_fields("new data");
        OniNodeInfo& info = info_.nodes[node->index];
        if (frame == 0 || frame > info.frames_declared || (node->has_data && frame <= node->last_frame)) {
          return fail_record(OniCheck::bad_frame, offset,
                             "frame number " + std::to_string(frame) + " of node \"" + info.name + "\" (previous " +
                                 std::to_string(node->last_frame) + ", declared " +
                                 std::to_string(info.frames_declared) + ")");
        }
        if (timestamp > info_.max_timestamp_us) {
          return fail_record(OniCheck::bad_timestamp, offset,
                             "timestamp " + std::to_string(timestamp) + " us above the header's largest " +
                                 std::to_string(info_.max_timestamp_us));
        }
        if (payload_size == 0) return fail_record(OniCheck::bad_record, offset, "new data without a payload");
        if (node->has_data) {
          if (timestamp > info.last_timestamp_us) {
            info.max_timestamp_step_us = std::max(info.max_timestamp_step_us, timestamp - info.last_timestamp_us);
          }
        } else {
          info.first_frame = frame;
          info.first_timestamp_us = timestamp;
        }
        info.last_frame = frame;
        info.last_timestamp_us = timestamp;
        ++info.data_records;
        node->last_frame = frame;
        node->has_data = true;
        any_data_ = true;
        return {};
      }
      case kSeekTable: {
        if (!nodes_[node_id].ever_added)
          return fail_record(OniCheck::bad_node, offset, "seek table of an unknown node");
        const OniNodeInfo& info = info_.nodes[nodes_[node_id].index];
        const std::uint64_t entry = wide_ ? 20 : 16;
        if (payload_size != (std::uint64_t{info.frames_declared} + 1) * entry) {
          return fail_record(OniCheck::bad_record, offset,
                             "seek table of " + std::to_string(payload_size) + " bytes for " +
                                 std::to_string(info.frames_declared) + " frames");
        }
        seek_tables_.emplace_back(node_id, offset);
        return {};
      }
      case kEnd: return {};
      default: return fail_record(OniCheck::bad_record, offset, "unknown record type");
    }
  }

  const OniByteSource& source_;
  OniFileInfo& info_;
  bool wide_ = true;
  std::uint32_t header_bytes_ = 28;
  bool ended_ = false;
  bool any_data_ = false;
  std::vector<NodeState> nodes_;
  std::vector<std::uint64_t> record_offsets_;  // increasing
  std::vector<std::pair<std::uint32_t, std::uint64_t>> seek_tables_;
  std::vector<std::uint8_t> fields_;
};

class MemorySource final : public OniByteSource {
 public:
  MemorySource(const std::uint8_t* data, std::size_t size) noexcept : data_(data), size_(size) {}
  std::uint64_t size() const noexcept override { return size_; }
  bool read(std::uint64_t offset, void* out, std::size_t count) const noexcept override {
    if (offset > size_ || count > size_ - offset) return false;
    if (count != 0) std::memcpy(out, data_ + offset, count);
    return true;
  }

 private:
  const std::uint8_t* data_;
  std::size_t size_;
};

class FileSource final : public OniByteSource {
 public:
  FileSource(int fd, std::uint64_t size) noexcept : fd_(fd), size_(size) {}
  std::uint64_t size() const noexcept override { return size_; }
  bool read(std::uint64_t offset, void* out, std::size_t count) const noexcept override {
    auto* bytes = static_cast<std::uint8_t*>(out);
    while (count > 0) {
      const ssize_t got = ::pread(fd_, bytes, count, static_cast<off_t>(offset));
      if (got < 0 && errno == EINTR) continue;
      if (got <= 0) return false;
      bytes += got;
      count -= static_cast<std::size_t>(got);
      offset += static_cast<std::uint64_t>(got);
    }
    return true;
  }

 private:
  int fd_;
  std::uint64_t size_;
};

}  // namespace

const char* oni_check_name(OniCheck check) noexcept {
  switch (check) {
    case OniCheck::ok: return "ok";
    case OniCheck::io_error: return "io_error";
    case OniCheck::too_short: return "too_short";
    case OniCheck::bad_magic: return "bad_magic";
    case OniCheck::unsupported_version: return "unsupported_version";
    case OniCheck::bad_node_count: return "bad_node_count";
    case OniCheck::truncated: return "truncated";
    case OniCheck::bad_record: return "bad_record";
    case OniCheck::bad_string: return "bad_string";
    case OniCheck::bad_node: return "bad_node";
    case OniCheck::bad_frame: return "bad_frame";
    case OniCheck::bad_timestamp: return "bad_timestamp";
    case OniCheck::bad_position: return "bad_position";
    case OniCheck::no_data: return "no_data";
    case OniCheck::too_many_records: return "too_many_records";
  }
  return "unknown";
}

const OniNodeInfo* OniFileInfo::first_node_of_type(std::uint32_t type) const noexcept {
  for (const OniNodeInfo& node : nodes) {
    if (node.type == type && node.data_records > 0) return &node;
  }
  return nullptr;
}

OniCheckResult check_oni(const OniByteSource& source, OniFileInfo& info) { return Walker(source, info).run(); }

OniCheckResult check_oni_bytes(const std::uint8_t* data, std::size_t size, OniFileInfo& info) {
  const MemorySource source(data, data == nullptr ? 0 : size);
  return check_oni(source, info);
}

OniCheckResult check_oni_file(const std::string& path, OniFileInfo& info) {
  info = OniFileInfo{};
  OniCheckResult result;
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) {
    result.status = OniCheck::io_error;
    result.message = "cannot open \"" + path + "\": " + std::strerror(errno);
    return result;
  }
  struct stat st {};
  if (::fstat(fd, &st) != 0 || !S_ISREG(st.st_mode)) {
    ::close(fd);
    result.status = OniCheck::io_error;
    result.message = "\"" + path + "\" is not a regular file";
    return result;
  }
  const FileSource source(fd, static_cast<std::uint64_t>(st.st_size));
  result = check_oni(source, info);
  ::close(fd);
  if (!result.ok()) result.message = "\"" + path + "\": " + result.message;
  return result;
}

}  // namespace pliant::drivers::openni2

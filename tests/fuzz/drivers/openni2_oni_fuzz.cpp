// libFuzzer target: the .oni structural check of drivers/openni2 (oni_file.hpp) on arbitrary
// bytes. Checks that it never crashes, always explains a refusal, and that what it accepts is
// consistent: every node with data has frame numbers within its declared count, and the walk
// covered the file up to any trailing bytes.
#include <cstddef>
#include <cstdint>
#include <cstdlib>

#include "pliant/drivers/openni2/oni_file.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace pliant::drivers::openni2;
  OniFileInfo info;
  const OniCheckResult result = check_oni_bytes(data, size, info);
  if (!result.ok()) {
    if (result.message.empty()) std::abort();
    if (result.offset > size) std::abort();
    return 0;
  }
  if (info.file_bytes != size || info.trailing_bytes > size || info.records == 0) std::abort();
  bool any_data = false;
  for (const OniNodeInfo& node : info.nodes) {
    if (node.data_records == 0) continue;
    any_data = true;
    if (node.first_frame == 0 || node.last_frame > node.frames_declared || node.first_frame > node.last_frame)
      std::abort();
    if (node.last_timestamp_us > info.max_timestamp_us) std::abort();
    if (node.data_records > node.last_frame - node.first_frame + 1) std::abort();
  }
  if (!any_data) std::abort();
  return 0;
}

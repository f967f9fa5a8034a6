#include "fake_backend.hpp"

#include <algorithm>

namespace pliant::drivers::libcamera_test {

using hal::HalStatus;
using libcamera_detail::BufferPlanes;
using libcamera_detail::Completion;
using libcamera_detail::CompletionStatus;

HalStatus FakeBackend::open(const LibcameraCameraConfig&, libcamera_detail::StreamSetup& setup, std::string& error) {
  ++state_.opens;
  if (state_.open_status != HalStatus::ok) {
    error = state_.open_error;
    return state_.open_status;
  }
  setup = state_.setup;
  return HalStatus::ok;
}

BufferPlanes FakeBackend::buffer(int index) const noexcept {
  BufferPlanes planes;
  if (index < 0 || static_cast<std::size_t>(index) >= state_.buffers.size()) return planes;
  const std::vector<std::uint8_t>& bytes = state_.buffers[static_cast<std::size_t>(index)];
  if (state_.planes_per_buffer == 2) {
    planes.count = 2;
    planes.data[0] = bytes.data();
    planes.length[0] = state_.plane0_bytes;
    planes.data[1] = bytes.data() + state_.plane0_bytes;
    planes.length[1] = bytes.size() - state_.plane0_bytes;
  } else {
    planes.count = 1;
    planes.data[0] = bytes.data();
    planes.length[0] = bytes.size();
  }
  return planes;
}

HalStatus FakeBackend::start(libcamera_detail::CompletionSink& sink, std::string& error) {
  ++state_.starts;
  if (state_.start_status != HalStatus::ok) {
    error = "fake start refused";
    return state_.start_status;
  }
  state_.sink = &sink;
  state_.running = true;
  state_.queued.clear();
  for (int i = 0; i < state_.setup.buffer_count; ++i) state_.queued.push_back(i);
  return HalStatus::ok;
}

bool FakeBackend::requeue(int index) noexcept {
  if (!state_.running || state_.refuse_requeue) return false;
  state_.queued.push_back(index);  // capacity reserved by make_buffers: no allocation
  state_.requeues.fetch_add(1);
  return true;
}

void FakeBackend::stop() noexcept {
  ++state_.stops;
  if (!state_.running) return;
  state_.running = false;
  const std::vector<int> pending = state_.queued;
  state_.queued.clear();
  for (const int index : pending) {
    Completion c;
    c.buffer = index;
    c.status = CompletionStatus::cancelled;
    state_.sink->on_completion(c);
  }
}

void FakeBackend::close() noexcept { ++state_.closes; }

void make_buffers(FakeBackendState& state, int count, std::size_t bytes) {
  state.buffers.assign(static_cast<std::size_t>(count), std::vector<std::uint8_t>(bytes, 0));
  state.setup.buffer_count = count;
  state.queued.reserve(static_cast<std::size_t>(count) * 4 + 16);
}

void complete(FakeBackendState& state, int index, CompletionStatus status, std::uint32_t sequence,
              std::uint64_t timestamp_ns, std::size_t bytes_used) {
  const auto it = std::find(state.queued.begin(), state.queued.end(), index);
  if (it != state.queued.end()) state.queued.erase(it);
  Completion c;
  c.buffer = index;
  c.status = status;
  c.sequence = sequence;
  c.timestamp_ns = timestamp_ns;
  c.bytes_used[0] = bytes_used;
  state.sink->on_completion(c);
}

}  // namespace pliant::drivers::libcamera_test

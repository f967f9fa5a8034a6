#include "pliant/host/replay/replay_channels.hpp"

namespace pliant::host {
namespace {

// Appends one row unless its time does not follow the previous row's.
bool append_row(hal::RecordedChannel& channel, double t_s, const double* values) {
  if (!channel.t_s.empty() && !(t_s > channel.t_s.back())) return false;
  channel.t_s.push_back(t_s);
  channel.values.insert(channel.values.end(), values, values + channel.width);
  return true;
}

}  // namespace

ReplayChannels replay_channels_of(const Recording& recording) {
  ReplayChannels out;
  out.particles.width = recording.particle_count * recording.dimension;
  out.particles.t_s = recording.frame_times_s;
  out.particles.values = recording.positions;
  if (!recording.wrench.empty()) {
    hal::RecordedChannel& w = out.wrench.emplace();
    w.width = 6;
    for (const WrenchSample& s : recording.wrench) {
      const double row[6] = {s.force_n[0], s.force_n[1], s.force_n[2], s.torque_nm[0], s.torque_nm[1], s.torque_nm[2]};
      out.skipped_rows += append_row(w, s.t_s, row) ? 0 : 1;
    }
  }
  if (!recording.gripper.empty()) {
    hal::RecordedChannel& g = out.gripper.emplace();
    g.width = 2;
    for (const GripperSample& s : recording.gripper) {
      const double row[2] = {s.width, s.force_n};
      out.skipped_rows += append_row(g, s.t_s, row) ? 0 : 1;
    }
  }
  return out;
}

}  // namespace pliant::host

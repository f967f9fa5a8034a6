// Particle chunks -> tracker frames -> recording frames (rules in recording_builder.hpp).
#include "pliant/host/telemetry/recording_builder.hpp"

#include <charconv>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace pliant::host::telemetry {
namespace {

// The double with the f32's shortest decimal form, so that particles.csv shows 0.01 rather than
// 0.009999999776482582; it reads back to the same f32.
double widen(float value) {
  char buffer[32];
  const auto printed = std::to_chars(buffer, buffer + sizeof buffer, value);
  double out = static_cast<double>(value);
  std::from_chars(buffer, printed.ptr, out);
  return out;
}

bool observed(const std::vector<float>& positions, const std::vector<std::uint8_t>& status, std::size_t id,
              std::size_t dim) {
  if (status[id] != PLIANT_TM_OBSERVED) return false;
  for (std::size_t axis = 0; axis < dim; ++axis) {
    if (!std::isfinite(positions[id * dim + axis])) return false;
  }
  return true;
}

}  // namespace

void RecordingBuilder::add(const pliant_tm_particles_t& chunk, std::uint64_t stamp_us) {
  if (pending_ && (pending_->frame != chunk.frame || pending_->dim != chunk.dim || pending_->total != chunk.total)) {
    ++counts_.incomplete;  // another frame began before this one was whole
    pending_.reset();
  }
  if (!pending_) {
    Pending fresh;
    fresh.frame = chunk.frame;
    fresh.dim = chunk.dim;
    fresh.total = chunk.total;
    fresh.stamp_us = stamp_us;
    fresh.positions.assign(std::size_t{chunk.total} * chunk.dim, std::numeric_limits<float>::quiet_NaN());
    fresh.status.assign(chunk.total, PLIANT_TM_LOST);
    fresh.covered.assign(chunk.total, false);
    pending_ = std::move(fresh);
  }
  Pending& p = *pending_;
  for (std::uint16_t i = 0; i < chunk.count; ++i) {
    const std::size_t id = std::size_t{chunk.first} + i;
    if (p.covered[id]) {
      p.overlap = true;
      continue;
    }
    p.covered[id] = true;
    ++p.covered_count;
    float xyz[3];
    pliant_tm_particles_get(&chunk, i, xyz, &p.status[id]);
    for (std::size_t axis = 0; axis < p.dim; ++axis) p.positions[id * p.dim + axis] = xyz[axis];
  }
  if (p.covered_count == p.total) {
    const Pending whole = std::move(p);
    pending_.reset();
    if (whole.overlap) {
      ++counts_.incomplete;
    } else {
      complete(whole);
    }
  }
}

void RecordingBuilder::finish() {
  if (pending_) ++counts_.incomplete;
  pending_.reset();
}

void RecordingBuilder::complete(const Pending& f) {
  const std::size_t dim = f.dim;
  if (counts_.kept == 0) {
    if (f.total == 0) {
      ++counts_.shape;
      return;
    }
    for (std::size_t id = 0; id < f.total; ++id) {
      if (!observed(f.positions, f.status, id, dim)) {
        ++counts_.before_rest;
        return;
      }
    }
    dimension_ = f.dim;
    particle_count_ = f.total;
  } else if (f.dim != dimension_ || f.total != particle_count_) {
    ++counts_.shape;
    return;
  } else if (f.stamp_us <= last_stamp_us_) {
    ++counts_.time;
    return;
  }
  last_stamp_us_ = f.stamp_us;
  frame_times_s_.push_back(static_cast<double>(f.stamp_us) * 1e-6);
  for (std::size_t id = 0; id < f.total; ++id) {
    const bool seen = observed(f.positions, f.status, id, dim);
    for (std::size_t axis = 0; axis < dim; ++axis) {
      positions_.push_back(seen ? widen(f.positions[id * dim + axis]) : std::numeric_limits<double>::quiet_NaN());
    }
  }
  ++counts_.kept;
}

Recording RecordingBuilder::recording(const std::string& name, const std::string& length_unit) const {
  if (counts_.kept == 0) throw std::runtime_error("no complete particle frame observing every particle");
  Recording r;
  r.name = name;
  r.dimension = dimension_;
  r.length_unit = length_unit;
  r.particle_count = particle_count_;
  r.masses.assign(static_cast<std::size_t>(particle_count_), 1.0);
  r.files["particles"] = "particles.csv";
  r.meta = nlohmann::json::object({{"source", "pliant telemetry"}});
  r.frame_times_s = frame_times_s_;
  r.positions = positions_;
  r.rest_positions.assign(positions_.begin(),
                          positions_.begin() + static_cast<std::ptrdiff_t>(particle_count_ * dimension_));
  return r;
}

}  // namespace pliant::host::telemetry

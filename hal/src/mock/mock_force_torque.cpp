#include "pliant/hal/mock/mock_force_torque.hpp"

#include <cmath>
#include <limits>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "sample_faults.hpp"

namespace pliant::hal {

using detail::SampleFate;

HalStatus MockForceTorqueSensor::on_configure() {
  const MockForceTorqueConfig& c = config_;
  if (!plant_.configured()) return HalStatus::invalid_argument;
  if (!(std::isfinite(c.force_noise_n) && c.force_noise_n >= 0) ||
      !(std::isfinite(c.torque_noise_nm) && c.torque_noise_nm >= 0)) {
    return HalStatus::invalid_argument;
  }
  const Eigen::Matrix3d r = Eigen::Map<const Eigen::Matrix<double, 3, 3, Eigen::RowMajor>>(c.rotation);
  if (!r.allFinite() || !(r.transpose() * r).isApprox(Eigen::Matrix3d::Identity(), 1e-9) || !(r.determinant() > 0)) {
    return HalStatus::invalid_argument;
  }
  for (int d = 0; d < 3; ++d) {
    if (!std::isfinite(c.lever_m[d]) || !std::isfinite(c.load_n[d])) return HalStatus::invalid_argument;
  }
  const HalStatus s = stream_.configure(c.period_s, 0.0, kForceTorqueFaults);
  if (s != HalStatus::ok) return s;
  stream_.clear_fault_counters();
  rng_.seed(c.seed);
  has_last_ = false;
  return HalStatus::ok;
}

HalStatus MockForceTorqueSensor::on_start() noexcept {
  stream_.start(clock_.now_s());
  return HalStatus::ok;
}

HalStatus MockForceTorqueSensor::on_read(WrenchReading& out) noexcept {
  plant_.sync();
  const double now = clock_.now_s();
  const HalStatus link = stream_.read_fault(now);
  if (link != HalStatus::ok) return link;
  std::uint64_t index = 0, sequence = 0;
  double stamp = 0;
  if (!stream_.take(now, index, stamp, sequence)) return HalStatus::no_data;
  const ActiveFaults f = stream_.sample_faults(stamp);
  const SampleFate fate = detail::sample_fate(f, has_last_, stream_);
  if (fate == SampleFate::dropped) return HalStatus::no_data;
  WrenchReading r;
  if (fate == SampleFate::fresh) {
    const Eigen::Matrix3d rot = Eigen::Map<const Eigen::Matrix<double, 3, 3, Eigen::RowMajor>>(config_.rotation);
    const Eigen::Vector3d contact(plant_.grip_force_n(), 0, 0);
    const Eigen::Vector3d force = rot.transpose() * (contact + Eigen::Map<const Eigen::Vector3d>(config_.load_n));
    const Eigen::Vector3d torque = rot.transpose() * Eigen::Map<const Eigen::Vector3d>(config_.lever_m).cross(contact);
    for (int d = 0; d < 3; ++d) {
      r.wrench[d] = force(d) + config_.force_noise_n * normal_(rng_);
      r.wrench[3 + d] = torque(d) + config_.torque_noise_nm * normal_(rng_);
    }
    r.header.status_bits = 0;
  } else {
    r = last_;  // freeze_stamp: the whole previous reading; freeze_data: its values and status
  }
  if (fate != SampleFate::repeat_previous) {
    r.header.stamp_s = stamp;
    if (detail::take_fault(f, FaultKind::nan, stream_)) {
      for (double& v : r.wrench) v = std::numeric_limits<double>::quiet_NaN();
    }
    detail::apply_stamp_and_status_faults(f, config_.fault_bits, stream_, r.header.stamp_s, r.header.status_bits);
  }
  r.header.sequence = sequence;
  last_ = r;
  has_last_ = true;
  out = r;
  return HalStatus::ok;
}

}  // namespace pliant::hal

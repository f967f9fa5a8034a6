#include "pliant/host/msm_setup.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace pliant::host {

void require_ok(Status status, const char* what) {
  if (status != Status::ok) throw std::runtime_error(std::string(what) + ": " + status_name(status));
}

StillRest rest_from_still_frames(const Recording& recording) {
  StillRest out;
  out.positions = recording.rest_positions;
  const int n = recording.particle_count;
  const int dim = recording.dimension;
  const int frames = recording.frame_count();
  if (recording.mesh || recording.fixed.empty() || frames < 3) return out;

  std::vector<double> changes;
  for (int k = 1; k < frames; ++k) {
    for (int id : recording.fixed) {
      if (!recording.observed(k, id) || !recording.observed(k - 1, id)) continue;
      for (int d = 0; d < dim; ++d)
        changes.push_back(std::abs(recording.position(k, id, d) - recording.position(k - 1, id, d)));
    }
  }
  if (changes.size() < 8) return out;
  auto middle = changes.begin() + static_cast<std::ptrdiff_t>(changes.size() / 2);
  std::nth_element(changes.begin(), middle, changes.end());
  // Median |difference of two N(0, s^2)| = 0.6745 * sqrt(2) * s.
  const double noise = *middle / (0.6745 * std::sqrt(2.0));
  out.noise_std = noise;
  if (!(noise > 0)) return out;

  const double limit = 5.0 * std::sqrt(2.0) * noise;
  int still = 1;
  for (; still < frames; ++still) {
    bool moved = false;
    for (int i = 0; i < n && !moved; ++i) {
      if (!recording.observed(still, i)) continue;
      for (int d = 0; d < dim; ++d) {
        if (std::abs(recording.position(still, i, d) - recording.position(0, i, d)) > limit) moved = true;
      }
    }
    if (moved) break;
  }
  // The last still frame may already hold the first, sub-threshold part of the motion.
  still = std::max(1, still - 1);
  std::vector<double> count(static_cast<std::size_t>(n), 0.0);
  std::fill(out.positions.begin(), out.positions.end(), 0.0);
  for (int k = 0; k < still; ++k) {
    for (int i = 0; i < n; ++i) {
      if (!recording.observed(k, i)) continue;
      count[static_cast<std::size_t>(i)] += 1.0;
      for (int d = 0; d < dim; ++d) out.positions[static_cast<std::size_t>(i * dim + d)] += recording.position(k, i, d);
    }
  }
  for (int i = 0; i < n; ++i) {
    for (int d = 0; d < dim; ++d)
      out.positions[static_cast<std::size_t>(i * dim + d)] /= count[static_cast<std::size_t>(i)];
  }
  out.frames = still;
  return out;
}

template <int Dim>
std::unique_ptr<HostMsmModel<Dim>> build_msm_model(const Recording& recording, const MsmSetupOptions& options) {
  if (recording.dimension != Dim) throw std::runtime_error("recording dimension does not match the model");
  const int n = recording.particle_count;
  std::vector<std::uint8_t> fixed(static_cast<std::size_t>(n), 0);
  for (int id : recording.fixed) fixed[static_cast<std::size_t>(id)] = 1;
  std::vector<int> drivable;
  auto out = std::make_unique<HostMsmModel<Dim>>();
  for (const auto& window : recording.driven) {
    drivable.push_back(window.id);
    out->driven.push_back(window);
  }
  // The noise measurement is wanted even when frame 0 is the rest shape.
  StillRest rest = rest_from_still_frames(recording);
  if (options.rest == RestSource::first_frame) {
    rest.positions = recording.rest_positions;
    rest.frames = 1;
  }
  out->rest_frames = rest.frames;
  out->rest = rest.positions;
  out->noise_std = rest.noise_std;
  MsmModelConfig<Dim, double> config;
  config.particle_count = n;
  config.rest_positions = rest.positions.data();
  config.masses = recording.masses.empty() ? nullptr : recording.masses.data();
  config.fixed = fixed.data();
  config.drivable_ids = drivable.empty() ? nullptr : drivable.data();
  config.drivable_count = static_cast<int>(drivable.size());
  config.driven_mass_factor = options.driven_mass_factor;
  config.clusters = options.clusters;
  const std::size_t bytes = msm_model_workspace_size(config);
  // A zero size means the configuration is invalid; init over the empty block says why.
  out->block = std::make_unique<unsigned char[]>(std::max<std::size_t>(bytes, 1));
  Arena arena(out->block.get(), bytes);
  require_ok(msm_model_init(arena, config, out->model), "cannot build the MSM model");
  return out;
}

template <int Dim>
ObservationSequence<Dim, double> observations_of(const Recording& recording, const HostMsmModel<Dim>& model) {
  ObservationSequence<Dim, double> obs;
  obs.frame_count = recording.frame_count();
  obs.particle_count = recording.particle_count;
  obs.times_s = recording.frame_times_s.data();
  obs.positions = recording.positions.data();
  obs.driven = model.driven.empty() ? nullptr : model.driven.data();
  obs.driven_count = static_cast<int>(model.driven.size());
  return obs;
}

template <int Dim>
MsmParams<Dim, double> base_params(const Recording& recording, double msm_alpha) {
  MsmParams<Dim, double> params;
  params.msm_alpha = msm_alpha;
  if (recording.gravity) {
    for (int d = 0; d < Dim; ++d) params.gravity(d) = (*recording.gravity)[static_cast<std::size_t>(d)];
  }
  return params;
}

template std::unique_ptr<HostMsmModel<2>> build_msm_model<2>(const Recording&, const MsmSetupOptions&);
template std::unique_ptr<HostMsmModel<3>> build_msm_model<3>(const Recording&, const MsmSetupOptions&);
template ObservationSequence<2, double> observations_of<2>(const Recording&, const HostMsmModel<2>&);
template ObservationSequence<3, double> observations_of<3>(const Recording&, const HostMsmModel<3>&);
template MsmParams<2, double> base_params<2>(const Recording&, double);
template MsmParams<3, double> base_params<3>(const Recording&, double);

}  // namespace pliant::host

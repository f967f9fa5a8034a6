#include "pliant/host/msm_setup.hpp"

#include <algorithm>
#include <stdexcept>
#include <string>

namespace pliant::host {

void require_ok(Status status, const char* what) {
  if (status != Status::ok) throw std::runtime_error(std::string(what) + ": " + status_name(status));
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
  MsmModelConfig<Dim, double> config;
  config.particle_count = n;
  config.rest_positions = recording.rest_positions.data();
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

// Builds core MSM objects from a Recording, in host (heap-owning) memory.
//
// The model follows the project-wide MSM defaults: rest = the recording's rest configuration,
// masses as the recording gives them, recording `fixed` ids pinned, every `driven` id drivable,
// one cluster per particle within 1.5x the median nearest-neighbour distance (unless
// `clusters` says otherwise). Host code: allocates, throws std::runtime_error naming the core
// status when the recording cannot define a model.
#pragma once

#include <cstddef>
#include <memory>
#include <vector>

#include "pliant/core/msm.hpp"
#include "pliant/core/observations.hpp"
#include "pliant/host/recording.hpp"

namespace pliant::host {

struct MsmSetupOptions {
  ClusterConfig clusters;
  double driven_mass_factor = 1.0;
};

/// An MSM model and the memory it lives in. Not copyable (the model points into `block`).
template <int Dim>
struct HostMsmModel {
  std::unique_ptr<unsigned char[]> block;
  MsmModel<Dim, double> model;
  std::vector<DrivenWindow> driven;  ///< the recording's driven windows
};

template <int Dim>
std::unique_ptr<HostMsmModel<Dim>> build_msm_model(const Recording& recording, const MsmSetupOptions& options);

/// Observation view over recording.positions (no copy; the recording must outlive it).
template <int Dim>
ObservationSequence<Dim, double> observations_of(const Recording& recording, const HostMsmModel<Dim>& model);

/// Base parameters from a recording: gravity when declared, else none.
template <int Dim>
MsmParams<Dim, double> base_params(const Recording& recording, double msm_alpha);

/// Throws std::runtime_error("<what>: <status name>") unless status is ok.
void require_ok(Status status, const char* what);

}  // namespace pliant::host

// The job of `pliant refine`: FEM material parameters and the rest shape of a recording, written
// as a material card (docs/spec/outputs-v1.md, job.hpp). Which estimator runs is decided from
// what the recording contains (refine_plan.hpp).
#pragma once

#include <optional>
#include <string>

#include <nlohmann/json.hpp>

#include "job.hpp"

namespace pliant::cli {

/// The options of `pliant refine`, by their long names. An empty optional was not given (some
/// options only warn when given to an estimator that does not use them).
struct RefineJob {
  std::string mesh;                           ///< --mesh FILE replacing the recording's mesh.vtk
  std::optional<std::string> estimate;        ///< --estimate LIST
  std::string estimator = "auto";             ///< --estimator auto|force|reaction|trajectory
  std::string volumetric = "auto";            ///< --volumetric auto|element|nodal_average
  std::string json;                           ///< --json OUT: write the card there; "" or "-": no file
  std::string vtk;                            ///< --vtk DIR: the fitted model as a VTK series
  std::optional<double> max_strain;           ///< --max-strain E, (0, 1]; default 0.10
  bool no_force_offset = false;               ///< --no-force-offset
  std::optional<double> initial_modulus;      ///< --initial-modulus PA, > 0
  std::optional<std::string> control_points;  ///< --control-points auto|N|FILE; default "auto"
  std::optional<int> rest_frame;              ///< --rest-frame K, >= 0; default 0
  std::optional<std::string> rest_mesh;       ///< --rest-mesh FILE
  std::optional<double> until;                ///< --until S
  std::optional<int> substeps;                ///< --substeps N, 1..64; default 4
  int threads = 0;                            ///< --threads N, 0..256 (0: one per core)
  bool progress = false;                      ///< the progress line on stderr (only on a terminal)
};

struct RefineDone {
  nlohmann::json card;         ///< the material card (pliant-material v1)
  std::string summary;         ///< what the command prints (refine_summary)
  std::string rest_mesh;       ///< the rest mesh written ("" without rest_shape)
  std::string vtk_collection;  ///< the .pvd written ("" without --vtk)
};

/// Checks the options, takes the recording from `source` (its warnings, and options that do not
/// apply, go to `warn`), fits, and writes the rest mesh, the VTK series and job.json. Throws as
/// job.hpp says.
RefineDone run_refine_job(const RefineJob& job, const RecordingSource& source, const WarningSink& warn);

}  // namespace pliant::cli

// `pliant refine` outputs: the material card (docs/spec/outputs-v1.md, "pliant-material" v1),
// the human summary, the rest-shape mesh and the VTK time series of the fitted model.
//
// Card keys beyond the spec (README "Refining with FEM"): "estimator" (force, reaction or
// trajectory; absent when only the rest shape was estimated), "assumed" (values the model used
// that the recording does not give: poisson_ratio 0.45, density 1000 kg/m^3, Rayleigh 0),
// "volumetric" (element or nodal_average: how the model integrates the volume, chosen from
// poisson_ratio, see fem_model.hpp), "material_map" adds "uncertainty" (1 sd per control point) and "kernel_width" (m,
// the Gaussian width of material_map.hpp, needed to rebuild the per-element field), and "diagnostics" (free_rms,
// counts, convergence, the estimator's own residuals).
#pragma once

#include <string>

#include <nlohmann/json.hpp>

#include "pliant/host/fem/fem_recording.hpp"
#include "pliant/host/recording.hpp"
#include "refine_plan.hpp"
#include "refine_run.hpp"

namespace pliant::cli {

/// What the outputs need besides the outcome.
struct RefineReport {
  const host::Recording* recording = nullptr;  ///< the recording as read (material, name)
  const host::fem::FemRecordingProblem* problem = nullptr;
  const RefinePlan* plan = nullptr;
  const RefineOutcome* outcome = nullptr;
  std::string mesh_source;     ///< "mesh.vtk of the recording" or the --mesh path
  std::string rest_shape_ref;  ///< the card's rest_shape value (empty without a rest shape)
  double runtime_s = 0;
};

/// The material card.
nlohmann::json material_card(const RefineReport& report);

/// A few aligned lines for a person: recording, estimator and why, every parameter with its
/// uncertainty or source, the map, the rest shape, rms, convergence and run time.
std::string refine_summary(const RefineReport& report);

/// Writes the estimated rest shape as legacy VTK (point i = particle i; per-tetrahedron
/// youngs_modulus when the model has a map or the mesh had one), atomically. Throws
/// std::runtime_error on I/O failure.
void write_rest_mesh(const std::string& path, const RefineReport& report);

/// Writes the fitted model's frames to DIR/refine.pvd + DIR/refine_NNNNNN.vtu: positions of the
/// model, point vectors "displacement" (from the rest shape, m), "observed_position" (the
/// tracked position; the model's where unobserved) and "residual" (observed - model; zero where
/// unobserved), cell scalars "youngs_modulus" (Pa). Returns the .pvd path. Throws like
/// VtkSeriesWriter.
std::string write_refine_vtk(const std::string& directory, const RefineReport& report);

}  // namespace pliant::cli

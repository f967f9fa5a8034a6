#include "job_refine.hpp"

#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <stdexcept>
#include <system_error>
#include <thread>
#include <vector>

#include "atomic_write.hpp"
#include "exit_status.hpp"
#include "pliant/host/diagnose/noise_floor.hpp"
#include "pliant/host/fem/fem_recording.hpp"
#include "pliant/host/fem/material_map.hpp"
#include "refine_control_points.hpp"
#include "refine_mesh.hpp"
#include "refine_output.hpp"
#include "refine_plan.hpp"
#include "refine_progress.hpp"
#include "refine_run.hpp"

namespace pliant::cli {
namespace {

namespace fs = std::filesystem;

fs::path parent_or_current(const fs::path& path) {
  const fs::path parent = path.parent_path();
  return parent.empty() ? fs::path(".") : parent;
}

// Refuses, before any work, an output file that cannot be written: its directory is missing or
// read-only, or the path is a directory.
void check_output_file(const std::string& path, const std::string& flag) {
  std::error_code error;
  if (fs::is_directory(path, error)) throw UsageError(flag + ": " + path + " is a directory");
  const fs::path directory = parent_or_current(path);
  if (!fs::is_directory(directory, error)) {
    throw UsageError(flag + ": cannot write " + path + ": no such directory " + directory.string());
  }
  if (access(directory.c_str(), W_OK) != 0) {
    throw UsageError(flag + ": cannot write " + path + ": directory " + directory.string() + " is not writable");
  }
}

// A directory that exists (and is writable) or can be created under a writable ancestor.
void check_output_directory(const std::string& path, const std::string& flag) {
  std::error_code error;
  fs::path at = fs::absolute(path, error);
  if (error) throw UsageError(flag + ": bad path " + path);
  if (fs::exists(at, error) && !fs::is_directory(at, error)) {
    throw UsageError(flag + ": " + path + " is not a directory");
  }
  while (!fs::exists(at, error) && at.has_parent_path() && at.parent_path() != at) at = at.parent_path();
  if (!fs::is_directory(at, error)) {
    throw UsageError(flag + ": cannot create " + path + ": " + at.string() + " is not a directory");
  }
  if (access(at.c_str(), W_OK) != 0) throw UsageError(flag + ": cannot write into " + at.string());
}

// What the card names: the rest mesh relative to the card's directory.
std::string card_reference(const std::string& rest_mesh, const std::string& card) {
  if (card.empty() || card == "-") return rest_mesh;
  std::error_code error;
  const fs::path relative = fs::absolute(rest_mesh, error)
                                .lexically_normal()
                                .lexically_relative(fs::absolute(parent_or_current(card), error).lexically_normal());
  return relative.empty() ? fs::absolute(rest_mesh, error).string() : relative.string();
}

bool writes_card(const RefineJob& job) { return !job.json.empty() && job.json != "-"; }

// Options first: nothing is read or computed for a command that cannot succeed.
ControlPointSource check_options(const RefineJob& job, RefineRequest& request) {
  if (job.estimate) request = parse_estimate_list(*job.estimate);
  if (job.estimator != "auto" && job.estimator != "force" && job.estimator != "reaction" &&
      job.estimator != "trajectory") {
    throw UsageError("--estimator must be auto, force, reaction or trajectory");
  }
  if (job.volumetric != "auto" && job.volumetric != "element" && job.volumetric != "nodal_average") {
    throw UsageError("--volumetric must be auto, element or nodal_average");
  }
  const double max_strain = job.max_strain.value_or(0.10);
  if (!(max_strain > 0.0 && max_strain <= 1.0)) throw UsageError("--max-strain must be in (0, 1]");
  if (job.initial_modulus && !(std::isfinite(*job.initial_modulus) && *job.initial_modulus > 0.0)) {
    throw UsageError("--initial-modulus must be a positive number of Pa");
  }
  if (job.until && !std::isfinite(*job.until)) throw UsageError("--until must be a number of seconds");
  const int substeps = job.substeps.value_or(4);
  if (substeps < 1 || substeps > 64) throw UsageError("--substeps must be between 1 and 64");
  if (job.threads < 0 || job.threads > 256) throw UsageError("--threads must be between 0 and 256");
  if (job.rest_frame.value_or(0) < 0) throw UsageError("--rest-frame must be >= 0");
  const ControlPointSource control = parse_control_points(job.control_points.value_or("auto"));
  if (writes_card(job)) check_output_file(job.json, "--json");
  if (!job.vtk.empty()) check_output_directory(job.vtk, "--vtk");
  return control;
}

// The recording with the job's mesh attached; `mesh_source` says where the mesh came from.
host::Recording load_recording(const RefineJob& job, const RecordingSource& source, const WarningSink& warn,
                               std::string& mesh_source) {
  host::Recording recording = source();
  for (const std::string& warning : recording.warnings) warn(warning);
  mesh_source = "mesh.vtk of the recording";
  if (!job.mesh.empty()) {
    std::vector<std::string> warnings;
    attach_mesh(recording, job.mesh, warnings);
    for (const std::string& warning : warnings) warn(warning);
    mesh_source = job.mesh;
  } else if (!recording.mesh) {
    throw UsageError(
        "the recording has no mesh (recording.json files.mesh) and no --mesh was given: the FEM needs a "
        "tetrahedral mesh whose point i is particle i");
  }
  return recording;
}

host::fem::FemRecordingProblem fem_problem(const RefineJob& job, const host::Recording& recording) {
  host::fem::FemRecordingProblem problem;
  try {
    problem = host::fem::fem_problem_from_recording(recording);
  } catch (const std::invalid_argument& e) {
    throw UsageError(e.what());
  }
  if (job.until) host::fem::keep_frames_until(problem, *job.until);
  if (job.volumetric == "element") problem.material.volumetric = host::fem::FemVolumetric::element;
  if (job.volumetric == "nodal_average") problem.material.volumetric = host::fem::FemVolumetric::nodal_average;
  return problem;
}

// Options given to an estimator that does not use them are ignored with a warning.
void warn_unused_options(const RefineJob& job, const RefinePlan& plan, const WarningSink& warn) {
  const bool reaction = plan.estimator && *plan.estimator == RefineEstimator::reaction;
  const bool trajectory = plan.estimator && *plan.estimator == RefineEstimator::trajectory;
  if (!reaction && (job.max_strain || job.no_force_offset)) {
    warn("--max-strain and --no-force-offset apply to the reaction estimator only; ignored");
  }
  if (!trajectory && job.substeps) warn("--substeps applies to the trajectory estimator only; ignored");
  if (!plan.youngs_modulus && job.initial_modulus) {
    warn("--initial-modulus applies when youngs_modulus is estimated; ignored");
  }
  if (!plan.estimator && job.estimator != "auto") warn("--estimator: no material parameter to estimate; ignored");
  if (!plan.material_map && job.control_points) warn("--control-points applies to material_map only; ignored");
  if (!plan.rest_shape && (job.rest_frame || job.rest_mesh)) {
    warn("--rest-frame and --rest-mesh apply to rest_shape only; ignored");
  }
}

RefineSettings refine_settings(const RefineJob& job, const RefinePlan& plan,
                               const host::fem::FemRecordingProblem& problem, const ControlPointSource& control) {
  RefineSettings settings;
  settings.max_strain = job.max_strain.value_or(0.10);
  settings.force_offset = !job.no_force_offset;
  settings.initial_youngs_modulus_pa = job.initial_modulus.value_or(0.0);
  settings.rest_frame = job.rest_frame.value_or(0);
  settings.substeps = job.substeps.value_or(4);
  settings.threads = job.threads > 0 ? job.threads : std::max(1, static_cast<int>(std::thread::hardware_concurrency()));
  if (plan.material_map) {
    if (control.count > problem.mesh.tet_count()) {
      throw UsageError("--control-points " + std::to_string(control.count) + " exceeds the mesh's " +
                       std::to_string(problem.mesh.tet_count()) + " tetrahedra");
    }
    settings.select_control_points = control.automatic;
    settings.control_point_count = control.count;
    settings.control_points_m = control.points_m;
    if (!control.points_m.empty()) {
      try {
        const host::fem::MaterialMap check(problem.mesh, control.points_m);
      } catch (const std::invalid_argument& e) {
        throw UsageError("--control-points " + job.control_points.value_or("auto") + ": " + e.what());
      }
    }
  }
  return settings;
}

// Where the rest mesh goes: --rest-mesh, else beside the card, else the current directory.
std::string rest_mesh_path(const RefineJob& job) {
  if (job.rest_mesh && !job.rest_mesh->empty()) return *job.rest_mesh;
  if (!writes_card(job)) return "rest_shape.vtk";
  return (parent_or_current(job.json) / "rest_shape.vtk").string();
}

}  // namespace

RefineDone run_refine_job(const RefineJob& job, const RecordingSource& source, const WarningSink& warn) {
  const auto start = std::chrono::steady_clock::now();
  RefineRequest request;
  const ControlPointSource control = check_options(job, request);

  std::string mesh_source;
  const host::Recording recording = load_recording(job, source, warn, mesh_source);
  const host::fem::FemRecordingProblem problem = fem_problem(job, recording);
  const RefinePlan plan = plan_refine(problem, request, job.estimator);
  check_rest_shape(problem, plan, job.rest_frame.value_or(0));
  warn_unused_options(job, plan, warn);
  RefineSettings settings = refine_settings(job, plan, problem, control);
  settings.position_noise_m = host::estimate_noise_std(recording);
  RefineDone done;
  if (plan.rest_shape) {
    done.rest_mesh = rest_mesh_path(job);
    check_output_file(done.rest_mesh, "--rest-mesh");
  }

  RefineOutcome outcome;
  {
    RefineProgress progress(job.progress);
    outcome = run_refine(problem, plan, settings, progress);
  }

  RefineReport report;
  report.recording = &recording;
  report.problem = &problem;
  report.plan = &plan;
  report.outcome = &outcome;
  report.mesh_source = mesh_source;
  if (plan.rest_shape) report.rest_shape_ref = card_reference(done.rest_mesh, job.json);
  for (const std::string& warning : outcome.warnings) warn(warning);
  if (!outcome.converged) {
    warn("the fit did not converge" + (outcome.fit_message.empty() ? std::string() : ": " + outcome.fit_message) +
         " (see diagnostics in the card)");
  }
  if (plan.rest_shape) write_rest_mesh(done.rest_mesh, report);
  if (!job.vtk.empty()) done.vtk_collection = write_refine_vtk(job.vtk, report);
  report.runtime_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  done.card = material_card(report);
  done.summary = refine_summary(report);
  if (writes_card(job)) write_file_atomically(job.json, done.card.dump(2) + "\n");
  return done;
}

}  // namespace pliant::cli

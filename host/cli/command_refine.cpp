#include "command_refine.hpp"

#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <iostream>
#include <limits>
#include <stdexcept>
#include <system_error>
#include <thread>
#include <vector>

#include "atomic_write.hpp"
#include "exit_status.hpp"
#include "pliant/host/fem/fem_recording.hpp"
#include "pliant/host/fem/material_map.hpp"
#include "pliant/host/recording.hpp"
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

}  // namespace

RefineCommand::RefineCommand(CLI::App& parent) {
  app_ = parent.add_subcommand(
      "refine",
      "Fit FEM material parameters (youngs_modulus, Rayleigh damping, a material map) and the rest shape of a 3D "
      "recording in metres, and write them as a material card");
  app_->footer(
      "Estimators (chosen from the recording, or with --estimator):\n"
      "  reaction    the wrench acts on fixed or driven particles (a compression or indentation test): the\n"
      "              simulated reaction of the prescribed displacements is fitted to it, frame by frame, statically\n"
      "  force       the wrench acts on free particles: it is applied as a load and the tracked free particles\n"
      "              are fitted, frame by frame, statically (needs tracked free particles)\n"
      "  trajectory  no wrench (free motion, e.g. vibration after release): the whole recording is simulated from\n"
      "              frame 0 and the tracked free particles fitted in every frame; the only estimator for\n"
      "              rayleigh and material_map (needs >= 3 frames and the same driven particles throughout)\n"
      "rest_shape needs gravity, density and youngs_modulus (given, or estimated in the same run) and a static frame\n"
      "observing every mesh point. Units: m, s, Pa, N; rayleigh_alpha 1/s, rayleigh_beta s.\n"
      "Exit status: 0 ok, 1 estimation failed, 2 bad options, a malformed recording or mesh, or an estimate the\n"
      "recording cannot support.");
  app_->add_option("REC", recording_, "Recording directory (docs/spec/recording-v1.md): 3D, length_unit m")->required();
  app_->add_option("--mesh", mesh_path_,
                   "Tetrahedral mesh (point i = particle i; extra points are unobserved nodes) replacing the "
                   "recording's mesh.vtk: .msh, .vtk, .node/.ele, or a closed .obj/.ply/.stl surface (tetrahedralized)")
      ->type_name("FILE");
  app_->add_option("--estimate", estimate_,
                   "Comma-separated: youngs_modulus, rayleigh (= rayleigh_alpha,rayleigh_beta), rayleigh_alpha, "
                   "rayleigh_beta, material_map, rest_shape. Default: youngs_modulus, plus rayleigh with the "
                   "trajectory estimator; parameters recording.json gives are never estimated")
      ->type_name("LIST");
  app_->add_option("--estimator", estimator_, "Material estimator (see below)")
      ->type_name("auto|force|reaction|trajectory")
      ->capture_default_str();
  app_->add_option("--json", json_path_,
                   "Write the material card (pliant-material v1) to OUT atomically; '-' prints it to stdout instead "
                   "of the summary")
      ->type_name("OUT");
  app_->add_option("--vtk", vtk_dir_,
                   "Write the fitted model as a VTK time series, DIR/refine.pvd (open in ParaView), with point "
                   "vectors displacement, observed_position, residual and cell scalars youngs_modulus")
      ->type_name("DIR");
  app_->add_option("--max-strain", max_strain_,
                   "reaction: use frames from the start while the nominal strain stays <= E (the model is linear "
                   "elastic), in (0, 1]; 1 uses every frame")
      ->type_name("E")
      ->capture_default_str();
  app_->add_flag("--no-force-offset", no_force_offset_,
                 "reaction: no constant force offset (by default one is fitted: the toe of a compression curve)");
  app_->add_option("--initial-modulus", initial_modulus_pa_,
                   "Start of the youngs_modulus fit in Pa (> 0; default: the recording's value, else 1e5)")
      ->type_name("PA");
  app_->add_option("--control-points", control_points_,
                   "material_map: N points spread over the mesh (1-64), or FILE with one 'x,y,z' (m) per line")
      ->type_name("N|FILE")
      ->capture_default_str();
  app_->add_option("--rest-frame", rest_frame_, "rest_shape: the frame holding the body at rest under gravity")
      ->type_name("K")
      ->capture_default_str();
  app_->add_option("--rest-mesh", rest_mesh_path_,
                   "rest_shape: where to write the rest mesh (legacy VTK; default rest_shape.vtk beside the card, "
                   "or in the current directory without --json OUT)")
      ->type_name("FILE");
  app_->add_option("--until", until_s_, "Use only frames with t <= S seconds")->type_name("S");
  app_->add_option("--volumetric", volumetric_,
                   "How the FEM integrates the volume change: auto (nodal_average from poisson_ratio 0.45 up), "
                   "element (plain linear tetrahedra; they lock as poisson_ratio nears 0.5) or nodal_average "
                   "(averaged nodal pressure, docs/fem.md)")
      ->type_name("auto|element|nodal_average")
      ->capture_default_str();
  app_->add_option("--substeps", substeps_, "trajectory: Newmark substeps per frame interval (1-64)")
      ->type_name("N")
      ->capture_default_str();
  app_->add_option("--threads", threads_, "Threads for the simulations; 0: one per core")
      ->type_name("N")
      ->capture_default_str();
  app_->add_flag("-q,--quiet", quiet_, "No progress line");
}

int RefineCommand::run() const {
  const auto start = std::chrono::steady_clock::now();
  // Options first: nothing is read or computed for a command that cannot succeed.
  RefineRequest request;
  if (app_->count("--estimate") > 0) request = parse_estimate_list(estimate_);
  if (estimator_ != "auto" && estimator_ != "force" && estimator_ != "reaction" && estimator_ != "trajectory") {
    throw UsageError("--estimator must be auto, force, reaction or trajectory");
  }
  if (volumetric_ != "auto" && volumetric_ != "element" && volumetric_ != "nodal_average") {
    throw UsageError("--volumetric must be auto, element or nodal_average");
  }
  if (!(max_strain_ > 0.0 && max_strain_ <= 1.0)) throw UsageError("--max-strain must be in (0, 1]");
  if (app_->count("--initial-modulus") > 0 && !(std::isfinite(initial_modulus_pa_) && initial_modulus_pa_ > 0.0)) {
    throw UsageError("--initial-modulus must be a positive number of Pa");
  }
  if (app_->count("--until") > 0 && !std::isfinite(until_s_)) throw UsageError("--until must be a number of seconds");
  if (substeps_ < 1 || substeps_ > 64) throw UsageError("--substeps must be between 1 and 64");
  if (threads_ < 0 || threads_ > 256) throw UsageError("--threads must be between 0 and 256");
  if (rest_frame_ < 0) throw UsageError("--rest-frame must be >= 0");
  const ControlPointSource control = parse_control_points(control_points_);
  if (!json_path_.empty() && json_path_ != "-") check_output_file(json_path_, "--json");
  if (!vtk_dir_.empty()) check_output_directory(vtk_dir_, "--vtk");

  host::Recording recording = host::read_recording(recording_);
  for (const std::string& warning : recording.warnings) report_warning(warning);
  std::string mesh_source = "mesh.vtk of the recording";
  if (!mesh_path_.empty()) {
    std::vector<std::string> warnings;
    attach_mesh(recording, mesh_path_, warnings);
    for (const std::string& warning : warnings) report_warning(warning);
    mesh_source = mesh_path_;
  } else if (!recording.mesh) {
    throw UsageError(
        "the recording has no mesh (recording.json files.mesh) and no --mesh was given: the FEM needs a "
        "tetrahedral mesh whose point i is particle i");
  }
  host::fem::FemRecordingProblem problem;
  try {
    problem = host::fem::fem_problem_from_recording(recording);
  } catch (const std::invalid_argument& e) {
    throw UsageError(e.what());
  }
  if (app_->count("--until") > 0) host::fem::keep_frames_until(problem, until_s_);
  if (volumetric_ == "element") problem.material.volumetric = host::fem::FemVolumetric::element;
  if (volumetric_ == "nodal_average") problem.material.volumetric = host::fem::FemVolumetric::nodal_average;

  const RefinePlan plan = plan_refine(problem, request, estimator_);
  check_rest_shape(problem, plan, rest_frame_);
  const bool reaction = plan.estimator && *plan.estimator == RefineEstimator::reaction;
  const bool trajectory = plan.estimator && *plan.estimator == RefineEstimator::trajectory;
  if (!reaction && (app_->count("--max-strain") > 0 || no_force_offset_)) {
    report_warning("--max-strain and --no-force-offset apply to the reaction estimator only; ignored");
  }
  if (!trajectory && app_->count("--substeps") > 0) {
    report_warning("--substeps applies to the trajectory estimator only; ignored");
  }
  if (!plan.youngs_modulus && app_->count("--initial-modulus") > 0) {
    report_warning("--initial-modulus applies when youngs_modulus is estimated; ignored");
  }
  if (!plan.estimator && estimator_ != "auto") {
    report_warning("--estimator: no material parameter to estimate; ignored");
  }
  if (!plan.material_map && app_->count("--control-points") > 0) {
    report_warning("--control-points applies to material_map only; ignored");
  }
  if (!plan.rest_shape && (app_->count("--rest-frame") > 0 || app_->count("--rest-mesh") > 0)) {
    report_warning("--rest-frame and --rest-mesh apply to rest_shape only; ignored");
  }

  RefineSettings settings;
  settings.max_strain = max_strain_;
  settings.force_offset = !no_force_offset_;
  settings.initial_youngs_modulus_pa = initial_modulus_pa_;
  settings.rest_frame = rest_frame_;
  settings.substeps = substeps_;
  settings.threads = threads_ > 0 ? threads_ : std::max(1, static_cast<int>(std::thread::hardware_concurrency()));
  if (plan.material_map) {
    if (control.count > problem.mesh.tet_count()) {
      throw UsageError("--control-points " + std::to_string(control.count) + " exceeds the mesh's " +
                       std::to_string(problem.mesh.tet_count()) + " tetrahedra");
    }
    settings.control_point_count = control.count;
    settings.control_points_m = control.points_m;
    if (!control.points_m.empty()) {
      try {
        const host::fem::MaterialMap check(problem.mesh, control.points_m);
      } catch (const std::invalid_argument& e) {
        throw UsageError("--control-points " + control_points_ + ": " + e.what());
      }
    }
  }
  std::string rest_mesh = rest_mesh_path_;
  if (plan.rest_shape) {
    if (rest_mesh.empty()) {
      rest_mesh = (json_path_.empty() || json_path_ == "-")
                      ? std::string("rest_shape.vtk")
                      : (parent_or_current(json_path_) / "rest_shape.vtk").string();
    }
    check_output_file(rest_mesh, "--rest-mesh");
  }

  RefineOutcome outcome;
  {
    RefineProgress progress(!quiet_);
    outcome = run_refine(problem, plan, settings, progress);
  }

  RefineReport report;
  report.recording = &recording;
  report.problem = &problem;
  report.plan = &plan;
  report.outcome = &outcome;
  report.mesh_source = mesh_source;
  if (plan.rest_shape) report.rest_shape_ref = card_reference(rest_mesh, json_path_);
  if (!outcome.converged) {
    report_warning("the fit did not converge" +
                   (outcome.fit_message.empty() ? std::string() : ": " + outcome.fit_message) +
                   " (see diagnostics in the card)");
  }
  if (plan.rest_shape) write_rest_mesh(rest_mesh, report);
  std::string vtk_collection;
  if (!vtk_dir_.empty()) vtk_collection = write_refine_vtk(vtk_dir_, report);
  report.runtime_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  const nlohmann::json card = material_card(report);
  if (json_path_ == "-") {
    std::cout << card.dump(2) << '\n';
  } else {
    if (!json_path_.empty()) write_file_atomically(json_path_, card.dump(2) + "\n");
    std::cout << refine_summary(report);
    if (plan.rest_shape) std::cout << "wrote " << rest_mesh << '\n';
    if (!vtk_collection.empty()) std::cout << "wrote " << vtk_collection << '\n';
    if (!json_path_.empty()) std::cout << "wrote " << json_path_ << '\n';
  }
  std::cout.flush();
  if (!std::cout) throw std::runtime_error("cannot write to standard output");
  return exit_ok;
}

}  // namespace pliant::cli

#include "command_refine.hpp"

#include <iostream>
#include <stdexcept>

#include "exit_status.hpp"
#include "job_refine.hpp"

namespace pliant::cli {

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
                   "material_map: auto (as many as the data determine: 1, 2, 4, ... points, the lowest BIC), N points "
                   "spread over the mesh (1-64), or FILE with one 'x,y,z' (m) per line")
      ->type_name("auto|N|FILE")
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
  RefineJob job;
  job.mesh = mesh_path_;
  if (app_->count("--estimate") > 0) job.estimate = estimate_;
  job.estimator = estimator_;
  job.volumetric = volumetric_;
  job.json = json_path_;
  job.vtk = vtk_dir_;
  if (app_->count("--max-strain") > 0) job.max_strain = max_strain_;
  job.no_force_offset = no_force_offset_;
  if (app_->count("--initial-modulus") > 0) job.initial_modulus = initial_modulus_pa_;
  if (app_->count("--control-points") > 0) job.control_points = control_points_;
  if (app_->count("--rest-frame") > 0) job.rest_frame = rest_frame_;
  if (app_->count("--rest-mesh") > 0) job.rest_mesh = rest_mesh_path_;
  if (app_->count("--until") > 0) job.until = until_s_;
  if (app_->count("--substeps") > 0) job.substeps = substeps_;
  job.threads = threads_;
  job.progress = !quiet_;
  const RefineDone done = run_refine_job(job, recording_from(recording_), report_warning);
  if (json_path_ == "-") {
    std::cout << done.card.dump(2) << '\n';
  } else {
    std::cout << done.summary;
    if (!done.rest_mesh.empty()) std::cout << "wrote " << done.rest_mesh << '\n';
    if (!done.vtk_collection.empty()) std::cout << "wrote " << done.vtk_collection << '\n';
    if (!json_path_.empty()) std::cout << "wrote " << json_path_ << '\n';
  }
  std::cout.flush();
  if (!std::cout) throw std::runtime_error("cannot write to standard output");
  return exit_ok;
}

}  // namespace pliant::cli

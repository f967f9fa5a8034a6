// `pliant refine REC`: FEM material parameters (Young's modulus, Rayleigh damping, a material
// map) and the rest shape of a recording, written as a material card (docs/spec/outputs-v1.md).
// Which estimator runs is decided from what the recording contains (refine_plan.hpp).
#pragma once

#include <string>

#include <CLI/CLI.hpp>

namespace pliant::cli {

class RefineCommand {
 public:
  /// Registers the subcommand and its options on `parent`.
  explicit RefineCommand(CLI::App& parent);

  bool selected() const { return app_->parsed(); }
  /// Runs after a successful parse; throws on failure (see exit_status.hpp for the mapping).
  int run() const;

 private:
  CLI::App* app_ = nullptr;
  std::string recording_;
  std::string mesh_path_;
  std::string estimate_;
  std::string estimator_ = "auto";
  std::string volumetric_ = "auto";
  std::string json_path_;
  std::string vtk_dir_;
  double max_strain_ = 0.10;
  bool no_force_offset_ = false;
  double initial_modulus_pa_ = 0;
  std::string control_points_ = "auto";
  int rest_frame_ = 0;
  std::string rest_mesh_path_;
  double until_s_ = 0;
  int substeps_ = 4;
  int threads_ = 0;
  bool quiet_ = false;
};

}  // namespace pliant::cli

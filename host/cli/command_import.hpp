// `pliant import compression CSV... -o DIR`: lab compression tests (universal testing machine
// CSV) as recordings for the FEM estimators (pliant/host/fem/compression_test.hpp).
#pragma once

#include <string>
#include <vector>

#include <CLI/CLI.hpp>

namespace pliant::cli {

class ImportCommand {
 public:
  /// Registers `import` and its subcommand `compression` on `parent`.
  explicit ImportCommand(CLI::App& parent);

  bool selected() const { return app_->parsed(); }
  /// Runs after a successful parse; throws on failure (see exit_status.hpp for the mapping).
  int run() const;

 private:
  CLI::App* app_ = nullptr;          // import
  CLI::App* compression_ = nullptr;  // import compression
  std::vector<std::string> csv_files_;
  std::string output_;
  double max_strain_ = 0.0;  // read only when given
  int frames_ = 0;
  double frame_interval_s_ = 1.0;
  std::string contact_ = "frictionless";
  std::string expansion_ = "small-strain";
  double poisson_ratio_ = 0.49;
  double density_kg_m3_ = 1070.0;
  std::string mesh_divisions_ = "2,24,5";
  std::string source_;
  std::string license_;
  bool force_ = false;
};

}  // namespace pliant::cli

#include "command_import.hpp"

#include <charconv>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <limits>
#include <set>
#include <stdexcept>
#include <string>
#include <system_error>
#include <vector>

#include "exit_status.hpp"
#include "output_directory.hpp"
#include "pliant/host/fem/compression_test.hpp"
#include "pliant/host/recording.hpp"

namespace pliant::cli {
namespace {

namespace fs = std::filesystem;

std::string number(double value) {
  char buffer[32];
  std::snprintf(buffer, sizeof buffer, "%.4g", value);
  return buffer;
}

// "2,24,5" -> radial, circumferential, axial.
host::CylinderMeshDivisions parse_divisions(const std::string& text) {
  host::CylinderMeshDivisions divisions;
  int* const targets[3] = {&divisions.radial, &divisions.circumferential, &divisions.axial};
  const char* at = text.data();
  const char* const end = text.data() + text.size();
  for (int k = 0; k < 3; ++k) {
    const auto result = std::from_chars(at, end, *targets[k]);
    const bool separator_ok = k < 2 ? (result.ptr != end && *result.ptr == ',') : result.ptr == end;
    if (result.ec != std::errc() || !separator_ok) {
      throw UsageError("--mesh-divisions must be three integers r,c,z (e.g. 2,24,5), found '" + text + "'");
    }
    at = result.ptr + 1;
  }
  if (divisions.radial < 1 || divisions.axial < 1) throw UsageError("--mesh-divisions: r and z must be >= 1");
  if (divisions.circumferential < 8 || divisions.circumferential % 8 != 0) {
    throw UsageError("--mesh-divisions: c must be a multiple of 8, >= 8");
  }
  return divisions;
}

host::LateralExpansion parse_expansion(std::string text) {
  for (char& c : text) c = c == '-' ? '_' : c;
  if (text == "small_strain") return host::LateralExpansion::small_strain;
  if (text == "finite_strain") return host::LateralExpansion::finite_strain;
  throw UsageError("--expansion must be small-strain or finite-strain");
}

}  // namespace

ImportCommand::ImportCommand(CLI::App& parent) {
  app_ = parent.add_subcommand("import", "Convert lab measurements into recordings");
  app_->require_subcommand(1);
  app_->footer("Run 'pliant import compression --help' for the compression tests.");
  compression_ = app_->add_subcommand(
      "compression",
      "Uniaxial compression tests of cylinders (testing-machine CSV: metadata lines, then Time (s), "
      "Compression (mm), Load (N), ...) as 3D recordings with a tetrahedral mesh, driven platen faces and the "
      "measured load, for the FEM estimators");
  compression_->footer(
      "Each recording: mesh.vtk (the cylinder), particles.csv (the platen-face nodes only; every other node is "
      "unobserved), wrench.csv (fz = -load on the top face), recording.json (poisson_ratio and density as known "
      "material, provenance and boundary conditions in meta). Lateral platen positions are modelled: with "
      "frictionless platens both faces are driven and expand as under uniaxial stress; with bonded platens the "
      "bottom face is fixed and the top face moves only in z.\n"
      "One CSV: -o is the recording directory. Several: one recording per CSV in DIR/<file name without .csv>.\n"
      "Exit status: 0 ok, 1 I/O failure, 2 bad options or a malformed CSV.");
  compression_->add_option("CSV", csv_files_, "Compression-test CSV files")->required();
  compression_->add_option("-o,--output", output_, "Recording directory (one CSV) or parent directory (several)")
      ->type_name("DIR")
      ->required();
  compression_
      ->add_option("--max-strain", max_strain_,
                   "Stop at the first frame whose strain compression/height exceeds E, in (0, 1) "
                   "(default: the whole test)")
      ->type_name("E");
  auto* frames =
      compression_->add_option("--frames", frames_, "Frames evenly spaced over the test (>= 2)")->type_name("N");
  compression_->add_option("--frame-interval", frame_interval_s_, "Seconds between frames (> 0)")
      ->type_name("S")
      ->capture_default_str()
      ->excludes(frames);
  compression_
      ->add_option("--contact", contact_,
                   "Platens: frictionless (faces slide: lateral expansion of uniaxial stress, as the "
                   "lab's reference moduli assume) or bonded (faces stick)")
      ->type_name("frictionless|bonded")
      ->capture_default_str();
  compression_
      ->add_option("--expansion", expansion_,
                   "Frictionless lateral stretch: small-strain 1 + nu e (stress-free for a corotational "
                   "linear model) or finite-strain (1 - e)^-nu (volume-keeping at nu = 0.5)")
      ->type_name("small-strain|finite-strain")
      ->capture_default_str();
  compression_->add_option("--poisson-ratio", poisson_ratio_, "material.poisson_ratio, in [0, 0.5)")
      ->type_name("NU")
      ->capture_default_str();
  compression_->add_option("--density", density_kg_m3_, "material.density in kg/m^3, in (0, 1e5]")
      ->type_name("RHO")
      ->capture_default_str();
  compression_
      ->add_option("--mesh-divisions", mesh_divisions_,
                   "Cylinder mesh: r rings outside the core, c nodes around (multiple of 8), z layers")
      ->type_name("r,c,z")
      ->capture_default_str();
  compression_->add_option("--source", source_, "meta.source: where the data comes from")->type_name("TEXT");
  compression_->add_option("--license", license_, "meta.license: the data's licence")->type_name("TEXT");
  compression_->add_flag("--force", force_, "Write into non-empty directories, replacing files of the same names");
}

int ImportCommand::run() const {
  host::CompressionRecordingOptions options;
  if (compression_->count("--max-strain") > 0) {
    if (!(max_strain_ > 0.0 && max_strain_ < 1.0)) throw UsageError("--max-strain must be in (0, 1)");
    options.max_strain = max_strain_;
  }
  if (compression_->count("--frames") > 0) {
    if (frames_ < 2 || frames_ > host::kMaxCompressionFrames) {
      throw UsageError("--frames must be between 2 and " + std::to_string(host::kMaxCompressionFrames));
    }
    options.frame_count = frames_;
  }
  if (!(std::isfinite(frame_interval_s_) && frame_interval_s_ > 0.0)) throw UsageError("--frame-interval must be > 0");
  options.frame_interval_s = frame_interval_s_;
  if (contact_ == "frictionless") {
    options.platen_contact = host::PlatenContact::frictionless;
  } else if (contact_ == "bonded") {
    options.platen_contact = host::PlatenContact::bonded;
  } else {
    throw UsageError("--contact must be frictionless or bonded");
  }
  options.lateral_expansion = parse_expansion(expansion_);
  if (!(poisson_ratio_ >= 0.0 && poisson_ratio_ < 0.5)) throw UsageError("--poisson-ratio must be in [0, 0.5)");
  options.poisson_ratio = poisson_ratio_;
  if (!(density_kg_m3_ > 0.0 && density_kg_m3_ <= 1e5)) throw UsageError("--density must be in (0, 1e5]");
  options.density_kg_m3 = density_kg_m3_;
  options.mesh = parse_divisions(mesh_divisions_);
  options.source = source_;
  options.license = license_;

  // Everything is read and converted before anything is written: a bad file writes nothing.
  struct Job {
    std::string directory;
    host::CompressionTest test;
    host::Recording recording;
  };
  std::vector<Job> jobs;
  std::set<std::string> names;
  for (const std::string& csv : csv_files_) {
    Job job;
    if (csv_files_.size() == 1) {
      job.directory = output_;
    } else {
      const std::string stem = fs::path(csv).stem().string();
      if (stem.empty() || stem == "." || stem == "..") throw UsageError("cannot name a recording after '" + csv + "'");
      if (!names.insert(stem).second) {
        throw UsageError("two CSV files are named '" + stem + "'; convert them in separate runs");
      }
      job.directory = (fs::path(output_) / stem).string();
    }
    job.test = host::read_compression_csv(csv);
    host::CompressionRecordingOptions own = options;
    own.name = fs::path(job.directory).filename().string();
    try {
      job.recording = host::compression_test_recording(job.test, own);
    } catch (const std::invalid_argument& e) {
      throw UsageError(csv + ": " + e.what());
    }
    check_output_directory(job.directory, force_);
    jobs.push_back(std::move(job));
  }

  for (const Job& job : jobs) {
    host::write_recording(job.recording, job.directory);
    const host::Recording& r = job.recording;
    const host::CompressionTest& t = job.test;
    const std::size_t last = static_cast<std::size_t>(r.frame_count() - 1);
    const double compression = t.height_m - r.position(r.frame_count() - 1, r.particle_count - 1, 2);
    std::cout << "wrote " << job.directory << ": " << (t.sample_name.empty() ? r.name : t.sample_name) << ", "
              << r.particle_count << " nodes, " << r.mesh->tet_count() << " tetrahedra x " << r.frame_count()
              << " frames over " << number(r.frame_times_s[last] - r.frame_times_s[0]) << " s, compression to "
              << number(1e3 * compression) << " mm (strain " << number(compression / t.height_m) << "), load "
              << number(-r.wrench[last].force_n[2]) << " N, " << host::to_string(options.platen_contact) << " platens";
    try {
      const host::LinearModulusFit fit = host::fit_linear_modulus(t, 0.02, 0.10);
      std::cout << "; linear modulus 2-10 % strain " << number(fit.youngs_modulus_pa * 1e-3) << " kPa";
    } catch (const std::invalid_argument&) {
      // The test does not reach that window: nothing to add.
    }
    std::cout << '\n';
  }
  std::cout.flush();
  if (!std::cout) throw std::runtime_error("cannot write to standard output");
  return exit_ok;
}

}  // namespace pliant::cli

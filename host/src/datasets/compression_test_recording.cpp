// Compression test -> recording v1 (contract in compression_test.hpp).
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <limits>
#include <stdexcept>
#include <string>
#include <vector>

#include "pliant/host/text_fields.hpp"
#include "pliant/host/fem/compression_test.hpp"
#include "pliant/host/fem/cylinder_mesh.hpp"

namespace pliant::host {
namespace {

using detail::format_double;

constexpr double kPi = 3.14159265358979323846;
constexpr double kMaxDensity_kg_m3 = 1e5;

[[noreturn]] void bad_option(const std::string& what) {
  throw std::invalid_argument("compression_test_recording: " + what);
}

[[noreturn]] void bad_test(const CompressionTest& test, const std::string& what) {
  throw RecordingError(detail::printable(test.label, 200) + ": " + what);
}

void check_options(const CompressionRecordingOptions& o) {
  if (std::isnan(o.max_strain) || !(o.max_strain > 0.0)) bad_option("max_strain must be > 0");
  if (o.frame_count != 0 && (o.frame_count < 2 || o.frame_count > kMaxCompressionFrames)) {
    bad_option("frame_count must be 0 or in 2.." + std::to_string(kMaxCompressionFrames));
  }
  if (o.frame_count == 0 && !(std::isfinite(o.frame_interval_s) && o.frame_interval_s > 0.0)) {
    bad_option("frame_interval_s must be finite and > 0");
  }
  if (!(o.poisson_ratio >= 0.0 && o.poisson_ratio < 0.5)) bad_option("poisson_ratio must be in [0, 0.5)");
  if (!(o.density_kg_m3 > 0.0 && o.density_kg_m3 <= kMaxDensity_kg_m3)) {
    bad_option("density_kg_m3 must be in (0, 1e5]");
  }
}

void check_test(const CompressionTest& t) {
  if (!(std::isfinite(t.diameter_m) && t.diameter_m > 0.0 && std::isfinite(t.height_m) && t.height_m > 0.0)) {
    bad_test(t, "diameter and height must be finite and positive");
  }
  const std::size_t n = t.time_s.size();
  if (n < 2) bad_test(t, "fewer than two rows");
  if (t.compression_m.size() != n || t.load_n.size() != n) bad_test(t, "columns of different lengths");
  double largest = -std::numeric_limits<double>::infinity();
  for (std::size_t i = 0; i < n; ++i) {
    if (!std::isfinite(t.time_s[i]) || !std::isfinite(t.compression_m[i]) || !std::isfinite(t.load_n[i])) {
      bad_test(t, "row " + std::to_string(i) + " is not finite");
    }
    if (i > 0 && !(t.time_s[i] > t.time_s[i - 1])) bad_test(t, "time must increase");
    if (!(std::fabs(t.compression_m[i]) < t.height_m)) bad_test(t, "compression reaches the specimen height");
    largest = std::max(largest, t.compression_m[i]);
  }
  if (!(largest > 0.0)) bad_test(t, "the specimen is never compressed (largest compression is not positive)");
}

// Linear interpolation of `values` sampled at increasing `times`, held constant outside.
double value_at(const std::vector<double>& times, const std::vector<double>& values, double t) {
  if (t <= times.front()) return values.front();
  if (t >= times.back()) return values.back();
  const auto upper = std::upper_bound(times.begin(), times.end(), t);
  const auto i = static_cast<std::size_t>(upper - times.begin());
  const double w = (t - times[i - 1]) / (times[i] - times[i - 1]);
  return values[i - 1] + w * (values[i] - values[i - 1]);
}

std::vector<double> frame_times(const CompressionTest& test, const CompressionRecordingOptions& o, int particle_count) {
  const double t0 = test.time_s.front();
  double t_end = test.time_s.back();
  if (std::isfinite(o.max_strain)) {
    for (std::size_t i = 0; i < test.time_s.size(); ++i) {
      if (test.compression_m[i] / test.height_m > o.max_strain) {
        t_end = test.time_s[i];
        break;
      }
    }
  }
  std::vector<double> times;
  if (o.frame_count >= 2) {
    const auto last = static_cast<double>(o.frame_count - 1);
    for (int k = 0; k < o.frame_count; ++k) {
      times.push_back(k == o.frame_count - 1 ? t_end : t0 + (t_end - t0) * static_cast<double>(k) / last);
    }
  } else {
    const double span = test.time_s.back() - t0;
    // A frame within a millionth of an interval of the last sample still counts as inside.
    const double count = std::floor(span / o.frame_interval_s + 1e-6) + 1.0;
    if (!(count <= static_cast<double>(kMaxCompressionFrames))) {
      bad_option("frame_interval_s " + format_double(o.frame_interval_s) + " s gives more than " +
                 std::to_string(kMaxCompressionFrames) + " frames");
    }
    const auto frames = static_cast<int>(count);
    for (int k = 0; k < frames; ++k) {
      times.push_back(std::min(t0 + o.frame_interval_s * static_cast<double>(k), test.time_s.back()));
    }
  }
  // Keep frames up to the first one past max_strain (the fit window then ends past it).
  if (std::isfinite(o.max_strain)) {
    for (std::size_t f = 0; f < times.size(); ++f) {
      if (value_at(test.time_s, test.compression_m, times[f]) / test.height_m > o.max_strain) {
        times.resize(f + 1);
        break;
      }
    }
  }
  // The reader's limit on stored coordinates, so that what is written can be read back.
  const double values = static_cast<double>(times.size()) * 3.0 * particle_count;
  if (values > static_cast<double>(detail::kMaxPositionValues)) {
    bad_option(std::to_string(times.size()) + " frames of " + std::to_string(particle_count) +
               " nodes exceed the limit of " + std::to_string(detail::kMaxPositionValues) +
               " stored coordinates; use fewer frames or a coarser mesh");
  }
  // Equal neighbours can only come from clamping to the last sample; drop them.
  times.erase(std::unique(times.begin(), times.end()), times.end());
  if (times.size() < 2) {
    bad_option("only one frame: the frame interval (" + format_double(o.frame_interval_s) +
               " s) or max_strain leaves a single frame of the " + format_double(test.time_s.back() - t0) + " s test");
  }
  return times;
}

// `value` to 12 significant digits, so that a unit conversion shows 10 rather than 10.000000000000002.
double rounded(double value) {
  char buffer[32];
  std::snprintf(buffer, sizeof buffer, "%.12g", value);
  return std::strtod(buffer, nullptr);
}

std::string base_name(const std::string& path) {
  const std::size_t slash = path.find_last_of('/');
  return slash == std::string::npos ? path : path.substr(slash + 1);
}

}  // namespace

double frictionless_lateral_stretch(double strain, double poisson_ratio, LateralExpansion expansion) {
  if (expansion == LateralExpansion::finite_strain) return std::pow(1.0 - strain, -poisson_ratio);
  return 1.0 + poisson_ratio * strain;
}

Recording compression_test_recording(const CompressionTest& test, const CompressionRecordingOptions& options) {
  check_options(options);
  check_test(test);
  TetMesh mesh = cylinder_tet_mesh(test.diameter_m, test.height_m, options.mesh);
  const int count = mesh.point_count();
  const std::vector<double> times = frame_times(test, options, count);

  const int per_level = count / (options.mesh.axial + 1);
  const int top_first = count - per_level;
  const bool frictionless = options.platen_contact == PlatenContact::frictionless;
  const double height = test.height_m;

  Recording r;
  r.name = !options.name.empty() ? options.name : !test.sample_name.empty() ? test.sample_name : "compression_test";
  r.dimension = 3;
  r.length_unit = "m";
  r.particle_count = count;

  // Lumped mass: a quarter of each tetrahedron's mass on each of its points.
  r.masses.assign(static_cast<std::size_t>(count), 0.0);
  double volume = 0.0;
  for (int tet = 0; tet < mesh.tet_count(); ++tet) {
    const double v = tet_signed_volume(mesh, tet);
    volume += v;
    for (int k = 0; k < 4; ++k) {
      r.masses[static_cast<std::size_t>(mesh.tetrahedra[static_cast<std::size_t>(4 * tet + k)])] +=
          0.25 * v * options.density_kg_m3;
    }
  }

  std::vector<int> top;
  std::vector<int> bottom;
  for (int id = 0; id < per_level; ++id) {
    bottom.push_back(id);
    top.push_back(top_first + id);
  }
  for (const int id : top) r.driven.push_back(DrivenWindow{id, -HUGE_VAL, HUGE_VAL});
  if (frictionless) {
    for (const int id : bottom) r.driven.push_back(DrivenWindow{id, -HUGE_VAL, HUGE_VAL});
  } else {
    r.fixed = bottom;
  }
  r.files = {{"particles", "particles.csv"}, {"wrench", "wrench.csv"}, {"mesh", "mesh.vtk"}};
  r.wrench_applied_to = top;
  r.material = {{"poisson_ratio", options.poisson_ratio}, {"density", options.density_kg_m3}};

  const std::size_t frame_size = 3 * static_cast<std::size_t>(count);
  r.frame_times_s = times;
  r.positions.assign(times.size() * frame_size, std::numeric_limits<double>::quiet_NaN());
  for (std::size_t f = 0; f < times.size(); ++f) {
    const double compression = value_at(test.time_s, test.compression_m, times[f]);
    const double lateral = frictionless ? frictionless_lateral_stretch(compression / height, options.poisson_ratio,
                                                                       options.lateral_expansion)
                                        : 1.0;
    const auto place = [&](int id, double z) {
      const auto at = static_cast<std::size_t>(id) * 3;
      double* slot = r.positions.data() + f * frame_size + at;
      slot[0] = mesh.points[at] * lateral;
      slot[1] = mesh.points[at + 1] * lateral;
      slot[2] = z;
    };
    for (const int id : bottom) place(id, 0.0);
    for (const int id : top) place(id, height - compression);
    WrenchSample sample;
    sample.t_s = times[f];
    sample.force_n[2] = -value_at(test.time_s, test.load_n, times[f]);
    r.wrench.push_back(sample);
  }

  nlohmann::json meta = nlohmann::json::object();
  if (!test.sample_name.empty()) meta["sample"] = test.sample_name;
  meta["source_file"] = base_name(test.label);
  if (!options.source.empty()) meta["source"] = options.source;
  if (!options.license.empty()) meta["license"] = options.license;
  if (!test.notes.empty()) meta["notes"] = test.notes;
  if (!test.machine.empty()) meta["machine"] = test.machine;
  if (!test.load_cell.empty()) meta["load_cell"] = test.load_cell;
  if (test.speed_m_per_s) meta["speed_mm_per_min"] = rounded(*test.speed_m_per_s * 60e3);
  meta["diameter_m"] = test.diameter_m;
  meta["height_m"] = test.height_m;
  meta["test"] =
      "uniaxial compression between parallel platens; the top face follows the measured crosshead compression, "
      "wrench.csv is the measured load";
  meta["platen_contact"] = to_string(options.platen_contact);
  if (frictionless) {
    meta["lateral_expansion"] = to_string(options.lateral_expansion);
    meta["boundary_conditions"] =
        std::string(
            "frictionless platens: top and bottom faces driven; z from the measured compression (bottom at "
            "z = 0), x and y scaled about the axis by the lateral stretch of homogeneous uniaxial stress, ") +
        (options.lateral_expansion == LateralExpansion::small_strain ? "1 + nu * compression / height"
                                                                     : "(1 - compression / height)^(-nu)") +
        " with nu = material.poisson_ratio (the lab's reference moduli assume homogeneous uniaxial stress)";
    meta["lateral_positions"] =
        "modelled, not measured: the x and y of every platen node come from the frictionless uniaxial solution";
  } else {
    meta["boundary_conditions"] =
        "bonded platens: bottom face fixed at rest; top face driven, x and y at rest, z from the measured compression";
    meta["lateral_positions"] = "modelled, not measured: platen nodes keep their rest x and y (no slip)";
  }
  meta["unobserved"] = "lateral-surface and interior nodes: nan in every frame; the rest shape is mesh.vtk";
  meta["wrench"] = "fz = -measured load (N): the top platen pushes the top face toward -z; torques 0";
  meta["gravity"] = "left out: the load reads about 0 N at zero compression, so the specimen's weight is not in it";
  if (std::isfinite(options.max_strain)) meta["max_strain"] = options.max_strain;
  if (options.frame_count >= 2) {
    meta["frames"] = {{"count", options.frame_count}};
  } else {
    meta["frames"] = {{"interval_s", options.frame_interval_s}};
  }
  meta["mesh"] = {{"kind", "cylinder O-grid, prisms split into 3 tetrahedra"},
                  {"divisions", {options.mesh.radial, options.mesh.circumferential, options.mesh.axial}},
                  {"points", count},
                  {"tetrahedra", mesh.tet_count()},
                  {"volume_ratio", volume / (kPi * 0.25 * test.diameter_m * test.diameter_m * height)}};
  r.meta = std::move(meta);
  r.mesh = std::move(mesh);
  finalize_recording(r);
  return r;
}

}  // namespace pliant::host

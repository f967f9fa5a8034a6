// Writes a synthetic diagnosis report to the directory named on the command line, for the
// browser rendering test (report_render_test.sh). The scene: 32 particles on an 8 x 4 grid,
// 150 frames at 50 Hz; a tool presses particles 12-19 down and lets go, and they keep part of
// the dent (plasticity). The baseline returns them fully, the augmented model keeps the set.
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <exception>
#include <iostream>
#include <limits>
#include <string>

#include "pliant/host/diagnose/diagnosis.hpp"
#include "pliant/host/diagnose/html_report.hpp"

namespace {

using pliant::host::Diagnosis;
using pliant::host::DiagnosisEvidence;

// Deterministic noise in [-1, 1].
double jitter(std::uint32_t& state) {
  state = state * 1664525u + 1013904223u;
  return static_cast<double>(state >> 8) / static_cast<double>(1u << 24) * 2.0 - 1.0;
}

void sample(Diagnosis& d, DiagnosisEvidence& e) {
  const int particles = 32;
  const int frames = 150;
  const double nan = std::numeric_limits<double>::quiet_NaN();
  e.dimension = 2;
  e.particle_count = particles;
  e.length_unit = "m";
  const auto cells = static_cast<std::size_t>(particles * frames);
  e.residual_baseline.assign(cells, nan);
  e.residual_augmented.assign(cells, nan);
  e.observed.assign(cells * 2, nan);
  e.simulated_baseline.assign(cells * 2, nan);
  e.simulated_augmented.assign(cells * 2, nan);
  std::uint32_t state = 7;
  for (int f = 0; f < frames; ++f) {
    const double t = 0.02 * f;
    e.frame_times_s.push_back(t);
    e.held_out.push_back(f >= 120 ? 1 : 0);
    // Press depth: ramps to 4 mm over 1-2 s, released over 2-2.2 s.
    const double press = t < 1.0 ? 0.0 : t < 2.0 ? 0.004 * (t - 1.0) : t < 2.2 ? 0.004 * (2.2 - t) / 0.2 : 0.0;
    const double set = t < 1.0 ? 0.0 : std::min(0.0014, 0.0014 * (t - 1.0));
    for (int p = 0; p < particles; ++p) {
      const double x = 0.01 * (p % 8);
      const double y = 0.01 * (p / 8);
      const bool pressed = p >= 12 && p <= 19;
      const double base_dy = pressed ? -press : -0.2 * press;
      const double kept = pressed ? -std::max(set, press) : base_dy;
      const auto i = static_cast<std::size_t>(f * particles + p);
      const double ox = x + 2e-4 * jitter(state);
      const double oy = y + kept + 2e-4 * jitter(state);
      const bool occluded = p == 5 && f >= 40 && f < 70;
      if (!occluded) {
        e.observed[2 * i] = ox;
        e.observed[2 * i + 1] = oy;
      }
      e.simulated_baseline[2 * i] = x;
      e.simulated_baseline[2 * i + 1] = y + base_dy;
      e.simulated_augmented[2 * i] = x;
      e.simulated_augmented[2 * i + 1] = y + kept + 5e-5 * jitter(state);
      if (!occluded) {
        e.residual_baseline[i] = std::hypot(ox - x, oy - (y + base_dy));
        e.residual_augmented[i] = std::hypot(ox - x, oy - e.simulated_augmented[2 * i + 1]);
      }
    }
  }
  e.fixed = {0, 1, 2, 3, 4, 5, 6, 7};
  e.driven = {12, 13, 14, 15, 16, 17, 18, 19};
  e.signatures = {{"persistence_after_unload", 0.82}, {"rate_dependence", 0.07}, {"contact_slip_mm", 0.01}};

  d.recording = "press_foam_3";
  d.baseline.model = "msm";
  d.baseline.parameters = {{"msm_alpha", 1.0}, {"msm_beta", 0.58}};
  d.baseline.parameter_std = {{"msm_beta", 0.02}};
  d.baseline.rms = 1.9e-3;
  d.noise_rms = 2.0e-4;
  d.verdict = "missing_physics";
  d.effect = "plasticity";
  d.explanation =
      "After release, particles 12-19 under the tool stay 1.4 mm below where the elastic model "
      "returns them; a yield/creep rest-shape update explains it.";
  d.location.particles = {12, 13, 14, 15, 16, 17, 18, 19};
  d.location.t_start = 2.1;
  d.location.t_end = 2.98;
  d.augmented.model = "msm";
  d.augmented.parameters = {{"msm_alpha", 1.0}, {"msm_beta", 0.61}, {"yield", 0.04}, {"creep", 0.8}};
  d.augmented.parameter_std = {{"msm_beta", 0.02}, {"yield", 0.005}, {"creep", 0.1}};
  d.augmented.rms = 3.1e-4;
  d.improvement = 0.84;
  pliant::host::Candidate plasticity;
  plasticity.effect = "plasticity";
  plasticity.rms = 3.1e-4;
  plasticity.bic = -8120.5;
  plasticity.parameters = {{"yield", 0.04}, {"creep", 0.8}};
  plasticity.parameter_std = {{"yield", 0.005}, {"creep", 0.1}};
  pliant::host::Candidate viscosity;
  viscosity.effect = "viscosity";
  viscosity.rms = 1.2e-3;
  viscosity.bic = -6011.2;
  viscosity.parameters = {{"damping", 3.0}};
  d.candidates = {plasticity, viscosity};
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 2) {
    std::cerr << "usage: write_sample_report <directory>\n";
    return 2;
  }
  try {
    Diagnosis d;
    DiagnosisEvidence e;
    sample(d, e);
    pliant::host::write_diagnosis_report(d, e, argv[1]);
  } catch (const std::exception& error) {
    std::cerr << "write_sample_report: " << error.what() << "\n";
    return 1;
  }
  return 0;
}

// `pliant diagnose --model fem` (fem_diagnose.hpp, fem_model_run.hpp).
//
// Built twice from this file:
// - fem_diagnose_test (fast, a few seconds; also run under ASan + UBSan): the force noise
//   estimator; every effect of the FEM run approaches the baseline as its parameter approaches
//   the null, and the force scales with E; the JSON, summary and report with force-only evidence;
//   end-to-end diagnoses of small compressions generated with the fitted model itself (exactness:
//   a linear material is consistent with E recovered, a stiffening one is named with its k, the
//   thread count changes nothing), the statics/dynamics rule both ways, and the refusals.
// - fem_diagnose_acceptance_test (PLIANT_FEM_DIAGNOSE_ACCEPTANCE, label "acceptance", under a
//   minute of CPU in Release):
//   * synthetic compressions of a small cylinder with bonded platens, generated on a refined copy
//     of the recording's mesh (so the generator is not the fitted model with one switch flipped)
//     with force noise: a stiffening material is named, a linear one is consistent, a wrench
//     stream shifted in time is named latency. The coarse mesh is stiffer than the refined one
//     (linear tetrahedra lock at nu = 0.45 against bonded faces): the E the diagnosis should
//     find is the one at which the coarse mesh reproduces the refined mesh's linear forces
//     (about 0.85 E), computed here, not E itself;
//   * the real Instron compressions of examples/phantom_compression, full curves to about 66 %
//     strain: stiffening is named and the held-out force rms improves.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <ctime>
#include <iostream>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include "pliant/host/diagnose/diagnose.hpp"
#include "pliant/host/diagnose/fem_diagnose.hpp"
#include "pliant/host/diagnose/fem_model_run.hpp"
#include "pliant/host/diagnose/html_report.hpp"
#include "pliant/host/fem/compression_test.hpp"
#include "pliant/host/fem/cylinder_mesh.hpp"
#include "pliant/host/fem/fem_box_mesh.hpp"
#include "pliant/host/recording.hpp"

namespace pliant::host {
namespace {

constexpr double kDiameter = 0.025;
constexpr double kHeight = 0.015;
constexpr double kYoungs = 50e3;
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

std::size_t at(int i) { return static_cast<std::size_t>(i); }

// Compression of the cylinder: 0 -> peak strain over the whole duration, or (unload) over the
// first half and back to 0 over the second.
double compression_m(double t, double duration, double peak_strain, bool unload) {
  const double half = 0.5 * duration;
  const double s = !unload ? t / duration : (t <= half ? t / half : (duration - t) / half);
  return peak_strain * kHeight * std::max(0.0, s);
}

// A bonded-platen compression recording on `mesh`: bottom face fixed, top face driven straight
// down (x, y at rest), the wrench (given per frame, or zero) applied to the top face. `observed`
// (frame-major positions of every node, or empty): the other nodes are observed where finite.
Recording compression_recording(const TetMesh& mesh, int frames, double dt, double peak_strain, bool unload,
                                const std::vector<double>& wrench_z, const std::vector<double>& observed = {}) {
  Recording r;
  r.name = "synthetic_compression";
  r.dimension = 3;
  r.length_unit = "m";
  r.particle_count = mesh.point_count();
  r.masses.assign(at(r.particle_count), 1e-4);
  r.material = {{"poisson_ratio", 0.45}, {"density", 1000.0}};
  std::vector<int> top;
  for (int i = 0; i < mesh.point_count(); ++i) {
    const double z = mesh.points[at(i) * 3 + 2];
    if (z == 0.0) r.fixed.push_back(i);
    if (z == kHeight) top.push_back(i);
  }
  for (int id : top) r.driven.push_back({id});
  r.wrench_applied_to = top;
  r.mesh = mesh;
  r.files = {{"particles", "particles.csv"}, {"mesh", "mesh.vtk"}, {"wrench", "wrench.csv"}};
  const double duration = dt * (frames - 1);
  for (int k = 0; k < frames; ++k) {
    const double t = dt * k;
    r.frame_times_s.push_back(t);
    std::vector<double> frame(at(r.particle_count) * 3, kNaN);
    if (!observed.empty()) {
      for (int i = 0; i < r.particle_count; ++i) {
        const double z = mesh.points[at(i) * 3 + 2];
        if (z == 0.0 || z == kHeight) continue;
        for (int d = 0; d < 3; ++d) {
          frame[at(i) * 3 + at(d)] = observed[(at(k) * at(r.particle_count) + at(i)) * 3 + at(d)];
        }
      }
    }
    for (int id : top) {
      frame[at(id) * 3] = mesh.points[at(id) * 3];
      frame[at(id) * 3 + 1] = mesh.points[at(id) * 3 + 1];
      frame[at(id) * 3 + 2] = kHeight - compression_m(t, duration, peak_strain, unload);
    }
    r.positions.insert(r.positions.end(), frame.begin(), frame.end());
    WrenchSample w;
    w.t_s = t;
    w.force_n[2] = wrench_z.empty() ? 0.0 : wrench_z[at(k)];
    r.wrench.push_back(w);
  }
  finalize_recording(r);
  return r;
}

// The z force of a run of `recording` per frame (NaN where the run has none).
std::vector<double> force_z(const Recording& recording, FemTimeMode mode, const FemRunSettings& settings) {
  FemRecordingSimulator simulator(recording, mode, 1);
  const FemRun run = simulator.simulate(settings);
  EXPECT_TRUE(run.ok) << run.failure;
  std::vector<double> out(recording.frame_times_s.size(), kNaN);
  for (std::size_t k = 0; k < out.size() && run.ok; ++k) out[k] = run.force[k * 3 + 2];
  return out;
}

double peak_magnitude(const std::vector<double>& values) {
  double peak = 0;
  for (double v : values) peak = std::max(peak, std::abs(v));
  return peak;
}

// `values` plus white noise of std `sigma`.
std::vector<double> with_noise(std::vector<double> values, double sigma, unsigned seed) {
  std::mt19937 random(seed);
  std::normal_distribution<double> noise(0.0, sigma);
  for (double& v : values) v += noise(random);
  return values;
}

DiagnoseResult diagnose_fem(const Recording& recording, int threads = 0) {
  DiagnoseOptions options;
  options.model = "fem";
  options.threads = threads;
  return diagnose_recording(recording, options);
}

void print(const std::string& label, const DiagnoseResult& r) {
  const Diagnosis& d = r.diagnosis;
  std::cout << "[ fem      ] " << label << ": " << d.verdict << " (" << d.effect << "), E "
            << d.baseline.parameters.at("youngs_modulus") << " Pa, force rms " << d.baseline.force_rms << " -> "
            << d.augmented.force_rms << " N (noise " << d.force_noise_rms << "), improvement " << d.improvement << ", "
            << r.runtime_s << " s\n  " << d.explanation << "\n";
  for (const Candidate& c : d.candidates) {
    std::cout << "    " << c.effect << ": force rms " << c.force_rms << ", bic " << c.bic;
    for (const auto& [name, value] : c.parameters) std::cout << ", " << name << " " << value;
    std::cout << "\n";
  }
}

#ifndef PLIANT_FEM_DIAGNOSE_ACCEPTANCE

TEST(FemDiagnose, ForceNoiseOfAStreamIsItsWhiteNoise) {
  Recording r;
  std::mt19937 random(7);
  std::normal_distribution<double> noise(0.0, 0.05);
  for (int k = 0; k < 400; ++k) {
    WrenchSample w;
    w.t_s = 0.01 * k;
    w.force_n[0] = 3.0 * std::sin(2.0 * w.t_s) + noise(random);
    w.force_n[2] = -10.0 * w.t_s * w.t_s + noise(random);
    r.wrench.push_back(w);  // force_n[1] constant: left out
  }
  EXPECT_NEAR(estimate_force_noise_std(r), 0.05, 0.006);
  r.wrench.resize(4);
  EXPECT_EQ(estimate_force_noise_std(r), 0.0);
}

// Principle 1 of DIAGNOSIS.md: each effect is the baseline at its null. Checked by approaching
// the null (1e-9 away), which runs the effect's own code path, rather than by switching it off.
TEST(FemDiagnose, EffectsApproachTheBaselineAtTheirNullsAndTheForceScalesWithE) {
  const TetMesh mesh = cylinder_tet_mesh(kDiameter, kHeight, 1, 8, 2);
  const Recording recording = compression_recording(mesh, 12, 1.0, 0.2, true, {});
  FemRecordingSimulator simulator(recording, FemTimeMode::quasi_static, 1);
  EXPECT_TRUE(simulator.scale_invariant(FemRunSettings{}));
  FemRunSettings settings;
  settings.youngs_modulus_pa = kYoungs;
  const FemRun baseline = simulator.simulate(settings);
  ASSERT_TRUE(baseline.ok) << baseline.failure;
  const double peak = peak_magnitude(std::vector<double>(baseline.force.begin(), baseline.force.end()));
  EXPECT_LT(baseline.force[6 * 3 + 2], 0.0);  // the top platen pushes down at peak strain
  std::vector<FemRunSettings> nulls(6, settings);
  nulls[0].stiffening = 1e-9;
  nulls[1].relaxation_fraction = 1e-9;
  nulls[1].relaxation_time_s = 3.0;
  nulls[2].plastic_yield = 0.0;
  nulls[2].plastic_creep = 1e-9;
  nulls[3].wrench_latency_s = 1e-9;
  nulls[4].element_factor.assign(static_cast<std::size_t>(simulator.element_count()), 1.0 + 1e-9);
  nulls[5].extra_gravity_m_s2 = Eigen::Vector3d(1e-9, -1e-9, 1e-9);
  for (std::size_t e = 0; e < nulls.size(); ++e) {
    SCOPED_TRACE("null " + std::to_string(e));
    const FemRun run = simulator.simulate(nulls[e]);
    ASSERT_TRUE(run.ok) << run.failure;
    for (std::size_t i = 0; i < run.force.size(); ++i) {
      if (std::isfinite(baseline.force[i])) {
        EXPECT_NEAR(run.force[i], baseline.force[i], 1e-6 * peak);
      }
    }
    for (std::size_t i = 0; i < run.positions.size(); ++i) {
      EXPECT_NEAR(run.positions[i], baseline.positions[i], 1e-7 * kHeight);
    }
  }
  FemRunSettings doubled = settings;
  doubled.youngs_modulus_pa = 2.0 * kYoungs;
  const FemRun stiffer = simulator.simulate(doubled);
  ASSERT_TRUE(stiffer.ok);
  EXPECT_NEAR(stiffer.force[6 * 3 + 2], 2.0 * baseline.force[6 * 3 + 2], 1e-6 * peak);
  // Each effect away from its null changes the force (or the rest shape).
  FemRunSettings stiffening = settings;
  stiffening.stiffening = 5.0;
  const FemRun stiffened = simulator.simulate(stiffening);
  ASSERT_TRUE(stiffened.ok) << stiffened.failure;
  EXPECT_LT(stiffened.force[6 * 3 + 2], 1.05 * baseline.force[6 * 3 + 2]);  // more compressive force
  FemRunSettings late = settings;
  late.wrench_latency_s = 1.0;
  const FemRun lagged = simulator.simulate(late);
  EXPECT_NEAR(lagged.force[6 * 3 + 2], baseline.force[5 * 3 + 2], 1e-9 * peak);
  FemRunSettings relaxing = settings;
  relaxing.relaxation_fraction = 0.5;
  relaxing.relaxation_time_s = 2.0;
  const FemRun relaxed = simulator.simulate(relaxing);
  EXPECT_LT(relaxed.force[6 * 3 + 2], 1.1 * baseline.force[6 * 3 + 2]);  // loading: stiffer than long-term
  EXPECT_GT(relaxed.force[11 * 3 + 2], 0.0);  // back at zero strain the unloading has not relaxed yet
  FemRunSettings creeping = settings;
  creeping.plastic_yield = 0.02;
  creeping.plastic_creep = 0.5;
  const FemRun crept = simulator.simulate(creeping);
  ASSERT_TRUE(crept.ok) << crept.failure;
  // A permanent set: back at its original height the body is stretched against its crept rest
  // shape, so the platen has to pull it up.
  EXPECT_GT(crept.force[11 * 3 + 2], 0.05 * peak);
}

TEST(FemDiagnose, ForceOnlyDiagnosisIsWrittenWithNullPositionRms) {
  Diagnosis d;
  d.recording = "phantom";
  d.baseline.model = "fem";
  d.baseline.parameters = {{"youngs_modulus", 2e5}, {"poisson_ratio", 0.49}, {"density", 1040.0}};
  d.baseline.rms = std::numeric_limits<double>::quiet_NaN();
  d.baseline.force_rms = 60.0;
  d.noise_rms = std::numeric_limits<double>::quiet_NaN();
  d.force_noise_rms = 0.02;
  d.verdict = "missing_physics";
  d.effect = "stiffening";
  d.augmented = d.baseline;
  d.augmented.parameters["stiffening"] = 5.0;
  d.augmented.force_rms = 9.0;
  d.improvement = 0.85;
  Candidate c;
  c.effect = "stiffening";
  c.rms = std::numeric_limits<double>::quiet_NaN();
  c.force_rms = 9.0;
  d.candidates.push_back(c);
  const nlohmann::json j = diagnosis_json(d);
  EXPECT_TRUE(j.at("baseline").at("rms").is_null());
  EXPECT_TRUE(j.at("noise_rms").is_null());
  EXPECT_DOUBLE_EQ(j.at("baseline").at("force_rms").get<double>(), 60.0);
  EXPECT_DOUBLE_EQ(j.at("augmented").at("force_rms").get<double>(), 9.0);
  EXPECT_DOUBLE_EQ(j.at("force_noise_rms").get<double>(), 0.02);
  EXPECT_TRUE(j.at("candidates").at(0).at("rms").is_null());
  const std::string summary = diagnosis_summary(d, "m");
  EXPECT_NE(summary.find("force rms 60 N"), std::string::npos) << summary;

  // The MSM document is unchanged: no force keys.
  Diagnosis msm;
  msm.baseline.parameters = {{"msm_alpha", 1.0}, {"msm_beta", 0.5}};
  msm.augmented = msm.baseline;
  const nlohmann::json m = diagnosis_json(msm);
  EXPECT_FALSE(m.contains("force_noise_rms"));
  EXPECT_FALSE(m.at("baseline").contains("force_rms"));
  EXPECT_TRUE(m.at("baseline").at("rms").is_number());

  // The report draws the force and survives the missing position rms.
  DiagnosisEvidence evidence;
  evidence.dimension = 3;
  evidence.particle_count = 2;
  for (int k = 0; k < 5; ++k) {
    evidence.frame_times_s.push_back(k);
    for (double v : {0.0, 0.0, -1.0 * k}) evidence.force_observed.push_back(v);
    for (double v : {0.0, 0.0, -0.8 * k}) evidence.force_baseline.push_back(v);
    for (double v : {0.0, 0.0, -0.95 * k}) evidence.force_augmented.push_back(v);
  }
  evidence.held_out.assign(5, 0);
  const std::string html = diagnosis_html(d, evidence);
  EXPECT_NE(html.find("data-plot=\"force\""), std::string::npos);
  EXPECT_NE(html.find("data-note=\"force-only\""), std::string::npos);  // no maps of constrained nodes
}

// A small bonded compression generated with the fitted model itself (same mesh, same solver),
// force noise 0.2 % of the peak: the diagnosis must give the generator's parameters back.
struct SelfGenerated {
  Recording recording;
  double peak_force = 0;
};

SelfGenerated self_generated(const TetMesh& mesh, int frames, double dt, double stiffening, unsigned seed,
                             FemTimeMode mode = FemTimeMode::quasi_static) {
  const Recording clean = compression_recording(mesh, frames, dt, 0.3, false, {});
  FemRunSettings settings;
  settings.youngs_modulus_pa = kYoungs;
  settings.stiffening = stiffening;
  const std::vector<double> force = force_z(clean, mode, settings);
  SelfGenerated out;
  out.peak_force = peak_magnitude(force);
  out.recording = compression_recording(mesh, frames, dt, 0.3, false, with_noise(force, 0.002 * out.peak_force, seed));
  return out;
}

TEST(FemDiagnose, SelfGeneratedLinearCompressionIsConsistentAndGivesEBack) {
  const SelfGenerated s = self_generated(cylinder_tet_mesh(kDiameter, kHeight, 1, 8, 2), 24, 0.5, 0.0, 21);
  const DiagnoseResult r = diagnose_fem(s.recording);
  print("self-generated linear", r);
  const Diagnosis& d = r.diagnosis;
  EXPECT_EQ(d.verdict, "consistent");
  EXPECT_EQ(d.effect, "none");
  EXPECT_EQ(d.improvement, 0.0);
  EXPECT_NEAR(d.baseline.parameters.at("youngs_modulus"), kYoungs, 0.01 * kYoungs);
  EXPECT_NEAR(d.baseline.force_rms, d.force_noise_rms, 0.5 * d.force_noise_rms);  // at the noise floor
  EXPECT_EQ(r.evidence.signatures.at("quasi_static"), 1.0);
  EXPECT_TRUE(std::isnan(d.baseline.rms));  // no free node observed: position rms undefined
  EXPECT_FALSE(d.candidates.empty());
}

// Free nodes observed too (positions with 20 um noise): positions and forces are compared
// together, the heterogeneity effect is offered (it needs positions), and a recording generated
// by the model itself is consistent. A stiff region (4 times E where x > 4 mm) is named
// heterogeneity, with the patches over it stiffer than the reference.
TEST(FemDiagnose, ObservedFreeNodesAreComparedAndAStiffRegionIsNamedHeterogeneity) {
  const TetMesh mesh = cylinder_tet_mesh(kDiameter, kHeight, 1, 8, 2);
  const int frames = 24;
  const double dt = 0.5;
  const Recording clean = compression_recording(mesh, frames, dt, 0.3, false, {});
  for (const bool stiff_region : {false, true}) {
    SCOPED_TRACE(stiff_region ? "stiff region" : "homogeneous");
    FemRecordingSimulator generator(clean, FemTimeMode::quasi_static, 1);
    FemRunSettings settings;
    settings.youngs_modulus_pa = kYoungs;
    if (stiff_region) {
      const std::vector<double> centroids = generator.element_centroids();
      for (std::size_t e = 0; e < centroids.size() / 3; ++e) {
        settings.element_factor.push_back(centroids[3 * e] > 0.004 ? 4.0 : 1.0);
      }
    }
    const FemRun run = generator.simulate(settings);
    ASSERT_TRUE(run.ok) << run.failure;
    std::vector<double> force(at(frames));
    for (int k = 0; k < frames; ++k) force[at(k)] = run.force[at(k) * 3 + 2];
    const double sigma = 2e-5;
    const Recording recording =
        compression_recording(mesh, frames, dt, 0.3, false, with_noise(force, 0.002 * peak_magnitude(force), 31),
                              with_noise(run.positions, sigma, 32));
    const DiagnoseResult r = diagnose_fem(recording);
    print(stiff_region ? "observed, stiff region" : "observed, homogeneous", r);
    const Diagnosis& d = r.diagnosis;
    EXPECT_TRUE(std::isfinite(d.baseline.rms));
    EXPECT_NEAR(d.noise_rms, std::sqrt(3.0) * sigma, 0.3 * std::sqrt(3.0) * sigma);
    bool offered = false;
    for (const Candidate& c : d.candidates) offered = offered || c.effect == "heterogeneity";
    EXPECT_TRUE(offered);
    if (!stiff_region) {
      EXPECT_EQ(d.verdict, "consistent");
      EXPECT_NEAR(d.baseline.parameters.at("youngs_modulus"), kYoungs, 0.01 * kYoungs);
      EXPECT_NEAR(d.baseline.rms, d.noise_rms, 0.3 * d.noise_rms);
    } else {
      EXPECT_EQ(d.verdict, "missing_physics");
      EXPECT_EQ(d.effect, "heterogeneity");
      EXPECT_GT(d.improvement, 0.5);
    }
  }
}

TEST(FemDiagnose, SelfGeneratedStiffeningIsNamedWithItsParametersWhateverTheThreadCount) {
  const SelfGenerated s = self_generated(cylinder_tet_mesh(kDiameter, kHeight, 1, 8, 2), 24, 0.5, 4.0, 22);
  const DiagnoseResult r = diagnose_fem(s.recording, 2);
  print("self-generated stiffening k = 4", r);
  const Diagnosis& d = r.diagnosis;
  EXPECT_EQ(d.verdict, "missing_physics");
  ASSERT_EQ(d.effect, "stiffening");
  EXPECT_GT(d.improvement, 0.8);
  EXPECT_NEAR(d.augmented.parameters.at("stiffening"), 4.0, 0.2);
  EXPECT_NEAR(d.augmented.parameters.at("youngs_modulus"), kYoungs, 0.03 * kYoungs);
  EXPECT_GT(d.baseline.parameters.at("youngs_modulus"), 1.1 * kYoungs);  // the linear fit is pulled up
  EXPECT_LT(d.augmented.force_rms, 2.0 * d.force_noise_rms);
  EXPECT_GT(d.baseline.force_rms, 10.0 * d.force_noise_rms);
  EXPECT_NE(d.explanation.find("rises with strain"), std::string::npos) << d.explanation;
  EXPECT_GT(r.evidence.signatures.at("force_load_sign_change"), 0.0);  // stiffening's tell-tale
  // One worker thread gives the same document.
  const DiagnoseResult single = diagnose_fem(s.recording, 1);
  EXPECT_EQ(diagnosis_json(single.diagnosis).dump(), diagnosis_json(d).dump());
}

// Loading within a few natural periods: the rule picks dynamics (Newmark, every frame), and a
// recording generated dynamically with the same model is consistent with E given back.
TEST(FemDiagnose, FastLoadingIsDiagnosedDynamically) {
  const TetMesh mesh = cylinder_tet_mesh(kDiameter, kHeight, 1, 8, 2);
  const Recording probe = compression_recording(mesh, 12, 1.0, 0.3, false, {});
  const double period = FemRecordingSimulator(probe, FemTimeMode::quasi_static, 1).lowest_period_s(kYoungs);
  ASSERT_TRUE(std::isfinite(period));
  const int frames = 60;
  const SelfGenerated s = self_generated(mesh, frames, 3.0 * period / (frames - 1), 0.0, 23, FemTimeMode::dynamic);
  const DiagnoseResult r = diagnose_fem(s.recording);
  print("dynamic linear", r);
  EXPECT_EQ(r.evidence.signatures.at("quasi_static"), 0.0);
  EXPECT_EQ(r.diagnosis.verdict, "consistent");
  EXPECT_NEAR(r.diagnosis.baseline.parameters.at("youngs_modulus"), kYoungs, 0.02 * kYoungs);
  // Frames are held out of this 20 ms test, and the held-out misfit is the generator's noise
  // (0.2 % of the peak per component). The noise estimated from the stream is higher: undamped
  // element modes ring faster than a local cubic over 7 samples follows.
  const double noise_rms = std::sqrt(3.0) * 0.002 * s.peak_force;
  EXPECT_NEAR(r.diagnosis.baseline.force_rms, noise_rms, 0.3 * noise_rms);
}

// Every node is on a platen (one layer of prisms): nothing can vibrate, so the rule keeps statics
// however fast the loading (no finite natural period).
TEST(FemDiagnose, EveryNodeConstrainedStaysQuasiStatic) {
  const SelfGenerated s = self_generated(cylinder_tet_mesh(kDiameter, kHeight, 1, 8, 1), 20, 1e-4, 0.0, 24);
  const DiagnoseResult r = diagnose_fem(s.recording);
  EXPECT_EQ(r.evidence.signatures.at("quasi_static"), 1.0);
  EXPECT_FALSE(std::isfinite(r.evidence.signatures.at("lowest_period_s")));
  EXPECT_EQ(r.diagnosis.verdict, "consistent");
  EXPECT_NEAR(r.diagnosis.baseline.parameters.at("youngs_modulus"), kYoungs, 0.01 * kYoungs);
}

TEST(FemDiagnose, RecordingsTheFemCannotTakeAreRefusedWithOneLine) {
  auto refusal = [](const Recording& recording) {
    try {
      diagnose_fem(recording);
    } catch (const std::runtime_error& error) {
      return std::string(error.what());
    }
    return std::string("(accepted)");
  };
  const TetMesh mesh = cylinder_tet_mesh(kDiameter, kHeight, 1, 8, 2);
  Recording no_mesh = compression_recording(mesh, 12, 1.0, 0.2, false, {});
  no_mesh.mesh.reset();
  const std::string a = refusal(no_mesh);
  EXPECT_NE(a.find("--model fem"), std::string::npos) << a;
  EXPECT_EQ(a.find('\n'), std::string::npos) << a;
  // Nothing to compare: no wrench and no observed free node.
  Recording blind = compression_recording(mesh, 12, 1.0, 0.2, false, {});
  blind.wrench.clear();
  blind.wrench_applied_to.clear();
  const std::string b = refusal(blind);
  EXPECT_NE(b.find("nothing to compare"), std::string::npos) << b;
  Recording short_recording = compression_recording(mesh, 5, 1.0, 0.2, false, {});
  EXPECT_NE(refusal(short_recording).find("too few frames"), std::string::npos);
}

#else  // PLIANT_FEM_DIAGNOSE_ACCEPTANCE

struct Synthetic {
  Recording recording;
  double peak_force = 0;
  /// The modulus at which the recording's (coarse) mesh reproduces the generator's (refined)
  /// linear forces, least squares over the frames: what a correct fit of E should find.
  double mesh_youngs = 0;
};

// 40 frames over 30 s of bonded compression to 35 % strain, generated on the refined mesh with
// E exp(k eps^2), the force read `latency_s` late, plus white force noise of `noise_fraction`
// times the peak force; the recording carries the coarse mesh.
Synthetic synthetic_compression(double stiffening, double latency_s, double noise_fraction, unsigned seed,
                                bool unload) {
  const int frames = 40;
  const double dt = 0.75;
  const double peak_strain = 0.35;
  const TetMesh coarse = cylinder_tet_mesh(kDiameter, kHeight, 1, 16, 3);
  const TetMesh fine = fem::refine_tet_mesh(coarse);
  const Recording fine_recording = compression_recording(fine, frames, dt, peak_strain, unload, {});
  const Recording coarse_recording = compression_recording(coarse, frames, dt, peak_strain, unload, {});
  FemRunSettings settings;
  settings.youngs_modulus_pa = kYoungs;
  const std::vector<double> fine_linear = force_z(fine_recording, FemTimeMode::quasi_static, settings);
  const std::vector<double> coarse_linear = force_z(coarse_recording, FemTimeMode::quasi_static, settings);
  double ab = 0;
  double aa = 0;
  for (std::size_t k = 0; k < fine_linear.size(); ++k) {
    ab += coarse_linear[k] * fine_linear[k];
    aa += coarse_linear[k] * coarse_linear[k];
  }
  Synthetic out;
  out.mesh_youngs = kYoungs * ab / aa;
  settings.stiffening = stiffening;
  settings.wrench_latency_s = latency_s;
  const std::vector<double> force = stiffening == 0.0 && latency_s == 0.0
                                        ? fine_linear
                                        : force_z(fine_recording, FemTimeMode::quasi_static, settings);
  out.peak_force = peak_magnitude(force);
  out.recording = compression_recording(coarse, frames, dt, peak_strain, unload,
                                        with_noise(force, noise_fraction * out.peak_force, seed));
  std::cout << "[ fem      ] generator: refined mesh " << fine.point_count() << " nodes, recording mesh "
            << coarse.point_count() << " nodes; E " << kYoungs << " Pa on the refined mesh is " << out.mesh_youngs
            << " Pa on the recording's\n";
  return out;
}

TEST(FemDiagnose, StiffeningMaterialIsNamedStiffening) {
  const Synthetic s = synthetic_compression(4.0, 0.0, 0.003, 11, false);
  const DiagnoseResult r = diagnose_fem(s.recording);
  print("stiffening k = 4", r);
  const Diagnosis& d = r.diagnosis;
  EXPECT_EQ(d.baseline.model, "fem");
  EXPECT_EQ(d.verdict, "missing_physics");
  ASSERT_EQ(d.effect, "stiffening");
  EXPECT_GT(d.improvement, 0.8);
  EXPECT_LT(d.augmented.force_rms, 0.1 * d.baseline.force_rms);
  EXPECT_TRUE(std::isnan(d.baseline.rms));  // no free node observed: position rms undefined
  EXPECT_NEAR(d.augmented.parameters.at("stiffening"), 4.0, 0.5);
  EXPECT_NEAR(d.augmented.parameters.at("youngs_modulus"), s.mesh_youngs, 0.05 * s.mesh_youngs);
  const nlohmann::json j = diagnosis_json(d);
  EXPECT_EQ(j.at("baseline").at("model"), "fem");
  EXPECT_TRUE(j.at("baseline").at("rms").is_null());
  EXPECT_TRUE(j.at("baseline").contains("force_rms"));
  EXPECT_TRUE(j.contains("force_noise_rms"));
  EXPECT_TRUE(j.at("baseline").at("parameters").contains("poisson_ratio"));
  EXPECT_EQ(r.evidence.force_observed.size(), s.recording.frame_times_s.size() * 3);
}

// The 15 % gap between the fitted E and the generator's is the recording mesh's discretisation
// (mesh_youngs), not a bias of the fit: held to 2 % of mesh_youngs.
TEST(FemDiagnose, LinearMaterialIsConsistent) {
  const Synthetic s = synthetic_compression(0.0, 0.0, 0.003, 12, false);
  const DiagnoseResult r = diagnose_fem(s.recording);
  print("linear", r);
  EXPECT_EQ(r.diagnosis.verdict, "consistent");
  EXPECT_EQ(r.diagnosis.effect, "none");
  EXPECT_EQ(r.diagnosis.improvement, 0.0);
  EXPECT_NEAR(r.diagnosis.baseline.parameters.at("youngs_modulus"), s.mesh_youngs, 0.02 * s.mesh_youngs);
  EXPECT_LT(s.mesh_youngs, 0.95 * kYoungs);  // the coarse mesh is measurably stiffer
}

TEST(FemDiagnose, ShiftedWrenchStreamIsNamedLatency) {
  const Synthetic s = synthetic_compression(0.0, 1.0, 0.003, 13, true);
  const DiagnoseResult r = diagnose_fem(s.recording);
  print("latency 1 s", r);
  const Diagnosis& d = r.diagnosis;
  ASSERT_EQ(d.effect, "latency");
  EXPECT_GT(d.improvement, 0.8);
  EXPECT_NEAR(d.augmented.parameters.at("wrench_latency_s"), 1.0, 0.1);
  EXPECT_NEAR(d.augmented.parameters.at("youngs_modulus"), s.mesh_youngs, 0.03 * s.mesh_youngs);
}

const std::string kDir = PLIANT_PHANTOM_COMPRESSION_DIR;

class FemDiagnosePhantom : public ::testing::TestWithParam<const char*> {};

TEST_P(FemDiagnosePhantom, FullCurveIsNamedStiffeningAndTheForceFitImproves) {
  const Recording recording = read_recording(kDir + "/" + GetParam());
  const auto cpu_started = std::clock();
  const DiagnoseResult r = diagnose_fem(recording);
  const double cpu_s = static_cast<double>(std::clock() - cpu_started) / CLOCKS_PER_SEC;
  const Diagnosis& d = r.diagnosis;
  std::cout << "[ phantom  ] " << GetParam() << ": " << d.verdict << " (" << d.effect << "), E baseline "
            << d.baseline.parameters.at("youngs_modulus") << " Pa, force rms " << d.baseline.force_rms << " -> "
            << d.augmented.force_rms << " N (noise " << d.force_noise_rms << " N), improvement " << d.improvement
            << ", " << r.runtime_s << " s wall, " << cpu_s << " s CPU\n  " << d.explanation << "\n";
  for (const Candidate& c : d.candidates) {
    std::cout << "    " << c.effect << ": force rms " << c.force_rms << ", bic " << c.bic;
    for (const auto& [name, value] : c.parameters) std::cout << ", " << name << " " << value;
    std::cout << "\n";
  }
  EXPECT_EQ(d.baseline.model, "fem");
  EXPECT_EQ(d.verdict, "missing_physics");
  ASSERT_EQ(d.effect, "stiffening");
  EXPECT_LT(d.augmented.force_rms, 0.25 * d.baseline.force_rms);
  EXPECT_GT(d.improvement, 0.75);
  EXPECT_TRUE(std::isnan(d.baseline.rms));  // force-only: no free node is observed
  // The material stiffens: k clearly above its null, and the modulus of the stiffening law below
  // the linear fit's, which the high-strain end pulls up.
  EXPECT_GT(d.augmented.parameters.at("stiffening"), 1.0);
  EXPECT_LT(d.augmented.parameters.at("youngs_modulus"), d.baseline.parameters.at("youngs_modulus"));
  EXPECT_GT(r.evidence.signatures.at("force_load_sign_change"), 0.0);
  EXPECT_EQ(r.evidence.signatures.at("quasi_static"), 1.0);
}

INSTANTIATE_TEST_SUITE_P(Phantoms, FemDiagnosePhantom, ::testing::Values("EF10_0T_B5", "EF30_0T_A5", "EF50_0T_A4"));

// Issue 17 item 5: the same curve imported with bonded platens (bottom face fixed, top face moved
// in z only, so the cylinder barrels and the averaged nodal pressure carries nu = 0.48) is still
// named stiffening, and the stiffening fit at least halves the force misfit. A coarse cylinder
// (205 nodes) keeps the run within a CPU minute; the 582-node import gives the same verdict
// (improvement 0.83-0.88 on the three silicones, docs/fem.md).
TEST(FemDiagnosePhantomBonded, FullCurveWithBondedPlatensIsNamedStiffeningAndTheForceFitHalves) {
  const CompressionTest test = read_compression_csv(kDir + "/source/EF30_0T_A5.csv");
  CompressionRecordingOptions options;
  options.platen_contact = PlatenContact::bonded;
  options.poisson_ratio = 0.48;
  options.mesh = CylinderMeshDivisions{1, 16, 4};
  const Recording recording = compression_test_recording(test, options);
  const DiagnoseResult r = diagnose_fem(recording);
  const Diagnosis& d = r.diagnosis;
  std::cout << "[ bonded   ] EF30_0T_A5: " << d.verdict << " (" << d.effect << "), force rms " << d.baseline.force_rms
            << " -> " << d.augmented.force_rms << " N, improvement " << d.improvement << ", " << r.runtime_s
            << " s wall\n  " << d.explanation << "\n";
  EXPECT_EQ(d.verdict, "missing_physics");
  ASSERT_EQ(d.effect, "stiffening");
  EXPECT_LE(d.augmented.force_rms, 0.5 * d.baseline.force_rms);
  EXPECT_GT(d.improvement, 0.5);
}

#endif  // PLIANT_FEM_DIAGNOSE_ACCEPTANCE

}  // namespace
}  // namespace pliant::host

// Compression test -> recording: round trip through write_recording / read_recording, platen
// boundary conditions, wrench sign, frame selection and option checks.
#include <algorithm>
#include <cmath>
#include <limits>
#include <set>
#include <stdexcept>
#include <string>
#include <vector>

#include "pliant/host/fem/compression_test.hpp"
#include "pliant/host/fem/cylinder_mesh.hpp"
#include "recording_test_support.hpp"

namespace pliant::host::test {
namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kModulus_pa = 60e3;
constexpr int kPerLevel = 97;  // section nodes of the default mesh (2, 24, 5)
constexpr int kPoints = 582;

// A linear-elastic specimen pressed at 10 mm/min for `duration_s`, sampled every 0.1 s.
CompressionTest synthetic_test(double duration_s = 60.0) {
  CompressionTest t;
  t.label = "lab/synthetic.csv";
  t.sample_name = "synthetic_1";
  t.diameter_m = 0.05;
  t.height_m = 0.03;
  t.speed_m_per_s = 10e-3 / 60.0;
  t.machine = "INSTRON 5900";
  t.load_cell = "1kN";
  for (int i = 0; i * 0.1 <= duration_s + 1e-9; ++i) {
    const double time = 0.1 * i;
    const double compression = *t.speed_m_per_s * time;
    t.time_s.push_back(time);
    t.compression_m.push_back(compression);
    t.load_n.push_back(kModulus_pa * compression / t.height_m * t.cross_section_m2());
  }
  return t;
}

double compression_at(const CompressionTest& t, double time) { return *t.speed_m_per_s * time; }

std::vector<int> range(int first, int count) {
  std::vector<int> ids(static_cast<std::size_t>(count));
  for (int k = 0; k < count; ++k) ids[static_cast<std::size_t>(k)] = first + k;
  return ids;
}

std::set<int> driven_ids(const Recording& r) {
  std::set<int> ids;
  for (const DrivenWindow& w : r.driven) {
    EXPECT_TRUE(std::isinf(w.from_s) && w.from_s < 0.0);
    EXPECT_TRUE(std::isinf(w.to_s) && w.to_s > 0.0);
    ids.insert(w.id);
  }
  return ids;
}

Recording round_trip(const Recording& r) {
  TempDir dir;
  write_recording(r, dir.str() + "/rec");
  return read_recording(dir.str() + "/rec");
}

TEST(CompressionRecording, FrictionlessRoundTrip) {
  const CompressionTest test = synthetic_test();
  const Recording made = compression_test_recording(test, CompressionRecordingOptions{});
  const Recording r = round_trip(made);

  EXPECT_EQ(r.dimension, 3);
  EXPECT_EQ(r.length_unit, "m");
  EXPECT_FALSE(r.gravity.has_value());
  ASSERT_EQ(r.particle_count, kPoints);
  ASSERT_TRUE(r.mesh.has_value());
  EXPECT_EQ(r.mesh->tet_count(), 2520);
  ASSERT_EQ(r.frame_count(), 61);
  for (int f = 0; f < r.frame_count(); ++f) EXPECT_DOUBLE_EQ(r.frame_times_s[static_cast<std::size_t>(f)], f);

  const std::vector<int> bottom = range(0, kPerLevel);
  const std::vector<int> top = range(kPoints - kPerLevel, kPerLevel);
  EXPECT_TRUE(r.fixed.empty());
  std::set<int> platens(bottom.begin(), bottom.end());
  platens.insert(top.begin(), top.end());
  EXPECT_EQ(driven_ids(r), platens);
  EXPECT_EQ(r.wrench_applied_to, top);

  EXPECT_DOUBLE_EQ(r.material.at("poisson_ratio"), 0.49);
  EXPECT_DOUBLE_EQ(r.material.at("density"), 1070.0);
  EXPECT_EQ(r.meta.at("platen_contact"), "frictionless");
  EXPECT_EQ(r.meta.at("lateral_expansion"), "small_strain");
  EXPECT_NE(r.meta.at("lateral_positions").get<std::string>().find("modelled, not measured"), std::string::npos);
  EXPECT_EQ(r.meta.at("sample"), "synthetic_1");
  EXPECT_EQ(r.meta.at("source_file"), "synthetic.csv");
  EXPECT_DOUBLE_EQ(r.meta.at("speed_mm_per_min").get<double>(), 10.0);
  EXPECT_EQ(r.meta.at("mesh").at("tetrahedra"), 2520);

  // Lumped masses add up to density x mesh volume.
  double volume = 0.0;
  for (int t = 0; t < r.mesh->tet_count(); ++t) volume += tet_signed_volume(*r.mesh, t);
  double mass = 0.0;
  for (const double m : r.masses) mass += m;
  EXPECT_NEAR(mass, 1070.0 * volume, 1e-12);
  EXPECT_NEAR(r.meta.at("mesh").at("volume_ratio").get<double>(), volume / (kPi * 0.025 * 0.025 * 0.03), 1e-12);

  // Only the platen faces are observed, in every frame; the rest comes from mesh.vtk.
  for (int f = 0; f < r.frame_count(); ++f) {
    for (int id = 0; id < r.particle_count; ++id) {
      EXPECT_EQ(r.observed(f, id), platens.count(id) == 1) << "frame " << f << " id " << id;
    }
  }
  // The wrench: the force of the top platen on the specimen, -z in compression, no torque.
  ASSERT_EQ(r.wrench.size(), 61u);
  for (std::size_t f = 0; f < r.wrench.size(); ++f) {
    const WrenchSample& w = r.wrench[f];
    EXPECT_DOUBLE_EQ(w.t_s, r.frame_times_s[f]);
    const double load = kModulus_pa * compression_at(test, w.t_s) / test.height_m * test.cross_section_m2();
    EXPECT_NEAR(w.force_n[2], -load, 1e-9);
    if (f > 0) {
      EXPECT_LT(w.force_n[2], 0.0);
    }
    EXPECT_EQ(w.force_n[0], 0.0);
    EXPECT_EQ(w.force_n[1], 0.0);
    for (const double torque : w.torque_nm) EXPECT_EQ(torque, 0.0);
  }
  // The writer is exact: what was made is what is read.
  EXPECT_EQ(r.frame_times_s, made.frame_times_s);
  for (std::size_t i = 0; i < r.positions.size(); ++i) {
    if (!std::isnan(made.positions[i])) {
      ASSERT_EQ(r.positions[i], made.positions[i]) << "value " << i;
    }
  }
}

// x and y of the platen nodes scaled about the axis by `lateral`; z from the compression.
void expect_platens(const Recording& r, const CompressionTest& test, double poisson_ratio, LateralExpansion expansion,
                    bool frictionless) {
  for (int f = 0; f < r.frame_count(); ++f) {
    const double compression = compression_at(test, r.frame_times_s[static_cast<std::size_t>(f)]);
    const double strain = compression / test.height_m;
    double lateral = 1.0;
    if (frictionless) {
      lateral = expansion == LateralExpansion::small_strain ? 1.0 + poisson_ratio * strain
                                                            : std::pow(1.0 - strain, -poisson_ratio);
      EXPECT_DOUBLE_EQ(frictionless_lateral_stretch(strain, poisson_ratio, expansion), lateral);
    }
    for (int k = 0; k < kPerLevel; ++k) {
      for (const int id : {k, kPoints - kPerLevel + k}) {
        const auto at = 3 * static_cast<std::size_t>(id);
        const bool is_top = id >= kPerLevel;
        EXPECT_NEAR(r.position(f, id, 0), r.mesh->points[at] * lateral, 1e-15);
        EXPECT_NEAR(r.position(f, id, 1), r.mesh->points[at + 1] * lateral, 1e-15);
        EXPECT_NEAR(r.position(f, id, 2), is_top ? test.height_m - compression : 0.0, 1e-15);
      }
    }
  }
}

TEST(CompressionRecording, FrictionlessLateralExpansionFollowsTheFormula) {
  const CompressionTest test = synthetic_test();
  CompressionRecordingOptions options;
  options.poisson_ratio = 0.45;
  const Recording small = compression_test_recording(test, options);
  expect_platens(small, test, 0.45, LateralExpansion::small_strain, true);

  options.lateral_expansion = LateralExpansion::finite_strain;
  const Recording finite = round_trip(compression_test_recording(test, options));
  expect_platens(finite, test, 0.45, LateralExpansion::finite_strain, true);
  EXPECT_EQ(finite.meta.at("lateral_expansion"), "finite_strain");

  // The axis nodes stay on the axis.
  const int axis = 3 * 7 + 3;
  for (int f = 0; f < finite.frame_count(); ++f) {
    EXPECT_EQ(finite.position(f, axis, 0), 0.0);
    EXPECT_EQ(finite.position(f, kPoints - kPerLevel + axis, 1), 0.0);
  }
  // The finite-strain stretch keeps volume at nu = 0.5; the small-strain one is first-order exact.
  for (const double e : {0.01, 0.1, 0.3, 0.66}) {
    const double l = frictionless_lateral_stretch(e, 0.5, LateralExpansion::finite_strain);
    EXPECT_NEAR(l * l * (1.0 - e), 1.0, 1e-14);
    EXPECT_DOUBLE_EQ(frictionless_lateral_stretch(e, 0.3, LateralExpansion::small_strain), 1.0 + 0.3 * e);
  }
}

TEST(CompressionRecording, BondedPlatensKeepRestXYAndFixTheBottom) {
  const CompressionTest test = synthetic_test();
  CompressionRecordingOptions options;
  options.platen_contact = PlatenContact::bonded;
  const Recording r = round_trip(compression_test_recording(test, options));
  EXPECT_EQ(r.fixed, range(0, kPerLevel));
  const std::vector<int> top = range(kPoints - kPerLevel, kPerLevel);
  EXPECT_EQ(driven_ids(r), std::set<int>(top.begin(), top.end()));
  EXPECT_EQ(r.wrench_applied_to, top);
  EXPECT_EQ(r.meta.at("platen_contact"), "bonded");
  EXPECT_FALSE(r.meta.contains("lateral_expansion"));
  expect_platens(r, test, 0.49, LateralExpansion::small_strain, false);
}

TEST(CompressionRecording, MaxStrainKeepsFramesUpToTheFirstPastIt) {
  const CompressionTest test = synthetic_test(120.0);
  for (const double max_strain : {0.095, 0.1, 0.2}) {
    CompressionRecordingOptions options;
    options.max_strain = max_strain;
    const Recording r = compression_test_recording(test, options);
    const auto strain = [&](int f) { return (test.height_m - r.position(f, kPoints - 1, 2)) / test.height_m; };
    ASSERT_GE(r.frame_count(), 2);
    const int last = r.frame_count() - 1;
    EXPECT_GT(strain(last), max_strain);
    for (int f = 0; f < last; ++f) EXPECT_LE(strain(f), max_strain) << "frame " << f;
    EXPECT_LT(r.frame_times_s.back(), 120.0);
    EXPECT_DOUBLE_EQ(r.meta.at("max_strain").get<double>(), max_strain);
    EXPECT_EQ(r.wrench.size(), static_cast<std::size_t>(r.frame_count()));
  }
  CompressionRecordingOptions options;
  options.max_strain = 0.095;  // strain 0.095 at t = 17.1 s: frames 0..18 s
  EXPECT_EQ(compression_test_recording(test, options).frame_count(), 19);
}

TEST(CompressionRecording, FrameCountSpreadsFramesOverTheKeptTest) {
  const CompressionTest test = synthetic_test(60.0);
  CompressionRecordingOptions options;
  options.frame_count = 13;
  const Recording r = compression_test_recording(test, options);
  ASSERT_EQ(r.frame_count(), 13);
  for (int f = 0; f < 13; ++f) EXPECT_NEAR(r.frame_times_s[static_cast<std::size_t>(f)], 5.0 * f, 1e-12);
  EXPECT_EQ(r.meta.at("frames").at("count"), 13);

  options.max_strain = 0.0952;
  const Recording cut = compression_test_recording(test, options);
  ASSERT_EQ(cut.frame_count(), 13);
  EXPECT_NEAR(cut.frame_times_s.back(), 17.2, 1e-9);  // the first sample past strain 0.0952
}

TEST(CompressionRecording, FramesBetweenSamplesAreInterpolated) {
  CompressionTest test = synthetic_test(10.0);
  // Irregular sampling: keep every third row.
  CompressionTest sparse = test;
  sparse.time_s.clear();
  sparse.compression_m.clear();
  sparse.load_n.clear();
  for (std::size_t i = 0; i < test.time_s.size(); i += 3) {
    sparse.time_s.push_back(test.time_s[i] + (i % 2 == 0 ? 0.0 : 0.05));
    sparse.compression_m.push_back(compression_at(test, sparse.time_s.back()));
    sparse.load_n.push_back(2.0 * sparse.time_s.back());
  }
  CompressionRecordingOptions options;
  options.frame_interval_s = 0.25;
  const Recording r = compression_test_recording(sparse, options);
  for (int f = 0; f < r.frame_count(); ++f) {
    const double t = r.frame_times_s[static_cast<std::size_t>(f)];
    EXPECT_NEAR(r.position(f, kPoints - 1, 2), test.height_m - compression_at(test, t), 1e-15);
    EXPECT_NEAR(r.wrench[static_cast<std::size_t>(f)].force_n[2], -2.0 * t, 1e-12);
  }
}

TEST(CompressionRecording, RefusesBadOptionsAndTestsThatDoNotCompress) {
  const CompressionTest test = synthetic_test(10.0);
  const auto with = [&](auto change) {
    CompressionRecordingOptions options;
    change(options);
    return options;
  };
  using O = CompressionRecordingOptions;
  EXPECT_THROW(compression_test_recording(test, with([](O& o) { o.poisson_ratio = 0.5; })), std::invalid_argument);
  EXPECT_THROW(compression_test_recording(test, with([](O& o) { o.poisson_ratio = -0.1; })), std::invalid_argument);
  EXPECT_THROW(compression_test_recording(test, with([](O& o) { o.density_kg_m3 = 0.0; })), std::invalid_argument);
  EXPECT_THROW(compression_test_recording(test, with([](O& o) { o.frame_interval_s = 0.0; })), std::invalid_argument);
  EXPECT_THROW(compression_test_recording(test, with([](O& o) { o.frame_interval_s = 50.0; })), std::invalid_argument);
  EXPECT_THROW(compression_test_recording(test, with([](O& o) { o.frame_count = 1; })), std::invalid_argument);
  // A million frames of 582 nodes would exceed what a reader stores.
  EXPECT_THROW(compression_test_recording(test, with([](O& o) { o.frame_count = kMaxCompressionFrames; })),
               std::invalid_argument);
  EXPECT_THROW(compression_test_recording(test, with([](O& o) { o.max_strain = 0.0; })), std::invalid_argument);
  EXPECT_THROW(compression_test_recording(test, with([](O& o) { o.max_strain = std::nan(""); })),
               std::invalid_argument);
  EXPECT_THROW(compression_test_recording(test, with([](O& o) { o.mesh.circumferential = 12; })),
               std::invalid_argument);
  // Past max_strain already in the first frame: a single frame is no recording.
  CompressionTest preloaded = test;
  for (double& c : preloaded.compression_m) c += 0.001;
  EXPECT_THROW(compression_test_recording(preloaded, with([](O& o) { o.max_strain = 0.01; })), std::invalid_argument);

  CompressionTest stretched = test;
  for (double& c : stretched.compression_m) c = -c;
  expect_message(error_of([&] { compression_test_recording(stretched, CompressionRecordingOptions{}); }),
                 "lab/synthetic.csv: ", "never compressed");
}

}  // namespace
}  // namespace pliant::host::test

// The phantom compression data shipped in examples/phantom_compression: the modulus of the data
// itself against the lab's own Neo-Hookean fits, and the shipped recordings against their source
// CSVs and the current converter.
#include <cmath>
#include <fstream>
#include <iostream>
#include <sstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "pliant/host/fem/compression_test.hpp"
#include "recording_test_support.hpp"

namespace pliant::host::test {
namespace {

const std::string kDir = PLIANT_PHANTOM_COMPRESSION_DIR;

// One specimen per material: the one whose 2-10 % linear modulus is closest to the mean of the
// material's ten specimens (source/README.md).
struct Specimen {
  const char* material;
  const char* name;
  double density_kg_m3;  // as tools/make_phantom_examples.sh gives it
};
constexpr Specimen kSpecimens[] = {
    {"EF10_0T", "EF10_0T_B5", 1040.0}, {"EF30_0T", "EF30_0T_A5", 1070.0}, {"EF50_0T", "EF50_0T_A4", 1070.0}};

nlohmann::json reference_parameters() {
  std::ifstream in(kDir + "/source/hyperelastic_parameters.json");
  std::stringstream text;
  text << in.rdbuf();
  return nlohmann::json::parse(text.str());
}

// 3 x the Neo-Hookean shear modulus of `material` (Pa): its small-strain Young's modulus at
// incompressibility.
double reference_youngs_modulus_pa(const nlohmann::json& parameters, const std::string& material) {
  const nlohmann::json& fit = parameters.at("engineering").at(material).at("Neo Hookean");
  EXPECT_EQ(fit.at("stress_unit"), "kPa");
  return 3.0 * fit.at("parameters").at(0).get<double>() * 1e3;
}

TEST(PhantomCompressionData, LinearModulusWithinTenPercentOfThreeTimesTheNeoHookeanShearModulus) {
  const nlohmann::json parameters = reference_parameters();
  const double expected_reference_kpa[] = {65.9, 110.0, 170.0};  // PROVENANCE.md
  int k = 0;
  for (const Specimen& s : kSpecimens) {
    const CompressionTest test = read_compression_csv(kDir + "/source/" + s.name + ".csv");
    const LinearModulusFit fit = fit_linear_modulus(test, 0.02, 0.10);
    const double reference = reference_youngs_modulus_pa(parameters, s.material);
    std::cout << "[ modulus  ] " << s.name << ": 2-10 % linear fit " << fit.youngs_modulus_pa * 1e-3 << " kPa over "
              << fit.rows << " rows, 3 x Neo-Hookean mu " << reference * 1e-3 << " kPa, ratio "
              << fit.youngs_modulus_pa / reference << "\n";
    EXPECT_NEAR(reference * 1e-3, expected_reference_kpa[k++], 0.1);
    EXPECT_NEAR(fit.youngs_modulus_pa / reference, 1.0, 0.10) << s.name;
    EXPECT_GT(fit.rows, 100u);
  }
}

TEST(PhantomCompressionData, SourceFilesParseWithTheirGeometry) {
  for (const Specimen& s : kSpecimens) {
    const CompressionTest test = read_compression_csv(kDir + "/source/" + s.name + ".csv");
    EXPECT_DOUBLE_EQ(test.diameter_m, 0.05);
    EXPECT_DOUBLE_EQ(test.height_m, 0.03);
    ASSERT_TRUE(test.speed_m_per_s.has_value());
    EXPECT_EQ(test.machine, "INSTRON 5900");
    EXPECT_GT(test.row_count(), 1000u);
    EXPECT_EQ(test.engineering_stress_pa.size(), test.row_count());
    // The file's own engineering stress (negative in compression, kPa) is load / area.
    for (std::size_t i = 0; i < test.row_count(); i += 50) {
      EXPECT_NEAR(-test.engineering_stress_pa[i], test.load_n[i] / test.cross_section_m2(), 1e-3) << i;
    }
    // Tested to about two thirds of the height.
    EXPECT_NEAR(test.compression_m.back() / test.height_m, 2.0 / 3.0, 0.01);
  }
}

// Least-squares slope of -fz / area against (height - z_top) / height over frames in the window.
double recording_modulus_pa(const Recording& r, double height_m, double area_m2) {
  const int top_node = r.particle_count - 1;
  double n = 0, se = 0, ss = 0, see = 0, ses = 0;
  for (int f = 0; f < r.frame_count(); ++f) {
    const double e = (height_m - r.position(f, top_node, 2)) / height_m;
    if (e < 0.02 || e > 0.10) continue;
    const double s = -r.wrench[static_cast<std::size_t>(f)].force_n[2] / area_m2;
    n += 1;
    se += e;
    ss += s;
    see += e * e;
    ses += e * s;
  }
  return (n * ses - se * ss) / (n * see - se * se);
}

TEST(PhantomCompressionData, ShippedRecordingsAreWhatTheConverterMakesFromTheSource) {
  for (const Specimen& s : kSpecimens) {
    SCOPED_TRACE(s.name);
    const CompressionTest test = read_compression_csv(kDir + "/source/" + s.name + ".csv");
    const Recording shipped = read_recording(kDir + "/" + s.name);
    CompressionRecordingOptions options;  // tools/make_phantom_examples.sh: the defaults but density
    options.density_kg_m3 = s.density_kg_m3;
    const Recording made = compression_test_recording(test, options);

    EXPECT_EQ(shipped.particle_count, 582);
    ASSERT_TRUE(shipped.mesh.has_value());
    EXPECT_EQ(shipped.mesh->tet_count(), 2520);
    EXPECT_EQ(shipped.frame_count(), 121);  // every second of the 120 s test
    EXPECT_EQ(shipped.meta.at("sample"), test.sample_name);
    EXPECT_EQ(shipped.meta.at("platen_contact"), "frictionless");
    EXPECT_EQ(shipped.meta.at("source_file"), std::string(s.name) + ".csv");
    EXPECT_TRUE(shipped.meta.contains("source"));
    EXPECT_EQ(shipped.meta.at("license"), "CC BY 4.0");
    EXPECT_DOUBLE_EQ(shipped.material.at("poisson_ratio"), 0.49);
    EXPECT_DOUBLE_EQ(shipped.material.at("density"), s.density_kg_m3);

    // Bit for bit what the converter makes now (the writer and reader are exact).
    EXPECT_EQ(shipped.frame_times_s, made.frame_times_s);
    EXPECT_EQ(shipped.masses, made.masses);
    EXPECT_EQ(shipped.fixed, made.fixed);
    EXPECT_EQ(shipped.wrench_applied_to, made.wrench_applied_to);
    EXPECT_EQ(shipped.mesh->points, made.mesh->points);
    EXPECT_EQ(shipped.mesh->tetrahedra, made.mesh->tetrahedra);
    ASSERT_EQ(shipped.positions.size(), made.positions.size());
    std::size_t differing = 0;
    for (std::size_t i = 0; i < made.positions.size(); ++i) {
      const double a = shipped.positions[i];
      const double b = made.positions[i];
      if (!(a == b || (std::isnan(a) && std::isnan(b)))) ++differing;
    }
    EXPECT_EQ(differing, 0u);
    ASSERT_EQ(shipped.wrench.size(), made.wrench.size());
    for (std::size_t f = 0; f < made.wrench.size(); ++f) {
      EXPECT_EQ(shipped.wrench[f].force_n[2], made.wrench[f].force_n[2]);
    }

    // What an estimator sees at 1 frame/s gives the modulus of the full-rate data within 3 %.
    const double from_recording = recording_modulus_pa(shipped, test.height_m, test.cross_section_m2());
    const double from_csv = fit_linear_modulus(test, 0.02, 0.10).youngs_modulus_pa;
    EXPECT_NEAR(from_recording / from_csv, 1.0, 0.03);
  }
}

}  // namespace
}  // namespace pliant::host::test

// Young's modulus of three real silicone phantoms (Ecoflex 00-10 / 00-30 / 00-50 cylinders,
// 50 mm x 30 mm, Instron compression; examples/phantom_compression) with the displacement-driven
// estimator: the recording's platens drive the top and bottom faces (frictionless: the lateral
// positions follow homogeneous uniaxial stress), the measured load is fitted up to 10 % nominal
// strain. Reference: 3 x the lab's Neo-Hookean shear modulus (small-strain E at
// incompressibility), read from the JSON copied into the repository.
//
// What limits the agreement: the corotational model is linear in the strain, while the measured
// curves are not. They start softer than their straight middle part (seating of the platens), so a
// line through the origin misses the modulus of the linear part: EF10 comes out 14 % low that way.
// Toe compensation (a fitted force offset, ReactionEstimateOptions::fit_force_offset) is the
// standard remedy and is what is held to 10 % here; both are printed. The mesh's polygonal cross
// section has 98.9 % of the disc's area (recording meta mesh.volume_ratio), which biases E by
// +1.2 %. Boundary conditions are not the limit: with frictionless platens the homogeneous state is
// the model's exact solution.
#include <cmath>
#include <cstdio>
#include <fstream>
#include <sstream>
#include <string>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "pliant/host/fem/estimate_static.hpp"
#include "pliant/host/recording.hpp"

namespace {

using namespace pliant::host::fem;

const std::string kDir = PLIANT_PHANTOM_COMPRESSION_DIR;

struct Specimen {
  const char* material;  // key in hyperelastic_parameters.json
  const char* recording;
};
constexpr Specimen kSpecimens[] = {{"EF10_0T", "EF10_0T_B5"}, {"EF30_0T", "EF30_0T_A5"}, {"EF50_0T", "EF50_0T_A4"}};

double reference_youngs_modulus_pa(const std::string& material) {
  std::ifstream in(kDir + "/source/hyperelastic_parameters.json");
  std::stringstream text;
  text << in.rdbuf();
  const nlohmann::json fit = nlohmann::json::parse(text.str()).at("engineering").at(material).at("Neo Hookean");
  EXPECT_EQ(fit.at("stress_unit"), "kPa");
  return 3.0 * fit.at("parameters").at(0).get<double>() * 1e3;
}

TEST(PhantomFit, YoungsModulusUpToTenPercentStrainWithinTenPercentOfThreeTimesNeoHookeanMu) {
  std::printf("[ phantom ] %-11s %-13s %16s %10s %8s %10s %6s %6s\n", "sample", "fit", "E_kPa +- sd", "ref_kPa",
              "error_%", "offset_N", "frames", "cpu_s");
  for (const Specimen& s : kSpecimens) {
    SCOPED_TRACE(s.recording);
    const FemRecordingProblem problem =
        fem_problem_from_recording(pliant::host::read_recording(kDir + "/" + s.recording));
    const double reference = reference_youngs_modulus_pa(s.material);
    for (bool offset : {false, true}) {
      ReactionEstimateOptions o;
      o.max_nominal_strain = 0.10;
      o.initial_youngs_modulus_pa = 1e5;
      o.fit_force_offset = offset;
      const YoungsModulusEstimate e = estimate_youngs_modulus_from_reaction(problem, o);
      const double error = (e.youngs_modulus_pa - reference) / reference;
      std::printf("[ phantom ] %-11s %-13s %8.1f +- %4.1f %10.1f %+8.1f %10.2f %6d %6.2f\n", s.recording,
                  offset ? "toe-comp." : "through 0", e.youngs_modulus_pa * 1e-3, e.standard_deviation_pa * 1e-3,
                  reference * 1e-3, 100 * error, e.force_offset_n.z(), e.frames_used, e.cpu_s);
      EXPECT_TRUE(e.converged) << e.message;
      EXPECT_EQ(e.frames_used, 19);  // 0 .. 18 s at 10 mm/min: up to 9.99 % of 30 mm
      EXPECT_GT(e.standard_deviation_pa, 0);
      if (offset) {
        EXPECT_LT(std::abs(error), 0.10) << e.message;
        EXPECT_GT(e.force_offset_n.z(), 0);  // the toe: the (negative) fz starts late
      }
    }
  }
}

}  // namespace

// `pliant import compression`: what it writes, what it refuses, and how it says so.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <fstream>
#include <string>

#include <nlohmann/json.hpp>

#include "../cli/cli_test_support.hpp"
#include "pliant/host/recording.hpp"

namespace pliant::cli_test {
namespace {

const std::string kSource = std::string(PLIANT_PHANTOM_COMPRESSION_DIR) + "/source/";
const std::string kEf10 = kSource + "EF10_0T_B5.csv";
const std::string kEf30 = kSource + "EF30_0T_A5.csv";

bool contains(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }

// One line on stderr, "pliant import compression: " or "pliant import: " first, naming `part`.
void expect_one_error_line(const CommandResult& r, const std::string& part) {
  EXPECT_EQ(r.status, 2) << r.err;
  ASSERT_EQ(r.err_lines().size(), 1u) << r.err;
  EXPECT_EQ(r.err.rfind("pliant import", 0), 0u) << r.err;
  EXPECT_TRUE(contains(r.err, part)) << r.err;
}

TEST(cli_import, OneCsvBecomesTheOutputDirectory) {
  TempDir dir;
  const std::string out = dir / "ef10";
  const CommandResult r =
      run_pliant("import compression " + quoted(kEf10) + " -o " + quoted(out) + " --max-strain 0.1 --frames 12");
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(r.err, "");
  ASSERT_EQ(lines_of(r.out).size(), 1u) << r.out;
  EXPECT_TRUE(contains(r.out, "wrote " + out)) << r.out;
  EXPECT_TRUE(contains(r.out, "EF10_0T_B_sample_5")) << r.out;
  EXPECT_TRUE(contains(r.out, "frictionless")) << r.out;
  const host::Recording rec = host::read_recording(out);
  EXPECT_EQ(rec.name, "ef10");
  EXPECT_EQ(rec.frame_count(), 12);
  EXPECT_EQ(rec.particle_count, 582);
  EXPECT_GT((0.03 - rec.position(11, rec.particle_count - 1, 2)) / 0.03, 0.1);
  EXPECT_DOUBLE_EQ(rec.meta.at("max_strain").get<double>(), 0.1);
}

TEST(cli_import, SeveralCsvsGoToSubdirectoriesNamedAfterTheFiles) {
  TempDir dir;
  const CommandResult r =
      run_pliant("import compression " + quoted(kEf10) + " " + quoted(kEf30) + " -o " + quoted(dir.path().string()) +
                 " --contact bonded --poisson-ratio 0.45 --density 1040 --mesh-divisions 1,8,2 "
                 "--frame-interval 10 --source 'lab X' --license 'CC BY 4.0'");
  ASSERT_EQ(r.status, 0) << r.err;
  ASSERT_EQ(lines_of(r.out).size(), 2u) << r.out;
  for (const char* name : {"EF10_0T_B5", "EF30_0T_A5"}) {
    const host::Recording rec = host::read_recording(dir / name);
    EXPECT_EQ(rec.name, name);
    EXPECT_EQ(rec.frame_count(), 13);  // 0, 10, ..., 120 s
    EXPECT_EQ(rec.mesh->tet_count(), 6 * (4 + 8) * 2);
    EXPECT_FALSE(rec.fixed.empty());
    EXPECT_EQ(rec.meta.at("platen_contact"), "bonded");
    EXPECT_EQ(rec.meta.at("source"), "lab X");
    EXPECT_EQ(rec.meta.at("license"), "CC BY 4.0");
    EXPECT_DOUBLE_EQ(rec.material.at("poisson_ratio"), 0.45);
    EXPECT_DOUBLE_EQ(rec.material.at("density"), 1040.0);
  }
}

TEST(cli_import, MalformedCsvExitsTwoNamingFileAndLineAndWritesNothing) {
  TempDir dir;
  std::string text = read_text(kEf10);
  text.replace(text.find("0.100000,"), 9, "0.1oo000,");  // line 10
  const std::string bad = dir / "bad.csv";
  write_text(bad, text);
  const std::string out = dir / "out";
  const CommandResult r = run_pliant("import compression " + quoted(bad) + " -o " + quoted(out));
  expect_one_error_line(r, bad + ":10: Time: expected a number, found '0.1oo000'");
  EXPECT_FALSE(fs::exists(out));

  // With several files, one bad file stops the run before anything is written.
  const CommandResult several =
      run_pliant("import compression " + quoted(kEf10) + " " + quoted(bad) + " -o " + quoted(out));
  expect_one_error_line(several, bad + ":10: ");
  EXPECT_FALSE(fs::exists(fs::path(out) / "EF10_0T_B5"));

  const CommandResult missing = run_pliant("import compression " + quoted(dir / "none.csv") + " -o " + quoted(out));
  expect_one_error_line(missing, "none.csv: no such file");
}

TEST(cli_import, BadOptionsExitTwoWithOneLine) {
  TempDir dir;
  const std::string base = "import compression " + quoted(kEf10) + " -o " + quoted(dir / "out") + " ";
  expect_one_error_line(run_pliant(base + "--contact sticky"), "--contact must be frictionless or bonded");
  expect_one_error_line(run_pliant(base + "--expansion huge"), "--expansion must be small-strain or finite-strain");
  expect_one_error_line(run_pliant(base + "--poisson-ratio 0.5"), "--poisson-ratio must be in [0, 0.5)");
  expect_one_error_line(run_pliant(base + "--density -3"), "--density must be in (0, 1e5]");
  expect_one_error_line(run_pliant(base + "--max-strain 1.5"), "--max-strain must be in (0, 1)");
  expect_one_error_line(run_pliant(base + "--frames 1"), "--frames must be between 2 and");
  expect_one_error_line(run_pliant(base + "--frame-interval 0"), "--frame-interval must be > 0");
  expect_one_error_line(run_pliant(base + "--frame-interval 500"), "only one frame");
  expect_one_error_line(run_pliant(base + "--mesh-divisions 2,24"), "--mesh-divisions must be three integers");
  expect_one_error_line(run_pliant(base + "--mesh-divisions 2,12,5"), "multiple of 8");
  expect_one_error_line(run_pliant(base + "--frames 10 --frame-interval 2"), "excludes");
  expect_one_error_line(run_pliant("import"), "subcommand");
  expect_one_error_line(run_pliant("import compression -o " + quoted(dir / "out")), "CSV");
  EXPECT_FALSE(fs::exists(dir / "out"));
}

TEST(cli_import, SameFileNameTwiceIsRefused) {
  TempDir dir;
  fs::create_directories(dir / "a");
  fs::create_directories(dir / "b");
  fs::copy_file(kEf10, dir / "a/x.csv");
  fs::copy_file(kEf10, dir / "b/x.csv");
  const CommandResult r = run_pliant("import compression " + quoted(dir / "a/x.csv") + " " + quoted(dir / "b/x.csv") +
                                     " -o " + quoted(dir / "out"));
  expect_one_error_line(r, "two CSV files are named 'x'");
}

TEST(cli_import, RefusesNonEmptyDirectoryWithoutForce) {
  TempDir dir;
  write_text(dir / "notes.txt", "keep me\n");
  const std::string args =
      "import compression " + quoted(kEf10) + " --max-strain 0.05 -o " + quoted(dir.path().string());
  const CommandResult refused = run_pliant(args);
  expect_one_error_line(refused, "--force");
  EXPECT_FALSE(fs::exists(dir / "recording.json"));
  const CommandResult forced = run_pliant(args + " --force");
  ASSERT_EQ(forced.status, 0) << forced.err;
  EXPECT_TRUE(fs::exists(dir / "recording.json"));
  EXPECT_EQ(read_text(dir / "notes.txt"), "keep me\n");
}

TEST(cli_import, HelpDescribesTheBoundaryConditions) {
  const CommandResult r = run_pliant("import compression --help");
  EXPECT_EQ(r.status, 0);
  EXPECT_TRUE(contains(r.out, "frictionless")) << r.out;
  EXPECT_TRUE(contains(r.out, "bonded")) << r.out;
  EXPECT_TRUE(contains(r.out, "--mesh-divisions")) << r.out;
  const CommandResult top = run_pliant("--help");
  EXPECT_TRUE(contains(top.out, "import")) << top.out;
}

// Real silicone through bonded platens, as a user would import it: at nu 0.48 a bonded cylinder
// reads stiffer than the homogeneous (frictionless) solution by the factor a converged FEM gives
// (CalculiX C3D10, tests/host/data/calculix_locking_references.json: 1.351). So the modulus
// `refine` fits through the bonded import, on a 582-node mesh, must be the frictionless fit
// divided by that factor. The linear tetrahedron used to lock here and read 21-22 % low; with
// the averaged nodal pressure it reads 6 % low (docs/fem.md), and the rest is the coarse mesh.
double calculix_bonded_factor(double nu) {
  std::ifstream file(std::string(PLIANT_TEST_DATA_DIR) + "/calculix_locking_references.json");
  const nlohmann::json doc = nlohmann::json::parse(file);
  for (const auto& item : doc.at("cases")) {
    if (item.at("problem") == "bonded_cylinder" && std::abs(item.at("poisson_ratio").get<double>() - nu) < 1e-9) {
      return item.at("apparent_modulus_factor").get<double>();
    }
  }
  return std::nan("");
}

// Imports EF30 with `contact` at nu 0.48 (once per directory and contact) and refines it with
// `volumetric` ("auto" for the default); the card must name the formulation that ran.
double refined_modulus_pa(const TempDir& dir, const std::string& contact, const std::string& volumetric = "auto") {
  const std::string out = dir / contact;
  if (!std::ifstream(out + "/recording.json")) {
    const CommandResult imported =
        run_pliant("import compression " + quoted(kEf30) + " -o " + quoted(out) + " --contact " + contact +
                   " --poisson-ratio 0.48 --density 1040 --mesh-divisions 2,24,5 --frame-interval 10");
    EXPECT_EQ(imported.status, 0) << imported.err;
  }
  const std::string card = dir / (contact + "_" + volumetric + ".json");
  const CommandResult refined = run_pliant("refine " + quoted(out) + " --estimate youngs_modulus -q --volumetric " +
                                           volumetric + " --json " + quoted(card));
  EXPECT_EQ(refined.status, 0) << refined.err;
  std::ifstream file(card);
  const nlohmann::json json = nlohmann::json::parse(file);
  EXPECT_EQ(json.at("volumetric"), volumetric == "element" ? "element" : "nodal_average");
  return json.at("parameters").at("youngs_modulus").get<double>();
}

TEST(cli_import, BondedPlatensReadTheModulusAConvergedFemImplies) {
  TempDir dir;
  const double factor = calculix_bonded_factor(0.48);
  ASSERT_TRUE(std::isfinite(factor)) << "no CalculiX reference at nu 0.48";
  const double frictionless = refined_modulus_pa(dir, "frictionless");
  const double bonded = refined_modulus_pa(dir, "bonded");
  const double expected = frictionless / factor;
  std::printf("EF30 nu 0.48: frictionless %.1f kPa, bonded %.1f kPa, expected %.1f kPa (%+.1f %%)\n",
              frictionless / 1e3, bonded / 1e3, expected / 1e3, 100 * (bonded / expected - 1));
  EXPECT_NEAR(bonded / expected, 1.0, 0.08);
  // Forced back to the plain element, the same fit locks and reads far too low.
  const double locked = refined_modulus_pa(dir, "bonded", "element");
  std::printf("EF30 nu 0.48, --volumetric element: bonded %.1f kPa (%+.1f %%)\n", locked / 1e3,
              100 * (locked / expected - 1));
  EXPECT_LT(locked / expected, 0.85);
  const CommandResult bad = run_pliant("refine " + quoted(dir / "bonded") + " --volumetric quadratic");
  EXPECT_EQ(bad.status, 2);
  EXPECT_TRUE(contains(bad.err, "--volumetric must be auto, element or nodal_average")) << bad.err;
}

}  // namespace
}  // namespace pliant::cli_test

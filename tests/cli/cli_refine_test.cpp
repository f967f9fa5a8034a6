// `pliant refine` end to end: the material card (docs/spec/outputs-v1.md) from each estimator on
// data with a known answer: a real silicone compression test (reaction estimator, against the
// lab's hyperelastic fit), a simulated vibrating bar (trajectory estimator, Rayleigh damping and a
// material map, against the generator's truth), and a sagging cantilever (rest shape, against the
// shape it was sagged from). Plus the VTK series and a mesh given with --mesh.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <set>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "cli_refine_recordings.hpp"
#include "cli_test_support.hpp"

namespace pliant::cli_test {
namespace {

const std::string kPhantoms = PLIANT_PHANTOM_COMPRESSION_DIR;

bool contains(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }

nlohmann::json read_json(const fs::path& path) { return nlohmann::json::parse(read_text(path)); }

double relative_error(double value, double truth) { return std::abs(value - truth) / std::abs(truth); }

int count_files(const fs::path& directory, const std::string& extension) {
  int count = 0;
  for (const auto& entry : fs::directory_iterator(directory)) count += entry.path().extension() == extension ? 1 : 0;
  return count;
}

// The keys and types of outputs-v1.md, the given parameters copied unchanged, nothing undocumented.
void expect_card_follows_spec(const nlohmann::json& card, const nlohmann::json& recording_json) {
  EXPECT_EQ(card.at("format"), "pliant-material");
  EXPECT_EQ(card.at("version"), 1);
  EXPECT_EQ(card.at("model"), "fem");
  EXPECT_TRUE(card.at("recording").is_string());
  ASSERT_TRUE(card.at("parameters").is_object());
  for (const auto& [name, value] : card.at("parameters").items()) EXPECT_TRUE(value.is_number()) << name;
  if (recording_json.contains("material")) {
    for (const auto& [name, value] : recording_json.at("material").items()) {
      EXPECT_EQ(card.at("parameters").at(name), value) << name << " must be copied unchanged";
      EXPECT_FALSE(card.at("uncertainty").contains(name)) << name << " is given, not estimated";
    }
  }
  ASSERT_TRUE(card.at("uncertainty").is_object());
  for (const auto& [name, value] : card.at("uncertainty").items()) {
    EXPECT_TRUE(card.at("parameters").contains(name)) << name;
    EXPECT_TRUE(value.is_number() || value.is_null()) << name;
  }
  EXPECT_TRUE(card.at("rms").is_number());
  EXPECT_GE(card.at("rms").get<double>(), 0.0);
  EXPECT_GT(card.at("runtime_s").get<double>(), 0.0);
  if (card.contains("material_map")) {
    const nlohmann::json& map = card.at("material_map");
    ASSERT_EQ(map.at("control_points").size(), map.at("youngs_modulus").size());
    for (const auto& point : map.at("control_points")) EXPECT_EQ(point.size(), 3u);
  }
  if (card.contains("rest_shape")) {
    EXPECT_TRUE(card.at("rest_shape").is_string());
  }
  const std::set<std::string> allowed = {"format",      "version",      "recording",  "model",      "parameters",
                                         "uncertainty", "material_map", "rest_shape", "rms",        "runtime_s",
                                         "estimator",   "assumed",      "volumetric", "diagnostics"};
  for (const auto& [key, value] : card.items()) EXPECT_EQ(allowed.count(key), 1u) << "undocumented key " << key;
  ASSERT_TRUE(card.contains("volumetric"));
  EXPECT_TRUE(card.at("volumetric") == "element" || card.at("volumetric") == "nodal_average") << card.at("volumetric");
}

double phantom_reference_pa(const std::string& material) {
  const nlohmann::json fit =
      read_json(kPhantoms + "/source/hyperelastic_parameters.json").at("engineering").at(material).at("Neo Hookean");
  return 3.0 * fit.at("parameters").at(0).get<double>() * 1e3;  // kPa -> Pa, E = 3 mu
}

// EF10 is the phantom with the longest toe (a line through the origin is 14 % low there).
TEST(cli_refine, PhantomCompressionFitsTheReactionWithinTenPercentOfTheLab) {
  TempDir dir;
  const std::string recording = kPhantoms + "/EF10_0T_B5";
  const std::string card_path = dir / "card.json";
  const std::string vtk = dir / "vtk";
  const CommandResult r =
      run_pliant("refine " + quoted(recording) + " --json " + quoted(card_path) + " --vtk " + quoted(vtk));
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(r.err, "");  // stderr is not a terminal: no progress line, and nothing to warn about
  EXPECT_TRUE(contains(r.out, "reaction")) << r.out;
  const nlohmann::json card = read_json(card_path);
  expect_card_follows_spec(card, read_json(recording + "/recording.json"));
  EXPECT_EQ(card.at("recording"), "EF10_0T_B5");
  EXPECT_EQ(card.at("estimator"), "reaction");
  const double reference = phantom_reference_pa("EF10_0T");
  const double youngs = card.at("parameters").at("youngs_modulus").get<double>();
  std::printf("[ refine ] EF10_0T_B5: youngs_modulus %.1f kPa (lab 3 mu %.1f kPa, %+.1f %%)\n", youngs * 1e-3,
              reference * 1e-3, 100 * (youngs - reference) / reference);
  EXPECT_LT(relative_error(youngs, reference), 0.10) << youngs << " Pa against " << reference << " Pa";
  EXPECT_GT(card.at("uncertainty").at("youngs_modulus").get<double>(), 0.0);
  EXPECT_EQ(card.at("uncertainty").size(), 1u);
  // Defaults of the host test (fem_phantom_fit_test): 10 % strain, toe offset fitted.
  const nlohmann::json& d = card.at("diagnostics");
  EXPECT_EQ(d.at("frames_used"), 19);
  EXPECT_EQ(d.at("max_strain"), 0.1);
  EXPECT_GT(d.at("force_offset").at(2).get<double>(), 0.0);
  EXPECT_TRUE(d.at("converged").get<bool>());
  EXPECT_GT(d.at("force_rms").get<double>(), 0.0);
  // Only the driven platens are observed: the model reproduces them exactly.
  EXPECT_EQ(card.at("rms"), 0.0);
  EXPECT_EQ(d.at("free_rms_pairs"), 0);
  EXPECT_FALSE(card.contains("material_map"));
  EXPECT_FALSE(card.contains("rest_shape"));
  EXPECT_TRUE(fs::exists(fs::path(vtk) / "refine.pvd"));
  EXPECT_EQ(count_files(vtk, ".vtu"), 19);
  const std::string frame = read_text(fs::path(vtk) / "refine_000018.vtu");
  for (const char* array : {"displacement", "observed_position", "residual", "youngs_modulus"}) {
    EXPECT_TRUE(contains(frame, std::string("Name=\"") + array + "\"")) << array;
  }
}

TEST(cli_refine, PhantomWithoutToeOffsetIsLowerAndStrainLimitCanBeLifted) {
  const std::string recording = kPhantoms + "/EF10_0T_B5";
  const CommandResult through_zero = run_pliant("refine " + quoted(recording) + " --no-force-offset --json -");
  ASSERT_EQ(through_zero.status, 0) << through_zero.err;
  const nlohmann::json card = nlohmann::json::parse(through_zero.out);
  EXPECT_FALSE(card.at("diagnostics").contains("force_offset"));
  EXPECT_LT(card.at("parameters").at("youngs_modulus").get<double>(), 0.9 * phantom_reference_pa("EF10_0T"));
  const CommandResult all = run_pliant("refine " + quoted(recording) + " --max-strain 1 --until 30 --json -");
  ASSERT_EQ(all.status, 0) << all.err;
  const nlohmann::json whole = nlohmann::json::parse(all.out);
  EXPECT_EQ(whole.at("diagnostics").at("frames_used"), 31);  // t = 0 .. 30 s
  EXPECT_TRUE(whole.at("diagnostics").at("max_strain").is_null());
}

TEST(cli_refine, ProbeIndentationWithAMeasuredForceUsesTheForceEstimator) {
  TempDir dir;
  const host::fem::StepeScenario block = make_coarse_stepe();
  const fs::path recording = dir.path() / "block";
  host::write_recording(block.recording, recording.string());
  const CommandResult r = run_pliant("refine " + quoted(recording.string()) + " -q --json -");
  ASSERT_EQ(r.status, 0) << r.err;
  const nlohmann::json card = nlohmann::json::parse(r.out);
  expect_card_follows_spec(card, read_json(recording / "recording.json"));
  EXPECT_EQ(card.at("estimator"), "force");
  const double youngs = card.at("parameters").at("youngs_modulus").get<double>();
  const double sd = card.at("uncertainty").at("youngs_modulus").get<double>();
  std::printf("[ refine ] coarse STEPE block: youngs_modulus %.1f +- %.1f kPa (truth 454 kPa), rms %.3g m, %.2f s\n",
              youngs * 1e-3, sd * 1e-3, card.at("rms").get<double>(), card.at("runtime_s").get<double>());
  EXPECT_LT(relative_error(youngs, 454e3), 0.10);
  EXPECT_GT(sd, 0.0);
  EXPECT_LT(std::abs(youngs - 454e3), 4 * sd);
  // Tracked top face, 0.1 mm noise per coordinate: about 0.17 mm in 3D.
  EXPECT_LT(card.at("diagnostics").at("free_rms").get<double>(), 0.3e-3);
  EXPECT_GT(card.at("diagnostics").at("free_rms_pairs").get<long>(), 0);
}

TEST(cli_refine, VibratingBarFitsModulusAndDampingWithTheTrajectoryEstimator) {
  TempDir dir;
  const host::fem::BarVibrationScenario bar = make_coarse_bar();
  const fs::path recording = dir.path() / "bar";
  host::write_recording(bar.recording, recording.string());
  const std::string card_path = dir / "card.json";
  const std::string vtk = dir / "vtk";
  const CommandResult r =
      run_pliant("refine " + quoted(recording.string()) + " -q --json " + quoted(card_path) + " --vtk " + quoted(vtk));
  ASSERT_EQ(r.status, 0) << r.err;
  // The summary names the estimator and why, and every parameter with its source.
  const std::vector<std::string> expected = {
      "trajectory: no wrench", "rayleigh_alpha", "rayleigh_beta", "poisson_ratio", "(given)",
      "wrote " + card_path,    "refine.pvd"};
  for (const std::string& text : expected) EXPECT_TRUE(contains(r.out, text)) << text << " in\n" << r.out;
  const nlohmann::json card = read_json(card_path);
  expect_card_follows_spec(card, read_json(recording / "recording.json"));
  EXPECT_EQ(card.at("estimator"), "trajectory");
  const nlohmann::json& p = card.at("parameters");
  const nlohmann::json& u = card.at("uncertainty");
  std::printf("[ refine ] bar: %s, rms %.3g m, runtime %.2f s\n", p.dump().c_str(), card.at("rms").get<double>(),
              card.at("runtime_s").get<double>());
  EXPECT_LT(relative_error(p.at("youngs_modulus").get<double>(), 6.8e5), 0.03) << p;
  EXPECT_LT(relative_error(p.at("rayleigh_alpha").get<double>(), 2e-2), 0.25) << p;
  EXPECT_LT(relative_error(p.at("rayleigh_beta").get<double>(), 1e-3), 0.25) << p;
  for (const char* name : {"youngs_modulus", "rayleigh_alpha", "rayleigh_beta"}) {
    EXPECT_TRUE(u.contains(name)) << name;
  }
  EXPECT_GT(u.at("youngs_modulus").get<double>(), 0.0);
  // The fitted motion: the tip swings by 8 cm; the model follows it to well under a millimetre.
  EXPECT_LT(card.at("rms").get<double>(), 1e-3);
  EXPECT_GT(card.at("diagnostics").at("free_rms_pairs").get<long>(), 0);
  EXPECT_EQ(count_files(vtk, ".vtu"), 120);
}

TEST(cli_refine, TwoPointMaterialMapFromAControlPointFile) {
  TempDir dir;
  const host::fem::BarVibrationScenario bar = make_coarse_bar({3e5, 1.2e6});
  host::Recording recording = bar.recording;
  recording.material["rayleigh_alpha"] = bar.rayleigh_alpha;  // damping known: the map alone is fitted
  recording.material["rayleigh_beta"] = bar.rayleigh_beta;
  const fs::path rec = dir.path() / "bar";
  host::write_recording(recording, rec.string());
  const fs::path points = dir.path() / "points.txt";
  write_text(points, "# along the axis, as the generator placed them\n0.2,0,0\n\n0.6 0 0\n");
  const CommandResult r =
      run_pliant("refine " + quoted(rec.string()) + " -q --estimate material_map --control-points " +
                 quoted(points.string()) + " --json -");
  ASSERT_EQ(r.status, 0) << r.err;
  const nlohmann::json card = nlohmann::json::parse(r.out);
  expect_card_follows_spec(card, read_json(rec / "recording.json"));
  const nlohmann::json& map = card.at("material_map");
  std::printf("[ refine ] two-point bar: map %s, runtime %.2f s\n", map.at("youngs_modulus").dump().c_str(),
              card.at("runtime_s").get<double>());
  ASSERT_EQ(map.at("youngs_modulus").size(), 2u);
  EXPECT_LT(relative_error(map.at("youngs_modulus").at(0).get<double>(), 3e5), 0.10) << map;
  EXPECT_LT(relative_error(map.at("youngs_modulus").at(1).get<double>(), 1.2e6), 0.10) << map;
  EXPECT_EQ(map.at("control_points").at(1).at(0), 0.6);
  EXPECT_GT(map.at("kernel_width").get<double>(), 0.0);
  EXPECT_EQ(map.at("uncertainty").size(), 2u);
  // The card's single modulus is the map's volume-weighted geometric mean: between the two.
  const double mean = card.at("parameters").at("youngs_modulus").get<double>();
  EXPECT_GT(mean, 3e5);
  EXPECT_LT(mean, 1.2e6);
  EXPECT_TRUE(card.at("uncertainty").contains("youngs_modulus"));
  EXPECT_FALSE(card.at("uncertainty").contains("rayleigh_alpha"));
}

// The default --control-points auto: the card says which counts were tried and which was kept.
TEST(cli_refine, MaterialMapCountChosenByTheDataIsReportedInTheCard) {
  TempDir dir;
  const host::fem::BarVibrationScenario bar = make_coarse_bar({3e5, 1.2e6});
  host::Recording recording = bar.recording;
  recording.material["rayleigh_alpha"] = bar.rayleigh_alpha;
  recording.material["rayleigh_beta"] = bar.rayleigh_beta;
  const fs::path rec = dir.path() / "bar";
  host::write_recording(recording, rec.string());
  const CommandResult r = run_pliant("refine " + quoted(rec.string()) + " -q --estimate material_map --json -");
  ASSERT_EQ(r.status, 0) << r.err;
  const nlohmann::json card = nlohmann::json::parse(r.out);
  expect_card_follows_spec(card, read_json(rec / "recording.json"));
  const nlohmann::json& selection = card.at("diagnostics").at("material_map_selection");
  std::printf("[ refine ] auto control points: %s\n", selection.dump().c_str());
  const nlohmann::json& tried = selection.at("tried");
  ASSERT_GE(tried.size(), 2u);
  EXPECT_EQ(tried.at(0).at("control_points"), 1);
  EXPECT_EQ(tried.at(1).at("control_points"), 2);
  const int chosen = selection.at("chosen_control_points").get<int>();
  EXPECT_GE(chosen, 2) << "the bar is two materials";
  EXPECT_EQ(card.at("material_map").at("youngs_modulus").size(), static_cast<std::size_t>(chosen));
  EXPECT_TRUE(selection.at("undetermined").is_array());
}

TEST(cli_refine, RestShapeOfASaggingCantileverIsWrittenBesideTheCard) {
  TempDir dir;
  const SagCase sag = make_sag_case();
  const fs::path recording = dir.path() / "sag";
  host::write_recording(sag.recording, recording.string());
  const fs::path out = dir.path() / "out";
  fs::create_directories(out);
  const std::string card_path = (out / "card.json").string();
  const CommandResult r = run_pliant("refine " + quoted(recording.string()) + " -q --estimate rest_shape --json " +
                                     quoted(card_path) + " --vtk " + quoted((out / "vtk").string()));
  ASSERT_EQ(r.status, 0) << r.err;
  const nlohmann::json card = read_json(card_path);
  expect_card_follows_spec(card, read_json(recording / "recording.json"));
  EXPECT_EQ(card.at("rest_shape"), "rest_shape.vtk");
  EXPECT_FALSE(card.contains("estimator"));
  EXPECT_TRUE(card.at("uncertainty").empty());
  EXPECT_TRUE(card.at("diagnostics").at("rest_shape").at("converged").get<bool>());
  // The simulation from the estimated rest shape sags back onto what was seen.
  EXPECT_LT(card.at("rms").get<double>(), 1e-6 * kSagLength);
  const host::TetMesh rest = host::parse_vtk_tet_mesh(read_text(out / "rest_shape.vtk"), "rest_shape.vtk");
  ASSERT_EQ(rest.points.size(), static_cast<std::size_t>(sag.true_rest_m.size()));
  double worst = 0;
  for (std::size_t i = 0; i < rest.points.size(); ++i) {
    worst = std::max(worst, std::abs(rest.points[i] - sag.true_rest_m(static_cast<Eigen::Index>(i))));
  }
  EXPECT_LT(worst, 1e-6 * kSagLength);
  EXPECT_EQ(count_files(out / "vtk", ".vtu"), 1);
}

TEST(cli_refine, MeshFileStandsInForAMissingRecordingMesh) {
  TempDir dir;
  SagCase sag = make_sag_case();
  const host::TetMesh mesh = *sag.recording.mesh;
  sag.recording.mesh.reset();  // frame 0, which observes every particle, is the rest shape
  sag.recording.files.erase("mesh");
  const fs::path recording = dir.path() / "sag";
  host::write_recording(sag.recording, recording.string());
  const fs::path msh = dir.path() / "seen.msh";
  write_msh_file(mesh, msh);
  const std::string rest_mesh = dir / "rest.vtk";
  const CommandResult r = run_pliant("refine " + quoted(recording.string()) + " -q --estimate rest_shape --mesh " +
                                     quoted(msh.string()) + " --rest-mesh " + quoted(rest_mesh) + " --json -");
  ASSERT_EQ(r.status, 0) << r.err;
  const nlohmann::json card = nlohmann::json::parse(r.out);
  EXPECT_EQ(card.at("rest_shape"), rest_mesh);  // no card file: the path as written
  EXPECT_TRUE(fs::exists(rest_mesh));
  EXPECT_LT(card.at("rms").get<double>(), 1e-6 * kSagLength);
}

TEST(cli_refine, HelpNamesTheEstimatorsUnitsAndDefaults) {
  const CommandResult r = run_pliant("refine --help");
  ASSERT_EQ(r.status, 0) << r.err;
  for (const char* text :
       {"--estimate", "--mesh", "--json", "--vtk", "--max-strain E=0.1", "--control-points auto|N|FILE=auto",
        "reaction", "force", "trajectory", "rest_shape", "Units: m, s, Pa, N"}) {
    EXPECT_TRUE(contains(r.out, text)) << text;
  }
  EXPECT_TRUE(contains(run_pliant("--help").out, "refine"));
}

}  // namespace
}  // namespace pliant::cli_test

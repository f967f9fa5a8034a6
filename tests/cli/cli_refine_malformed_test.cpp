// `pliant refine` refusals: every bad input or impossible request exits 2 with exactly one line
// on stderr saying why, writes nothing, and never crashes.
#include <gtest/gtest.h>

#include <string>

#include "cli_refine_recordings.hpp"
#include "cli_test_support.hpp"

namespace pliant::cli_test {
namespace {

const std::string kPhantom = std::string(PLIANT_PHANTOM_COMPRESSION_DIR) + "/EF30_0T_A5";

bool contains(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }

// Exit 2, one line under the command's prefix containing `reason`, nothing on stdout.
void expect_refused(const CommandResult& r, const std::string& reason) {
  EXPECT_EQ(r.status, 2) << r.err;
  ASSERT_EQ(r.err_lines().size(), 1u) << r.err;
  EXPECT_EQ(r.err.rfind("pliant refine: ", 0), 0u) << r.err;
  EXPECT_TRUE(contains(r.err, reason)) << "expected '" << reason << "' in: " << r.err;
  EXPECT_EQ(r.out, "");
}

fs::path write_sag(const TempDir& dir, SagCase sag, bool with_mesh) {
  if (!with_mesh) {
    sag.recording.mesh.reset();
    sag.recording.files.erase("mesh");
  }
  const fs::path recording = dir.path() / "sag";
  host::write_recording(sag.recording, recording.string());
  return recording;
}

TEST(cli_refine_malformed, MissingRecording) {
  TempDir dir;
  expect_refused(run_pliant("refine " + quoted(dir / "nothing_here")), "nothing_here");
}

TEST(cli_refine_malformed, RecordingWithoutMeshAndNoMeshOption) {
  TempDir dir;
  const fs::path recording = write_sag(dir, make_sag_case(), false);
  expect_refused(run_pliant("refine " + quoted(recording.string()) + " --estimate rest_shape"), "--mesh");
}

TEST(cli_refine_malformed, UnknownEstimateName) {
  expect_refused(run_pliant("refine " + quoted(kPhantom) + " --estimate youngs_modulus,stiffness"),
                 "unknown name 'stiffness'");
  expect_refused(run_pliant("refine " + quoted(kPhantom) + " --estimate youngs_modulus,,rayleigh"), "empty name");
}

TEST(cli_refine_malformed, BadMeshFiles) {
  TempDir dir;
  const fs::path recording = write_sag(dir, make_sag_case(), false);
  expect_refused(run_pliant("refine " + quoted(recording.string()) + " --mesh " + quoted(dir / "absent.msh")),
                 "absent.msh");
  const fs::path garbage = dir.path() / "garbage.msh";
  write_text(garbage, "$MeshFormat\n4.1 0 8\n$EndMeshFormat\n$Nodes\nnot numbers\n");
  expect_refused(run_pliant("refine " + quoted(recording.string()) + " --mesh " + quoted(garbage.string())),
                 "garbage.msh");
  const fs::path unknown = dir.path() / "mesh.xyz";
  write_text(unknown, "0 0 0\n");
  expect_refused(run_pliant("refine " + quoted(recording.string()) + " --mesh " + quoted(unknown.string())),
                 "mesh.xyz");
}

TEST(cli_refine_malformed, MeshWithFewerPointsThanParticles) {
  TempDir dir;
  const SagCase sag = make_sag_case();
  const fs::path recording = write_sag(dir, sag, false);
  const host::TetMesh small =
      host::fem::make_box_tet_mesh(Eigen::Vector3d(0.1, 0.03, 0.03), {1, 1, 1}, host::fem::BoxSplit::mirrored_kuhn);
  const fs::path msh = dir.path() / "small.msh";
  write_msh_file(small, msh);
  expect_refused(run_pliant("refine " + quoted(recording.string()) + " --mesh " + quoted(msh.string())),
                 "8 points but the recording has");
}

// A mesh with more points than particles: the extra one is an unobserved node, which the rest
// shape (every point observed) cannot work with.
TEST(cli_refine_malformed, RestShapeNeedsEveryMeshPointObserved) {
  TempDir dir;
  SagCase sag = make_sag_case();
  const host::TetMesh full = *sag.recording.mesh;
  host::Recording& r = sag.recording;
  const int last = r.particle_count - 1;  // an x = L corner, never fixed
  r.particle_count = last;
  r.masses.resize(static_cast<std::size_t>(last));
  r.positions.resize(3 * static_cast<std::size_t>(last));
  const fs::path recording = write_sag(dir, sag, false);
  const fs::path msh = dir.path() / "full.msh";
  write_msh_file(full, msh);
  const CommandResult res =
      run_pliant("refine " + quoted(recording.string()) + " --estimate rest_shape --mesh " + quoted(msh.string()));
  EXPECT_EQ(res.status, 2);
  // The extension is reported as a warning, then the refusal.
  ASSERT_EQ(res.err_lines().size(), 2u) << res.err;
  EXPECT_TRUE(contains(res.err_lines()[0], "unobserved")) << res.err;
  EXPECT_TRUE(contains(res.err_lines()[1], "observes " + std::to_string(last) + " of the mesh's")) << res.err;
}

TEST(cli_refine_malformed, UnwritableOutputsAreRefusedBeforeAnyWork) {
  TempDir dir;
  const std::string json = dir / "no_such_dir/card.json";
  expect_refused(run_pliant("refine " + quoted(kPhantom) + " --json " + quoted(json)), "no such directory");
  EXPECT_FALSE(fs::exists(json));
  expect_refused(run_pliant("refine " + quoted(kPhantom) + " --json " + quoted(dir.path().string())), "is a directory");
  const fs::path file = dir.path() / "plain_file";
  write_text(file, "x");
  expect_refused(run_pliant("refine " + quoted(kPhantom) + " --vtk " + quoted(file.string())), "not a directory");
}

TEST(cli_refine_malformed, ImpossibleCombinationsSayWhy) {
  expect_refused(run_pliant("refine " + quoted(kPhantom) + " --estimate youngs_modulus,rayleigh"),
                 "displacement-driven");
  expect_refused(run_pliant("refine " + quoted(kPhantom) + " --estimate rayleigh"), "youngs_modulus known");
  expect_refused(run_pliant("refine " + quoted(kPhantom) + " --estimator force"),
                 "wrench.applied_to holds fixed or driven");
  expect_refused(run_pliant("refine " + quoted(kPhantom) + " --estimator reaction --estimate material_map"),
                 "needs the trajectory estimator");
  expect_refused(run_pliant("refine " + quoted(kPhantom) + " --estimator trajectory"), "observed after frame 0");
  expect_refused(run_pliant("refine " + quoted(kPhantom) + " --estimate rest_shape"), "observes");
}

TEST(cli_refine_malformed, GivenParametersAreNotReestimated) {
  TempDir dir;
  const fs::path recording = write_sag(dir, make_sag_case(), true);
  expect_refused(run_pliant("refine " + quoted(recording.string()) + " --estimate youngs_modulus"),
                 "youngs_modulus is given in recording.json material");
  // A single frame and no wrench: only the trajectory estimator would apply, and it needs motion.
  expect_refused(run_pliant("refine " + quoted(recording.string())), "at least 3 frames");
  // A compression test that already gives youngs_modulus: nothing left for the static estimator.
  const fs::path phantom = dir.path() / "phantom";
  fs::copy(kPhantom, phantom);
  replace_in_file(phantom / "recording.json", "\"density\": 1070.0", "\"density\": 1070.0, \"youngs_modulus\": 1e5");
  expect_refused(run_pliant("refine " + quoted(phantom.string())), "nothing to estimate");
}

TEST(cli_refine_malformed, BadOptionValues) {
  TempDir dir;
  expect_refused(run_pliant("refine " + quoted(kPhantom) + " --max-strain 0"), "--max-strain");
  expect_refused(run_pliant("refine " + quoted(kPhantom) + " --estimator magic"), "--estimator");
  expect_refused(run_pliant("refine " + quoted(kPhantom) + " --control-points 0"), "--control-points");
  expect_refused(run_pliant("refine " + quoted(kPhantom) + " --initial-modulus -5"), "--initial-modulus");
  const fs::path points = dir.path() / "points.csv";
  write_text(points, "0.1,0,0\n0.2,zero,0\n");
  expect_refused(run_pliant("refine " + quoted(kPhantom) + " --control-points " + quoted(points.string())),
                 "points.csv:2:");
  expect_refused(run_pliant("refine " + quoted(kPhantom) + " --substeps 0"), "--substeps");
  expect_refused(run_pliant("refine"), "REC is required");
}

TEST(cli_refine_malformed, TwoDimensionalRecordingIsRefused) {
  TempDir dir;
  const fs::path recording = dir.path() / "rec";
  write_tiny_recording(recording);
  const fs::path msh = dir.path() / "m.msh";
  write_msh_file(host::fem::make_box_tet_mesh(Eigen::Vector3d(1, 1, 1), {1, 1, 1}), msh);
  expect_refused(run_pliant("refine " + quoted(recording.string()) + " --mesh " + quoted(msh.string())), "3D");
  expect_refused(run_pliant("refine " + quoted(recording.string())), "--mesh");
}

}  // namespace
}  // namespace pliant::cli_test

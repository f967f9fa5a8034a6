// Recording directories: file-level and cross-file errors, valid directories, and the writer's
// round trip.
#include <unistd.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <sstream>
#include <string>

#include "pliant/host/recording.hpp"
#include "recording_test_support.hpp"

namespace pliant::host::test {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

std::string read_error(const std::string& directory) {
  return error_of([&] { read_recording(directory); });
}

json minimal_json() { return json::parse(kMinimalJson2D); }

const std::string kMesh4 =
    "# vtk DataFile Version 3.0\nrest\nASCII\nDATASET UNSTRUCTURED_GRID\n"
    "POINTS 4 double\n0 0 0.5\n1 0 0.5\n0 1 0.5\n0 0 1.5\n"
    "CELLS 1 5\n4 0 1 2 3\nCELL_TYPES 1\n10\n";

// --- directory and file errors

TEST(ReadRecordingErrors, MissingDirectory) {
  TempDir dir;
  const std::string missing = (dir.path() / "nope").string();
  expect_message(read_error(missing), missing + ": ", "no such recording directory");
}

TEST(ReadRecordingErrors, PathIsAFile) {
  TempDir dir;
  const std::string file = dir.write("plain.txt", "x").string();
  expect_message(read_error(file), file + ": ", "not a directory");
}

TEST(ReadRecordingErrors, MissingRecordingJson) {
  TempDir dir;
  dir.write("particles.csv", kParticles2D);
  expect_message(read_error(dir.str()), "recording.json: ", "no such file");
}

TEST(ReadRecordingErrors, MissingParticlesFile) {
  TempDir dir;
  dir.write("recording.json", kMinimalJson2D);
  expect_message(read_error(dir.str()), "particles.csv: ", "no such file (named in recording.json files.particles)");
}

TEST(ReadRecordingErrors, MissingMediaFile) {
  TempDir dir;
  json doc = minimal_json();
  doc["files"]["video"] = "media/cam.mp4";
  dir.write("recording.json", doc.dump());
  dir.write("particles.csv", kParticles2D);
  expect_message(read_error(dir.str()), "media/cam.mp4: ", "no such file (named in recording.json files.video)");
}

TEST(ReadRecordingErrors, SymlinkLeavingTheDirectory) {
  TempDir outside;
  const fs::path target = outside.write("stolen.csv", kParticles2D);
  TempDir dir;
  json doc = minimal_json();
  doc["files"]["particles"] = "link.csv";
  dir.write("recording.json", doc.dump());
  fs::create_symlink(target, dir.path() / "link.csv");
  expect_message(read_error(dir.str()), "link.csv: ", "resolves outside the recording directory");
}

TEST(ReadRecordingErrors, ParticlesPathIsADirectory) {
  TempDir dir;
  json doc = minimal_json();
  doc["files"]["particles"] = "data";
  dir.write("recording.json", doc.dump());
  fs::create_directories(dir.path() / "data");
  expect_message(read_error(dir.str()), "data: ", "not a regular file");
}

TEST(ReadRecordingErrors, UnreadableFile) {
  if (::geteuid() == 0) GTEST_SKIP() << "root reads files whatever their permissions";
  TempDir dir;
  dir.write("recording.json", kMinimalJson2D);
  const fs::path particles = dir.write("particles.csv", kParticles2D);
  fs::permissions(particles, fs::perms::none);
  expect_message(read_error(dir.str()), "particles.csv: ", "cannot open");
}

TEST(ReadRecordingErrors, FileLargerThanTwoGibibytes) {
  TempDir dir;
  dir.write("recording.json", kMinimalJson2D);
  // A sparse file: resizing allocates no blocks, and the reader must refuse before reading.
  const fs::path particles = dir.write("particles.csv", kParticles2D);
  fs::resize_file(particles, (std::uintmax_t{2} << 30) + 1);
  expect_message(read_error(dir.str()), "particles.csv: ", "file too large (2147483649 bytes");
}

TEST(ReadRecordingErrors, ErrorsInsideFilesUseTheirRelativeNames) {
  TempDir dir;
  json doc = minimal_json();
  doc["files"]["particles"] = "data/p.csv";
  dir.write("recording.json", doc.dump());
  dir.write("data/p.csv", "t,id,x,y\n0,0,0,0\n0,7,0,0\n");
  expect_message(read_error(dir.str()), "data/p.csv:3: ", "id 7 out of range 0..3");
}

TEST(ReadRecordingErrors, JsonErrorsPropagate) {
  TempDir dir;
  json doc = minimal_json();
  doc["dimension"] = 1;
  dir.write("recording.json", doc.dump());
  dir.write("particles.csv", kParticles2D);
  expect_message(read_error(dir.str()), "recording.json: dimension: ", "must be 2 or 3");
}

TEST(ReadRecordingErrors, WrenchFileErrorsPropagate) {
  TempDir dir;
  json doc = minimal_json();
  doc["files"]["wrench"] = "wrench.csv";
  doc["wrench"] = {{"applied_to", {3}}};
  dir.write("recording.json", doc.dump());
  dir.write("particles.csv", kParticles2D);
  dir.write("wrench.csv", "t,fx,fy,fz,tx,ty,tz\n0,1,1,1,0,0,0\n0.1,1,1,1,0,0\n");
  expect_message(read_error(dir.str()), "wrench.csv:3: ", "expected 7 fields");
}

// --- cross-file checks

TEST(ReadRecordingErrors, HeaderOnlyParticles) {
  TempDir dir;
  dir.write("recording.json", kMinimalJson2D);
  dir.write("particles.csv", "t,id,x,y\n");
  expect_message(read_error(dir.str()), "particles.csv: ", "no frames");
}

TEST(ReadRecordingErrors, FirstFrameMissesAParticle) {
  TempDir dir;
  dir.write("recording.json", kMinimalJson2D);
  dir.write("particles.csv", "t,id,x,y\n0,0,0,0\n0,1,1,0\n0,3,1,1\n1,2,0,1\n");
  expect_message(read_error(dir.str()), "particles.csv: ", "the first frame (t=0) does not observe particle 2");
}

TEST(ReadRecordingErrors, FirstFrameHasNanParticle) {
  TempDir dir;
  dir.write("recording.json", kMinimalJson2D);
  dir.write("particles.csv", "t,id,x,y\n0,0,0,0\n0,1,nan,0\n0,2,0,1\n0,3,1,1\n");
  expect_message(read_error(dir.str()), "particles.csv: ", "does not observe particle 1");
}

TEST(ReadRecordingErrors, MeshPointCountDiffers) {
  TempDir dir;
  json doc = minimal_json();
  doc["particles"]["count"] = 3;
  doc["files"]["mesh"] = "mesh.vtk";
  dir.write("recording.json", doc.dump());
  dir.write("particles.csv", "t,id,x,y\n0,0,0,0\n");
  dir.write("mesh.vtk", kMesh4);
  expect_message(read_error(dir.str()), "mesh.vtk: ", "4 points but particles.count is 3");
}

TEST(FinalizeRecording, RejectsIdsOutOfRangeInCodeBuiltRecordings) {
  Recording r;
  r.particle_count = 2;
  r.masses = {1.0, 1.0};
  r.frame_times_s = {0.0};
  // clang-format off
  r.positions = {0, 0, 1, 1};
  r.fixed = {2};
  expect_message(error_of([&] { finalize_recording(r); }), "recording.json: particles.fixed: ",
                 "id 2 out of range 0..1");
}

// --- valid directories

TEST(ReadRecording, MinimalTwoDimensional) {
  TempDir dir;
  const fs::path recording_dir = dir.path() / "foam_press";
  fs::create_directories(recording_dir);
  std::ofstream(recording_dir / "recording.json") << kMinimalJson2D;
  std::ofstream(recording_dir / "particles.csv") << kParticles2D;
  const Recording r = read_recording(recording_dir.string() + "/");
  EXPECT_EQ(r.name, "foam_press");
  EXPECT_EQ(r.frame_count(), 2);
  EXPECT_EQ(r.rest_positions, (std::vector<double>{0, 0, 1, 0, 0, 1, 1, 1}));
  EXPECT_FALSE(r.mesh.has_value());
  EXPECT_TRUE(r.warnings.empty());
}

TEST(ReadRecording, RestShapeFromMeshAllowsIncompleteFirstFrame) {
  TempDir dir;
  json doc = minimal_json();
  doc["files"]["mesh"] = "mesh.vtk";
  dir.write("recording.json", doc.dump());
  dir.write("particles.csv", "t,id,x,y\n0,0,0,0\n0.1,1,1,0\n");
  dir.write("mesh.vtk", kMesh4);
  const Recording r = read_recording(dir.str());
  ASSERT_TRUE(r.mesh.has_value());
  EXPECT_EQ(r.mesh->tet_count(), 1);
  // 2D recording: the first two coordinates of each mesh point.
  EXPECT_EQ(r.rest_positions, (std::vector<double>{0, 0, 1, 0, 0, 1, 0, 0}));
  EXPECT_FALSE(r.observed(0, 1));
}

TEST(ReadRecording, UnknownKeyWarningAndMediaFile) {
  TempDir dir;
  json doc = minimal_json();
  doc["calibration"] = "intrinsics.yaml";
  doc["files"]["video"] = "media/cam.mp4";
  dir.write("recording.json", doc.dump());
  dir.write("particles.csv", kParticles2D);
  dir.write("media/cam.mp4", "not really a video");
  const Recording r = read_recording(dir.str());
  ASSERT_EQ(r.warnings.size(), 1u);
  EXPECT_NE(r.warnings[0].find("calibration"), std::string::npos);
  EXPECT_EQ(r.unknown_keys.at("calibration"), "intrinsics.yaml");
}

// --- writer

void expect_same_bits(const std::vector<double>& a, const std::vector<double>& b,
                      const char* what) {
  ASSERT_EQ(a.size(), b.size()) << what;
  for (std::size_t i = 0; i < a.size(); ++i) {
    EXPECT_EQ(std::memcmp(&a[i], &b[i], sizeof(double)), 0)
        << what << "[" << i << "]: " << a[i] << " vs " << b[i];
  }
}

Recording full_recording() {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  Recording r;
  r.dimension = 3;
  r.length_unit = "m";
  r.gravity = std::vector<double>{0.0, 0.0, -9.81};
  r.particle_count = 4;
  r.masses = {0.001, 0.002, 1.0 / 3.0, 5e-324};
  r.fixed = {0, 1};
  r.driven = {DrivenWindow{3, -inf, inf}, DrivenWindow{2, -inf, 0.5},
              DrivenWindow{2, 1.0, 2.0}, DrivenWindow{2, 2.5, inf}};
  r.files = {{"particles", "data/particles.csv"}, {"wrench", "wrench.csv"}};
  r.wrench_applied_to = {3};
  r.material = {{"poisson_ratio", 0.45}, {"density", 1000.0}};
  r.meta = json::parse(R"({"object": "foam 39/200", "runs": [1, 2, {"deep": null}]})");
  r.unknown_keys = json::parse(R"({"calibration": {"k": [1.5, 2.5]}})");
  r.frame_times_s = {0.0, 0.1, 0.30000000000000004, 1e-300 + 1.0};
  // clang-format off
  r.positions = {
      0.1, 0.2, 0.3,   1.0 / 3.0, -0.0, 2.0,   5e-324, 1e308, -1e-308, 4.0, 5.0, 6.0,  // frame 0
      nan, nan, nan,   1.0, nan, 2.0,          7.0, 8.0, 9.0,          nan, 1.0, nan,  // frame 1
      nan, nan, nan,   nan, nan, nan,          nan, nan, nan,          nan, nan, nan,  // frame 2
      1.1, 2.2, 3.3,   4.4, 5.5, 6.6,          7.7, 8.8, 9.9,          0.0, 0.0, 0.0};  // frame 3
  // clang-format on
  WrenchSample w;
  w.t_s = 0.05;
  w.force_n[0] = 1.25;
  w.force_n[2] = -3.0;
  w.torque_nm[1] = 1e-9;
  r.wrench = {w};
  w.t_s = 0.15;
  w.force_n[1] = 0.1 + 0.2;
  r.wrench.push_back(w);
  r.gripper = {GripperSample{0.0, 0.08, 0.0}, GripperSample{0.2, 0.071, 14.5}};
  TetMesh mesh;
  mesh.points = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0.1, 0.2, 1.0 / 7.0};
  mesh.tetrahedra = {0, 1, 2, 3};
  mesh.youngs_modulus = {4.2e4};
  r.mesh = mesh;
  return r;
}

TEST(WriteRecording, RoundTripIsBitExact) {
  TempDir dir;
  const Recording original = full_recording();
  write_recording(original, dir.str());
  const Recording back = read_recording(dir.str());

  EXPECT_EQ(back.dimension, original.dimension);
  EXPECT_EQ(back.length_unit, original.length_unit);
  ASSERT_TRUE(back.gravity.has_value());
  expect_same_bits(*back.gravity, *original.gravity, "gravity");
  EXPECT_EQ(back.particle_count, original.particle_count);
  expect_same_bits(back.masses, original.masses, "masses");
  EXPECT_EQ(back.fixed, original.fixed);
  ASSERT_EQ(back.driven.size(), original.driven.size());
  for (std::size_t i = 0; i < back.driven.size(); ++i) {
    EXPECT_EQ(back.driven[i].id, original.driven[i].id);
    EXPECT_EQ(back.driven[i].from_s, original.driven[i].from_s);
    EXPECT_EQ(back.driven[i].to_s, original.driven[i].to_s);
  }
  std::map<std::string, std::string> files = original.files;
  files["gripper"] = "gripper.csv";
  files["mesh"] = "mesh.vtk";
  EXPECT_EQ(back.files, files);
  EXPECT_EQ(back.wrench_applied_to, original.wrench_applied_to);
  EXPECT_EQ(back.material, original.material);
  EXPECT_EQ(back.meta, original.meta);
  EXPECT_EQ(back.unknown_keys, original.unknown_keys);
  expect_same_bits(back.frame_times_s, original.frame_times_s, "frame_times_s");
  expect_same_bits(back.positions, original.positions, "positions");
  ASSERT_EQ(back.wrench.size(), original.wrench.size());
  for (std::size_t i = 0; i < back.wrench.size(); ++i) {
    EXPECT_EQ(std::memcmp(&back.wrench[i], &original.wrench[i], sizeof(WrenchSample)), 0);
  }
  ASSERT_EQ(back.gripper.size(), original.gripper.size());
  for (std::size_t i = 0; i < back.gripper.size(); ++i) {
    EXPECT_EQ(std::memcmp(&back.gripper[i], &original.gripper[i], sizeof(GripperSample)), 0);
  }
  ASSERT_TRUE(back.mesh.has_value());
  expect_same_bits(back.mesh->points, original.mesh->points, "mesh.points");
  EXPECT_EQ(back.mesh->tetrahedra, original.mesh->tetrahedra);
  expect_same_bits(back.mesh->youngs_modulus, original.mesh->youngs_modulus, "youngs_modulus");
  expect_same_bits(back.rest_positions, original.mesh->points, "rest_positions");
  EXPECT_EQ(back.name, dir.path().filename().string());
}

std::string file_text(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

TEST(WriteRecording, RewriteIsByteIdenticalAndLeavesNoTemporaries) {
  TempDir first;
  TempDir second;
  write_recording(full_recording(), first.str());
  write_recording(read_recording(first.str()), second.str());
  // Writing over an existing recording replaces it.
  write_recording(read_recording(second.str()), second.str());
  for (const char* name : {"recording.json", "data/particles.csv", "wrench.csv", "gripper.csv", "mesh.vtk"}) {
    EXPECT_EQ(file_text(first.path() / name), file_text(second.path() / name)) << name;
  }
  for (const auto& entry : fs::recursive_directory_iterator(second.path())) {
    EXPECT_EQ(entry.path().filename().string().find("tmp"), std::string::npos) << entry.path();
  }
}

TEST(WriteRecording, RecordingJsonListsSpecKeysInOrder) {
  TempDir dir;
  write_recording(full_recording(), dir.str());
  const std::string text = file_text(dir.path() / "recording.json");
  std::size_t previous = 0;
  for (const char* key : {"\"format\"", "\"version\"", "\"dimension\"", "\"length_unit\"", "\"gravity\"",
                          "\"particles\"", "\"files\"", "\"wrench\"", "\"material\"", "\"meta\"", "\"calibration\""}) {
    const std::size_t at = text.find(key);
    ASSERT_NE(at, std::string::npos) << key;
    EXPECT_GT(at, previous) << key;
    previous = at;
  }
}

TEST(WriteRecording, RejectsPathsThatLeaveTheDirectory) {
  TempDir dir;
  Recording r = full_recording();
  r.files["particles"] = "../escape.csv";
  EXPECT_THROW(write_recording(r, dir.str()), std::runtime_error);
  EXPECT_FALSE(fs::exists(dir.path().parent_path() / "escape.csv"));
}

TEST(WriteRecording, RejectsTwoFilesUnderOneName) {
  TempDir dir;
  Recording r = full_recording();
  r.files["wrench"] = "data/./particles.csv";
  EXPECT_THROW(write_recording(r, dir.str()), std::runtime_error);
  EXPECT_FALSE(fs::exists(dir.path() / "recording.json"));
}

}  // namespace
}  // namespace pliant::host::test

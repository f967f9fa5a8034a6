// fem_problem_from_recording: constraints, driven windows, gaps in a driven node's track, wrench
// interpolation, known material, and the recordings it must refuse.
#include "pliant/host/fem/fem_recording.hpp"

#include <cmath>
#include <stdexcept>

#include <gtest/gtest.h>

namespace {

using pliant::host::Recording;
using pliant::host::TetMesh;
using pliant::host::WrenchSample;
using pliant::host::fem::fem_problem_from_recording;
using pliant::host::fem::keep_frames_until;

// One tetrahedron, nodes 0..3; node 3 pressed down 1 mm per frame over four frames at 10 Hz.
Recording single_tet_recording() {
  Recording r;
  r.name = "tet";
  r.dimension = 3;
  r.length_unit = "m";
  r.particle_count = 4;
  r.masses.assign(4, 1.0);
  r.fixed = {2, 0, 1};
  r.driven.push_back({3, 0.05, 1.0});
  r.wrench_applied_to = {3};
  r.material = {{"poisson_ratio", 0.3}, {"density", 1200.0}};
  r.gravity = std::vector<double>{0.0, 0.0, -9.81};
  TetMesh mesh;
  mesh.points = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1};
  mesh.tetrahedra = {0, 1, 2, 3};
  r.mesh = mesh;
  const double nan = std::nan("");
  for (int f = 0; f < 4; ++f) {
    r.frame_times_s.push_back(0.1 * f);
    for (int id = 0; id < 4; ++id) {
      for (int a = 0; a < 3; ++a) {
        double v = mesh.points[static_cast<size_t>(3 * id + a)];
        if (id == 3 && a == 2) v -= 0.001 * f;
        if (id == 3 && f == 2) v = nan;  // tracking gap in the driven node
        if (id == 1 && f >= 1) v = nan;  // node 1 lost after the first frame
        r.positions.push_back(v);
      }
    }
  }
  r.rest_positions = mesh.points;
  WrenchSample w0, w1;
  w0.t_s = 0.0;
  w1.t_s = 0.2;
  w1.force_n[2] = -2.0;
  r.wrench = {w0, w1};
  return r;
}

TEST(FemRecording, ReadsConstraintsMaterialAndFrames) {
  const auto problem = fem_problem_from_recording(single_tet_recording());
  EXPECT_EQ(problem.fixed_nodes, (std::vector<int>{0, 1, 2}));
  EXPECT_EQ(problem.applied_to, (std::vector<int>{3}));
  EXPECT_DOUBLE_EQ(problem.material.poisson_ratio, 0.3);
  EXPECT_DOUBLE_EQ(problem.material.density_kg_m3, 1200.0);
  EXPECT_TRUE(problem.gravity_declared);
  EXPECT_DOUBLE_EQ(problem.material.gravity_m_s2.z(), -9.81);
  EXPECT_TRUE(problem.is_known("density"));
  EXPECT_FALSE(problem.is_known("youngs_modulus"));
  ASSERT_EQ(problem.frames.size(), 4u);
  // Frame 0 is before the driven window opens.
  EXPECT_TRUE(problem.frames[0].driven_nodes.empty());
  EXPECT_EQ(problem.frames[1].driven_nodes, (std::vector<int>{3}));
  EXPECT_EQ(problem.frames[1].observed_nodes, (std::vector<int>{0, 2, 3}));
  EXPECT_TRUE(std::isnan(problem.frames[1].observed_position_m(3)));
}

TEST(FemRecording, DrivenGapIsInterpolatedInTime) {
  const auto problem = fem_problem_from_recording(single_tet_recording());
  // Frame 2 lost the driven node: halfway between 0.999 (frame 1) and 0.997 (frame 3).
  EXPECT_NEAR(problem.frames[2].driven_position_m(2), 0.998, 1e-12);
  EXPECT_NEAR(problem.frames[3].driven_position_m(2), 0.997, 1e-12);
}

TEST(FemRecording, WrenchIsInterpolatedAndAbsentOutsideItsSpan) {
  const auto problem = fem_problem_from_recording(single_tet_recording());
  ASSERT_TRUE(problem.frames[1].has_wrench);
  EXPECT_NEAR(problem.frames[1].wrench_force_n.z(), -1.0, 1e-12);
  EXPECT_NEAR(problem.frames[2].wrench_force_n.z(), -2.0, 1e-12);
  EXPECT_FALSE(problem.frames[3].has_wrench);  // t = 0.3 s, after the last sample
}

TEST(FemRecording, KeepFramesUntil) {
  auto problem = fem_problem_from_recording(single_tet_recording());
  keep_frames_until(problem, 0.15);
  EXPECT_EQ(problem.frames.size(), 2u);
  keep_frames_until(problem, -1.0);
  EXPECT_EQ(problem.frames.size(), 1u);  // never empty
}

TEST(FemRecording, RefusesWhatTheFemCannotUse) {
  Recording flat = single_tet_recording();
  flat.dimension = 2;
  EXPECT_THROW(fem_problem_from_recording(flat), std::invalid_argument);
  Recording pixels = single_tet_recording();
  pixels.length_unit = "px";
  EXPECT_THROW(fem_problem_from_recording(pixels), std::invalid_argument);
  Recording meshless = single_tet_recording();
  meshless.mesh.reset();
  EXPECT_THROW(fem_problem_from_recording(meshless), std::invalid_argument);
  Recording blind = single_tet_recording();
  for (int f = 0; f < 4; ++f) {
    for (int a = 0; a < 3; ++a) blind.positions[static_cast<size_t>((f * 4 + 3) * 3 + a)] = std::nan("");
  }
  EXPECT_THROW(fem_problem_from_recording(blind), std::invalid_argument);
}

}  // namespace

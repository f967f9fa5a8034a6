// Sliding supports of the FEM diagnosis model (FemRunSettings::support_friction; the `friction`
// effect of `pliant diagnose --model fem`).
//
// The oracles are laws, not runs of the same code: Coulomb's law at one support in closed form;
// once a block slides as a whole the supports carry exactly mu times the normal force they carry
// (the force balance of gross sliding), and without friction no tangential force at all; an
// unbounded friction coefficient is the pinned baseline. The condensed stiffness is checked
// against the full stiffness matrix with the probed nodes displaced and the others solved.
#include <gtest/gtest.h>

#include <Eigen/Dense>

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include "pliant/host/diagnose/fem_effects.hpp"
#include "pliant/host/diagnose/fem_model_run.hpp"
#include "pliant/host/diagnose/support_friction.hpp"
#include "pliant/host/fem/fem_box_mesh.hpp"
#include "pliant/host/fem/fem_condensation.hpp"
#include "pliant/host/fem/fem_model.hpp"
#include "pliant/host/recording.hpp"

namespace pliant::host {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kSide = 0.02;    // m, the block is kSide x kSide x kHeight
constexpr double kHeight = 0.01;  // m
std::size_t at(int i) { return static_cast<std::size_t>(i); }

SupportPlane table_plane() {
  SupportPlane plane;
  plane.valid = true;
  plane.normal = Eigen::Vector3d::UnitZ();
  plane.tangents.col(0) = Eigen::Vector3d::UnitX();
  plane.tangents.col(1) = Eigen::Vector3d::UnitY();
  return plane;
}

TEST(CoulombSlip, OneSupportSlidesByTheExcessOverItsStiffness) {
  const Eigen::MatrixXd stiffness = 1000.0 * Eigen::MatrixXd::Identity(3, 3);
  const Eigen::VectorXd held = Eigen::Vector3d(5.0, 0.0, 10.0);  // 5 N sideways, 10 N pressing
  const Eigen::VectorXd slip = coulomb_slip(table_plane(), 0.3, held, stiffness, Eigen::VectorXd::Zero(3), 1e-15);
  // |t + k u| = mu N with u against t: u = -(5 - 3) / 1000 m along x.
  EXPECT_NEAR(slip(0), -0.002, 1e-12);
  EXPECT_NEAR(slip(1), 0.0, 1e-15);
  EXPECT_EQ(slip(2), 0.0);  // never off the plane
}

TEST(CoulombSlip, AnisotropicStiffnessEndsOnTheFrictionLimitAgainstTheSlip) {
  Eigen::MatrixXd stiffness = Eigen::MatrixXd::Zero(3, 3);
  stiffness.diagonal() << 1000.0, 4000.0, 2000.0;
  const Eigen::VectorXd held = Eigen::Vector3d(3.0, 4.0, 10.0);
  const double mu = 0.2;
  const Eigen::VectorXd slip = coulomb_slip(table_plane(), mu, held, stiffness, Eigen::VectorXd::Zero(3), 1e-15);
  const Eigen::Vector3d reaction = held + stiffness * slip;
  const Eigen::Vector2d tangential = reaction.head<2>();
  EXPECT_NEAR(tangential.norm(), mu * reaction(2), 1e-9);
  // Friction opposes the slip: the reaction and the slip are antiparallel.
  const Eigen::Vector2d u = slip.head<2>();
  EXPECT_NEAR(tangential.normalized().dot(u.normalized()), -1.0, 1e-9);
}

TEST(CoulombSlip, StuckWithinTheLimitAndFreeWhenPulled) {
  const Eigen::MatrixXd stiffness = 1000.0 * Eigen::MatrixXd::Identity(3, 3);
  const Eigen::VectorXd within = Eigen::Vector3d(2.0, 1.0, 10.0);  // |t| = 2.24 < 3
  EXPECT_EQ(coulomb_slip(table_plane(), 0.3, within, stiffness, Eigen::VectorXd::Zero(3), 1e-15).norm(), 0.0);
  // A support pulled off the plane (normal reaction < 0) has no friction: it slides until its
  // tangential reaction is zero.
  const Eigen::VectorXd pulled = Eigen::Vector3d(2.0, -1.0, -4.0);
  const Eigen::VectorXd slip = coulomb_slip(table_plane(), 0.3, pulled, stiffness, Eigen::VectorXd::Zero(3), 1e-15);
  EXPECT_NEAR(slip(0), -0.002, 1e-12);
  EXPECT_NEAR(slip(1), 0.001, 1e-12);
}

TEST(CoulombSlip, CoupledSupportsSatisfyTheLawTogether) {
  // Two supports joined by a spring (k_c) and each held by its own (k): a load on one drags the
  // other. Every support ends stuck within its limit or slipping on it against its slip.
  const double k = 1000.0;
  const double kc = 800.0;
  Eigen::MatrixXd stiffness = Eigen::MatrixXd::Zero(6, 6);
  for (int a = 0; a < 3; ++a) {
    stiffness(a, a) = stiffness(3 + a, 3 + a) = k + kc;
    stiffness(a, 3 + a) = stiffness(3 + a, a) = -kc;
  }
  Eigen::VectorXd held(6);
  held << 9.0, 1.0, 10.0, -1.0, 0.5, 10.0;
  const double mu = 0.4;
  const Eigen::VectorXd slip = coulomb_slip(table_plane(), mu, held, stiffness, Eigen::VectorXd::Zero(6), 1e-14);
  const Eigen::VectorXd reaction = held + stiffness * slip;
  for (int i = 0; i < 2; ++i) {
    const Eigen::Vector2d t = reaction.segment<2>(3 * i);
    const Eigen::Vector2d u = slip.segment<2>(3 * i);
    const double limit = mu * reaction(3 * i + 2);
    EXPECT_LE(t.norm(), limit * (1 + 1e-7)) << "support " << i;
    if (u.norm() > 1e-12) {
      EXPECT_NEAR(t.norm(), limit, 1e-6 * limit) << "support " << i;
      EXPECT_NEAR(t.normalized().dot(u.normalized()), -1.0, 1e-6) << "support " << i;
    }
  }
  EXPECT_GT(slip.segment<2>(0).norm(), 0.0);
}

TEST(SupportPlane, FoundOnACoplanarBaseAndRefusedOtherwise) {
  const TetMesh mesh = fem::make_box_tet_mesh(Eigen::Vector3d(kSide, kSide, kHeight), {4, 4, 2});
  Eigen::VectorXd points(3 * mesh.point_count());
  for (int i = 0; i < 3 * mesh.point_count(); ++i) points(i) = mesh.points[at(i)];
  const Eigen::Vector3d centre(kSide / 2, kSide / 2, kHeight / 2);
  const std::vector<int> bottom = fem::points_on_plane(mesh, 2, 0.0, 1e-9);
  const SupportPlane plane = find_support_plane(points, bottom, centre);
  ASSERT_TRUE(plane.valid);
  EXPECT_NEAR(plane.normal.z(), 1.0, 1e-12);  // toward the body
  EXPECT_NEAR(plane.tangents.col(0).dot(plane.normal), 0.0, 1e-12);
  EXPECT_NEAR(plane.tangents.col(1).dot(plane.tangents.col(0)), 0.0, 1e-12);

  std::vector<int> line;  // the bottom nodes on one edge: a line, not a plane
  for (int id : bottom) {
    if (mesh.points[at(id) * 3 + 1] == 0.0) line.push_back(id);
  }
  EXPECT_FALSE(find_support_plane(points, line, centre).valid);
  std::vector<int> two_faces = bottom;  // the base and one side: not one plane
  for (int id : fem::points_on_plane(mesh, 0, 0.0, 1e-9)) {
    if (std::find(two_faces.begin(), two_faces.end(), id) == two_faces.end()) two_faces.push_back(id);
  }
  EXPECT_FALSE(find_support_plane(points, two_faces, centre).valid);
}

TEST(CondensedStiffness, MatchesTheFullSystemWithTheOthersSolved) {
  const TetMesh mesh = fem::make_box_tet_mesh(Eigen::Vector3d(kSide, kSide, kHeight), {3, 3, 2});
  fem::FemMaterial material;
  material.youngs_modulus_pa = 5e4;
  material.poisson_ratio = 0.3;
  const fem::FemModel model(mesh, material);
  const Eigen::VectorXd rest = model.rest_position_m();
  const std::vector<int> probed = fem::points_on_plane(mesh, 2, 0.0, 1e-9);
  const std::vector<int> clamped = fem::points_on_plane(mesh, 2, kHeight, 1e-9);
  const Eigen::MatrixXd condensed = fem::condensed_stiffness(model, rest, probed, clamped);

  // Oracle: the dense stiffness, probed nodes moved by u, clamped held, the rest solved; the
  // force on the probed nodes must be condensed * u.
  const Eigen::MatrixXd k = Eigen::MatrixXd(fem::stiffness_matrix(model, rest));
  std::vector<int> role(at(model.node_count()), 0);  // 0 relaxed, 1 probed, 2 clamped
  for (int id : probed) role[at(id)] = 1;
  for (int id : clamped) role[at(id)] = 2;
  std::vector<int> relaxed_dofs;
  for (int node = 0; node < model.node_count(); ++node) {
    if (role[at(node)] == 0) {
      for (int a = 0; a < 3; ++a) relaxed_dofs.push_back(3 * node + a);
    }
  }
  Eigen::VectorXd motion = Eigen::VectorXd::Zero(3 * model.node_count());
  Eigen::VectorXd u(3 * static_cast<Eigen::Index>(probed.size()));
  for (Eigen::Index i = 0; i < u.size(); ++i) u(i) = 1e-4 * std::sin(0.7 * static_cast<double>(i) + 0.3);
  for (std::size_t i = 0; i < probed.size(); ++i)
    motion.segment<3>(3 * probed[i]) = u.segment<3>(3 * static_cast<Eigen::Index>(i));
  const Eigen::Index r = static_cast<Eigen::Index>(relaxed_dofs.size());
  Eigen::MatrixXd k_ff(r, r);
  Eigen::VectorXd rhs(r);
  const Eigen::VectorXd pushed = k * motion;
  for (Eigen::Index a = 0; a < r; ++a) {
    rhs(a) = -pushed(relaxed_dofs[at(static_cast<int>(a))]);
    for (Eigen::Index b = 0; b < r; ++b)
      k_ff(a, b) = k(relaxed_dofs[at(static_cast<int>(a))], relaxed_dofs[at(static_cast<int>(b))]);
  }
  const Eigen::VectorXd relaxed = k_ff.ldlt().solve(rhs);
  for (Eigen::Index a = 0; a < r; ++a) motion(relaxed_dofs[at(static_cast<int>(a))]) = relaxed(a);
  const Eigen::VectorXd force = k * motion;
  const Eigen::VectorXd predicted = condensed * u;
  for (std::size_t i = 0; i < probed.size(); ++i) {
    for (int a = 0; a < 3; ++a) {
      EXPECT_NEAR(force(3 * probed[i] + a), predicted(3 * static_cast<Eigen::Index>(i) + a),
                  1e-9 * predicted.cwiseAbs().maxCoeff());
    }
  }
  EXPECT_THROW(fem::condensed_stiffness(model, rest, probed, probed), std::invalid_argument);
}

// A block standing on its base (fixed: the support plane), its top driven: pressed down by
// `press` of the height over the first third, then moved sideways along x by `shift` (m) over
// the rest, pressed all along. The wrench stream (zeros) is applied to the top, so every frame's
// simulated force is the net force the top exerts on the block.
Recording press_and_shear(int frames, double press, double shift, double poisson, double frame_s = 0.1) {
  const TetMesh mesh = fem::make_box_tet_mesh(Eigen::Vector3d(kSide, kSide, kHeight), {4, 4, 2});
  Recording r;
  r.name = "press_and_shear";
  r.dimension = 3;
  r.length_unit = "m";
  r.particle_count = mesh.point_count();
  r.masses.assign(at(r.particle_count), 1e-4);
  r.material = {{"poisson_ratio", poisson}, {"density", 1000.0}};
  r.fixed = fem::points_on_plane(mesh, 2, 0.0, 1e-9);
  const std::vector<int> top = fem::points_on_plane(mesh, 2, kHeight, 1e-9);
  for (int id : top) r.driven.push_back({id});
  r.wrench_applied_to = top;
  r.mesh = mesh;
  r.files = {{"particles", "particles.csv"}, {"mesh", "mesh.vtk"}, {"wrench", "wrench.csv"}};
  const int pressing = frames / 3;
  for (int k = 0; k < frames; ++k) {
    const double t = frame_s * k;
    r.frame_times_s.push_back(t);
    const double down = press * kHeight * std::min(1.0, static_cast<double>(k) / pressing);
    const double along = k <= pressing ? 0.0 : shift * static_cast<double>(k - pressing) / (frames - 1 - pressing);
    std::vector<double> frame(at(r.particle_count) * 3, kNaN);
    for (int id : top) {
      frame[at(id) * 3] = mesh.points[at(id) * 3] + along;
      frame[at(id) * 3 + 1] = mesh.points[at(id) * 3 + 1];
      frame[at(id) * 3 + 2] = kHeight - down;
    }
    r.positions.insert(r.positions.end(), frame.begin(), frame.end());
    WrenchSample w;
    w.t_s = t;
    r.wrench.push_back(w);
  }
  finalize_recording(r);
  return r;
}

FemRun run_with_friction(const Recording& recording, double mu, FemTimeMode mode = FemTimeMode::quasi_static) {
  FemRecordingSimulator simulator(recording, mode, 1);
  FemRunSettings settings;
  settings.youngs_modulus_pa = 5e4;
  settings.support_friction = mu;
  FemRun run = simulator.simulate(settings);
  EXPECT_TRUE(run.ok) << run.failure;
  return run;
}

Eigen::Vector3d force_at(const FemRun& run, int frame) {
  return Eigen::Vector3d(run.force[at(frame) * 3], run.force[at(frame) * 3 + 1], run.force[at(frame) * 3 + 2]);
}

TEST(FemFriction, OnlyABaseOnOnePlaneCanSlide) {
  const Recording recording = press_and_shear(6, 0.05, 0.0, 0.3);
  EXPECT_TRUE(FemRecordingSimulator(recording, FemTimeMode::quasi_static, 1).has_support_plane());
  Recording walled = recording;
  for (int id : fem::points_on_plane(*recording.mesh, 0, 0.0, 1e-9)) {
    if (std::find(walled.fixed.begin(), walled.fixed.end(), id) == walled.fixed.end()) walled.fixed.push_back(id);
  }
  std::sort(walled.fixed.begin(), walled.fixed.end());
  walled.driven.clear();  // the x = 0 wall overlaps the top: keep the wall, drop the drive
  walled.wrench.clear();
  walled.wrench_applied_to.clear();
  walled.files.erase("wrench");
  finalize_recording(walled);
  FemRecordingSimulator simulator(walled, FemTimeMode::quasi_static, 1);
  EXPECT_FALSE(simulator.has_support_plane());
  FemEffectContext context;
  context.support_plane = false;
  for (const FemEffect& effect : fem_effect_catalogue(context)) EXPECT_NE(effect.name, "friction");
  context.support_plane = true;
  int offered = 0;
  for (const FemEffect& effect : fem_effect_catalogue(context)) offered += effect.name == "friction" ? 1 : 0;
  EXPECT_EQ(offered, 1);
}

// Where every support presses on the plane. (A support pulled off the plane slides freely at any
// mu: on a real table it would lift off; see fem_model_run.hpp.)
TEST(FemFriction, UnboundedFrictionIsThePinnedBaseline) {
  const Recording recording = press_and_shear(10, 0.08, 0.0, 0.45);
  FemRecordingSimulator simulator(recording, FemTimeMode::quasi_static, 1);
  FemRunSettings pinned;
  pinned.youngs_modulus_pa = 5e4;
  const FemRun baseline = simulator.simulate(pinned);
  const FemRun stuck = run_with_friction(recording, 1e9);
  ASSERT_TRUE(baseline.ok);
  for (std::size_t i = 0; i < baseline.positions.size(); ++i) {
    ASSERT_NEAR(stuck.positions[i], baseline.positions[i], 1e-10) << "entry " << i;
  }
}

TEST(FemFriction, AGrossSlideCarriesMuTimesTheNormalForce) {
  const int frames = 16;
  const Recording recording = press_and_shear(frames, 0.05, 0.006, 0.3);
  // mu below a sixth of width over height: the drag's moment leaves every support pressing (no
  // support pulled, whose friction would be zero).
  for (double mu : {0.1, 0.25}) {
    const FemRun run = run_with_friction(recording, mu);
    const Eigen::Vector3d pressed = force_at(run, frames / 3);
    EXPECT_NEAR(pressed.x() / pressed.z(), 0.0, 1e-6) << "mu " << mu << ": no shear before the slide";
    const Eigen::Vector3d sliding = force_at(run, frames - 1);
    ASSERT_GT(std::abs(sliding.z()), 0.0);
    // The top pushes the block down and drags it along +x: the supports resist with mu N.
    EXPECT_NEAR(sliding.x() / std::abs(sliding.z()), mu, 0.01 * mu) << "mu " << mu;
    // The base moved with the top, nearly rigidly: the whole block slides.
    const int corner = recording.fixed.front();
    const double base_shift = run.positions[(at(frames - 1) * at(recording.particle_count) + at(corner)) * 3] -
                              recording.mesh->points[at(corner) * 3];
    EXPECT_GT(base_shift, 0.5 * 0.006) << "mu " << mu;
  }
}

TEST(FemFriction, WithoutFrictionTheSupportsCarryNoShear) {
  const int frames = 10;
  const Recording recording = press_and_shear(frames, 0.05, 0.004, 0.3);
  const FemRun run = run_with_friction(recording, 0.0);
  for (int f = 1; f < frames; ++f) {
    const Eigen::Vector3d force = force_at(run, f);
    // Zero to the slip tolerance (1e-6 of the block's size times the supports' stiffness).
    EXPECT_NEAR(force.x(), 0.0, 1e-4 * std::abs(force.z())) << "frame " << f;
    EXPECT_NEAR(force.y(), 0.0, 1e-4 * std::abs(force.z())) << "frame " << f;
  }
}

TEST(FemFriction, LessFrictionLetsThePressedBaseSpreadFurther) {
  // Pressing the block bulges it; the base spreads outward as far as friction lets it.
  const int frames = 6;
  const Recording recording = press_and_shear(frames, 0.10, 0.0, 0.45);
  int corner = -1;
  for (int id : recording.fixed) {
    if (recording.mesh->points[at(id) * 3] == 0.0 && recording.mesh->points[at(id) * 3 + 1] == 0.0) corner = id;
  }
  ASSERT_GE(corner, 0);
  double last = std::numeric_limits<double>::infinity();
  for (double mu : {0.0, 0.1, 0.3, 1e9}) {
    const FemRun run = run_with_friction(recording, mu);
    const double outward = -run.positions[(at(frames - 1) * at(recording.particle_count) + at(corner)) * 3];
    EXPECT_LT(outward, last) << "mu " << mu;
    last = outward;
  }
  EXPECT_NEAR(last, 0.0, 1e-12);  // pinned
}

TEST(FemFriction, DynamicRunsSlideToo) {
  // One linearised Newmark step per frame: the frames must be short enough for the motion of a
  // step to stay small (as in a recording that calls for dynamics), here 0.1 mm.
  const int frames = 61;
  Recording recording = press_and_shear(frames, 0.05, 0.004, 0.3, 0.01);
  recording.material["rayleigh_beta"] = 1e-3;  // damps the ringing where the base starts to slide
  const FemRun run = run_with_friction(recording, 0.25, FemTimeMode::dynamic);
  const Eigen::Vector3d sliding = force_at(run, frames - 1);
  // Slow drive (1.5 s against a lowest period of milliseconds): inertia is negligible.
  EXPECT_NEAR(sliding.x() / std::abs(sliding.z()), 0.25, 0.025);
}

}  // namespace
}  // namespace pliant::host

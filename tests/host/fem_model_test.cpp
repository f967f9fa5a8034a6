// Corotational FEM model: input validation, element stiffness against an independently coded
// Voigt-notation oracle, polar decomposition, rotation invariance of the elastic forces, energy
// consistency, and the structured box and refinement helpers.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <map>
#include <random>
#include <stdexcept>
#include <vector>

#include <Eigen/Dense>

#include "fem_test_meshes.hpp"
#include "pliant/host/fem/fem_box_mesh.hpp"
#include "pliant/host/fem/fem_model.hpp"

namespace pliant::host::test {
namespace {

using fem::FemMaterial;
using fem::FemModel;

constexpr double kPi = 3.14159265358979323846;

FemMaterial material(double youngs = 1e5, double nu = 0.3) {
  FemMaterial m;
  m.youngs_modulus_pa = youngs;
  m.poisson_ratio = nu;
  m.density_kg_m3 = 1200;
  return m;
}

Eigen::Matrix3d rotation(double angle_rad, const Eigen::Vector3d& axis) {
  return Eigen::AngleAxisd(angle_rad, axis.normalized()).toRotationMatrix();
}

// Rigid motion x -> Q x + t of a 3n vector.
Eigen::VectorXd transform(const Eigen::VectorXd& x, const Eigen::Matrix3d& q, const Eigen::Vector3d& t) {
  Eigen::VectorXd out(x.size());
  for (Eigen::Index i = 0; i < x.size() / 3; ++i) out.segment<3>(3 * i) = q * x.segment<3>(3 * i) + t;
  return out;
}

Eigen::VectorXd rotate_vectors(const Eigen::VectorXd& f, const Eigen::Matrix3d& q) {
  Eigen::VectorXd out(f.size());
  for (Eigen::Index i = 0; i < f.size() / 3; ++i) out.segment<3>(3 * i) = q * f.segment<3>(3 * i);
  return out;
}

// A deformed configuration: rest plus a smooth bend and twist plus random jitter.
Eigen::VectorXd deformed(const FemModel& model, double jitter, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  Eigen::VectorXd x = model.rest_position_m();
  for (int i = 0; i < model.node_count(); ++i) {
    const Eigen::Vector3d p = x.segment<3>(3 * i);
    x.segment<3>(3 * i) =
        rotation(0.05 * p.x(), Eigen::Vector3d::UnitX()) * p + Eigen::Vector3d(0, 0, 0.02 * p.x() * p.x());
    for (int d = 0; d < 3; ++d) x[3 * i + d] += jitter * u(rng);
  }
  return x;
}

TEST(FemModel, RejectsBadInput) {
  const TetMesh tet = ipc_mesh("tet.msh");
  EXPECT_NO_THROW(FemModel(tet, material()));
  {
    TetMesh inverted = tet;
    std::swap(inverted.tetrahedra[0], inverted.tetrahedra[1]);
    EXPECT_THROW(FemModel(inverted, material()), std::invalid_argument);
  }
  {
    TetMesh flat = tet;
    for (int i = 0; i < flat.point_count(); ++i) flat.points[static_cast<std::size_t>(3 * i + 2)] = 0;
    EXPECT_THROW(FemModel(flat, material()), std::invalid_argument);
  }
  {
    TetMesh bad = tet;
    bad.points[0] = std::numeric_limits<double>::quiet_NaN();
    EXPECT_THROW(FemModel(bad, material()), std::invalid_argument);
  }
  {
    TetMesh bad = tet;
    bad.tetrahedra[2] = 7;
    EXPECT_THROW(FemModel(bad, material()), std::invalid_argument);
  }
  {
    TetMesh extra = tet;
    extra.points.insert(extra.points.end(), {5.0, 5.0, 5.0});  // a node no element uses
    EXPECT_THROW(FemModel(extra, material()), std::invalid_argument);
  }
  {
    TetMesh per_element = tet;
    per_element.youngs_modulus = {-1.0};
    EXPECT_THROW(FemModel(per_element, material()), std::invalid_argument);
    per_element.youngs_modulus = {1.0, 2.0};
    EXPECT_THROW(FemModel(per_element, material()), std::invalid_argument);
    per_element.youngs_modulus = {3e4};
    EXPECT_NO_THROW(FemModel(per_element, material(0.0)));  // global E unused when per element
  }
  EXPECT_THROW(FemModel(tet, material(0.0)), std::invalid_argument);
  EXPECT_THROW(FemModel(tet, material(std::numeric_limits<double>::infinity())), std::invalid_argument);
  EXPECT_THROW(FemModel(tet, material(1e5, 0.5)), std::invalid_argument);
  EXPECT_THROW(FemModel(tet, material(1e5, -1.0)), std::invalid_argument);
  EXPECT_THROW(FemModel(tet, material(1e5, std::numeric_limits<double>::quiet_NaN())), std::invalid_argument);
  FemMaterial m = material();
  m.density_kg_m3 = 0;
  EXPECT_THROW(FemModel(tet, m), std::invalid_argument);
  m = material();
  m.rayleigh_beta = -1e-3;
  EXPECT_THROW(FemModel(tet, m), std::invalid_argument);
  m = material();
  m.gravity_m_s2.x() = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW(FemModel(tet, m), std::invalid_argument);
  EXPECT_THROW(FemModel(TetMesh{}, material()), std::invalid_argument);

  FemModel model(tet, material());
  EXPECT_THROW(model.set_youngs_modulus(-2.0), std::invalid_argument);
  EXPECT_THROW(model.set_youngs_modulus(Eigen::VectorXd::Ones(2)), std::invalid_argument);
  EXPECT_THROW(model.set_poisson_ratio(0.5), std::invalid_argument);
  EXPECT_THROW(model.set_rayleigh(0.1, -0.1), std::invalid_argument);
  Eigen::VectorXd flipped = model.rest_position_m();
  flipped.segment<3>(0).swap(flipped.segment<3>(3));  // swaps corners 0 and 1: negative volume
  EXPECT_THROW(model.set_rest_position(flipped), std::invalid_argument);
  EXPECT_DOUBLE_EQ(model.youngs_modulus_pa()[0], 1e5);  // unchanged after the failed setters
  EXPECT_DOUBLE_EQ(model.poisson_ratio(), 0.3);
  EXPECT_NEAR(model.element_volume_m3()[0], 1.0 / 6.0, 1e-15);
}

TEST(FemModel, VolumesAndLumpedMass) {
  const TetMesh cube = ipc_mesh("cube.msh");
  FemModel model(cube, material());
  EXPECT_EQ(model.element_count(), 6);
  EXPECT_NEAR(model.element_volume_m3().sum(), 1.0, 1e-14);
  EXPECT_NEAR(model.total_mass_kg(), 1200.0, 1e-10);
  for (int e = 0; e < model.element_count(); ++e) {
    EXPECT_GT(model.element_volume_m3()[e], 0);
  }
  model.set_density(500);
  EXPECT_NEAR(model.total_mass_kg(), 500.0, 1e-10);
  // Shape gradients: sum to zero and reproduce a linear field exactly.
  for (int e = 0; e < model.element_count(); ++e) {
    const auto& b = model.shape_gradients(e);
    EXPECT_LT((b.rowwise().sum()).norm(), 1e-12);
    Eigen::Matrix3d grad = Eigen::Matrix3d::Zero();
    const Eigen::Matrix3d a = (Eigen::Matrix3d() << 1, 2, 3, 4, 5, 6, 7, 8, 10).finished();
    for (int c = 0; c < 4; ++c)
      grad += a *
              model.rest_position_m().segment<3>(
                  3 * model.elements()[static_cast<std::size_t>(e)][static_cast<std::size_t>(c)]) *
              b.col(c).transpose();
    EXPECT_LT((grad - a).norm(), 1e-12);
  }
}

// Independent oracle: K = V B^T D B with the 6 x 12 strain-displacement matrix in Voigt notation
// (engineering shear strains) and the isotropic elasticity matrix D.
Eigen::Matrix<double, 12, 12> voigt_stiffness(const std::array<Eigen::Vector3d, 4>& x, double youngs, double nu) {
  Eigen::Matrix4d c;
  for (int a = 0; a < 4; ++a) c.row(a) << 1.0, x[static_cast<std::size_t>(a)].transpose();
  const Eigen::Matrix4d ci = c.inverse();  // rows 1..3: gradient coefficients of N_a
  const double volume = std::abs(c.determinant()) / 6.0;
  Eigen::Matrix<double, 6, 12> bm = Eigen::Matrix<double, 6, 12>::Zero();
  for (int a = 0; a < 4; ++a) {
    const double bx = ci(1, a), by = ci(2, a), bz = ci(3, a);
    bm(0, 3 * a) = bx;
    bm(1, 3 * a + 1) = by;
    bm(2, 3 * a + 2) = bz;
    bm(3, 3 * a) = by;
    bm(3, 3 * a + 1) = bx;
    bm(4, 3 * a + 1) = bz;
    bm(4, 3 * a + 2) = by;
    bm(5, 3 * a) = bz;
    bm(5, 3 * a + 2) = bx;
  }
  Eigen::Matrix<double, 6, 6> d = Eigen::Matrix<double, 6, 6>::Zero();
  const double f = youngs / ((1 + nu) * (1 - 2 * nu));
  d.topLeftCorner<3, 3>().setConstant(f * nu);
  d.topLeftCorner<3, 3>().diagonal().setConstant(f * (1 - nu));
  d.bottomRightCorner<3, 3>().diagonal().setConstant(f * (1 - 2 * nu) / 2);
  return volume * bm.transpose() * d * bm;
}

TEST(FemModel, UnitElementStiffnessMatchesVoigtOracle) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-0.3, 0.3);
  for (double nu : {0.0, 0.25, 0.45}) {
    TetMesh mesh;
    std::array<Eigen::Vector3d, 4> corners = {Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(1, 0, 0),
                                              Eigen::Vector3d(0, 1, 0), Eigen::Vector3d(0, 0, 1)};
    for (auto& p : corners) p += Eigen::Vector3d(u(rng), u(rng), u(rng));
    for (const auto& p : corners) mesh.points.insert(mesh.points.end(), {p.x(), p.y(), p.z()});
    mesh.tetrahedra = {0, 1, 2, 3};
    Eigen::Matrix3d dm;
    dm << corners[1] - corners[0], corners[2] - corners[0], corners[3] - corners[0];
    if (dm.determinant() < 0) {
      std::swap(mesh.tetrahedra[2], mesh.tetrahedra[3]);
      std::swap(corners[2], corners[3]);
    }
    FemMaterial element_material = material(1.0, nu);
    element_material.volumetric = fem::FemVolumetric::element;  // the plain element the oracle codes
    FemModel model(mesh, element_material);
    const Eigen::Matrix<double, 12, 12> k = model.unit_element_stiffness(0);
    const Eigen::Matrix<double, 12, 12> oracle = voigt_stiffness(corners, 1.0, nu);
    EXPECT_LT((k - oracle).norm(), 1e-12 * oracle.norm()) << "nu " << nu;
    EXPECT_LT((k - k.transpose()).norm(), 1e-14 * k.norm());
    // Rigid motions are in the null space: 3 translations and 3 infinitesimal rotations.
    Eigen::Matrix<double, 12, 6> rigid;
    for (int a = 0; a < 4; ++a) {
      rigid.block<3, 3>(3 * a, 0).setIdentity();
      const Eigen::Vector3d& p = corners[static_cast<std::size_t>(a)];
      rigid.block<3, 3>(3 * a, 3) << 0, p.z(), -p.y(), -p.z(), 0, p.x(), p.y(), -p.x(), 0;
    }
    EXPECT_LT((k * rigid).norm(), 1e-12 * k.norm());
    // The assembled rest stiffness is E times the unit element stiffness.
    model.set_youngs_modulus(3.5e4);
    const Eigen::MatrixXd assembled = Eigen::MatrixXd(fem::stiffness_matrix(model, model.rest_position_m()));
    EXPECT_LT((assembled - 3.5e4 * k).norm(), 1e-11 * assembled.norm());
    // On a single tetrahedron every nodal average is the element's own value, so the averaged
    // nodal pressure formulation must give the same matrix.
    FemMaterial nodal_material = element_material;
    nodal_material.volumetric = fem::FemVolumetric::nodal_average;
    const FemModel nodal(mesh, nodal_material);
    const Eigen::MatrixXd nodal_k = Eigen::MatrixXd(fem::stiffness_matrix(nodal, nodal.rest_position_m()));
    EXPECT_LT((nodal_k - oracle).norm(), 1e-12 * oracle.norm()) << "nu " << nu;
  }
}

void expect_polar(const Eigen::Matrix3d& f, const char* what) {
  const Eigen::Matrix3d r = fem::polar_rotation(f);
  ASSERT_TRUE(r.allFinite()) << what;
  EXPECT_LT((r.transpose() * r - Eigen::Matrix3d::Identity()).norm(), 1e-13) << what;
  EXPECT_NEAR(r.determinant(), 1.0, 1e-13) << what;
  const Eigen::Matrix3d s = r.transpose() * f;
  EXPECT_LT((s - s.transpose()).norm(), 1e-12 * std::max(1.0, f.norm())) << what;
}

TEST(PolarRotation, ProperRotationForAnyMatrix) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (int trial = 0; trial < 200; ++trial) {
    Eigen::Matrix3d f;
    for (int i = 0; i < 9; ++i) f(i / 3, i % 3) = u(rng);
    if (trial % 3 == 0) f += 2 * Eigen::Matrix3d::Identity();  // mostly well conditioned
    expect_polar(f, "random");
    if (f.determinant() > 0) {
      Eigen::JacobiSVD<Eigen::Matrix3d> svd(f, Eigen::ComputeFullU | Eigen::ComputeFullV);
      EXPECT_LT((fem::polar_rotation(f) - svd.matrixU() * svd.matrixV().transpose()).norm(), 1e-11);
    }
  }
  const Eigen::Matrix3d q = rotation(2.0, Eigen::Vector3d(1, 2, 3));
  expect_polar(q * Eigen::Vector3d(2.0, 0.5, -0.1).asDiagonal(), "inverted");
  expect_polar(q * Eigen::Vector3d(3.0, 1.0, 0.0).asDiagonal(), "flat");
  expect_polar(q * Eigen::Vector3d(3.0, 0.0, 0.0).asDiagonal(), "collinear");
  expect_polar(Eigen::Matrix3d::Zero(), "collapsed");
  expect_polar(q * Eigen::Vector3d(1e6, 1e-6, 1.0).asDiagonal(), "extreme stretch");
  EXPECT_LT((fem::polar_rotation(q) - q).norm(), 1e-14);
  EXPECT_LT((fem::polar_rotation(q * Eigen::Vector3d(2, 3, 4).asDiagonal()) - q).norm(), 1e-13);
  Eigen::Matrix3d nan = Eigen::Matrix3d::Identity();
  nan(1, 2) = std::numeric_limits<double>::quiet_NaN();
  EXPECT_TRUE(fem::polar_rotation(nan).isIdentity());
}

TEST(CorotationalForce, RotationInvariance) {
  const TetMesh mesh = ipc_mesh("bar-651.msh");
  FemModel model(mesh, material(2e5, 0.35));
  const Eigen::VectorXd x = deformed(model, 0.02, 11);
  Eigen::VectorXd f;
  fem::internal_force(model, x, f);
  const double scale = f.cwiseAbs().maxCoeff();
  ASSERT_GT(scale, 0);
  const double energy = fem::elastic_energy(model, x);
  ASSERT_GT(energy, 0);
  const Eigen::Vector3d t(3.0, -7.0, 0.5);
  for (double degrees : {30.0, 89.0, 91.0, 135.0, 180.0, 250.0, 359.0}) {
    for (const Eigen::Vector3d& axis :
         {Eigen::Vector3d(0, 0, 1), Eigen::Vector3d(1, -2, 0.5), Eigen::Vector3d(-1, 1, 1)}) {
      const Eigen::Matrix3d q = rotation(degrees * kPi / 180, axis);
      Eigen::VectorXd fq;
      fem::internal_force(model, transform(x, q, t), fq);
      EXPECT_LT((fq - rotate_vectors(f, q)).cwiseAbs().maxCoeff(), 1e-9 * scale) << degrees << " deg";
      EXPECT_NEAR(fem::elastic_energy(model, transform(x, q, t)), energy, 1e-10 * energy) << degrees << " deg";
      // Rigid motion of the rest shape: no force, no energy.
      Eigen::VectorXd f0;
      fem::internal_force(model, transform(model.rest_position_m(), q, t), f0);
      EXPECT_LT(f0.cwiseAbs().maxCoeff(), 1e-9 * scale) << degrees << " deg";
      EXPECT_LT(fem::elastic_energy(model, transform(model.rest_position_m(), q, t)), 1e-12 * energy);
    }
  }
}

TEST(CorotationalForce, NoNetForceOrTorque) {
  const TetMesh mesh = ipc_mesh("bar-186.msh");
  FemModel model(mesh, material(1e5, 0.3));
  const Eigen::VectorXd x = deformed(model, 0.05, 5);
  Eigen::VectorXd f;
  fem::internal_force(model, x, f);
  Eigen::Vector3d net = Eigen::Vector3d::Zero();
  Eigen::Vector3d torque = Eigen::Vector3d::Zero();
  double magnitude = 0;
  for (int i = 0; i < model.node_count(); ++i) {
    net += f.segment<3>(3 * i);
    torque += x.segment<3>(3 * i).cross(Eigen::Vector3d(f.segment<3>(3 * i)));
    magnitude += f.segment<3>(3 * i).norm() * (1 + x.segment<3>(3 * i).norm());
  }
  EXPECT_LT(net.norm(), 1e-12 * magnitude);
  EXPECT_LT(torque.norm(), 1e-12 * magnitude);  // holds only with the exact polar rotation
}

TEST(CorotationalForce, IsMinusEnergyGradient) {
  const TetMesh mesh = ipc_mesh("bar-186.msh");
  FemModel model(mesh, material(1e5, 0.3));
  Eigen::VectorXd x = deformed(model, 0.05, 9);
  Eigen::VectorXd f;
  fem::internal_force(model, x, f);
  std::mt19937 rng(1);
  std::uniform_int_distribution<int> pick(0, model.dof_count() - 1);
  const double h = 1e-6;
  for (int k = 0; k < 40; ++k) {
    const int dof = pick(rng);
    const double saved = x[dof];
    x[dof] = saved + h;
    const double up = fem::elastic_energy(model, x);
    x[dof] = saved - h;
    const double down = fem::elastic_energy(model, x);
    x[dof] = saved;
    EXPECT_NEAR(-(up - down) / (2 * h), f[dof], 1e-6 * f.cwiseAbs().maxCoeff()) << "dof " << dof;
  }
}

TEST(StiffnessMatrix, IsForceDerivativeAtRestAndScalesWithPerElementModulus) {
  const TetMesh mesh = ipc_mesh("bar-186.msh");
  FemModel model(mesh, material(1e5, 0.3));
  Eigen::VectorXd youngs(model.element_count());
  for (int e = 0; e < model.element_count(); ++e) youngs[e] = 1e4 * (1 + e % 7);
  model.set_youngs_modulus(youngs);
  const Eigen::SparseMatrix<double> k = fem::stiffness_matrix(model, model.rest_position_m());
  std::mt19937 rng(2);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  Eigen::VectorXd dir(model.dof_count());
  for (Eigen::Index i = 0; i < dir.size(); ++i) dir[i] = u(rng);
  const double h = 1e-7;
  Eigen::VectorXd up, down;
  fem::internal_force(model, model.rest_position_m() + h * dir, up);
  fem::internal_force(model, model.rest_position_m() - h * dir, down);
  const Eigen::VectorXd kd = k * dir;
  EXPECT_LT((-(up - down) / (2 * h) - kd).norm(), 1e-6 * kd.norm());
  // Assembled from E_e * K_e_unit.
  Eigen::MatrixXd sum = Eigen::MatrixXd::Zero(model.dof_count(), model.dof_count());
  for (int e = 0; e < model.element_count(); ++e) {
    const Eigen::Matrix<double, 12, 12> ke = youngs[e] * model.unit_element_stiffness(e);
    const auto& n = model.elements()[static_cast<std::size_t>(e)];
    for (int a = 0; a < 4; ++a) {
      for (int b = 0; b < 4; ++b) {
        sum.block<3, 3>(3 * n[static_cast<std::size_t>(a)], 3 * n[static_cast<std::size_t>(b)]) +=
            ke.block<3, 3>(3 * a, 3 * b);
      }
    }
  }
  EXPECT_LT((Eigen::MatrixXd(k) - sum).norm(), 1e-12 * sum.norm());
}

// Every face of the mesh: interior faces appear twice, boundary faces once; total boundary area.
struct FaceCensus {
  int interior = 0;
  int boundary = 0;
  int overused = 0;
  double boundary_area = 0;
};

FaceCensus face_census(const TetMesh& mesh) {
  std::map<std::array<int, 3>, int> faces;
  constexpr int kFaces[4][3] = {{1, 2, 3}, {0, 2, 3}, {0, 1, 3}, {0, 1, 2}};
  for (int e = 0; e < mesh.tet_count(); ++e) {
    for (const auto& face : kFaces) {
      std::array<int, 3> key{};
      for (int k = 0; k < 3; ++k)
        key[static_cast<std::size_t>(k)] = mesh.tetrahedra[static_cast<std::size_t>(4 * e + face[k])];
      std::sort(key.begin(), key.end());
      ++faces[key];
    }
  }
  FaceCensus census;
  auto point = [&](int i) {
    return Eigen::Vector3d(mesh.points[static_cast<std::size_t>(3 * i)],
                           mesh.points[static_cast<std::size_t>(3 * i + 1)],
                           mesh.points[static_cast<std::size_t>(3 * i + 2)]);
  };
  for (const auto& [key, count] : faces) {
    if (count == 2) ++census.interior;
    if (count > 2) ++census.overused;
    if (count == 1) {
      ++census.boundary;
      census.boundary_area += 0.5 * (point(key[1]) - point(key[0])).cross(point(key[2]) - point(key[0])).norm();
    }
  }
  return census;
}

TEST(BoxMesh, ConformingPositiveAndSymmetric) {
  for (fem::BoxSplit split : {fem::BoxSplit::kuhn, fem::BoxSplit::mirrored_kuhn}) {
    const TetMesh box = fem::make_box_tet_mesh({2.0, 1.0, 0.5}, {4, 3, 2}, split);
    EXPECT_EQ(box.tet_count(), 6 * 4 * 3 * 2);
    EXPECT_EQ(box.point_count(), 5 * 4 * 3);
    FemModel model(box, material());  // throws on any non-positive volume
    EXPECT_NEAR(model.element_volume_m3().sum(), 1.0, 1e-12);
    const FaceCensus census = face_census(box);
    EXPECT_EQ(census.overused, 0);
    EXPECT_NEAR(census.boundary_area, 2 * (2.0 * 1.0 + 2.0 * 0.5 + 1.0 * 0.5), 1e-12);
  }
  // The mirrored split has the box's mirror symmetry x -> 2 - x: the reflected tetrahedra are the
  // same set (for an even cell count along x).
  const TetMesh box = fem::make_box_tet_mesh({2.0, 1.0, 0.5}, {4, 2, 2}, fem::BoxSplit::mirrored_kuhn);
  std::map<std::array<int, 4>, int> tets;
  auto mirror = [&](int i) {
    const int ix = i % 5;
    return i - ix + (4 - ix);
  };
  for (int e = 0; e < box.tet_count(); ++e) {
    std::array<int, 4> t{};
    for (int a = 0; a < 4; ++a) t[static_cast<std::size_t>(a)] = box.tetrahedra[static_cast<std::size_t>(4 * e + a)];
    std::sort(t.begin(), t.end());
    ++tets[t];
  }
  for (int e = 0; e < box.tet_count(); ++e) {
    std::array<int, 4> t{};
    for (int a = 0; a < 4; ++a)
      t[static_cast<std::size_t>(a)] = mirror(box.tetrahedra[static_cast<std::size_t>(4 * e + a)]);
    std::sort(t.begin(), t.end());
    EXPECT_EQ(tets.count(t), 1u);
  }
  EXPECT_THROW(fem::make_box_tet_mesh({1, 1, 0}, {1, 1, 1}), std::invalid_argument);
  EXPECT_THROW(fem::make_box_tet_mesh({1, 1, 1}, {1, 0, 1}), std::invalid_argument);
}

TEST(RefineTetMesh, EightChildrenConformingSameVolume) {
  for (const char* name : {"cube.msh", "bar-186.msh"}) {
    TetMesh mesh = ipc_mesh(name);
    mesh.youngs_modulus.assign(static_cast<std::size_t>(mesh.tet_count()), 0);
    for (int e = 0; e < mesh.tet_count(); ++e) mesh.youngs_modulus[static_cast<std::size_t>(e)] = 1e3 * (e + 1);
    const TetMesh fine = fem::refine_tet_mesh(mesh);
    EXPECT_EQ(fine.tet_count(), 8 * mesh.tet_count());
    const FemModel coarse_model(mesh, material());
    const FemModel fine_model(fine, material());  // positive volumes
    EXPECT_NEAR(fine_model.element_volume_m3().sum(), coarse_model.element_volume_m3().sum(), 1e-12);
    const FaceCensus coarse = face_census(mesh);
    const FaceCensus refined = face_census(fine);
    EXPECT_EQ(refined.overused, 0);
    EXPECT_EQ(refined.boundary, 4 * coarse.boundary);
    EXPECT_NEAR(refined.boundary_area, coarse.boundary_area, 1e-12);
    for (int e = 0; e < fine.tet_count(); ++e) {
      EXPECT_EQ(fine.youngs_modulus[static_cast<std::size_t>(e)], mesh.youngs_modulus[static_cast<std::size_t>(e / 8)]);
    }
  }
}

}  // namespace
}  // namespace pliant::host::test

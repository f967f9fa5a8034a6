// Rotation extraction checked against an SVD-based polar decomposition (an independent method)
// and on the degenerate inputs shape matching meets: zero, collinear, flat, inverted, NaN.
#include "pliant/core/polar.hpp"

#include <Eigen/SVD>
#include <gtest/gtest.h>

#include <random>

namespace {

template <int Dim>
Eigen::Matrix<double, Dim, Dim> svd_rotation(const Eigen::Matrix<double, Dim, Dim>& a) {
  Eigen::JacobiSVD<Eigen::Matrix<double, Dim, Dim>> svd(a, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Eigen::Matrix<double, Dim, Dim> fix = Eigen::Matrix<double, Dim, Dim>::Identity();
  fix(Dim - 1, Dim - 1) = (svd.matrixU() * svd.matrixV().transpose()).determinant() < 0 ? -1.0 : 1.0;
  return svd.matrixU() * fix * svd.matrixV().transpose();
}

template <int Dim>
void expect_rotation(const Eigen::Matrix<double, Dim, Dim>& r) {
  ASSERT_TRUE(r.allFinite());
  EXPECT_NEAR((r.transpose() * r - Eigen::Matrix<double, Dim, Dim>::Identity()).norm(), 0.0, 1e-9);
  EXPECT_NEAR(r.determinant(), 1.0, 1e-9);
}

Eigen::Matrix3d rotation_3d(const Eigen::Quaterniond& q) { return q.normalized().toRotationMatrix(); }

TEST(Polar2d, MatchesSvdOnRandomMatricesWithPositiveDeterminant) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-2.0, 2.0);
  for (int trial = 0; trial < 500; ++trial) {
    Eigen::Matrix2d a;
    a << u(rng), u(rng), u(rng), u(rng);
    if (a.determinant() < 1e-3) continue;
    Eigen::Matrix2d r = Eigen::Matrix2d::Identity();
    ASSERT_TRUE(pliant::extract_rotation(a, r));
    EXPECT_NEAR((r - svd_rotation<2>(a)).norm(), 0.0, 1e-9);
  }
}

TEST(Polar3d, MatchesSvdFromAColdStart) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> angle(-1.2, 1.2);
  std::uniform_real_distribution<double> stretch(0.6, 1.6);
  for (int trial = 0; trial < 300; ++trial) {
    const Eigen::Matrix3d rot = (Eigen::AngleAxisd(angle(rng), Eigen::Vector3d::UnitX()) *
                                 Eigen::AngleAxisd(angle(rng), Eigen::Vector3d::UnitY()) *
                                 Eigen::AngleAxisd(angle(rng), Eigen::Vector3d::UnitZ()))
                                    .toRotationMatrix();
    Eigen::Matrix3d s = Eigen::Vector3d(stretch(rng), stretch(rng), stretch(rng)).asDiagonal();
    const Eigen::Matrix3d a = rot * s;
    Eigen::Quaterniond q = Eigen::Quaterniond::Identity();
    ASSERT_TRUE(pliant::extract_rotation(a, q, 64));
    EXPECT_NEAR((rotation_3d(q) - svd_rotation<3>(a)).norm(), 0.0, 1e-6) << "trial " << trial;
  }
}

TEST(Polar3d, WarmStartConvergesInFewIterations) {
  const Eigen::Matrix3d rot = Eigen::AngleAxisd(0.8, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
  const Eigen::Matrix3d a = rot * Eigen::Vector3d(1.2, 0.9, 1.1).asDiagonal();
  Eigen::Quaterniond warm(Eigen::AngleAxisd(0.78, Eigen::Vector3d(1, 2, 3).normalized()));
  ASSERT_TRUE(pliant::extract_rotation(a, warm, 4));
  EXPECT_NEAR((rotation_3d(warm) - svd_rotation<3>(a)).norm(), 0.0, 1e-8);
}

TEST(Polar2d, DegenerateInputsGiveRotations) {
  const Eigen::Matrix2d cases[] = {
      Eigen::Matrix2d::Zero(),
      (Eigen::Matrix2d() << 1, 2, 2, 4).finished(),        // rank 1: collinear cluster
      (Eigen::Matrix2d() << 1, 0, 0, -1).finished(),       // reflection, no rotational content
      (Eigen::Matrix2d() << -1, 0.2, 0.1, -1).finished(),  // inverted by 180 degrees
      (Eigen::Matrix2d() << 1e-300, 0, 0, 1e-300).finished(),
  };
  for (const auto& a : cases) {
    Eigen::Matrix2d r = Eigen::Matrix2d::Identity();
    ASSERT_TRUE(pliant::extract_rotation(a, r));
    expect_rotation<2>(r);
  }
}

TEST(Polar3d, DegenerateInputsGiveRotations) {
  Eigen::Matrix3d flat = Eigen::Matrix3d::Zero();
  flat.topLeftCorner<2, 2>() << 1.1, 0.2, -0.1, 0.9;  // a flat (planar) cluster
  const Eigen::Vector3d u(1, 2, 3);
  const Eigen::Matrix3d cases[] = {
      Eigen::Matrix3d::Zero(),
      flat,
      u * Eigen::Vector3d(0.5, -1, 2).transpose(),             // collinear cluster
      Eigen::Vector3d(1, 1, -1).asDiagonal().toDenseMatrix(),  // inverted (reflection)
      -Eigen::Matrix3d::Identity(),                            // point inversion
      Eigen::Matrix3d::Identity() * 1e-200,
  };
  for (const auto& a : cases) {
    Eigen::Quaterniond q = Eigen::Quaterniond::Identity();
    ASSERT_TRUE(pliant::extract_rotation(a, q));
    expect_rotation<3>(rotation_3d(q));
  }
}

TEST(Polar, NonFiniteInputLeavesTheRotationUnchanged) {
  Eigen::Matrix2d a2 = Eigen::Matrix2d::Identity();
  a2(0, 1) = std::numeric_limits<double>::quiet_NaN();
  Eigen::Matrix2d r2;
  r2 << 0, -1, 1, 0;
  const Eigen::Matrix2d before = r2;
  EXPECT_FALSE(pliant::extract_rotation(a2, r2));
  EXPECT_EQ(r2, before);

  Eigen::Matrix3d a3 = Eigen::Matrix3d::Identity();
  a3(2, 2) = std::numeric_limits<double>::infinity();
  Eigen::Quaterniond q(Eigen::AngleAxisd(0.3, Eigen::Vector3d::UnitZ()));
  const Eigen::Quaterniond q_before = q;
  EXPECT_FALSE(pliant::extract_rotation(a3, q));
  EXPECT_EQ(q.coeffs(), q_before.coeffs());
}

TEST(Polar, FloatAgreesWithDouble) {
  const Eigen::Matrix3d a = Eigen::AngleAxisd(0.5, Eigen::Vector3d(0, 1, 1).normalized()).toRotationMatrix() *
                            Eigen::Vector3d(1.3, 0.8, 1.0).asDiagonal();
  Eigen::Quaterniond qd = Eigen::Quaterniond::Identity();
  Eigen::Quaternionf qf = Eigen::Quaternionf::Identity();
  ASSERT_TRUE(pliant::extract_rotation(a, qd));
  ASSERT_TRUE(pliant::extract_rotation(Eigen::Matrix3f(a.cast<float>()), qf));
  EXPECT_NEAR((qf.toRotationMatrix().cast<double>() - qd.toRotationMatrix()).norm(), 0.0, 1e-5);
}

}  // namespace

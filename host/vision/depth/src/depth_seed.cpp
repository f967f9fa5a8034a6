#include "pliant/vision/depth_seed.hpp"

#include <cmath>
#include <cstdint>
#include <limits>
#include <map>
#include <tuple>

#include <Eigen/Eigenvalues>

#include "pliant/vision/depth_image.hpp"

namespace pliant::vision {

SeededParticles seed_particles(const DepthCloud& cloud, double spacing_m, const Eigen::Isometry3d& camera_to_world,
                               int min_points) {
  if (!(std::isfinite(spacing_m) && spacing_m > 0)) throw DepthError("seed_particles: spacing must be finite and > 0");
  if (min_points < 3) throw DepthError("seed_particles: min_points must be >= 3");
  // Voxel key (z, y, x) so that std::map orders the voxels deterministically.
  using Key = std::tuple<std::int64_t, std::int64_t, std::int64_t>;
  std::map<Key, std::vector<std::size_t>> voxels;
  const double limit = static_cast<double>(std::numeric_limits<std::int32_t>::max());
  for (std::size_t k = 0; k < cloud.points.size(); ++k) {
    const Eigen::Vector3d p = cloud.points[k].cast<double>();
    const Eigen::Vector3d cell = (p / spacing_m).array().floor();
    if (!cell.allFinite() || cell.cwiseAbs().maxCoeff() > limit) continue;
    voxels[Key{static_cast<std::int64_t>(cell.z()), static_cast<std::int64_t>(cell.y()),
               static_cast<std::int64_t>(cell.x())}]
        .push_back(k);
  }
  SeededParticles seeds;
  for (const auto& [key, members] : voxels) {
    if (members.size() < static_cast<std::size_t>(min_points)) continue;
    Eigen::Vector3d mean = Eigen::Vector3d::Zero();
    for (const std::size_t k : members) mean += cloud.points[k].cast<double>();
    mean /= static_cast<double>(members.size());
    Eigen::Matrix3d scatter = Eigen::Matrix3d::Zero();
    std::size_t nearest = members.front();
    double nearest_sq = std::numeric_limits<double>::infinity();
    for (const std::size_t k : members) {
      const Eigen::Vector3d d = cloud.points[k].cast<double>() - mean;
      scatter.noalias() += d * d.transpose();
      if (d.squaredNorm() < nearest_sq) {
        nearest_sq = d.squaredNorm();
        nearest = k;
      }
    }
    Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver;
    solver.computeDirect(scatter);
    Eigen::Vector3d normal = solver.eigenvectors().col(0);
    if (!normal.allFinite() || normal.norm() < 0.5) continue;
    normal.normalize();
    if (normal.dot(mean) > 0) normal = -normal;  // toward the camera at the origin
    seeds.positions.push_back(camera_to_world * cloud.points[nearest].cast<double>());
    seeds.normals.push_back(camera_to_world.linear() * normal);
  }
  if (seeds.positions.empty()) {
    throw DepthError("seed_particles: no voxel of the cloud holds " + std::to_string(min_points) + " points");
  }
  return seeds;
}

host::Recording seeded_plan(const SeededParticles& seeds, double t_s) {
  if (seeds.positions.empty()) throw DepthError("seeded_plan: no seeds");
  host::Recording plan;
  plan.name = "seeded";
  plan.dimension = 3;
  plan.length_unit = "m";
  plan.particle_count = static_cast<int>(seeds.positions.size());
  plan.masses.assign(seeds.positions.size(), 1.0);
  plan.files = {{"particles", "particles.csv"}};
  plan.frame_times_s = {t_s};
  for (const Eigen::Vector3d& p : seeds.positions) {
    for (int d = 0; d < 3; ++d) plan.positions.push_back(p(d));
  }
  plan.rest_positions = plan.positions;
  return plan;
}

}  // namespace pliant::vision

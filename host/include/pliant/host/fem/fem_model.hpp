// Corotational linear FEM on linear tetrahedra: the model (mesh, material, precomputed element
// data) and the element-level operations every solver and estimator builds on.
//
// Units are SI throughout: positions in m, forces in N, Young's modulus in Pa, density in kg/m^3,
// masses in kg, time in s, rayleigh_alpha in 1/s, rayleigh_beta in s, gravity in m/s^2.
// Node-major vectors: a "3n vector" holds x y z of node 0, then node 1, ... (n = node_count()).
//
// Model of the elastic force (stiffness warping, Mueller et al.): for element e with rest corner
// positions X_a and current positions x_a, F = Ds Dm^-1 is the deformation gradient, R the proper
// rotation of its polar decomposition F = R S, and
//     f_e = -R K_e (R^T x_e - X_e),     K_e = E_e * K_e_unit,
// where K_e_unit is the isotropic linear-elastic 12x12 element stiffness for E = 1 Pa and the
// model's Poisson ratio. With S symmetric this force is the exact gradient of the corotated
// energy  V_e (mu |S - I|^2 + lambda/2 tr(S - I)^2), so statics may line-search on it. The
// tangent used by the implicit solvers is the usual corotational approximation R K_e R^T (the
// derivative of R is dropped); it is symmetric positive semi-definite.
//
// Mass is lumped: each element gives a quarter of density * volume to each of its corners.
// Rayleigh damping: D = rayleigh_alpha M + rayleigh_beta K, with K the current R K R^T.
//
// Ownership and thread safety: FemModel owns copies of everything it needs. Const member and
// free functions are safe to call concurrently; setters are not (copy the model per thread when
// estimators vary parameters in parallel). Setters keep the sparsity pattern, so solvers built on
// the model stay valid and pick up the new values at their next call.
#pragma once

#include <array>
#include <vector>

#include <Eigen/Core>
#include <Eigen/SparseCore>

#include "pliant/host/recording.hpp"

namespace pliant::host::fem {

/// Material and environment of a model. Validated by FemModel (std::invalid_argument).
struct FemMaterial {
  /// Pa, > 0. Used for every element when the mesh carries no per-tetrahedron values; ignored
  /// (may stay 0) when TetMesh::youngs_modulus is given.
  double youngs_modulus_pa = 0;
  double poisson_ratio = 0.3;                              ///< dimensionless, in (-1, 0.5)
  double density_kg_m3 = 1000;                             ///< kg/m^3, > 0
  double rayleigh_alpha = 0;                               ///< 1/s, >= 0: mass-proportional damping
  double rayleigh_beta = 0;                                ///< s, >= 0: stiffness-proportional damping
  Eigen::Vector3d gravity_m_s2 = Eigen::Vector3d::Zero();  ///< body acceleration (finite)
};

/// Immutable topology plus per-element precomputation, with cheap pattern-preserving setters.
///
/// Construction is O(n + m) for n nodes and m tetrahedra and throws std::invalid_argument on:
/// empty mesh, sizes not multiples of 3 / 4, indices out of range, a node used by no element,
/// non-finite coordinates, an element with non-positive or negligible volume (volume <= 1e-12
/// times its longest edge cubed; orientation must be positive, det(X1-X0, X2-X0, X3-X0) > 0),
/// Young's modulus <= 0 or non-finite (global or per element), poisson_ratio outside (-1, 0.5),
/// density <= 0, negative Rayleigh coefficients, non-finite gravity.
class FemModel {
 public:
  FemModel(const TetMesh& mesh, const FemMaterial& material);

  int node_count() const { return node_count_; }
  int element_count() const { return static_cast<int>(elements_.size()); }
  int dof_count() const { return 3 * node_count_; }

  /// Rest positions (3n vector, m).
  const Eigen::VectorXd& rest_position_m() const { return rest_; }
  /// Corner node indices of each element, positively oriented.
  const std::vector<std::array<int, 4>>& elements() const { return elements_; }
  /// Element rest volumes (m^3), one per element.
  const Eigen::VectorXd& element_volume_m3() const { return volume_; }
  /// Young's modulus per element (Pa).
  const Eigen::VectorXd& youngs_modulus_pa() const { return youngs_; }
  /// Lumped mass per node (kg), n entries.
  const Eigen::VectorXd& lumped_mass_kg() const { return mass_; }
  double total_mass_kg() const { return mass_.sum(); }
  /// The material as last set (youngs_modulus_pa is the construction-time global value).
  const FemMaterial& material() const { return material_; }
  double poisson_ratio() const { return material_.poisson_ratio; }
  double rayleigh_alpha() const { return material_.rayleigh_alpha; }
  double rayleigh_beta() const { return material_.rayleigh_beta; }
  const Eigen::Vector3d& gravity_m_s2() const { return material_.gravity_m_s2; }

  /// Gradients of the four linear shape functions in the rest configuration (1/m): column a is
  /// grad N_a, so F = sum_a x_a grad N_a^T. Columns sum to zero.
  const Eigen::Matrix<double, 3, 4>& shape_gradients(int element) const {
    return gradients_[static_cast<std::size_t>(element)];
  }
  /// Lame parameters for E = 1 Pa and the current Poisson ratio (dimensionless):
  /// mu = 1 / (2 (1 + nu)), lambda = nu / ((1 + nu)(1 - 2 nu)). Multiply by E_e for element e.
  double unit_mu() const { return unit_mu_; }
  double unit_lambda() const { return unit_lambda_; }
  /// K_e_unit: the 12x12 rest-frame element stiffness for E = 1 Pa (N/m per Pa), corner-major
  /// (rows 3a..3a+2 belong to corner a). The element stiffness is youngs_modulus_pa()[e] times
  /// this. O(1); computed on demand from the shape gradients.
  Eigen::Matrix<double, 12, 12> unit_element_stiffness(int element) const;

  /// Setters. Each validates like the constructor and throws std::invalid_argument, leaving the
  /// model unchanged. O(m) at most; the sparsity pattern never changes.
  void set_youngs_modulus(double youngs_modulus_pa);                                 ///< every element
  void set_youngs_modulus(const Eigen::Ref<const Eigen::VectorXd>& per_element_pa);  ///< m entries
  void set_poisson_ratio(double poisson_ratio);
  void set_density(double density_kg_m3);  ///< recomputes the lumped masses
  void set_rayleigh(double rayleigh_alpha, double rayleigh_beta);
  void set_gravity(const Eigen::Vector3d& gravity_m_s2);
  /// New rest shape (3n vector, m): recomputes shape gradients, volumes and masses. Throws if an
  /// element would have non-positive volume.
  void set_rest_position(const Eigen::Ref<const Eigen::VectorXd>& rest_m);

 private:
  void precompute_geometry(const Eigen::VectorXd& rest);
  void update_lame();

  int node_count_ = 0;
  std::vector<std::array<int, 4>> elements_;
  Eigen::VectorXd rest_;
  Eigen::VectorXd volume_;
  Eigen::VectorXd youngs_;
  Eigen::VectorXd mass_;
  std::vector<Eigen::Matrix<double, 3, 4>> gradients_;
  FemMaterial material_;
  double unit_mu_ = 0;
  double unit_lambda_ = 0;
};

/// The rotation of the polar decomposition F = R S (R proper, det R = +1). Robust for inverted
/// (det F < 0) and degenerate (flat, collinear, collapsed) F: an SVD with the reflection moved to
/// the smallest singular value, so S = R^T F stays symmetric and no NaN is produced for finite F.
/// Well-conditioned F (the usual case) take a scaled Newton iteration, the same factor to
/// rounding. Non-finite F returns the identity. Allocation-free; about 0.1-1 us.
Eigen::Matrix3d polar_rotation(const Eigen::Matrix3d& deformation_gradient);

/// Deformation gradient F = Ds Dm^-1 of `element` at positions x (3n vector, m).
Eigen::Matrix3d deformation_gradient(const FemModel& model, int element,
                                     const Eigen::Ref<const Eigen::VectorXd>& position_m);

/// Corotational elastic (internal) forces at positions x: f = -sum_e R_e K_e (R_e^T x_e - X_e),
/// written into force_n (3n vector, N; resized). The forces of every element sum to zero and
/// have zero net torque about any point. O(m).
void internal_force(const FemModel& model, const Eigen::Ref<const Eigen::VectorXd>& position_m,
                    Eigen::VectorXd& force_n);

/// Corotational elastic energy at positions x (J): sum_e E_e/2 u_e^T K_e_unit u_e with
/// u_e = R_e^T x_e - X_e. Zero for any rigid motion of the rest shape. O(m).
double elastic_energy(const FemModel& model, const Eigen::Ref<const Eigen::VectorXd>& position_m);

/// Kinetic energy 1/2 v^T M v (J) of a 3n velocity vector with the lumped mass.
double kinetic_energy(const FemModel& model, const Eigen::Ref<const Eigen::VectorXd>& velocity_m_s);

/// Potential energy of gravity, -sum_i m_i g . x_i (J), zero at the origin.
double gravity_energy(const FemModel& model, const Eigen::Ref<const Eigen::VectorXd>& position_m);

/// The corotational tangent stiffness sum_e R_e K_e R_e^T at positions x, assembled over all 3n
/// DOFs (N/m, symmetric, compressed column). At the rest shape this is the linear stiffness.
/// For oracles, modal analysis and estimators; the solvers assemble their own. O(m) plus sort.
Eigen::SparseMatrix<double> stiffness_matrix(const FemModel& model,
                                             const Eigen::Ref<const Eigen::VectorXd>& position_m);

}  // namespace pliant::host::fem

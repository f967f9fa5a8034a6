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
// Volumetric locking and the averaged nodal pressure. A linear tetrahedron has one volume
// constraint per element, about five per node, against three degrees of freedom per node: as nu
// approaches 0.5 the mesh cannot keep every element's volume and deform, and it answers far too
// stiff (a coarse bonded cylinder at nu = 0.49 reads E about 30 % low when fitted). With
// FemVolumetric::nodal_average the energy is split into its deviatoric part, kept per element,
// and its volumetric part, integrated at the nodes (averaged nodal pressure, Bonet and Burton
// 1998, "A simple average nodal pressure tetrahedral element for incompressible and nearly
// incompressible dynamic explicit applications", Commun. Numer. Meth. Engng 14):
//     W = sum_e V_e mu_e |dev eps_e|^2  +  sum_a V_a kappa_a theta_a^2 / 2,
//     eps_e = sym(R_e^T F_e) - I,  theta_e = tr eps_e,  kappa = lambda + 2 mu / 3,
//     V_a = sum_{e at a} V_e / 4,  theta_a = sum_{e at a} (V_e / 4) theta_e / V_a,
//     kappa_a = sum_{e at a} (V_e / 4) kappa_e / V_a.
// One volume constraint per node is what the degrees of freedom can carry, so the element does
// not lock. The element then feels the pressure p_e = mean of kappa_a theta_a over its corners:
// f_e = -V_e R sigma b with sigma = 2 mu dev eps + p_e I. The tangent adds, for every node a,
// (kappa_a / V_a) g_a g_a^T with g_a = sum_{e at a} (V_e / 4) R_e b_e, which couples the nodes
// two element rings apart (a wider sparsity pattern than the element formulation's).
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

/// How the volumetric part of the elastic energy is integrated (see the top of this file).
enum class FemVolumetric {
  automatic,      ///< nodal_average when poisson_ratio >= kNodalAverageFromPoisson, else element
  element,        ///< per element: the plain linear tetrahedron, which locks as nu -> 0.5
  nodal_average,  ///< averaged nodal pressure: free of volumetric locking
};

/// Poisson ratio from which FemVolumetric::automatic integrates the volume at the nodes.
inline constexpr double kNodalAverageFromPoisson = 0.45;

const char* to_string(FemVolumetric volumetric);

struct FemMaterial;
/// The formulation a model built from `material` uses: material.volumetric, with automatic
/// resolved from material.poisson_ratio (never automatic).
FemVolumetric resolved_volumetric(const FemMaterial& material);

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
  /// Resolved once, by FemModel's constructor, from the Poisson ratio given there: the choice
  /// fixes the solvers' sparsity pattern, so set_poisson_ratio() never changes it.
  FemVolumetric volumetric = FemVolumetric::automatic;
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
  /// Whether the volumetric energy is integrated at the nodes (the resolved FemVolumetric).
  bool nodal_volumetric() const { return nodal_volumetric_; }
  /// The lambda the element term uses for E = 1 Pa: unit_lambda(), or -2 unit_mu() / 3 when the
  /// volumetric part sits at the nodes (then the element carries only 2 mu dev eps).
  double unit_element_lambda() const { return nodal_volumetric_ ? -2.0 * unit_mu_ / 3.0 : unit_lambda_; }
  /// Nodal volume V_a (m^3, n entries; a quarter of each adjoining element's rest volume) and
  /// nodal bulk modulus kappa_a (Pa, n entries; zero unless nodal_volumetric()).
  const Eigen::VectorXd& node_volume_m3() const { return node_volume_; }
  const Eigen::VectorXd& node_bulk_modulus_pa() const { return node_bulk_; }
  /// Elements at each node, as compressed rows: the elements at node a are
  /// node_elements()[node_element_offsets()[a] .. node_element_offsets()[a + 1]).
  const std::vector<int>& node_element_offsets() const { return node_element_offsets_; }
  const std::vector<int>& node_elements() const { return node_elements_; }
  /// K_e_unit: the 12x12 rest-frame element stiffness for E = 1 Pa (N/m per Pa), corner-major
  /// (rows 3a..3a+2 belong to corner a). The element stiffness is youngs_modulus_pa()[e] times
  /// this. O(1); computed on demand from the shape gradients. With nodal_volumetric() this is
  /// the deviatoric part only; the volumetric part is not an element matrix (see
  /// stiffness_matrix()).
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
  void update_node_bulk();
  void build_node_stars();

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
  bool nodal_volumetric_ = false;
  Eigen::VectorXd node_volume_;
  Eigen::VectorXd node_bulk_;
  std::vector<int> node_element_offsets_;
  std::vector<int> node_elements_;
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

/// With nodal_volumetric(), internal_force, elastic_energy and stiffness_matrix use the split
/// energy at the top of this file (the element part as below with unit_element_lambda()).
///
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

/// The volumetric part of stiffness_matrix() under the nodal formulation, sum_a (kappa_a / V_a)
/// g_a g_a^T (N/m, 3n x 3n); all zeros under the element formulation.
Eigen::SparseMatrix<double> volumetric_stiffness_matrix(const FemModel& model,
                                                        const Eigen::Ref<const Eigen::VectorXd>& position_m);

/// The pressure p_e each element feels at positions x under the nodal formulation (Pa, m
/// entries, positive in tension: the mean of kappa_a theta_a over its corners); all zeros under
/// the element formulation, whose pressure is in its own stress.
Eigen::VectorXd element_pressure_pa(const FemModel& model, const Eigen::Ref<const Eigen::VectorXd>& position_m);

}  // namespace pliant::host::fem

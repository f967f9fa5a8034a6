// Quasi-static estimators of estimate_static.hpp: frame plans, a pool of per-thread models and
// solvers with per-frame warm starts, and the three fits on top.
#include "pliant/host/fem/estimate_static.hpp"

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <exception>
#include <limits>
#include <map>
#include <memory>
#include <stdexcept>
#include <string>
#include <thread>
#include <utility>
#include <vector>

#include <Eigen/Dense>
#include <Eigen/Geometry>

namespace pliant::host::fem {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
using Clock = std::chrono::steady_clock;

std::size_t uz(int i) { return static_cast<std::size_t>(i); }
Eigen::Index ix(std::size_t i) { return static_cast<Eigen::Index>(i); }
Eigen::Index ix(int i) { return static_cast<Eigen::Index>(i); }

struct Timer {
  Clock::time_point wall0 = Clock::now();
  std::clock_t cpu0 = std::clock();
  double wall_s() const { return std::chrono::duration<double>(Clock::now() - wall0).count(); }
  double cpu_s() const { return static_cast<double>(std::clock() - cpu0) / CLOCKS_PER_SEC; }
};

double bounding_box_diagonal(const TetMesh& mesh) {
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity());
  Eigen::Vector3d hi = -lo;
  for (int i = 0; i < mesh.point_count(); ++i) {
    const Eigen::Vector3d p(mesh.points[uz(3 * i)], mesh.points[uz(3 * i + 1)], mesh.points[uz(3 * i + 2)]);
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  return (hi - lo).norm();
}

double robust_scatter(std::vector<double> values) {
  if (values.empty()) return kNaN;
  for (double& v : values) v = std::abs(v);
  const std::size_t mid = values.size() / 2;
  std::nth_element(values.begin(), values.begin() + static_cast<std::ptrdiff_t>(mid), values.end());
  return 1.4826 * values[mid];
}

double rms(const std::vector<double>& values) {
  if (values.empty()) return kNaN;
  double s = 0;
  for (double v : values) s += v * v;
  return std::sqrt(s / static_cast<double>(values.size()));
}

bool contains(const std::vector<int>& sorted, int value) {
  return std::binary_search(sorted.begin(), sorted.end(), value);
}

// Share of a contact force carried by each applied_to node. uniform_traction: consistent nodal
// loads of a uniform traction over the boundary triangles whose three corners are all in
// applied_to (area / 3 to each corner), normalised; equal shares when they span no triangle.
std::vector<double> contact_shares(const TetMesh& mesh, const std::vector<int>& applied_to, LoadSpread spread) {
  const std::size_t k = applied_to.size();
  std::vector<double> shares(k, 1.0 / static_cast<double>(k));
  if (spread == LoadSpread::equal_shares) return shares;
  std::vector<std::array<int, 3>> faces;
  for (int t = 0; t < mesh.tet_count(); ++t) {
    const int* v = &mesh.tetrahedra[uz(4 * t)];
    for (int skip = 0; skip < 4; ++skip) {
      std::array<int, 3> f{};
      int c = 0;
      for (int q = 0; q < 4; ++q) {
        if (q != skip) f[uz(c++)] = v[q];
      }
      std::sort(f.begin(), f.end());
      faces.push_back(f);
    }
  }
  std::sort(faces.begin(), faces.end());
  std::vector<double> area(k, 0.0);
  double total = 0;
  auto point = [&](int i) {
    return Eigen::Vector3d(mesh.points[uz(3 * i)], mesh.points[uz(3 * i + 1)], mesh.points[uz(3 * i + 2)]);
  };
  for (std::size_t i = 0; i < faces.size();) {
    std::size_t j = i + 1;
    while (j < faces.size() && faces[j] == faces[i]) ++j;
    const std::array<int, 3>& f = faces[i];
    if (j - i == 1 && contains(applied_to, f[0]) && contains(applied_to, f[1]) && contains(applied_to, f[2])) {
      const double a = 0.5 * (point(f[1]) - point(f[0])).cross(point(f[2]) - point(f[0])).norm();
      for (int c : f) {
        area[uz(static_cast<int>(std::lower_bound(applied_to.begin(), applied_to.end(), c) - applied_to.begin()))] +=
            a / 3.0;
      }
      total += a;
    }
    i = j;
  }
  if (!(total > 0)) return shares;
  for (std::size_t i = 0; i < k; ++i) shares[i] = area[i] / total;
  return shares;
}

// Adds force_n distributed by `shares` over applied_to, plus the least-squares couple carrying
// torque_nm about the nodes' centroid (add_spread_wrench) when it is nonzero.
void add_contact_load(const Eigen::Vector3d& force_n, const Eigen::Vector3d& torque_nm,
                      const std::vector<int>& applied_to, const std::vector<double>& shares,
                      const Eigen::VectorXd& rest, Eigen::VectorXd& load) {
  for (std::size_t i = 0; i < applied_to.size(); ++i) load.segment<3>(3 * ix(applied_to[i])) += shares[i] * force_n;
  if (torque_nm.squaredNorm() > 0) add_spread_wrench(Eigen::Vector3d::Zero(), torque_nm, applied_to, rest, load);
}

// What one used frame needs, fixed for the whole estimate.
struct FramePlan {
  int frame = 0;
  std::vector<int> driven;          // the frame's driven nodes that are not fixed, ascending
  Eigen::VectorXd driven_position;  // 3 per driven node
  std::vector<int> tracked;         // observed nodes neither fixed nor driven: the compared ones
  Eigen::VectorXd load;             // 3n constant external load, or empty
  std::vector<int> reaction_nodes;  // where the tool force is read (reaction estimator)
};

std::vector<int> select_frames(const FemRecordingProblem& problem, const FrameSelection& selection, bool need_wrench) {
  if (selection.frame_stride < 1) throw std::invalid_argument("estimate: frame_stride must be >= 1");
  if (!(selection.first_time_s <= selection.last_time_s)) {
    throw std::invalid_argument("estimate: first_time_s must not be after last_time_s");
  }
  std::vector<int> used;
  int in_window = 0;
  for (std::size_t f = 0; f < problem.frames.size(); ++f) {
    const FemFrame& frame = problem.frames[f];
    if (frame.time_s < selection.first_time_s || frame.time_s > selection.last_time_s) continue;
    const bool take = in_window % selection.frame_stride == 0;
    ++in_window;
    if (!take) continue;
    if (need_wrench && !frame.has_wrench) continue;
    used.push_back(static_cast<int>(f));
  }
  return used;
}

FramePlan make_plan(const FemRecordingProblem& problem, int f) {
  const FemFrame& frame = problem.frames[uz(f)];
  FramePlan plan;
  plan.frame = f;
  std::vector<Eigen::Vector3d> positions;
  for (std::size_t k = 0; k < frame.driven_nodes.size(); ++k) {
    const int node = frame.driven_nodes[k];
    if (contains(problem.fixed_nodes, node)) continue;  // a fixed node stays fixed
    plan.driven.push_back(node);
    positions.push_back(frame.driven_position_m.segment<3>(3 * ix(k)));
  }
  plan.driven_position.resize(3 * ix(plan.driven.size()));
  for (std::size_t k = 0; k < positions.size(); ++k) plan.driven_position.segment<3>(3 * ix(k)) = positions[k];
  for (int node : frame.observed_nodes) {
    if (contains(problem.fixed_nodes, node) || contains(plan.driven, node)) continue;
    plan.tracked.push_back(node);
  }
  return plan;
}

// Per-thread model copy and one solver per distinct driven set (built on first use).
struct Workspace {
  std::unique_ptr<FemModel> model;
  std::map<std::vector<int>, std::unique_ptr<FemSolver>> solvers;
  long static_solves = 0;
  long newton_iterations = 0;

  FemSolver& solver_for(const std::vector<int>& fixed, const std::vector<int>& driven) {
    auto it = solvers.find(driven);
    if (it == solvers.end()) {
      it = solvers.emplace(driven, std::make_unique<FemSolver>(*model, fixed, driven)).first;
    }
    return *it->second;
  }
};

// One solved parameter value of a frame: the key is what the solution depends on (compliance
// 1 / E for the modulus fits, the force vector for the contact-force fit).
struct MemoEntry {
  Eigen::VectorXd key;
  double youngs_modulus_pa = 0;
  Eigen::VectorXd position;
  Eigen::Vector3d tool_force = Eigen::Vector3d::Zero();
  bool converged = false;
  int newton_iterations = 0;
};

// A frame's current solution (the last one asked for) and its recent solutions: an exact repeat
// is not re-solved, and a new key starts from the affine prediction of the nearest ones.
struct FrameCache {
  Eigen::VectorXd position;
  bool valid = false;
  bool converged = false;
  int newton_iterations = 0;                             // of the solve that produced it
  Eigen::Vector3d tool_force = Eigen::Vector3d::Zero();  // sum of reactions over reaction_nodes
  std::vector<MemoEntry> memo;                           // oldest first

  void use(const MemoEntry& e, bool reused) {
    position = e.position;
    valid = true;
    converged = e.converged;
    (void)reused;
    newton_iterations = e.newton_iterations;
    tool_force = e.tool_force;
  }
};

constexpr std::size_t kMemoSize = 8;

// Warm start for `key` from the memo: the affine (in key) least-squares fit through the nearest
// entries (2 for a scalar key, up to 7 otherwise: a point and its central differences), taken as
// the minimum-norm combination of their positions that reproduces the key. One entry: its
// position, scaled about the rest shape by key / key_entry when through_rest (displacements
// proportional to compliance). Empty when the memo is.
Eigen::VectorXd predict_start(const FrameCache& c, const Eigen::VectorXd& key, const Eigen::VectorXd& rest,
                              bool through_rest) {
  std::vector<std::size_t> order;
  for (std::size_t i = 0; i < c.memo.size(); ++i) {
    if (c.memo[i].converged && c.memo[i].key.size() == key.size()) order.push_back(i);
  }
  if (order.empty()) return {};
  std::sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
    return (c.memo[a].key - key).squaredNorm() < (c.memo[b].key - key).squaredNorm();
  });
  const std::size_t want = key.size() == 1 ? 2 : 7;
  if (order.size() > want) order.resize(want);
  const MemoEntry& nearest = c.memo[order.front()];
  if (order.size() == 1) {
    if (through_rest && key.size() == 1 && nearest.key(0) != 0) {
      return rest + (key(0) / nearest.key(0)) * (nearest.position - rest);
    }
    return nearest.position;
  }
  double scale = 0;
  for (std::size_t i : order) scale = std::max(scale, (c.memo[i].key - key).norm());
  if (!(scale > 0)) return nearest.position;
  const Eigen::Index m = ix(order.size());
  Eigen::MatrixXd conditions(key.size() + 1, m);
  for (Eigen::Index i = 0; i < m; ++i) {
    conditions(0, i) = 1.0;
    conditions.col(i).tail(key.size()) = (c.memo[order[uz(static_cast<int>(i))]].key - key) / scale;
  }
  Eigen::VectorXd target = Eigen::VectorXd::Zero(key.size() + 1);
  target(0) = 1.0;
  const Eigen::VectorXd w = conditions.completeOrthogonalDecomposition().solve(target);
  if (!w.allFinite() || w.cwiseAbs().maxCoeff() > 10) return nearest.position;  // wild extrapolation
  Eigen::VectorXd start = Eigen::VectorXd::Zero(rest.size());
  for (Eigen::Index i = 0; i < m; ++i) start += w(i) * c.memo[order[uz(static_cast<int>(i))]].position;
  return start;
}

// The model of the problem with a uniform Young's modulus (a per-element field is dropped).
FemModel uniform_model(const FemRecordingProblem& problem, double youngs_modulus_pa) {
  TetMesh mesh = problem.mesh;
  mesh.youngs_modulus.clear();
  FemMaterial material = problem.material;
  material.youngs_modulus_pa = youngs_modulus_pa;
  return FemModel(mesh, material);
}

class FramePool {
 public:
  FramePool(const FemRecordingProblem& problem, std::vector<FramePlan> plans, int threads,
            const FemStaticOptions& static_options, double youngs_modulus_pa)
      : problem_(problem), plans_(std::move(plans)), cache_(plans_.size()), static_options_(static_options) {
    if (threads < 1) throw std::invalid_argument("estimate: threads must be >= 1");
    const int count = std::max(1, std::min<int>(threads, static_cast<int>(plans_.size())));
    for (int t = 0; t < count; ++t) {
      auto w = std::make_unique<Workspace>();
      w->model = std::make_unique<FemModel>(uniform_model(problem, youngs_modulus_pa));
      workspaces_.push_back(std::move(w));
    }
    if (static_options_.displacement_tolerance_m <= 0) {
      static_options_.displacement_tolerance_m = 1e-8 * bounding_box_diagonal(problem.mesh);
    }
    rest_ = workspaces_.front()->model->rest_position_m();
    // Nodal force of a displacement tolerance on one element: E x edge x tolerance (per unit E).
    if (static_options_.residual_tolerance_n <= 0) {
      const FemModel& m = *workspaces_.front()->model;
      double edges = 0;
      for (const auto& tet : m.elements()) {
        for (int a = 0; a < 4; ++a) {
          for (int b = a + 1; b < 4; ++b) {
            edges += (rest_.segment<3>(3 * ix(tet[uz(a)])) - rest_.segment<3>(3 * ix(tet[uz(b)]))).norm();
          }
        }
      }
      const double mean_edge = edges / (6.0 * m.element_count());
      residual_tolerance_per_pa_ = 0.1 * mean_edge * static_options_.displacement_tolerance_m;
    }
  }

  const std::vector<FramePlan>& plans() const { return plans_; }
  const std::vector<FrameCache>& cache() const { return cache_; }
  const Eigen::VectorXd& rest() const { return rest_; }
  int thread_count() const { return static_cast<int>(workspaces_.size()); }
  const FemModel& model(int thread) const { return *workspaces_[uz(thread)]->model; }

  // Contiguous block of plans for thread t.
  std::pair<std::size_t, std::size_t> block(int t) const {
    const std::size_t n = plans_.size();
    const std::size_t count = workspaces_.size();
    return {n * uz(t) / count, n * (uz(t) + 1) / count};
  }

  // Solves plan p on thread t's workspace with the given load (3n or empty) at E; `key` is what
  // the solution depends on besides the load (see MemoEntry). An exact repeat of a memo entry is
  // reused. Warm start: predict_start from the plan's memo (through the rest shape when
  // through_rest), else the current solution of `previous` (a plan solved earlier on this
  // thread, -1 for none), else rest; if that fails, once more from the nearest memo entry.
  bool solve(int t, std::size_t p, double youngs_modulus_pa, const Eigen::VectorXd& load, const Eigen::VectorXd& key,
             bool through_rest, long previous, const Eigen::VectorXd* driven_position = nullptr) {
    Workspace& w = *workspaces_[uz(t)];
    const FramePlan& plan = plans_[p];
    FrameCache& c = cache_[p];
    for (const MemoEntry& e : c.memo) {
      if (e.youngs_modulus_pa == youngs_modulus_pa && e.key == key) {
        c.use(e, true);
        return e.converged;
      }
    }
    if (scale_by_modulus_ && driven_position == nullptr && load.size() == 0 &&
        reuse_scaled(c, youngs_modulus_pa, key)) {
      return true;
    }
    w.model->set_youngs_modulus(youngs_modulus_pa);  // O(elements), negligible beside a solve
    Eigen::VectorXd start = predict_start(c, key, rest_, through_rest);
    if (start.size() == 0 && previous >= 0 && cache_[uz(static_cast<int>(previous))].valid) {
      start = cache_[uz(static_cast<int>(previous))].position;
    }
    FemSolver& solver = w.solver_for(problem_.fixed_nodes, plan.driven);
    const Eigen::VectorXd none;
    FemStaticOptions static_options = static_options_;
    if (residual_tolerance_per_pa_ > 0)
      static_options.residual_tolerance_n = residual_tolerance_per_pa_ * youngs_modulus_pa;
    MemoEntry entry;
    entry.key = key;
    entry.youngs_modulus_pa = youngs_modulus_pa;
    for (int attempt = 0; attempt < 2; ++attempt) {
      FemStaticResult result;
      bool ok = false;
      try {
        result = solver.solve_static(driven_position != nullptr ? *driven_position : plan.driven_position,
                                     load.size() != 0 ? load : none, static_options, start);
        ok = result.converged;
      } catch (const std::runtime_error&) {
        ok = false;
      }
      ++w.static_solves;
      w.newton_iterations += result.iterations;
      entry.newton_iterations += result.iterations;
      if (ok || attempt == 1 || c.memo.empty()) {
        entry.converged = ok;
        entry.position = ok ? result.position_m : (result.position_m.size() != 0 ? result.position_m : rest_);
        entry.tool_force = plan.reaction_nodes.empty() || !ok ? Eigen::Vector3d::Zero()
                                                              : net_force(result.reaction_n, plan.reaction_nodes);
        break;
      }
      // Retry from the nearest solved entry.
      std::size_t nearest = 0;
      for (std::size_t i = 1; i < c.memo.size(); ++i) {
        if ((c.memo[i].key - key).squaredNorm() < (c.memo[nearest].key - key).squaredNorm()) nearest = i;
      }
      start = c.memo[nearest].position;
    }
    c.memo.push_back(std::move(entry));
    if (c.memo.size() > kMemoSize) c.memo.erase(c.memo.begin());
    c.use(c.memo.back(), false);
    return c.converged;
  }

  // Prescribed displacements alone (no load, no gravity): f_int(x; E) = E f_int(x; 1), so the
  // equilibrium does not depend on E and the reactions are proportional to it. Then a frame solved
  // once at any E is solved at every E (the fit's other evaluations cost no static solve).
  void set_scale_by_modulus(bool on) { scale_by_modulus_ = on; }

  // Every plan at E with its own constant load. False when a solve failed or did not converge.
  // Key: the compliance 1 / E; through_rest for force loading (displacement proportional to it).
  bool solve_all(double youngs_modulus_pa, bool through_rest) {
    const Eigen::VectorXd key = Eigen::VectorXd::Constant(1, 1.0 / youngs_modulus_pa);
    std::vector<char> ok(workspaces_.size(), 1);
    auto run = [&](int t) {
      try {
        const auto [begin, end] = block(t);
        long previous = -1;
        for (std::size_t p = begin; p < end; ++p) {
          if (!solve(t, p, youngs_modulus_pa, plans_[p].load, key, through_rest, previous)) {
            ok[uz(t)] = 0;  // the evaluation fails; the other frames would be wasted work
            break;
          }
          previous = static_cast<long>(p);
        }
      } catch (const std::exception&) {
        ok[uz(t)] = 0;
      }
    };
    for_each_thread(run);
    return std::all_of(ok.begin(), ok.end(), [](char v) { return v != 0; });
  }

  // Runs fn(t) for every thread index, t = 0 on the calling thread. fn must not throw.
  template <typename Fn>
  void for_each_thread(Fn&& fn) {
    std::vector<std::thread> threads;
    for (int t = 1; t < thread_count(); ++t) threads.emplace_back([&fn, t] { fn(t); });
    fn(0);
    for (std::thread& th : threads) th.join();
  }

  long static_solves() const {
    long s = 0;
    for (const auto& w : workspaces_) s += w->static_solves;
    return s;
  }
  long newton_iterations() const {
    long s = 0;
    for (const auto& w : workspaces_) s += w->newton_iterations;
    return s;
  }

 private:
  const FemRecordingProblem& problem_;
  std::vector<FramePlan> plans_;
  std::vector<FrameCache> cache_;
  std::vector<std::unique_ptr<Workspace>> workspaces_;
  FemStaticOptions static_options_;
  Eigen::VectorXd rest_;
  double residual_tolerance_per_pa_ = 0;  // automatic residual tolerance / E; 0: the caller's
  bool scale_by_modulus_ = false;

  // The frame's converged solution at another E, its reactions scaled to E (set_scale_by_modulus).
  static bool reuse_scaled(FrameCache& c, double youngs_modulus_pa, const Eigen::VectorXd& key) {
    for (const MemoEntry& e : c.memo) {
      if (!e.converged || !(e.youngs_modulus_pa > 0)) continue;
      MemoEntry scaled = e;
      scaled.key = key;
      scaled.youngs_modulus_pa = youngs_modulus_pa;
      scaled.tool_force = (youngs_modulus_pa / e.youngs_modulus_pa) * e.tool_force;
      c.memo.push_back(std::move(scaled));
      if (c.memo.size() > kMemoSize) c.memo.erase(c.memo.begin());
      c.use(c.memo.back(), true);
      return true;
    }
    return false;
  }
};

int position_residual_count(const std::vector<FramePlan>& plans) {
  int count = 0;
  for (const FramePlan& plan : plans) count += 3 * static_cast<int>(plan.tracked.size());
  return count;
}

// Writes position residuals (x_sim - x_tracked) / noise into out starting at `offset`.
void position_residuals(const FemRecordingProblem& problem, const FramePool& pool, double noise_m,
                        std::vector<double>& out, std::size_t offset) {
  std::size_t k = offset;
  for (std::size_t p = 0; p < pool.plans().size(); ++p) {
    const FramePlan& plan = pool.plans()[p];
    const Eigen::VectorXd& x = pool.cache()[p].position;
    const Eigen::VectorXd& observed = problem.frames[uz(plan.frame)].observed_position_m;
    for (int node : plan.tracked) {
      for (int a = 0; a < 3; ++a) {
        const Eigen::Index i = 3 * ix(node) + a;
        out[k++] = (x(i) - observed(i)) / noise_m;
      }
    }
  }
}

void fill_position_rows(const FemRecordingProblem& problem, const FramePool& pool, std::vector<StaticFrameRow>& rows,
                        std::vector<double>& all_coordinates) {
  for (std::size_t p = 0; p < pool.plans().size(); ++p) {
    const FramePlan& plan = pool.plans()[p];
    const FemFrame& frame = problem.frames[uz(plan.frame)];
    const Eigen::VectorXd& x = pool.cache()[p].position;
    StaticFrameRow& row = rows[p];
    row.position_count = static_cast<int>(plan.tracked.size());
    double sum = 0;
    for (int node : plan.tracked) {
      const Eigen::Vector3d d = x.segment<3>(3 * ix(node)) - frame.observed_position_m.segment<3>(3 * ix(node));
      sum += d.squaredNorm();
      for (int a = 0; a < 3; ++a) all_coordinates.push_back(d(a));
    }
    row.position_rms_m = plan.tracked.empty() ? kNaN : std::sqrt(sum / static_cast<double>(plan.tracked.size()));
    row.newton_iterations = pool.cache()[p].newton_iterations;
  }
}

// The solutions at the estimate, for YoungsModulusOptions::keep_frame_positions.
void keep_positions(const FramePool& pool, std::vector<StaticFrameRow>& rows) {
  for (std::size_t p = 0; p < pool.plans().size(); ++p) rows[p].position_m = pool.cache()[p].position;
}

void check_modulus_options(const YoungsModulusOptions& options, double initial) {
  if (!(options.lower_youngs_modulus_pa > 0 && options.lower_youngs_modulus_pa < initial &&
        initial < options.upper_youngs_modulus_pa && std::isfinite(options.upper_youngs_modulus_pa))) {
    throw std::invalid_argument("estimate: need 0 < lower_youngs_modulus_pa < initial < upper_youngs_modulus_pa");
  }
  if (options.position_noise_m < 0 || options.force_noise_n < 0) {
    throw std::invalid_argument("estimate: noise options must be >= 0");
  }
}

FitParameter modulus_parameter(const YoungsModulusOptions& options, double initial) {
  FitParameter p;
  p.name = "youngs_modulus";
  p.initial = initial;
  p.lower = options.lower_youngs_modulus_pa;
  p.upper = options.upper_youngs_modulus_pa;
  p.log_scale = true;
  return p;
}

double initial_modulus(const FemRecordingProblem& problem, const YoungsModulusOptions& options) {
  return options.initial_youngs_modulus_pa > 0 ? options.initial_youngs_modulus_pa : problem.material.youngs_modulus_pa;
}

// Rescaled start (see YoungsModulusOptions::rescale_start). best_scale(E) solves every frame at E
// and returns the least-squares factor s that maps the simulated signal onto the measured one
// (NaN when undefined); the new start is E * s (reactions) or E / s (displacements).
template <typename BestScale>
double rescaled_start(const YoungsModulusOptions& options, double initial, bool displacement_signal,
                      BestScale&& best_scale, int& evaluations) {
  if (!options.rescale_start) return initial;
  const double lo = std::max(options.lower_youngs_modulus_pa, 1e-3 * initial);
  const double hi = std::min(options.upper_youngs_modulus_pa, 1e3 * initial);
  double e = initial;
  int raised = 0;
  for (int round = 0; round < 3; ++round) {
    ++evaluations;
    const double s = best_scale(e);
    if (std::isnan(s) && displacement_signal && raised < 3 && 10 * e < hi) {
      // The solve failed: the measured load crushes the model at this E. Stiffer, and again.
      e *= 10;
      ++raised;
      --round;
      continue;
    }
    if (!(s > 0) || !std::isfinite(s)) break;
    const double next = std::clamp(displacement_signal ? e / s : e * s, lo * 1.000001, hi * 0.999999);
    const bool small = std::abs(next / e - 1.0) < 0.01;
    e = next;
    if (small) break;
  }
  return e;
}

std::string format_kpa(double pa) {
  char buffer[64];
  std::snprintf(buffer, sizeof buffer, "%.4g kPa", pa * 1e-3);
  return buffer;
}

void finish_estimate(YoungsModulusEstimate& e, const YoungsModulusOptions& options, const FitResult& fit,
                     bool solves_converged, const char* what, const Timer& timer) {
  e.fit = fit;
  e.youngs_modulus_pa = fit.values.at(0);
  e.standard_deviation_pa = fit.standard_deviations.at(0);
  e.residual_sigma = fit.residual_sigma;
  // At a bound, judged on the log scale E is fitted on (FitResult::at_bound is relative to the
  // linear range, which for bounds decades apart flags any E near the lower one).
  const double lower = options.lower_youngs_modulus_pa;
  const double upper = options.upper_youngs_modulus_pa;
  const bool at_bound = e.youngs_modulus_pa <= lower * (1 + 1e-6) || e.youngs_modulus_pa >= upper * (1 - 1e-6);
  e.converged = fit.converged && solves_converged && !at_bound;
  e.wall_s = timer.wall_s();
  e.cpu_s = timer.cpu_s();
  e.message = std::string(what) + ": youngs_modulus " + format_kpa(e.youngs_modulus_pa) + " +- " +
              format_kpa(e.standard_deviation_pa) + " from " + std::to_string(e.frames_used) + " frames (" +
              std::to_string(e.residual_count) + " residuals), " + std::to_string(e.iterations) + " iterations, " +
              std::to_string(e.evaluations) + " evaluations, " +
              (e.converged ? "converged"
                           : (!fit.converged ? "not converged (iteration limit)"
                              : at_bound     ? "not converged (at a bound)"
                                             : "not converged (a static solve did not converge)"));
}

}  // namespace

// ---------------------------------------------------------------------------------------------
// (a) force-driven

YoungsModulusEstimate estimate_youngs_modulus_from_force(const FemRecordingProblem& problem,
                                                         const YoungsModulusOptions& options) {
  const Timer timer;
  const std::string label = "estimate_youngs_modulus_from_force(" + problem.name + "): ";
  if (!problem.has_wrench()) throw std::invalid_argument(label + "the recording has no wrench");
  const double initial = initial_modulus(problem, options);
  check_modulus_options(options, initial);
  const std::vector<int> used = select_frames(problem, options.frames, true);
  if (used.empty()) throw std::invalid_argument(label + "no selected frame has a wrench");

  // Loads: the measured wrench spread over applied_to at rest (torque about the rest centroid).
  const FemModel reference = uniform_model(problem, initial);
  const std::vector<double> shares = contact_shares(problem.mesh, problem.applied_to, options.load_spread);
  std::vector<FramePlan> plans;
  for (int f : used) {
    FramePlan plan = make_plan(problem, f);
    const FemFrame& frame = problem.frames[uz(f)];
    plan.load.setZero(reference.dof_count());
    add_contact_load(frame.wrench_force_n, frame.wrench_torque_nm, problem.applied_to, shares,
                     reference.rest_position_m(), plan.load);
    plans.push_back(std::move(plan));
  }
  const int residual_count = position_residual_count(plans);
  if (residual_count == 0) throw std::invalid_argument(label + "no tracked free node in the selected frames");

  FramePool pool(problem, std::move(plans), options.threads, options.static_options, initial);
  const double noise = options.position_noise_m > 0 ? options.position_noise_m : 1e-3;
  int extra_evaluations = 0;
  // Displacement scale: <u_sim, u_tracked> / <u_sim, u_sim> over the compared coordinates.
  const double start = rescaled_start(
      options, initial, true,
      [&](double youngs) {
        if (!pool.solve_all(youngs, true)) return kNaN;
        double su = 0, suu = 0;
        for (std::size_t p = 0; p < pool.plans().size(); ++p) {
          const Eigen::VectorXd& x = pool.cache()[p].position;
          const Eigen::VectorXd& observed = problem.frames[uz(pool.plans()[p].frame)].observed_position_m;
          for (int node : pool.plans()[p].tracked) {
            const Eigen::Vector3d sim = x.segment<3>(3 * ix(node)) - pool.rest().segment<3>(3 * ix(node));
            const Eigen::Vector3d obs = observed.segment<3>(3 * ix(node)) - pool.rest().segment<3>(3 * ix(node));
            su += sim.dot(obs);
            suu += sim.squaredNorm();
          }
        }
        return suu > 0 ? su / suu : kNaN;
      },
      extra_evaluations);
  const ResidualFunction residuals = [&](const std::vector<double>& values, std::vector<double>& r) {
    if (!pool.solve_all(values[0], true)) return false;
    position_residuals(problem, pool, noise, r, 0);
    return true;
  };
  const FitResult fit = fit_least_squares({modulus_parameter(options, start)}, residual_count, residuals, options.fit);

  YoungsModulusEstimate e;
  e.initial_youngs_modulus_pa = initial;
  e.rescaled_start_pa = start;
  e.frames_used = static_cast<int>(pool.plans().size());
  e.residual_count = residual_count;
  e.iterations = fit.iterations;
  const bool solved = pool.solve_all(fit.values.at(0), true);  // the table at the solution
  e.evaluations = fit.evaluations + extra_evaluations + 1;
  e.static_solves = pool.static_solves();
  e.newton_iterations = pool.newton_iterations();
  e.frames.resize(pool.plans().size());
  std::vector<double> coordinates;
  fill_position_rows(problem, pool, e.frames, coordinates);
  for (std::size_t p = 0; p < pool.plans().size(); ++p) {
    const FemFrame& frame = problem.frames[uz(pool.plans()[p].frame)];
    e.frames[p].frame = pool.plans()[p].frame;
    e.frames[p].time_s = frame.time_s;
    e.frames[p].measured_force_n = frame.wrench_force_n;
    e.frames[p].simulated_force_n = frame.wrench_force_n;
  }
  e.position_rms_m = rms(coordinates) * std::sqrt(3.0);
  e.position_noise_m = options.position_noise_m > 0 ? options.position_noise_m : robust_scatter(coordinates);
  if (options.keep_frame_positions) keep_positions(pool, e.frames);
  finish_estimate(e, options, fit, solved, "force-driven fit", timer);
  return e;
}

// ---------------------------------------------------------------------------------------------
// (b) displacement-driven with a measured reaction

namespace {

// Relative shortening between the centroid of applied_to and that of the other constrained nodes.
double nominal_strain(const FemRecordingProblem& problem, const FemFrame& frame, const Eigen::VectorXd& rest) {
  Eigen::Vector3d loaded = Eigen::Vector3d::Zero();
  Eigen::Vector3d loaded_rest = Eigen::Vector3d::Zero();
  for (int node : problem.applied_to) {
    const auto it = std::lower_bound(frame.driven_nodes.begin(), frame.driven_nodes.end(), node);
    Eigen::Vector3d p;
    if (it != frame.driven_nodes.end() && *it == node) {
      p = frame.driven_position_m.segment<3>(3 * ix(static_cast<int>(it - frame.driven_nodes.begin())));
    } else if (contains(problem.fixed_nodes, node)) {
      p = rest.segment<3>(3 * ix(node));
    } else {
      p = frame.observed_position_m.segment<3>(3 * ix(node));
      if (!p.allFinite()) return kNaN;
    }
    loaded += p;
    loaded_rest += rest.segment<3>(3 * ix(node));
  }
  Eigen::Vector3d other = Eigen::Vector3d::Zero();
  Eigen::Vector3d other_rest = Eigen::Vector3d::Zero();
  int count = 0;
  for (int node : problem.fixed_nodes) {
    if (contains(problem.applied_to, node)) continue;
    other += rest.segment<3>(3 * ix(node));
    other_rest += rest.segment<3>(3 * ix(node));
    ++count;
  }
  for (std::size_t k = 0; k < frame.driven_nodes.size(); ++k) {
    const int node = frame.driven_nodes[k];
    if (contains(problem.applied_to, node) || contains(problem.fixed_nodes, node)) continue;
    other += frame.driven_position_m.segment<3>(3 * ix(k));
    other_rest += rest.segment<3>(3 * ix(node));
    ++count;
  }
  if (count == 0 || problem.applied_to.empty()) return kNaN;
  const double n_loaded = static_cast<double>(problem.applied_to.size());
  const double d0 = (loaded_rest / n_loaded - other_rest / count).norm();
  if (!(d0 > 0)) return kNaN;
  return 1.0 - (loaded / n_loaded - other / count).norm() / d0;
}

}  // namespace

YoungsModulusEstimate estimate_youngs_modulus_from_reaction(const FemRecordingProblem& problem,
                                                            const ReactionEstimateOptions& options) {
  const Timer timer;
  const std::string label = "estimate_youngs_modulus_from_reaction(" + problem.name + "): ";
  if (!problem.has_wrench()) throw std::invalid_argument(label + "the recording has no wrench");
  const double initial = initial_modulus(problem, options);
  check_modulus_options(options, initial);
  if (!(options.position_weight >= 0)) throw std::invalid_argument(label + "position_weight must be >= 0");
  if (!(options.max_nominal_strain > 0)) throw std::invalid_argument(label + "max_nominal_strain must be > 0");

  const FemModel reference = uniform_model(problem, initial);
  const bool limit_strain = std::isfinite(options.max_nominal_strain);
  std::vector<FramePlan> plans;
  std::vector<double> strains;
  for (int f : select_frames(problem, options.frames, true)) {
    const FemFrame& frame = problem.frames[uz(f)];
    const double strain = nominal_strain(problem, frame, reference.rest_position_m());
    if (limit_strain) {
      if (!std::isfinite(strain)) {
        throw std::invalid_argument(label + "max_nominal_strain set but the strain of frame " + std::to_string(f) +
                                    " is not computable (applied_to untracked or no other constrained node)");
      }
      if (strain > options.max_nominal_strain) break;
    }
    FramePlan plan = make_plan(problem, f);
    for (int node : problem.applied_to) {
      if (contains(problem.fixed_nodes, node) || contains(plan.driven, node)) plan.reaction_nodes.push_back(node);
    }
    if (plan.reaction_nodes.empty()) plan.reaction_nodes = plan.driven;
    if (plan.reaction_nodes.empty()) {
      throw std::invalid_argument(label + "frame " + std::to_string(f) + " drives no node: nothing carries the load");
    }
    plans.push_back(std::move(plan));
    strains.push_back(strain);
  }
  if (plans.empty()) throw std::invalid_argument(label + "no frame selected (window, wrench, strain limit)");

  // Axes that carry information: measured somewhere above 1 % of the largest measured norm.
  double largest = 0;
  for (const FramePlan& plan : plans) largest = std::max(largest, problem.frames[uz(plan.frame)].wrench_force_n.norm());
  std::vector<int> axes;
  for (int a = 0; a < 3; ++a) {
    double most = 0;
    for (const FramePlan& plan : plans)
      most = std::max(most, std::abs(problem.frames[uz(plan.frame)].wrench_force_n(a)));
    if (most > 0.01 * largest && most > 0) axes.push_back(a);
  }
  if (axes.empty()) throw std::invalid_argument(label + "the measured force is zero in every selected frame");

  const int force_count = static_cast<int>(plans.size() * axes.size());
  const int position_count = options.position_weight > 0 ? position_residual_count(plans) : 0;
  FramePool pool(problem, std::move(plans), options.threads, options.static_options, initial);
  // Without gravity the prescribed displacements alone set the shape (no load is applied here).
  pool.set_scale_by_modulus(problem.material.gravity_m_s2.isZero(0.0));

  // Parameters: youngs_modulus, then (fit_force_offset) one offset per fitted axis.
  Eigen::Vector3d offset = Eigen::Vector3d::Zero();
  auto read_offsets = [&](const std::vector<double>& values) {
    offset.setZero();
    if (options.fit_force_offset) {
      for (std::size_t j = 0; j < axes.size(); ++j) offset(axes[j]) = values[j + 1];
    }
  };
  auto force_residuals = [&](double noise_n, std::vector<double>& r) {
    std::size_t k = 0;
    for (std::size_t p = 0; p < pool.plans().size(); ++p) {
      const Eigen::Vector3d& measured = problem.frames[uz(pool.plans()[p].frame)].wrench_force_n;
      for (int a : axes) r[k++] = (pool.cache()[p].tool_force(a) + offset(a) - measured(a)) / noise_n;
    }
  };
  auto parameters = [&](double youngs, const std::vector<double>* previous) {
    std::vector<FitParameter> list{modulus_parameter(options, youngs)};
    if (options.fit_force_offset) {
      const char* names[3] = {"force_offset_x", "force_offset_y", "force_offset_z"};
      for (std::size_t j = 0; j < axes.size(); ++j) {
        FitParameter q;
        q.name = names[axes[j]];
        q.lower = -largest;
        q.upper = largest;
        q.initial = previous != nullptr ? std::clamp((*previous)[j + 1], -0.999 * largest, 0.999 * largest) : 0.0;
        q.log_scale = false;
        list.push_back(q);
      }
    }
    return list;
  };

  // Force scale: <F_sim, F_measured> / <F_sim, F_sim> over the fitted axes.
  int evaluations = 0;
  const double start = rescaled_start(
      options, initial, false,
      [&](double youngs) {
        if (!pool.solve_all(youngs, false)) return kNaN;
        double sf = 0, sff = 0;
        for (std::size_t p = 0; p < pool.plans().size(); ++p) {
          const Eigen::Vector3d& measured = problem.frames[uz(pool.plans()[p].frame)].wrench_force_n;
          for (int a : axes) {
            sf += pool.cache()[p].tool_force(a) * measured(a);
            sff += pool.cache()[p].tool_force(a) * pool.cache()[p].tool_force(a);
          }
        }
        return sff > 0 ? sf / sff : kNaN;
      },
      evaluations);

  // Stage 1: forces only (the whole fit unless positions are weighted in).
  double force_noise = options.force_noise_n > 0 ? options.force_noise_n : 1.0;
  const ResidualFunction force_only = [&](const std::vector<double>& values, std::vector<double>& r) {
    if (!pool.solve_all(values[0], false)) return false;
    read_offsets(values);
    force_residuals(force_noise, r);
    return true;
  };
  FitResult fit = fit_least_squares(parameters(start, nullptr), force_count, force_only, options.fit);
  int iterations = fit.iterations;
  evaluations += fit.evaluations;

  YoungsModulusEstimate e;
  e.initial_youngs_modulus_pa = initial;
  e.rescaled_start_pa = start;
  double position_noise = options.position_noise_m;
  if (position_count > 0) {
    // Stage 2: forces and positions, each whitened by its noise (estimated at the stage-1 solution
    // when not given), positions weighted by position_weight.
    bool solved = pool.solve_all(fit.values.at(0), false);
    read_offsets(fit.values);
    ++evaluations;
    if (!solved) throw std::runtime_error(label + "a static solve failed at the force-only solution");
    if (options.force_noise_n <= 0) {
      std::vector<double> r(uz(force_count));
      force_residuals(1.0, r);
      force_noise = std::max(robust_scatter(r), 1e-12);
    }
    if (position_noise <= 0) {
      std::vector<double> r(uz(position_count));
      position_residuals(problem, pool, 1.0, r, 0);
      position_noise = std::max(robust_scatter(r), 1e-12);
    }
    const double position_scale = position_noise / std::sqrt(options.position_weight);
    const ResidualFunction combined = [&](const std::vector<double>& values, std::vector<double>& r) {
      if (!pool.solve_all(values[0], false)) return false;
      read_offsets(values);
      force_residuals(force_noise, r);
      position_residuals(problem, pool, position_scale, r, uz(force_count));
      return true;
    };
    const double restart = std::clamp(fit.values.at(0), options.lower_youngs_modulus_pa * 1.000001,
                                      options.upper_youngs_modulus_pa * 0.999999);
    const std::vector<double> previous = fit.values;
    fit = fit_least_squares(parameters(restart, &previous), force_count + position_count, combined, options.fit);
    iterations += fit.iterations;
    evaluations += fit.evaluations;
  }

  e.frames_used = static_cast<int>(pool.plans().size());
  e.residual_count = force_count + position_count;
  e.iterations = iterations;
  const bool solved = pool.solve_all(fit.values.at(0), false);
  read_offsets(fit.values);
  e.force_offset_n = offset;
  e.evaluations = evaluations + 1;
  e.static_solves = pool.static_solves();
  e.newton_iterations = pool.newton_iterations();
  e.frames.resize(pool.plans().size());
  std::vector<double> coordinates;
  fill_position_rows(problem, pool, e.frames, coordinates);
  std::vector<double> force_errors;
  for (std::size_t p = 0; p < pool.plans().size(); ++p) {
    const FemFrame& frame = problem.frames[uz(pool.plans()[p].frame)];
    StaticFrameRow& row = e.frames[p];
    row.frame = pool.plans()[p].frame;
    row.time_s = frame.time_s;
    row.nominal_strain = strains[p];
    row.measured_force_n = frame.wrench_force_n;
    row.simulated_force_n = pool.cache()[p].tool_force + offset;
    for (int a : axes) force_errors.push_back(row.simulated_force_n(a) - row.measured_force_n(a));
  }
  e.force_rms_n = rms(force_errors);
  e.force_noise_n = options.force_noise_n > 0 ? options.force_noise_n : robust_scatter(force_errors);
  e.position_rms_m = rms(coordinates) * std::sqrt(3.0);
  e.position_noise_m = position_count > 0
                           ? position_noise
                           : (options.position_noise_m > 0 ? options.position_noise_m : robust_scatter(coordinates));
  if (options.keep_frame_positions) keep_positions(pool, e.frames);
  finish_estimate(e, options, fit, solved,
                  options.fit_force_offset ? "reaction fit (with force offset)" : "reaction fit", timer);
  return e;
}

// ---------------------------------------------------------------------------------------------
// (f) remote force estimation

namespace {

void check_contact_inputs(const FemRecordingProblem& problem, double youngs_modulus_pa,
                          const ContactForceOptions& options, const std::string& label) {
  if (!(youngs_modulus_pa > 0) || !std::isfinite(youngs_modulus_pa)) {
    throw std::invalid_argument(label + "youngs_modulus_pa must be positive");
  }
  if (problem.applied_to.empty()) throw std::invalid_argument(label + "no contact region (wrench.applied_to)");
  if (options.force_bound_n < 0 || options.probe_travel_bound_m < 0 || options.position_noise_m < 0) {
    throw std::invalid_argument(label + "force_bound_n, probe_travel_bound_m and position_noise_m must be >= 0");
  }
}

// Rigid probe: adds the applied_to nodes that are neither fixed nor driven to the plan's driven set
// (kept ascending), at rest, and reads the tool force there. Returns their slots in the new set.
std::vector<int> attach_probe(const FemRecordingProblem& problem, FramePlan& plan, const std::string& label) {
  std::vector<int> driven = plan.driven;
  for (int node : problem.applied_to) {
    if (!contains(problem.fixed_nodes, node) && !contains(plan.driven, node)) driven.push_back(node);
  }
  std::sort(driven.begin(), driven.end());
  Eigen::VectorXd base(3 * ix(driven.size()));
  std::vector<int> slots;
  for (std::size_t k = 0; k < driven.size(); ++k) {
    const auto it = std::lower_bound(plan.driven.begin(), plan.driven.end(), driven[k]);
    if (it != plan.driven.end() && *it == driven[k]) {
      base.segment<3>(3 * ix(k)) = plan.driven_position.segment<3>(3 * (it - plan.driven.begin()));
    } else {
      base.segment<3>(3 * ix(k)) =
          Eigen::Vector3d(problem.mesh.points[uz(3 * driven[k])], problem.mesh.points[uz(3 * driven[k] + 1)],
                          problem.mesh.points[uz(3 * driven[k] + 2)]);
      slots.push_back(static_cast<int>(k));
    }
  }
  if (slots.empty()) throw std::invalid_argument(label + "every applied_to node is fixed or driven: no probe to move");
  plan.driven = std::move(driven);
  plan.driven_position = std::move(base);
  plan.reaction_nodes = problem.applied_to;
  return slots;
}

// The plans of the selected frames and, for the rigid probe, where the probe sits in each plan's
// driven set (probe_slots[p], one entry per plan; empty for spread_force).
struct ContactPlans {
  std::vector<FramePlan> plans;
  std::vector<std::vector<int>> probe_slots;
};

ContactPlans plan_contact_frames(const FemRecordingProblem& problem, const FrameSelection& selection, bool rigid,
                                 const std::string& label) {
  ContactPlans out;
  for (int f : select_frames(problem, selection, false)) {
    FramePlan plan = make_plan(problem, f);  // tracked: before the probe joins the driven set
    if (rigid) out.probe_slots.push_back(attach_probe(problem, plan, label));
    out.plans.push_back(std::move(plan));
  }
  if (out.plans.empty()) throw std::invalid_argument(label + "no frame selected");
  if (position_residual_count(out.plans) == 0) {
    throw std::invalid_argument(label + "no tracked free node in the selected frames");
  }
  return out;
}

// The per-frame fit of estimate_contact_force. Its unknown u (3 values) is the contact force (N,
// spread over applied_to by contact_shares) or the rigid probe's translation from rest (m); each
// frame's u minimises the whitened misfit of the tracked positions. Threads share the pool (one
// workspace each) and fit disjoint rows.
class ContactFrameFitter {
 public:
  ContactFrameFitter(const FemRecordingProblem& problem, FramePool& pool, const ContactForceOptions& options,
                     double youngs_modulus_pa, std::vector<std::vector<int>> probe_slots)
      : problem_(problem),
        pool_(pool),
        options_(options),
        youngs_modulus_pa_(youngs_modulus_pa),
        rigid_(options.contact == ContactModel::rigid_probe),
        probe_slots_(std::move(probe_slots)),
        shares_(contact_shares(problem.mesh, problem.applied_to, options.load_spread)),
        noise_m_(options.position_noise_m > 0 ? options.position_noise_m : 1e-3),
        node_count_(pool.model(0).node_count()) {
    const double diagonal = bounding_box_diagonal(problem.mesh);
    bound_ = rigid_ ? (options.probe_travel_bound_m > 0 ? options.probe_travel_bound_m : diagonal)
                    : (options.force_bound_n > 0 ? options.force_bound_n : youngs_modulus_pa * diagonal * diagonal);
  }

  // Fits thread t's block of plans in time order, each frame started from the previous one's u
  // (zero for the first); fills their rows. Returns the evaluations spent.
  int fit_block(int t, std::vector<ContactForceFrame>& rows) {
    const auto [begin, end] = pool_.block(t);
    Scratch scratch;
    scratch.load.resize(3 * ix(node_count_));
    Eigen::Vector3d start = Eigen::Vector3d::Zero();
    long previous = -1;
    int evaluations = 0;
    for (std::size_t p = begin; p < end; ++p) {
      const FramePlan& plan = pool_.plans()[p];
      const FemFrame& frame = problem_.frames[uz(plan.frame)];
      ContactForceFrame& row = rows[p];
      row.frame = plan.frame;
      row.time_s = frame.time_s;
      row.has_measurement = frame.has_wrench;
      row.measured_force_n = frame.wrench_force_n;
      row.position_count = static_cast<int>(plan.tracked.size());
      if (plan.tracked.empty()) continue;  // nothing to fit in this frame
      evaluations += fit_frame(t, p, previous, start, scratch, row);
      previous = static_cast<long>(p);
    }
    return evaluations;
  }

 private:
  // Per-thread buffers of the solves: the 3n load (spread_force), the driven positions (rigid).
  struct Scratch {
    Eigen::VectorXd load;
    Eigen::VectorXd driven;
  };

  // One static solve of plan p at u (FramePool::solve: memo, warm start from plan `warm`).
  bool simulate(int t, std::size_t p, const Eigen::VectorXd& u, long warm, Scratch& scratch) {
    if (rigid_) {
      scratch.driven = pool_.plans()[p].driven_position;
      for (int slot : probe_slots_[p]) scratch.driven.segment<3>(3 * ix(slot)) += u;
      return pool_.solve(t, p, youngs_modulus_pa_, Eigen::VectorXd(), u, false, warm, &scratch.driven);
    }
    scratch.load.setZero();
    add_contact_load(Eigen::Vector3d(u), Eigen::Vector3d::Zero(), problem_.applied_to, shares_, pool_.rest(),
                     scratch.load);
    return pool_.solve(t, p, youngs_modulus_pa_, scratch.load, u, false, warm);
  }

  // The three unknowns, each within +-bound, started at `start` (kept inside the bounds).
  std::vector<FitParameter> parameters(const Eigen::Vector3d& start) const {
    std::vector<FitParameter> parameters;
    const char* names[2][3] = {{"force_x", "force_y", "force_z"}, {"probe_dx", "probe_dy", "probe_dz"}};
    for (int a = 0; a < 3; ++a) {
      FitParameter q;
      q.name = names[rigid_ ? 1 : 0][a];
      q.lower = -bound_;
      q.upper = bound_;
      q.initial = std::clamp(start(a), -0.999 * bound_, 0.999 * bound_);
      q.log_scale = false;
      parameters.push_back(q);
    }
    return parameters;
  }

  // Covariance of the force (N^2) from the fit's covariance of u: the same for spread_force; for
  // the rigid probe J C J^T with J = dF/du by central differences (warm-started solves, counted in
  // `extra`). NaN when the fit gave none.
  Eigen::Matrix3d force_covariance(int t, std::size_t p, long warm, const Eigen::Vector3d& u, const FitResult& fit,
                                   Scratch& scratch, int& extra) {
    Eigen::Matrix3d covariance = Eigen::Matrix3d::Constant(kNaN);
    if (fit.covariance.rows() == 3) covariance = fit.covariance;
    if (!rigid_ || !covariance.allFinite()) return covariance;
    const double h = std::max(options_.fit.difference_step, 1e-9) * 2 * bound_;
    Eigen::Matrix3d jacobian;
    for (int a = 0; a < 3; ++a) {
      Eigen::Vector3d du = Eigen::Vector3d::Zero();
      du(a) = h;
      const bool plus_ok = simulate(t, p, Eigen::VectorXd(u + du), warm, scratch);
      const Eigen::Vector3d plus = pool_.cache()[p].tool_force;
      const bool minus_ok = simulate(t, p, Eigen::VectorXd(u - du), warm, scratch);
      const Eigen::Vector3d minus = pool_.cache()[p].tool_force;
      extra += 2;
      jacobian.col(a) =
          plus_ok && minus_ok ? Eigen::Vector3d((plus - minus) / (2 * h)) : Eigen::Vector3d::Constant(kNaN);
    }
    // In place: Eigen evaluates the aliased product through a temporary, and a returned product
    // rounds differently in the last bit (results are compared bit for bit across changes).
    covariance = jacobian * covariance * jacobian.transpose();
    return covariance;
  }

  // Fits plan p (warm-started from plan `warm`, -1 for none) from `start`, fills the row's
  // estimate, leaves the plan's cache at the solution and `start` at its u. Returns the evaluations.
  int fit_frame(int t, std::size_t p, long warm, Eigen::Vector3d& start, Scratch& scratch, ContactForceFrame& row) {
    const FramePlan& plan = pool_.plans()[p];
    const FemFrame& frame = problem_.frames[uz(plan.frame)];
    const ResidualFunction residuals = [&](const std::vector<double>& values, std::vector<double>& r) {
      if (!simulate(t, p, Eigen::Vector3d(values[0], values[1], values[2]).eval(), warm, scratch)) return false;
      const Eigen::VectorXd& x = pool_.cache()[p].position;
      std::size_t k = 0;
      for (int node : plan.tracked) {
        for (int a = 0; a < 3; ++a) {
          const Eigen::Index i = 3 * ix(node) + a;
          r[k++] = (x(i) - frame.observed_position_m(i)) / noise_m_;
        }
      }
      return true;
    };
    const FitResult fit = fit_least_squares(parameters(start), 3 * row.position_count, residuals, options_.fit);
    const Eigen::Vector3d u(fit.values[0], fit.values[1], fit.values[2]);
    int extra = 0;
    const Eigen::Matrix3d covariance = force_covariance(t, p, warm, u, fit, scratch, extra);
    const bool solved = simulate(t, p, Eigen::VectorXd(u), warm, scratch);  // leave the cache at the solution
    row.estimated_force_n = rigid_ ? pool_.cache()[p].tool_force : u;
    if (rigid_) row.probe_displacement_m = u;
    for (int a = 0; a < 3; ++a) row.standard_deviation_n(a) = std::sqrt(covariance(a, a));
    row.iterations = fit.iterations;
    row.evaluations = fit.evaluations + extra + 1;
    const bool at_bound = std::any_of(fit.at_bound.begin(), fit.at_bound.end(), [](bool b) { return b; });
    row.converged = fit.converged && solved && !at_bound;
    start = u;
    return row.evaluations;
  }

  const FemRecordingProblem& problem_;
  FramePool& pool_;
  const ContactForceOptions& options_;
  double youngs_modulus_pa_;
  bool rigid_;
  std::vector<std::vector<int>> probe_slots_;
  std::vector<double> shares_;  // of the force per applied_to node (spread_force)
  double noise_m_;              // whitening of the position residuals
  int node_count_;              // of the model
  double bound_ = 0;            // on each component of u (N or m)
};

// Runs fit_block on every thread of the pool; rethrows a thread's error with `label`. Returns
// the evaluations of all threads.
int fit_frames_on_threads(FramePool& pool, ContactFrameFitter& fitter, std::vector<ContactForceFrame>& rows,
                          const std::string& label) {
  std::vector<int> evaluations(uz(pool.thread_count()), 0);
  std::vector<std::string> errors(uz(pool.thread_count()));
  pool.for_each_thread([&](int t) {
    try {
      evaluations[uz(t)] = fitter.fit_block(t, rows);
    } catch (const std::exception& ex) {
      errors[uz(t)] = ex.what();
    }
  });
  for (const std::string& error : errors) {
    if (!error.empty()) throw std::runtime_error(label + error);
  }
  int total = 0;
  for (int v : evaluations) total += v;
  return total;
}

// Rms distance (m) between simulated and tracked positions of the plan's tracked nodes; appends
// every coordinate difference to `coordinates`.
double tracked_rms(const FramePlan& plan, const FemFrame& frame, const Eigen::VectorXd& x,
                   std::vector<double>& coordinates) {
  double sum = 0;
  for (int node : plan.tracked) {
    const Eigen::Vector3d d = x.segment<3>(3 * ix(node)) - frame.observed_position_m.segment<3>(3 * ix(node));
    sum += d.squaredNorm();
    for (int a = 0; a < 3; ++a) coordinates.push_back(d(a));
  }
  return std::sqrt(sum / static_cast<double>(plan.tracked.size()));
}

// STEPE Table III columns of a row: the estimate projected onto the measured direction, its
// difference from |m| and the relative error. False (row unchanged) without a measurement or
// with |m| = 0.
bool compare_with_measurement(ContactForceFrame& row) {
  const double norm = row.measured_force_n.norm();
  if (!row.has_measurement || !(norm > 0)) return false;
  row.projected_force_n = row.estimated_force_n.dot(row.measured_force_n) / norm;
  row.projected_difference_n = row.projected_force_n - norm;
  row.relative_error = (row.estimated_force_n - row.measured_force_n).norm() / norm;
  return true;
}

// After the fits: per-frame position rms, convergence, the Table III means and the position
// noise (given, or the robust scatter of the residuals).
void summarize_contact_fit(const FemRecordingProblem& problem, const FramePool& pool,
                           const ContactForceOptions& options, ContactForceEstimate& e) {
  std::vector<double> coordinates;
  double measured = 0, estimated = 0, projected = 0, relative = 0;
  e.converged = true;
  for (std::size_t p = 0; p < pool.plans().size(); ++p) {
    const FramePlan& plan = pool.plans()[p];
    ContactForceFrame& row = e.frames[p];
    if (plan.tracked.empty()) {
      e.converged = false;
      row.estimated_force_n.setConstant(kNaN);
      continue;
    }
    e.converged = e.converged && row.converged;
    row.position_rms_m = tracked_rms(plan, problem.frames[uz(plan.frame)], pool.cache()[p].position, coordinates);
    if (compare_with_measurement(row)) {
      ++e.compared_frames;
      measured += row.measured_force_n.norm();
      estimated += row.estimated_force_n.norm();
      projected += row.projected_force_n;
      relative += row.relative_error;
    }
  }
  if (e.compared_frames > 0) {
    const double c = e.compared_frames;
    e.mean_measured_norm_n = measured / c;
    e.mean_estimated_norm_n = estimated / c;
    e.mean_projected_n = projected / c;
    e.mean_difference_n = e.mean_projected_n - e.mean_measured_norm_n;
    e.mean_relative_error = relative / c;
  }
  e.position_noise_m = options.position_noise_m > 0 ? options.position_noise_m : robust_scatter(coordinates);
}

}  // namespace

ContactForceEstimate estimate_contact_force(const FemRecordingProblem& problem, double youngs_modulus_pa,
                                            const ContactForceOptions& options) {
  const Timer timer;
  const std::string label = "estimate_contact_force(" + problem.name + "): ";
  check_contact_inputs(problem, youngs_modulus_pa, options, label);
  ContactPlans plans =
      plan_contact_frames(problem, options.frames, options.contact == ContactModel::rigid_probe, label);
  FramePool pool(problem, std::move(plans.plans), options.threads, options.static_options, youngs_modulus_pa);
  ContactFrameFitter fitter(problem, pool, options, youngs_modulus_pa, std::move(plans.probe_slots));

  ContactForceEstimate e;
  e.youngs_modulus_pa = youngs_modulus_pa;
  e.contact = options.contact;
  e.frames.resize(pool.plans().size());
  e.evaluations = fit_frames_on_threads(pool, fitter, e.frames, label);
  summarize_contact_fit(problem, pool, options, e);
  e.static_solves = pool.static_solves();
  e.wall_s = timer.wall_s();
  e.cpu_s = timer.cpu_s();
  return e;
}

// ---------------------------------------------------------------------------------------------
// tables

std::string format_frame_table(const YoungsModulusEstimate& estimate) {
  std::string out;
  char line[256];
  std::snprintf(line, sizeof line, "%6s %9s %8s %10s %10s %10s %10s %10s %10s %5s %11s %6s\n", "frame", "time_s",
                "strain", "meas_fx_n", "meas_fy_n", "meas_fz_n", "sim_fx_n", "sim_fy_n", "sim_fz_n", "nodes",
                "pos_rms_mm", "newton");
  out += line;
  for (const StaticFrameRow& r : estimate.frames) {
    std::snprintf(line, sizeof line, "%6d %9.3f %8.4f %10.4g %10.4g %10.4g %10.4g %10.4g %10.4g %5d %11.4f %6d\n",
                  r.frame, r.time_s, r.nominal_strain, r.measured_force_n.x(), r.measured_force_n.y(),
                  r.measured_force_n.z(), r.simulated_force_n.x(), r.simulated_force_n.y(), r.simulated_force_n.z(),
                  r.position_count, r.position_rms_m * 1e3, r.newton_iterations);
    out += line;
  }
  return out;
}

std::string format_frame_table(const ContactForceEstimate& estimate) {
  std::string out;
  char line[320];
  std::snprintf(line, sizeof line, "%6s %9s %10s %10s %10s %10s %10s %10s %10s %10s %8s %5s %11s %5s %4s\n", "frame",
                "time_s", "est_fx_n", "est_fy_n", "est_fz_n", "meas_fx_n", "meas_fy_n", "meas_fz_n", "proj_n",
                "delta_n", "rel_err", "nodes", "pos_rms_mm", "evals", "conv");
  out += line;
  for (const ContactForceFrame& r : estimate.frames) {
    std::snprintf(line, sizeof line,
                  "%6d %9.3f %10.4g %10.4g %10.4g %10.4g %10.4g %10.4g %10.4g %10.4g %8.4f %5d %11.4f %5d %4s\n",
                  r.frame, r.time_s, r.estimated_force_n.x(), r.estimated_force_n.y(), r.estimated_force_n.z(),
                  r.measured_force_n.x(), r.measured_force_n.y(), r.measured_force_n.z(), r.projected_force_n,
                  r.projected_difference_n, r.relative_error, r.position_count, r.position_rms_m * 1e3, r.evaluations,
                  r.converged ? "yes" : "no");
    out += line;
  }
  return out;
}

}  // namespace pliant::host::fem

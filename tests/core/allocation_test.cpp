// No-heap proof: every real-time core call, in 2D and 3D, float and double, makes zero heap
// allocations and zero frees.
//
// How: tests/support/counting_allocator.cpp replaces the global operator new/delete (all
// forms) and, on glibc without sanitizers, interposes malloc/calloc/realloc/free/memalign, so
// any heap use by the core -- including Eigen code compiled into pliant::core -- is counted
// while an AllocationCounter is armed. Everything the calls need (model, states, workspaces,
// observations, targets, result storage) is built before arming; gtest assertions run only
// after disarming (a failing assertion allocates its message). Under valgrind's memcheck, which
// replaces the allocator itself, the tests fail in SetUp instead of passing vacuously.
//
// Eigen: this translation unit is compiled with EIGEN_RUNTIME_NO_MALLOC (see allocation.cmake)
// and the counter calls Eigen::internal::set_is_malloc_allowed(false) while armed, so a
// dynamic Eigen allocation made by inline Eigen code in this TU is reported as an
// eigen_violation. pliant::core itself is compiled without EIGEN_RUNTIME_NO_MALLOC; that is
// fine because the core uses only fixed-size Eigen types (Matrix<Scalar, Dim, 1>,
// Matrix<Scalar, Dim, Dim>, Quaternion), which never touch the heap. Should that ever change,
// the malloc interposition above still catches the allocation inside the core, because
// Eigen's aligned_malloc ends in std::malloc.
//
// Defining EIGEN_RUNTIME_NO_MALLOC (and the counting eigen_assert of counting_allocator.hpp)
// in this TU and not in the core's changes only whether Eigen's inline functions check their
// assertions; where the linker merges an inline function instantiated in both, either copy
// computes the same result. The fixed-size code paths shared with the core never call
// check_that_malloc_is_allowed().
#include "support/counting_allocator.hpp"  // first: configures eigen_assert before any Eigen header

#ifndef EIGEN_RUNTIME_NO_MALLOC
#error "allocation_test.cpp must be compiled with EIGEN_RUNTIME_NO_MALLOC (see allocation.cmake)"
#endif

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <limits>
#include <new>
#include <string>
#include <type_traits>
#include <vector>

#include "core/grasp_guard_fixture.hpp"
#include "pliant/core/deformability.hpp"
#include "pliant/core/grasp_guard.hpp"
#include "pliant/core/msm.hpp"
#include "pliant/core/msm_model.hpp"
#include "pliant/core/observations.hpp"
#include "pliant/core/online_deformability.hpp"
#include "pliant/core/tracker.hpp"

namespace pliant {
namespace {

using test::AllocationCounter;
using test::AllocationCounts;

std::string describe(const AllocationCounts& c) {
  std::string text = "news=" + std::to_string(c.news) + " deletes=" + std::to_string(c.deletes) +
                     " mallocs=" + std::to_string(c.mallocs) + " frees=" + std::to_string(c.frees) +
                     " eigen_violations=" + std::to_string(c.eigen_violations);
  if (c.eigen_expression != nullptr) text += std::string(" (first: ") + c.eigen_expression + ")";
  if (!test::malloc_interposed()) text += " [malloc not interposed in this build]";
  return text;
}

// True when an armed counter sees a plain `new`. False when something else owns the allocator
// (e.g. valgrind's memcheck replaces operator new and malloc): a zero count would then prove
// nothing, so every real-time test below checks this first.
bool counter_sees_new() {
  AllocationCounts counts;
  {
    AllocationCounter counter;
    int* volatile probe = new int(3);  // volatile: the allocation cannot be elided
    delete probe;
    counts = counter.stop();
  }
  return counts.news == 1 && counts.deletes == 1;
}

#define EXPECT_NO_HEAP(counts, what) EXPECT_EQ((counts).total(), 0u) << (what) << ": " << describe(counts)

// --- counter sanity: the proof below cannot pass vacuously ------------------------------------

TEST(AllocationCounterSanity, CountsPlainNew) {
  int* volatile pointer = nullptr;  // volatile: the allocation cannot be elided
  AllocationCounts counts;
  {
    AllocationCounter counter;
    pointer = new int(42);
    counts = counter.stop();
  }
  EXPECT_EQ(counts.news, 1u) << describe(counts);
  EXPECT_EQ(counts.total(), 1u) << describe(counts);
  delete pointer;
}

TEST(AllocationCounterSanity, CountsDeleteArrayAndAlignedForms) {
  struct alignas(64) Wide {
    double lane[8];
  };
  AllocationCounts counts;
  {
    AllocationCounter counter;
    double* volatile array = new double[16];
    Wide* volatile wide = new Wide;
    int* volatile nothrow = new (std::nothrow) int(1);
    delete[] array;
    delete wide;
    delete nothrow;
    counts = counter.stop();
  }
  EXPECT_EQ(counts.news, 3u) << describe(counts);
  EXPECT_EQ(counts.deletes, 3u) << describe(counts);
}

TEST(AllocationCounterSanity, CountsStandardContainers) {
  AllocationCounts counts;
  std::vector<double> values;
  {
    AllocationCounter counter;
    values.resize(100);
    counts = counter.stop();
  }
  EXPECT_GE(counts.total(), 1u) << describe(counts);
}

TEST(AllocationCounterSanity, CountsMallocWhenInterposed) {
  if (!test::malloc_interposed()) {
    GTEST_SKIP() << "malloc is not interposed in this build (sanitizer or non-glibc)";
  }
  AllocationCounts counts;
  {
    AllocationCounter counter;
    void* volatile block = std::malloc(64);
    std::free(block);
    counts = counter.stop();
  }
  EXPECT_EQ(counts.mallocs, 1u) << describe(counts);
  EXPECT_EQ(counts.frees, 1u) << describe(counts);
}

TEST(AllocationCounterSanity, CatchesDynamicEigenAllocation) {
  AllocationCounts counts;
  double sum = 0;
  {
    AllocationCounter counter;
    Eigen::VectorXd dynamic = Eigen::VectorXd::Constant(64, 0.5);
    sum = dynamic.sum();
    counts = counter.stop();
  }
  EXPECT_DOUBLE_EQ(sum, 32.0);
  EXPECT_GE(counts.eigen_violations, 1u) << describe(counts);
  if (test::malloc_interposed()) {
    EXPECT_GE(counts.mallocs, 1u) << describe(counts);
  }
}

void allocate_in_progress(void* context, int, int) {
  int* volatile leak_free = new int(1);  // volatile: the allocation cannot be elided
  delete leak_free;
  ++*static_cast<int*>(context);
}

// The counter sees allocations made from inside a pliant::core call (here by a progress
// callback invoked from estimate_deformability), so a zero count below means the core made none.
TEST(AllocationCounterSanity, SeesAllocationsInsideCoreCalls) {
  std::vector<float> rest = {0, 0, 1, 0, 2, 0, 0, 1, 1, 1, 2, 1};
  std::vector<std::uint8_t> fixed = {1, 1, 1, 0, 0, 0};
  const int tool = 4;
  MsmModelConfig<2, float> config;
  config.particle_count = 6;
  config.rest_positions = rest.data();
  config.fixed = fixed.data();
  config.drivable_ids = &tool;
  config.drivable_count = 1;
  std::vector<unsigned char> model_block(msm_model_workspace_size(config));
  Arena model_arena(model_block.data(), model_block.size());
  MsmModel<2, float> model;
  ASSERT_EQ(msm_model_init(model_arena, config, model), Status::ok);
  DeformabilityConfig fit;
  int calls = 0;
  fit.progress = &allocate_in_progress;
  fit.progress_context = &calls;
  std::vector<unsigned char> ws_block(deformability_workspace_size(model, 1, fit));
  Arena ws_arena(ws_block.data(), ws_block.size());
  DeformabilityWorkspace<2, float> workspace;
  ASSERT_EQ(deformability_workspace_init(ws_arena, model, 1, fit, workspace), Status::ok);
  std::vector<double> times = {0.0, 0.1, 0.2};
  std::vector<float> positions;
  for (int k = 0; k < 3; ++k) {
    for (std::size_t i = 0; i < rest.size(); ++i) {
      positions.push_back(rest[i] - (i == 9 ? 0.1f * static_cast<float>(k) : 0.0f));
    }
  }
  DrivenWindow window;
  window.id = tool;
  ObservationSequence<2, float> observations;
  observations.frame_count = 3;
  observations.particle_count = 6;
  observations.times_s = times.data();
  observations.positions = positions.data();
  observations.driven = &window;
  observations.driven_count = 1;
  DeformabilityResult result;
  Status status = Status::not_initialized;
  AllocationCounts counts;
  {
    AllocationCounter counter;
    status = estimate_deformability(model, MsmParams<2, float>{}, observations, fit, workspace, result);
    counts = counter.stop();
  }
  ASSERT_EQ(status, Status::ok);
  ASSERT_GT(calls, 0);
  EXPECT_EQ(counts.news, static_cast<std::size_t>(calls)) << describe(counts);
  EXPECT_EQ(counts.deletes, static_cast<std::size_t>(calls)) << describe(counts);
}

TEST(AllocationCounterSanity, QuietWhenDisarmed) {
  AllocationCounter counter;
  const AllocationCounts before = counter.stop();
  int* volatile pointer = new int(7);
  delete pointer;
  EXPECT_EQ(counter.counts().total(), before.total());
  EXPECT_EQ(before.total(), 0u) << describe(before);
}

// --- the scene: a small press experiment, all memory allocated up front ----------------------

// 2D: 8 columns x 4 rows (the paper's layout); 3D: 4 x 4 x 3. Bottom layer fixed; the
// top-centre particle (`tool`) is pressed down a third of the spacing over 0.5 s and held;
// `helper` is a second drivable top particle used by the msm_step tests. The observations
// are a noise-free truth run (beta 0.4) of the same model, so the estimators have a known
// answer.
template <int Dim, typename Scalar>
struct Scene {
  using Vec = Eigen::Matrix<Scalar, Dim, 1>;
  static constexpr int kFrames = 31;
  static constexpr double kRateHz = 30.0;
  static constexpr double kSpacing = 0.01;
  static constexpr double kTruthBeta = 0.4;

  int cols = Dim == 2 ? 8 : 4;
  int rows = 4;
  int layers = Dim == 2 ? 1 : 3;
  int n = 0;
  int tool = 0;
  int helper = 0;
  std::vector<Scalar> rest;
  std::vector<std::uint8_t> fixed;
  std::vector<int> drivable;
  std::vector<unsigned char> model_block;
  MsmModel<Dim, Scalar> model;

  std::vector<double> times;
  std::vector<Scalar> positions;  // [frame][particle][axis]
  std::vector<Vec> frames;        // same data as vectors, [frame * n + particle]
  std::vector<Vec> tool_targets;  // [frame]
  DrivenWindow window;
  ObservationSequence<Dim, Scalar> observations;

  static constexpr int down_axis() { return Dim - 1; }

  int id(int col, int row, int layer) const { return Dim == 2 ? row * cols + col : (layer * rows + row) * cols + col; }

  Status build() {
    n = cols * rows * layers;
    for (int l = 0; l < layers; ++l) {
      for (int r = 0; r < rows; ++r) {
        for (int c = 0; c < cols; ++c) {
          rest.push_back(static_cast<Scalar>(kSpacing * c));
          if (Dim == 2) {
            rest.push_back(static_cast<Scalar>(kSpacing * r));
          } else {
            rest.push_back(static_cast<Scalar>(kSpacing * r));
            rest.push_back(static_cast<Scalar>(kSpacing * l));
          }
        }
      }
    }
    fixed.assign(static_cast<std::size_t>(n), 0);
    // The bottom layer: row 0 in 2D, layer 0 in 3D.
    for (int i = 0; i < n; ++i) {
      if (rest[static_cast<std::size_t>(i * Dim + down_axis())] == Scalar(0)) fixed[static_cast<std::size_t>(i)] = 1;
    }
    tool = Dim == 2 ? id(cols / 2, rows - 1, 0) : id(cols / 2, rows / 2, layers - 1);
    helper = Dim == 2 ? id(1, rows - 1, 0) : id(0, 0, layers - 1);
    drivable = {tool, helper};

    MsmModelConfig<Dim, Scalar> config;
    config.particle_count = n;
    config.rest_positions = rest.data();
    config.fixed = fixed.data();
    config.drivable_ids = drivable.data();
    config.drivable_count = static_cast<int>(drivable.size());
    config.driven_mass_factor = 2.0;
    const std::size_t model_bytes = msm_model_workspace_size(config);
    if (model_bytes == 0) return Status::invalid_argument;
    model_block.resize(model_bytes);
    Arena arena(model_block.data(), model_block.size());
    const Status built = msm_model_init(arena, config, model);
    if (built != Status::ok) return built;

    // Truth run.
    std::vector<unsigned char> truth_block(msm_state_workspace_size(model));
    Arena truth_arena(truth_block.data(), truth_block.size());
    MsmState<Dim, Scalar> truth;
    const Status state_ok = msm_state_init(truth_arena, model, truth);
    if (state_ok != Status::ok) return state_ok;
    MsmParams<Dim, Scalar> params;
    params.msm_beta = static_cast<Scalar>(kTruthBeta);
    const double dt = 1.0 / kRateHz;
    auto record = [&] {
      for (int i = 0; i < n; ++i) {
        frames.push_back(truth.position[i]);
        for (int d = 0; d < Dim; ++d) positions.push_back(truth.position[i](d));
      }
      tool_targets.push_back(truth.position[tool]);
    };
    times.push_back(0.0);
    record();
    for (int k = 1; k < kFrames; ++k) {
      const double t = k * dt;
      Vec target = model.rest[tool];
      target(down_axis()) -= static_cast<Scalar>(kSpacing / 3.0 * std::min(1.0, t / 0.5));
      MsmStepInput<Dim, Scalar> input;
      input.dt = static_cast<Scalar>(dt);
      input.driven.ids = &tool;
      input.driven.positions = &target;
      input.driven.count = 1;
      const Status stepped = msm_step(model, params, input, truth);
      if (stepped != Status::ok) return stepped;
      times.push_back(t);
      record();
    }
    window.id = tool;  // driven for the whole recording
    observations.frame_count = kFrames;
    observations.particle_count = n;
    observations.times_s = times.data();
    observations.positions = positions.data();
    observations.driven = &window;
    observations.driven_count = 1;
    return Status::ok;
  }

  const Vec* frame(int k) const { return frames.data() + static_cast<std::ptrdiff_t>(k) * n; }
};

template <int D, typename S>
struct Case {
  static constexpr int kDim = D;
  using Scalar = S;
};

template <typename C>
class RealTimeAllocation : public ::testing::Test {
 protected:
  // Distinct names so the test bodies' local Dim / Scalar / Vec / scene do not shadow them.
  static constexpr int kFixtureDim = C::kDim;
  using FixtureScalar = typename C::Scalar;
  using FixtureVec = Eigen::Matrix<FixtureScalar, kFixtureDim, 1>;

  void SetUp() override {
    ASSERT_TRUE(counter_sees_new()) << "the counting allocator is not in effect (running under valgrind?)";
    ASSERT_EQ(scene_.build(), Status::ok);
  }

  // A state in its own block.
  struct OwnedState {
    std::vector<unsigned char> block;
    MsmState<kFixtureDim, FixtureScalar> state;
  };
  void make_state(OwnedState& owned) {
    owned.block.resize(msm_state_workspace_size(scene_.model));
    Arena arena(owned.block.data(), owned.block.size());
    ASSERT_EQ(msm_state_init(arena, scene_.model, owned.state), Status::ok);
  }

  struct OwnedWorkspace {
    std::vector<unsigned char> block;
    DeformabilityWorkspace<kFixtureDim, FixtureScalar> workspace;
  };
  void make_workspace(const DeformabilityConfig& config, OwnedWorkspace& owned) {
    owned.block.resize(deformability_workspace_size(scene_.model, 1, config));
    Arena arena(owned.block.data(), owned.block.size());
    ASSERT_EQ(deformability_workspace_init(arena, scene_.model, 1, config, owned.workspace), Status::ok);
  }

  // estimate_deformability on the scene with default MSM parameters, the heap counted around it.
  Status counted_estimate(const DeformabilityConfig& config, OwnedWorkspace& owned, DeformabilityResult& result,
                          AllocationCounts& counts) const {
    AllocationCounter counter;
    const Status status = estimate_deformability(scene_.model, MsmParams<kFixtureDim, FixtureScalar>{},
                                                 scene_.observations, config, owned.workspace, result);
    counts = counter.stop();
    return status;
  }

  bool state_finite(const MsmState<kFixtureDim, FixtureScalar>& state) const {
    for (int i = 0; i < scene_.n; ++i) {
      if (!state.position[i].allFinite() || !state.velocity[i].allFinite()) return false;
    }
    return true;
  }

  Scene<kFixtureDim, FixtureScalar> scene_;
};

struct CaseNames {
  template <typename C>
  static std::string GetName(int) {
    return std::to_string(C::kDim) + "d_" + (std::is_same<typename C::Scalar, float>::value ? "float" : "double");
  }
};

using Cases = ::testing::Types<Case<2, float>, Case<2, double>, Case<3, float>, Case<3, double>>;
TYPED_TEST_SUITE(RealTimeAllocation, Cases, CaseNames);

void count_progress(void* context, int, int) { ++*static_cast<int*>(context); }

// msm_step with every feature on: two driven targets moving, external forces, gravity,
// damping, plasticity, relaxation, stiffening, support friction and per-cluster beta.
TYPED_TEST(RealTimeAllocation, MsmStepWithAllFeatures) {
  using Scalar = typename TestFixture::FixtureScalar;
  using Vec = typename TestFixture::FixtureVec;
  constexpr int Dim = TestFixture::kFixtureDim;
  const auto& scene = this->scene_;
  typename TestFixture::OwnedState owned;
  this->make_state(owned);
  MsmState<Dim, Scalar>& state = owned.state;

  std::vector<Scalar> cluster_beta(static_cast<std::size_t>(scene.model.cluster_count));
  for (std::size_t c = 0; c < cluster_beta.size(); ++c) {
    cluster_beta[c] =
        static_cast<Scalar>(0.1 + 0.8 * static_cast<double>(c) / static_cast<double>(cluster_beta.size()));
  }
  MsmParams<Dim, Scalar> params;
  params.msm_alpha = Scalar(0.9);
  params.msm_beta = Scalar(0.3);
  params.cluster_beta = cluster_beta.data();
  params.gravity = Vec::Zero();
  params.gravity(Dim - 1) = Scalar(-9.81);
  params.velocity_damping = Scalar(2);
  params.plastic_yield = Scalar(0.01);
  params.plastic_creep = Scalar(5);
  params.plastic_max = Scalar(0.5);
  params.relaxation_fraction = Scalar(0.3);
  params.relaxation_time_s = Scalar(0.5);
  params.stiffening = Scalar(5);
  params.support_friction = Scalar(0.4);
  params.support_normal = Vec::Zero();
  params.support_normal(Dim - 1) = Scalar(1);

  std::vector<Vec> forces(static_cast<std::size_t>(scene.n), Vec::Zero());
  for (int i = 0; i < scene.n; ++i) forces[static_cast<std::size_t>(i)](0) = static_cast<Scalar>(0.01 * (i % 3));

  constexpr int kSteps = 60;
  const int ids[2] = {scene.tool, scene.helper};
  std::vector<Vec> targets(2 * kSteps);
  for (int k = 0; k < kSteps; ++k) {
    const double depth = Scene<Dim, Scalar>::kSpacing * 0.4 * std::sin(0.1 * k);
    targets[static_cast<std::size_t>(2 * k)] = scene.model.rest[scene.tool];
    targets[static_cast<std::size_t>(2 * k)](Dim - 1) -= static_cast<Scalar>(depth);
    targets[static_cast<std::size_t>(2 * k + 1)] = scene.model.rest[scene.helper];
    targets[static_cast<std::size_t>(2 * k + 1)](0) += static_cast<Scalar>(depth);
  }
  std::vector<Status> statuses(kSteps, Status::not_initialized);

  AllocationCounts counts;
  {
    AllocationCounter counter;
    for (int k = 0; k < kSteps; ++k) {
      MsmStepInput<Dim, Scalar> input;
      input.dt = Scalar(1) / Scalar(100);
      input.driven.ids = ids;
      input.driven.positions = targets.data() + 2 * k;
      input.driven.count = 2;
      input.external_force = forces.data();
      statuses[static_cast<std::size_t>(k)] = msm_step(scene.model, params, input, state);
    }
    counts = counter.stop();
  }
  EXPECT_NO_HEAP(counts, "msm_step");
  for (int k = 0; k < kSteps; ++k) EXPECT_EQ(statuses[static_cast<std::size_t>(k)], Status::ok) << "step " << k;
  EXPECT_EQ(state.steps, static_cast<std::uint32_t>(kSteps));
  EXPECT_EQ(state.dropped_targets, 0u);
  EXPECT_TRUE(this->state_finite(state));
  // The plastic path really ran: some cluster yielded.
  bool yielded = false;
  for (int c = 0; c < scene.model.cluster_count; ++c) {
    if (!state.plastic[c].isIdentity(Scalar(1e-4))) yielded = true;
  }
  EXPECT_TRUE(yielded) << "plasticity never engaged; the test does not cover update_plastic";
  bool relaxed = false;
  for (int c = 0; c < scene.model.cluster_count; ++c) {
    if (!state.relaxed[c].isIdentity(Scalar(1e-6))) relaxed = true;
  }
  EXPECT_TRUE(relaxed) << "relaxation never engaged";
}

TYPED_TEST(RealTimeAllocation, MsmStateReset) {
  using Scalar = typename TestFixture::FixtureScalar;
  constexpr int Dim = TestFixture::kFixtureDim;
  const auto& scene = this->scene_;
  typename TestFixture::OwnedState owned;
  this->make_state(owned);
  MsmState<Dim, Scalar>& state = owned.state;
  MsmParams<Dim, Scalar> params;
  params.msm_beta = Scalar(0.5);
  for (int k = 1; k < Scene<Dim, Scalar>::kFrames; ++k) {
    MsmStepInput<Dim, Scalar> input;
    input.dt = Scalar(1) / Scalar(30);
    input.driven.ids = &scene.tool;
    input.driven.positions = &scene.tool_targets[static_cast<std::size_t>(k)];
    input.driven.count = 1;
    ASSERT_EQ(msm_step(scene.model, params, input, state), Status::ok);
  }
  ASSERT_NE(state.position[scene.tool], scene.model.rest[scene.tool]);

  AllocationCounts counts;
  {
    AllocationCounter counter;
    msm_state_reset(scene.model, state);
    counts = counter.stop();
  }
  EXPECT_NO_HEAP(counts, "msm_state_reset");
  EXPECT_EQ(state.steps, 0u);
  for (int i = 0; i < scene.n; ++i) {
    EXPECT_EQ(state.position[i], scene.model.rest[i]) << "particle " << i;
    EXPECT_TRUE(state.velocity[i].isZero(Scalar(0))) << "particle " << i;
  }
}

// Bad inputs are refused or dropped with their documented status, and without heap use.
TYPED_TEST(RealTimeAllocation, MsmStepBadInputs) {
  using Scalar = typename TestFixture::FixtureScalar;
  using Vec = typename TestFixture::FixtureVec;
  constexpr int Dim = TestFixture::kFixtureDim;
  const auto& scene = this->scene_;
  typename TestFixture::OwnedState owned;
  this->make_state(owned);
  MsmState<Dim, Scalar>& state = owned.state;
  MsmParams<Dim, Scalar> params;
  params.msm_beta = Scalar(0.5);
  const Scalar nan = std::numeric_limits<Scalar>::quiet_NaN();
  const Scalar inf = std::numeric_limits<Scalar>::infinity();

  // Move away from rest first so "state unchanged" is a meaningful check.
  for (int k = 1; k < 10; ++k) {
    MsmStepInput<Dim, Scalar> input;
    input.dt = Scalar(1) / Scalar(30);
    input.driven.ids = &scene.tool;
    input.driven.positions = &scene.tool_targets[static_cast<std::size_t>(k)];
    input.driven.count = 1;
    ASSERT_EQ(msm_step(scene.model, params, input, state), Status::ok);
  }
  std::vector<Vec> before(static_cast<std::size_t>(scene.n));
  std::vector<Vec> after_rejections(static_cast<std::size_t>(scene.n));
  const Vec good_target = scene.tool_targets[10];
  Vec nan_target = good_target;
  nan_target(0) = nan;
  Vec inf_target = good_target;
  inf_target(Dim - 1) = -inf;
  std::vector<Vec> nan_forces(static_cast<std::size_t>(scene.n), Vec::Zero());
  nan_forces[static_cast<std::size_t>(scene.n - 1)](0) = nan;
  const std::uint32_t steps0 = state.steps;
  const std::uint32_t dropped0 = state.dropped_targets;
  const std::uint32_t rejected0 = state.rejected_steps;
  std::uint32_t steps_after_rejections = 0;

  Status nan_dt = Status::ok, inf_dt = Status::ok, zero_dt = Status::ok, negative_dt = Status::ok;
  Status nan_force = Status::ok, nan_target_status = Status::ok, inf_target_status = Status::ok;
  AllocationCounts counts;
  {
    AllocationCounter counter;
    for (int i = 0; i < scene.n; ++i) before[static_cast<std::size_t>(i)] = state.position[i];
    MsmStepInput<Dim, Scalar> input;
    input.driven.ids = &scene.tool;
    input.driven.positions = &good_target;
    input.driven.count = 1;
    input.dt = nan;
    nan_dt = msm_step(scene.model, params, input, state);
    input.dt = inf;
    inf_dt = msm_step(scene.model, params, input, state);
    input.dt = Scalar(0);
    zero_dt = msm_step(scene.model, params, input, state);
    input.dt = Scalar(-0.01);
    negative_dt = msm_step(scene.model, params, input, state);
    input.dt = Scalar(1) / Scalar(30);
    input.external_force = nan_forces.data();
    nan_force = msm_step(scene.model, params, input, state);
    for (int i = 0; i < scene.n; ++i) after_rejections[static_cast<std::size_t>(i)] = state.position[i];
    steps_after_rejections = state.steps;
    input.external_force = nullptr;
    input.driven.positions = &nan_target;
    nan_target_status = msm_step(scene.model, params, input, state);
    input.driven.positions = &inf_target;
    inf_target_status = msm_step(scene.model, params, input, state);
    counts = counter.stop();
  }
  EXPECT_NO_HEAP(counts, "msm_step with bad inputs");
  // Rejected steps: invalid_argument for a bad dt, non_finite_input for a bad force; state unchanged.
  EXPECT_EQ(nan_dt, Status::invalid_argument);
  EXPECT_EQ(inf_dt, Status::invalid_argument);
  EXPECT_EQ(zero_dt, Status::invalid_argument);
  EXPECT_EQ(negative_dt, Status::invalid_argument);
  EXPECT_EQ(nan_force, Status::non_finite_input);
  EXPECT_EQ(steps_after_rejections, steps0);
  for (int i = 0; i < scene.n; ++i) {
    EXPECT_EQ(after_rejections[static_cast<std::size_t>(i)], before[static_cast<std::size_t>(i)]) << "particle " << i;
  }
  // Dropped targets: the step runs, the target is counted, the status says non_finite_input.
  EXPECT_EQ(nan_target_status, Status::non_finite_input);
  EXPECT_EQ(inf_target_status, Status::non_finite_input);
  EXPECT_EQ(state.rejected_steps, rejected0 + 5);
  EXPECT_EQ(state.dropped_targets, dropped0 + 2);
  EXPECT_EQ(state.steps, steps0 + 2);
  EXPECT_TRUE(this->state_finite(state)) << "a non-finite input reached the state";
}

TYPED_TEST(RealTimeAllocation, OnlineDeformability) {
  using Scalar = typename TestFixture::FixtureScalar;
  using Vec = typename TestFixture::FixtureVec;
  constexpr int Dim = TestFixture::kFixtureDim;
  const auto& scene = this->scene_;
  OnlineDeformabilityConfig config;
  config.candidates = 11;
  config.forgetting = 0.99;
  config.step_candidates = 2;          // the multi-step rows interpolate targets in the workspace
  config.equilibrium_iterations = 16;  // the quasi-static row keeps its last iteration in the workspace
  std::vector<unsigned char> block(online_deformability_workspace_size(scene.model, config));
  Arena arena(block.data(), block.size());
  OnlineDeformability<Dim, Scalar> estimator;
  ASSERT_EQ(online_deformability_init(arena, scene.model, MsmParams<Dim, Scalar>{}, config, estimator), Status::ok);
  // Run once before the measured pass so the measured reset has real state to clear.
  const Scalar dt = Scalar(1) / Scalar(30);
  MsmDrivenTargets<Dim, Scalar> driven;
  driven.ids = &scene.tool;
  driven.count = 1;
  for (int k = 1; k < Scene<Dim, Scalar>::kFrames; ++k) {
    driven.positions = &scene.tool_targets[static_cast<std::size_t>(k)];
    ASSERT_EQ(online_deformability_update(scene.model, estimator, dt, driven, scene.frame(k)), Status::ok);
  }
  std::vector<Vec> unobserved(static_cast<std::size_t>(scene.n),
                              Vec::Constant(std::numeric_limits<Scalar>::quiet_NaN()));
  std::vector<Status> statuses(Scene<Dim, Scalar>::kFrames, Status::not_initialized);
  OnlineDeformabilityEstimate estimate;
  Status empty = Status::ok, rejected = Status::ok;

  AllocationCounts counts;
  {
    AllocationCounter counter;
    online_deformability_reset(scene.model, estimator);
    for (int k = 1; k < Scene<Dim, Scalar>::kFrames; ++k) {
      driven.positions = &scene.tool_targets[static_cast<std::size_t>(k)];
      statuses[static_cast<std::size_t>(k)] =
          online_deformability_update(scene.model, estimator, dt, driven, scene.frame(k));
    }
    estimate = online_deformability_estimate(estimator);
    empty = online_deformability_update(scene.model, estimator, dt, driven, unobserved.data());
    rejected = online_deformability_update(scene.model, estimator, std::numeric_limits<Scalar>::quiet_NaN(), driven,
                                           scene.frame(1));
    counts = counter.stop();
  }
  EXPECT_NO_HEAP(counts, "online_deformability reset/update/estimate");
  for (int k = 1; k < Scene<Dim, Scalar>::kFrames; ++k)
    EXPECT_EQ(statuses[static_cast<std::size_t>(k)], Status::ok) << k;
  EXPECT_EQ(empty, Status::no_observations);
  EXPECT_EQ(rejected, Status::invalid_argument);
  EXPECT_EQ(estimate.frames, static_cast<std::uint32_t>(Scene<Dim, Scalar>::kFrames - 1));
  const double truth_beta = Scene<Dim, Scalar>::kTruthBeta;
  EXPECT_NEAR(estimate.msm_beta, truth_beta, 0.1);
}

// The tracker: every frame of the scene with a third of the particles occluded and a few
// gross outliers, a frame without observations, a refused frame and a reset.
TYPED_TEST(RealTimeAllocation, Tracker) {
  using Scalar = typename TestFixture::FixtureScalar;
  using Vec = typename TestFixture::FixtureVec;
  constexpr int Dim = TestFixture::kFixtureDim;
  const auto& scene = this->scene_;
  TrackerConfig config;
  std::vector<unsigned char> block(tracker_workspace_size(scene.model, config));
  Arena arena(block.data(), block.size());
  Tracker<Dim, Scalar> tracker;
  MsmParams<Dim, Scalar> params;
  params.msm_beta = Scalar(0.5);
  ASSERT_EQ(tracker_init(arena, scene.model, params, config, tracker), Status::ok);
  // Observations prepared outside the measured region.
  const int frames = Scene<Dim, Scalar>::kFrames;
  std::vector<Vec> observed(static_cast<std::size_t>(frames * scene.n));
  for (int k = 0; k < frames; ++k) {
    for (int i = 0; i < scene.n; ++i) {
      Vec o = scene.frame(k)[i];
      if ((i + k / 10) % 3 == 0) o.setConstant(std::numeric_limits<Scalar>::quiet_NaN());
      if ((i * 7 + k) % 23 == 0) o(0) += Scalar(50) * scene.model.spacing;
      observed[static_cast<std::size_t>(k * scene.n + i)] = o;
    }
  }
  const Scalar dt = Scalar(1) / Scalar(30);
  TrackerFrame<Dim, Scalar> frame;
  frame.dt = dt;
  frame.driven.ids = &scene.tool;
  frame.driven.count = 1;
  std::vector<Status> statuses(static_cast<std::size_t>(frames), Status::not_initialized);
  Status empty = Status::ok, rejected = Status::ok;
  AllocationCounts counts;
  {
    AllocationCounter counter;
    tracker_reset(scene.model, tracker);
    for (int k = 1; k < frames; ++k) {
      frame.driven.positions = &scene.tool_targets[static_cast<std::size_t>(k)];
      frame.observed = observed.data() + static_cast<std::ptrdiff_t>(k) * scene.n;
      statuses[static_cast<std::size_t>(k)] = tracker_update(scene.model, tracker, frame);
    }
    frame.observed = nullptr;
    empty = tracker_update(scene.model, tracker, frame);
    frame.dt = std::numeric_limits<Scalar>::quiet_NaN();
    rejected = tracker_update(scene.model, tracker, frame);
    counts = counter.stop();
  }
  EXPECT_NO_HEAP(counts, "tracker reset/update");
  for (int k = 1; k < frames; ++k) EXPECT_EQ(statuses[static_cast<std::size_t>(k)], Status::ok) << k;
  EXPECT_EQ(empty, Status::no_observations);
  EXPECT_EQ(rejected, Status::invalid_argument);
  EXPECT_GT(tracker.counters.outliers, 0u);
  EXPECT_TRUE(this->state_finite(tracker.state));
}

TYPED_TEST(RealTimeAllocation, EstimateTrajectory) {
  using Scalar = typename TestFixture::FixtureScalar;
  constexpr int Dim = TestFixture::kFixtureDim;
  DeformabilityConfig config;
  config.mode = FitMode::trajectory;
  int progress_calls = 0;
  config.progress = &count_progress;
  config.progress_context = &progress_calls;
  typename TestFixture::OwnedWorkspace owned;
  this->make_workspace(config, owned);
  DeformabilityResult result;
  AllocationCounts counts;
  const Status status = this->counted_estimate(config, owned, result, counts);
  EXPECT_NO_HEAP(counts, "estimate_deformability (trajectory)");
  ASSERT_EQ(status, Status::ok);
  EXPECT_GT(result.evaluations, config.grid_points);
  EXPECT_EQ(progress_calls, result.evaluations);
  const double truth_beta = Scene<Dim, Scalar>::kTruthBeta;
  EXPECT_NEAR(result.msm_beta, truth_beta, 0.05);
}

TYPED_TEST(RealTimeAllocation, EstimateFinalEquilibrium) {
  DeformabilityConfig config;
  config.mode = FitMode::final_equilibrium;
  typename TestFixture::OwnedWorkspace owned;
  this->make_workspace(config, owned);
  DeformabilityResult result;
  AllocationCounts counts;
  const Status status = this->counted_estimate(config, owned, result, counts);
  EXPECT_NO_HEAP(counts, "estimate_deformability (final_equilibrium)");
  ASSERT_EQ(status, Status::ok);
  EXPECT_GT(result.evaluations, config.grid_points);
  EXPECT_GE(result.msm_beta, 0.0);
  EXPECT_LE(result.msm_beta, 1.0);
  EXPECT_TRUE(std::isfinite(result.error));
}

TYPED_TEST(RealTimeAllocation, EstimateWithAlpha) {
  DeformabilityConfig config;
  config.mode = FitMode::trajectory;
  config.estimate_alpha = true;
  typename TestFixture::OwnedWorkspace owned;
  this->make_workspace(config, owned);
  DeformabilityResult result;
  AllocationCounts counts;
  const Status status = this->counted_estimate(config, owned, result, counts);
  EXPECT_NO_HEAP(counts, "estimate_deformability (estimate_alpha)");
  ASSERT_EQ(status, Status::ok);
  EXPECT_GE(result.msm_alpha, config.alpha_min);
  EXPECT_LE(result.msm_alpha, 1.0);
  EXPECT_TRUE(std::isfinite(result.msm_beta));
  EXPECT_GT(result.evaluations, 5 * config.grid_points);
}

// Several MSM steps per frame interval (targets interpolated within it) use the workspace only;
// a count outside 1..max_steps_per_frame is refused before anything runs.
TYPED_TEST(RealTimeAllocation, EstimateWithStepsPerFrame) {
  using Scalar = typename TestFixture::FixtureScalar;
  constexpr int Dim = TestFixture::kFixtureDim;
  const auto& scene = this->scene_;
  DeformabilityConfig config;
  config.mode = FitMode::trajectory;
  config.steps_per_frame = 3;
  typename TestFixture::OwnedWorkspace owned;
  this->make_workspace(config, owned);
  DeformabilityResult result;
  AllocationCounts counts;
  const Status status = this->counted_estimate(config, owned, result, counts);
  EXPECT_NO_HEAP(counts, "estimate_deformability (steps_per_frame 3)");
  ASSERT_EQ(status, Status::ok);
  EXPECT_GE(result.msm_beta, 0.0);
  EXPECT_LE(result.msm_beta, 1.0);
  EXPECT_TRUE(std::isfinite(result.error));
  for (int steps : {0, -1, max_steps_per_frame + 1}) {
    config.steps_per_frame = steps;
    EXPECT_EQ(estimate_deformability(scene.model, MsmParams<Dim, Scalar>{}, scene.observations, config, owned.workspace,
                                     result),
              Status::invalid_argument)
        << steps;
  }
}

TYPED_TEST(RealTimeAllocation, EvaluateDeformabilityError) {
  using Scalar = typename TestFixture::FixtureScalar;
  constexpr int Dim = TestFixture::kFixtureDim;
  const auto& scene = this->scene_;
  DeformabilityConfig trajectory;
  trajectory.mode = FitMode::trajectory;
  DeformabilityConfig final_mode;
  final_mode.mode = FitMode::final_equilibrium;
  typename TestFixture::OwnedWorkspace owned;
  this->make_workspace(trajectory, owned);
  MsmParams<Dim, Scalar> truth;
  truth.msm_beta = static_cast<Scalar>(Scene<Dim, Scalar>::kTruthBeta);
  MsmParams<Dim, Scalar> wrong;
  wrong.msm_beta = Scalar(1);
  TrajectoryError at_truth, at_wrong, at_final;
  Status s_truth = Status::not_initialized, s_wrong = Status::not_initialized, s_final = Status::not_initialized;
  AllocationCounts counts;
  {
    AllocationCounter counter;
    s_truth =
        evaluate_deformability_error(scene.model, truth, scene.observations, trajectory, owned.workspace, at_truth);
    s_wrong =
        evaluate_deformability_error(scene.model, wrong, scene.observations, trajectory, owned.workspace, at_wrong);
    msm_state_reset(scene.model, owned.workspace.state);
    s_final =
        evaluate_deformability_error(scene.model, truth, scene.observations, final_mode, owned.workspace, at_final);
    counts = counter.stop();
  }
  EXPECT_NO_HEAP(counts, "evaluate_deformability_error");
  EXPECT_EQ(s_truth, Status::ok);
  EXPECT_EQ(s_wrong, Status::ok);
  EXPECT_EQ(s_final, Status::ok);
  EXPECT_GT(at_truth.count, 0);
  EXPECT_LT(at_truth.mean_distance, at_wrong.mean_distance);
  EXPECT_TRUE(at_final.converged);
}

// The grasp guard's real-time calls: grasp_guard_update over a grasp that goes through ok,
// limit and stop (a squeeze past the predicted safe closure, NaN and bus-off faults, a stale
// camera, a frozen wrench, slip), grasp_guard_measure_strain per camera frame (one with an
// unobserved particle), the prediction queries, acknowledge and reset.
TYPED_TEST(RealTimeAllocation, GraspGuard) {
  using Scalar = typename TestFixture::FixtureScalar;
  using Vec = typename TestFixture::FixtureVec;
  constexpr int Dim = TestFixture::kFixtureDim;
  test::GuardedObject<Dim, Scalar> object(test::lattice<Dim, Scalar>(6, 4, 3, 0.005));
  GraspGuardConfig config;
  config.nominal_force_n = 4;
  config.prediction_beta_points = 6;
  config.prediction_closure_points = 12;
  config.wrench_frozen_samples = 50;
  ASSERT_EQ(object.build_guard(config), Status::ok);
  GraspGuard<Dim, Scalar>& guard = object.guard;
  const double safe = grasp_guard_strain_safe_closure(guard, 0.3, 0.5);
  ASSERT_GT(safe, 0.0);

  // The whole scenario, prepared before arming.
  constexpr int kCycles = 2000;
  std::vector<GraspGuardInput> inputs(kCycles);
  for (int k = 0; k < kCycles; ++k) {
    GraspGuardInput& in = inputs[static_cast<std::size_t>(k)];
    const double t = 1.0 + 1e-3 * k;
    const double closure = k < 1000 ? std::min(1.3 * safe, safe * k / 600.0) : 0.5 * safe;
    in.now_s = t;
    in.gripper = GripperSample{};
    in.gripper.stamp_s = t;
    in.gripper.width_m = 0.03 - closure;
    in.gripper.force_n = 1.0 + 1000 * closure;
    in.gripper.valid = true;
    in.gripper.bus_off = k >= 1100 && k < 1110;
    if (k >= 1200 && k < 1205) in.gripper.width_m = std::numeric_limits<double>::quiet_NaN();
    in.wrench.stamp_s = t;
    in.wrench.valid = true;
    const bool slipping = k >= 1300 && k < 1500;
    const bool frozen = k >= 1600 && k < 1700;
    for (int d = 0; d < 6; ++d) in.wrench.wrench[d] = frozen ? 0.5 : 0.5 + 1e-4 * std::sin(0.3 * k + d);
    if (slipping) in.wrench.wrench[1] += 0.5 * std::sin(2 * 3.14159265358979 * 40 * 1e-3 * k);
    const bool camera_live = !(k >= 1800 && k < 1950);
    in.deformation.stamp_s = camera_live ? t - 0.02 : 1.0 + 1e-3 * 1799 - 0.02;
    in.deformation.strain = 0.01;
    in.deformation.valid = true;
    in.estimate.stamp_s = t;
    in.estimate.msm_beta = 0.4;
    in.estimate.msm_beta_std = k < 100 ? std::numeric_limits<double>::infinity() : 0.05;
    in.estimate.valid = true;
  }
  std::vector<GraspGuardOutput> outputs(kCycles);
  std::vector<Status> statuses(kCycles, Status::not_initialized);
  std::vector<Vec> squeezed(static_cast<std::size_t>(object.particle_count()));
  for (int i = 0; i < object.particle_count(); ++i) {
    squeezed[static_cast<std::size_t>(i)] = object.model.rest[i];
    squeezed[static_cast<std::size_t>(i)](0) *= Scalar(0.95);
  }
  std::vector<Vec> occluded = squeezed;
  occluded[3](1) = std::numeric_limits<Scalar>::quiet_NaN();
  GraspStrainMeasurement measured, partial;
  Status measured_status = Status::not_initialized, partial_status = Status::not_initialized;
  double predicted = 0, safe_closure = 0;
  GraspGuardOutput after_reset;
  Status after_reset_status = Status::not_initialized;

  AllocationCounts counts;
  {
    AllocationCounter counter;
    for (int k = 0; k < kCycles; ++k) {
      const auto u = static_cast<std::size_t>(k);
      if (k % 33 == 0) {
        measured_status = grasp_guard_measure_strain(object.model, guard, squeezed.data(), measured);
        partial_status = grasp_guard_measure_strain(object.model, guard, occluded.data(), partial);
      }
      statuses[u] = grasp_guard_update(guard, inputs[u], outputs[u]);
      if (k == 1150) grasp_guard_acknowledge_stop(guard);
    }
    predicted = grasp_guard_predicted_strain(guard, 0.5 * safe, 0.0, 1.0);
    safe_closure = grasp_guard_strain_safe_closure(guard, 0.2, 0.6);
    grasp_guard_reset(guard);
    GraspGuardInput next = inputs[kCycles - 1];
    next.now_s += 1e-3;
    next.gripper.stamp_s = next.now_s;
    after_reset_status = grasp_guard_update(guard, next, after_reset);
    counts = counter.stop();
  }
  EXPECT_NO_HEAP(counts, "grasp guard update / measure_strain / reset");
  int seen[3] = {0, 0, 0};
  bool slip = false;
  for (int k = 0; k < kCycles; ++k) {
    const auto u = static_cast<std::size_t>(k);
    EXPECT_EQ(statuses[u], Status::ok) << k;
    ++seen[static_cast<int>(outputs[u].verdict)];
    slip = slip || outputs[u].slip;
  }
  // The scenario really exercised every verdict and the slip cue.
  EXPECT_GT(seen[static_cast<int>(GraspVerdict::ok)], 0);
  EXPECT_GT(seen[static_cast<int>(GraspVerdict::limit)], 0);
  EXPECT_GT(seen[static_cast<int>(GraspVerdict::stop)], 0);
  EXPECT_TRUE(slip);
  EXPECT_EQ(outputs[700].reason, GuardReason::predicted_strain);
  EXPECT_TRUE(outputs[1650].reasons & (1u << static_cast<unsigned>(GuardReason::stale_wrench)));
  EXPECT_EQ(outputs[1900].reason, GuardReason::stale_camera);
  EXPECT_EQ(measured_status, Status::ok);
  EXPECT_NEAR(measured.strain, 0.05, 1e-3);
  EXPECT_EQ(partial_status, Status::ok);
  EXPECT_GT(partial.clusters_skipped, 0);
  EXPECT_GT(predicted, 0.0);
  EXPECT_GT(safe_closure, 0.0);
  EXPECT_EQ(after_reset_status, Status::ok);
  // A new grasp: contact is re-detected at the current width, so the closure starts from 0.
  EXPECT_DOUBLE_EQ(after_reset.closure_m, 0.0);
  EXPECT_DOUBLE_EQ(after_reset.allowed_force_n, config.nominal_force_n);
}

}  // namespace
}  // namespace pliant

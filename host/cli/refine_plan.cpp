#include "refine_plan.hpp"

#include <algorithm>
#include <vector>

#include "exit_status.hpp"

namespace pliant::cli {
namespace {

using host::fem::FemFrame;
using host::fem::FemRecordingProblem;

bool contains(const std::vector<int>& sorted, int value) {
  return std::binary_search(sorted.begin(), sorted.end(), value);
}

std::string trimmed(const std::string& text) {
  const auto first = text.find_first_not_of(" \t");
  if (first == std::string::npos) return "";
  const auto last = text.find_last_not_of(" \t");
  return text.substr(first, last - first + 1);
}

// What the recording offers the estimators.
struct Traits {
  bool usable_wrench = false;          // a wrench sample covers some frame
  bool wrench_on_constrained = false;  // applied_to holds a fixed node, or one driven while the wrench is measured
  bool drives_something = false;       // some frame drives a node
  bool tracked_after_first = false;    // frames >= 1 observe a free (neither fixed nor driven) node
  bool tracked_with_wrench = false;    // frames with a wrench observe a free node
  bool driven_set_constant = true;
};

bool tracks_free_node(const FemRecordingProblem& problem, const FemFrame& frame) {
  for (int node : frame.observed_nodes) {
    if (!contains(problem.fixed_nodes, node) && !contains(frame.driven_nodes, node)) return true;
  }
  return false;
}

Traits traits_of(const FemRecordingProblem& problem) {
  Traits t;
  for (int node : problem.applied_to) t.wrench_on_constrained |= contains(problem.fixed_nodes, node);
  for (std::size_t f = 0; f < problem.frames.size(); ++f) {
    const FemFrame& frame = problem.frames[f];
    const bool wrench = problem.has_wrench() && frame.has_wrench;
    const bool tracked = tracks_free_node(problem, frame);
    t.usable_wrench |= wrench;
    t.drives_something |= !frame.driven_nodes.empty();
    t.tracked_after_first |= f > 0 && tracked;
    t.tracked_with_wrench |= wrench && tracked;
    t.driven_set_constant &= frame.driven_nodes == problem.frames.front().driven_nodes;
    if (wrench) {
      for (int node : problem.applied_to) t.wrench_on_constrained |= contains(frame.driven_nodes, node);
    }
  }
  t.wrench_on_constrained &= t.usable_wrench;
  return t;
}

std::string damping_or_map(const RefinePlan& plan) {
  if (plan.material_map) return "material_map";
  if (plan.rayleigh_alpha && plan.rayleigh_beta) return "rayleigh";
  return plan.rayleigh_alpha ? "rayleigh_alpha" : "rayleigh_beta";
}

void require_known_free(const FemRecordingProblem& problem, const std::string& name, bool requested) {
  if (requested && problem.is_known(name)) {
    throw UsageError(name +
                     " is given in recording.json material (the card copies it unchanged); leave it out of "
                     "--estimate, or remove it from the recording to estimate it");
  }
}

RefineEstimator choose_automatically(const Traits& t, const RefinePlan& plan, std::string& reason) {
  const bool dynamic_only = plan.material_map || plan.rayleigh_alpha || plan.rayleigh_beta;
  if (dynamic_only) {
    if (t.wrench_on_constrained) {
      throw UsageError(damping_or_map(plan) +
                       " needs free motion (the trajectory estimator), but the recording is a displacement-driven "
                       "test: its wrench is the reaction of fixed or driven particles, and a quasi-static test "
                       "carries no damping; estimate youngs_modulus only");
    }
    reason = t.usable_wrench ? damping_or_map(plan) +
                                   " needs the trajectory estimator; the wrench on free particles is applied as a load"
                             : "no wrench, so the motion is fitted as a free trajectory from frame 0";
    return RefineEstimator::trajectory;
  }
  if (t.wrench_on_constrained) {
    reason = "the wrench acts on fixed or driven particles, so it is the reaction of a prescribed displacement";
    return RefineEstimator::reaction;
  }
  if (t.usable_wrench) {
    reason = "the wrench acts on free particles, so it is a load; fitted frame by frame as static equilibria";
    return RefineEstimator::force;
  }
  reason = "no wrench, so the motion is fitted as a free trajectory from frame 0";
  return RefineEstimator::trajectory;
}

// Refuses what the chosen estimator cannot do with this recording, with the reason.
void check_estimator(const FemRecordingProblem& problem, const Traits& t, const RefinePlan& plan) {
  const RefineEstimator e = *plan.estimator;
  const std::string name = std::string("the ") + to_string(e) + " estimator";
  if (e != RefineEstimator::trajectory && (plan.material_map || plan.rayleigh_alpha || plan.rayleigh_beta)) {
    throw UsageError(damping_or_map(plan) + " needs the trajectory estimator: " + name +
                     " fits one youngs_modulus to static equilibria, without damping");
  }
  if (e == RefineEstimator::force) {
    if (!t.usable_wrench) throw UsageError(name + " needs a wrench (wrench.csv) covering some frame");
    if (t.wrench_on_constrained) {
      throw UsageError(name +
                       " applies the wrench to free particles, but wrench.applied_to holds fixed or driven "
                       "particles (use --estimator reaction)");
    }
    if (!t.tracked_with_wrench) {
      throw UsageError(name + " needs tracked free particles (neither fixed nor driven) in frames with a wrench");
    }
  }
  if (e == RefineEstimator::reaction) {
    if (!t.usable_wrench) throw UsageError(name + " needs a wrench (wrench.csv) covering some frame");
    if (!t.wrench_on_constrained && !t.drives_something) {
      throw UsageError(name + " needs driven particles (or a fixed wrench.applied_to) to carry the measured reaction");
    }
  }
  if (e == RefineEstimator::trajectory) {
    if (problem.frames.size() < 3) {
      throw UsageError(name + " needs at least 3 frames (the recording has " + std::to_string(problem.frames.size()) +
                       ")");
    }
    if (!t.tracked_after_first) {
      throw UsageError(name + " needs free particles (neither fixed nor driven) observed after frame 0");
    }
    if (!t.driven_set_constant) {
      throw UsageError(name + " needs the same driven particles in every frame (driven windows start or end here)");
    }
  }
}

}  // namespace

const char* to_string(RefineEstimator estimator) {
  switch (estimator) {
    case RefineEstimator::force: return "force";
    case RefineEstimator::reaction: return "reaction";
    case RefineEstimator::trajectory: return "trajectory";
  }
  return "?";
}

RefineRequest parse_estimate_list(const std::string& text) {
  RefineRequest request;
  request.given = true;
  std::size_t start = 0;
  while (true) {
    const std::size_t comma = text.find(',', start);
    const std::string name =
        trimmed(text.substr(start, comma == std::string::npos ? std::string::npos : comma - start));
    if (name == "youngs_modulus") {
      request.youngs_modulus = true;
    } else if (name == "rayleigh") {
      request.rayleigh_alpha = request.rayleigh_beta = true;
    } else if (name == "rayleigh_alpha") {
      request.rayleigh_alpha = true;
    } else if (name == "rayleigh_beta") {
      request.rayleigh_beta = true;
    } else if (name == "material_map") {
      request.material_map = true;
    } else if (name == "rest_shape") {
      request.rest_shape = true;
    } else if (name.empty()) {
      throw UsageError("--estimate: empty name in '" + text + "'");
    } else {
      throw UsageError("--estimate: unknown name '" + name +
                       "' (known: youngs_modulus, rayleigh, rayleigh_alpha, rayleigh_beta, material_map, rest_shape)");
    }
    if (comma == std::string::npos) break;
    start = comma + 1;
  }
  return request;
}

RefinePlan plan_refine(const FemRecordingProblem& problem, const RefineRequest& request,
                       const std::string& estimator_choice) {
  std::optional<RefineEstimator> forced;
  if (estimator_choice == "force") forced = RefineEstimator::force;
  if (estimator_choice == "reaction") forced = RefineEstimator::reaction;
  if (estimator_choice == "trajectory") forced = RefineEstimator::trajectory;
  if (!forced && estimator_choice != "auto") {
    throw UsageError("--estimator must be auto, force, reaction or trajectory");
  }
  const Traits t = traits_of(problem);

  RefinePlan plan;
  if (request.given) {
    require_known_free(problem, "youngs_modulus", request.youngs_modulus || request.material_map);
    // `rayleigh` names both; one the recording gives is simply held. Named alone, it is refused.
    const bool both = request.rayleigh_alpha && request.rayleigh_beta;
    if (both && problem.is_known("rayleigh_alpha") && problem.is_known("rayleigh_beta")) {
      throw UsageError(
          "rayleigh_alpha and rayleigh_beta are both given in recording.json material; leave rayleigh out "
          "of --estimate");
    }
    if (!both) {
      require_known_free(problem, "rayleigh_alpha", request.rayleigh_alpha);
      require_known_free(problem, "rayleigh_beta", request.rayleigh_beta);
    }
    plan.youngs_modulus = request.youngs_modulus || request.material_map;
    plan.material_map = request.material_map;
    plan.rayleigh_alpha = request.rayleigh_alpha && !problem.is_known("rayleigh_alpha");
    plan.rayleigh_beta = request.rayleigh_beta && !problem.is_known("rayleigh_beta");
    plan.rest_shape = request.rest_shape;
  } else {
    plan.youngs_modulus = !problem.is_known("youngs_modulus");
    std::string ignored;
    const bool dynamic = forced ? *forced == RefineEstimator::trajectory
                                : choose_automatically(t, plan, ignored) == RefineEstimator::trajectory;
    if (dynamic) {
      plan.rayleigh_alpha = !problem.is_known("rayleigh_alpha");
      plan.rayleigh_beta = !problem.is_known("rayleigh_beta");
    }
    if (!plan.fits_material()) {
      throw UsageError("nothing to estimate: recording.json material gives every parameter the " +
                       std::string(dynamic ? "trajectory" : "static") +
                       " estimator fits; ask for --estimate rest_shape to estimate the rest shape");
    }
  }

  if ((plan.rayleigh_alpha || plan.rayleigh_beta) && !plan.youngs_modulus && !problem.is_known("youngs_modulus")) {
    throw UsageError(
        "rayleigh damping is fitted with youngs_modulus known: estimate it too "
        "(--estimate youngs_modulus,rayleigh) or give it in recording.json material");
  }
  if (plan.fits_material()) {
    if (forced) {
      plan.estimator = *forced;
      plan.reason = "chosen with --estimator";
    } else {
      plan.estimator = choose_automatically(t, plan, plan.reason);
    }
    check_estimator(problem, t, plan);
  }
  return plan;
}

void check_rest_shape(const FemRecordingProblem& problem, const RefinePlan& plan, int frame) {
  if (!plan.rest_shape) return;
  const int frames = static_cast<int>(problem.frames.size());
  if (frame < 0 || frame >= frames) {
    throw UsageError("--rest-frame " + std::to_string(frame) + " is out of range (the recording has " +
                     std::to_string(frames) + " frames)");
  }
  const FemFrame& f = problem.frames[static_cast<std::size_t>(frame)];
  const int nodes = problem.mesh.point_count();
  const std::string which = "rest_shape: frame " + std::to_string(frame);
  if (static_cast<int>(f.observed_nodes.size()) != nodes) {
    throw UsageError(which + " observes " + std::to_string(f.observed_nodes.size()) + " of the mesh's " +
                     std::to_string(nodes) + " points; the rest shape needs every point observed");
  }
  if (!f.driven_nodes.empty()) {
    throw UsageError(which + " drives particle " + std::to_string(f.driven_nodes.front()) +
                     " (its support force is unknown); choose a frame where only gravity and the fixed particles act "
                     "(--rest-frame)");
  }
  if (!problem.gravity_declared) {
    throw UsageError("rest_shape needs gravity in recording.json: nothing else makes a resting body sag");
  }
  if (!problem.is_known("density")) {
    throw UsageError("rest_shape needs density in recording.json material (the sag scales with it)");
  }
  if (!plan.youngs_modulus && !problem.is_known("youngs_modulus") && problem.mesh.youngs_modulus.empty()) {
    throw UsageError(
        "rest_shape needs youngs_modulus (the sag scales with 1/E): give it in recording.json material or "
        "estimate it in the same run (--estimate youngs_modulus,rest_shape)");
  }
}

}  // namespace pliant::cli

// diagnose_bench: scores and times `pliant diagnose` (diagnose_recording, default options).
// A plain program, not Google Benchmark: one diagnosis takes seconds, and what matters is
// whether it names the right effect as much as how long it takes. Three sections:
//   a. concealed families (docs/concealed_families.md): per family and case, truth, effect
//      size, verdict, what was named, improvement and runtime; then the confusion matrix truth x
//      found, the effect cases named right, named false alarms and wrong names (an effect named
//      that is not there), the mean held-out improvement on effect cases, and detection against
//      effect size (effect_size.rms_over_noise bins). Answers are read from each case's
//      truth.json after its diagnosis, never before. Default families: our simulator's suite
//      (examples/concealed) and the committed samples of msm-world (MSM model) and CalculiX (FEM
//      and MSM models); `--family` replaces them, e.g. with full generated families.
//   b. detection against effect size: each effect at five amplitudes of its main parameter on a
//      2D and a 3D scene simulated in memory (make_scenario, fixed seeds, noise 0.004 of the
//      spacing), plus no-effect controls, binned by the truth's effect_size.rms_over_noise.
//   c. speed: one diagnosis of a 32-particle x 150-frame 2D recording (budget 10 s) and of a
//      500-particle x 300-frame 3D recording (budget 120 s), wall and CPU time; each also
//      simulated with msm_alpha 0.5 and two steps per frame, so that the baseline fits msm_alpha.
// Usage: diagnose_bench [--quick] [--speed-only] [--suite DIR] [--family LABEL:MODEL:DIR]...
//   --quick       a smaller sweep in b (two amplitudes per effect, one control per scene)
//   --speed-only  section c only
//   --suite DIR   our simulator's suite (default: the source tree's examples/concealed)
//   --family F    a family to score in a, LABEL:MODEL:DIR with MODEL msm or fem (repeatable;
//                 replaces the default families)
// Exit status 0 whatever the scores (it reports, it does not judge); 2 for bad arguments.
#include <algorithm>
#include <array>
#include <chrono>
#include <cstdio>
#include <cstdint>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <map>
#include <stdexcept>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "pliant/host/diagnose/diagnose.hpp"
#include "pliant/host/recording.hpp"
#include "pliant/host/scenarios.hpp"

#ifndef PLIANT_CONCEALED_SUITE_DIR
#error "PLIANT_CONCEALED_SUITE_DIR must name the concealed suite directory"
#endif
#ifndef PLIANT_EXAMPLES_DIR
#error "PLIANT_EXAMPLES_DIR must name the examples directory"
#endif
#ifndef PLIANT_BENCH_BUILD_TYPE
#define PLIANT_BENCH_BUILD_TYPE "unknown"
#endif

namespace {

namespace fs = std::filesystem;
using pliant::host::DiagnoseOptions;
using pliant::host::DiagnoseResult;
using pliant::host::Recording;
using pliant::host::ScenarioOptions;
using pliant::host::ScenarioResult;

// Rows and columns of the confusion matrix: "none" is a consistent verdict; "unknown" is a
// missing_physics verdict without a catalogued effect name, or a diagnosis that threw.
const std::vector<std::string> kLabels = {"none",          "plasticity", "viscosity", "friction", "gravity",
                                          "heterogeneity", "stiffening", "latency",   "unknown"};
const std::vector<std::string> kShortLabels = {"none",   "plast", "visc",    "frict",  "grav",
                                               "hetero", "stiff", "latency", "unknown"};

struct Timed {
  DiagnoseResult result;
  double wall_s = 0;
  double baseline_wall_s = 0;  // until the baseline was fitted (model-form selection included)
  double cpu_s = 0;            // process CPU time (diagnose is single-threaded)
  std::string error;           // what() when diagnose_recording threw
};

Timed timed_diagnose(const Recording& recording, const std::string& model = "msm") {
  Timed timed;
  const auto wall0 = std::chrono::steady_clock::now();
  const std::clock_t cpu0 = std::clock();
  try {
    DiagnoseOptions options;
    options.model = model;
    options.progress = [&](const std::string& stage, int done, int total) {
      if (stage == "baseline" && done == total) {
        timed.baseline_wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall0).count();
      }
    };
    timed.result = pliant::host::diagnose_recording(recording, options);
  } catch (const std::exception& e) {
    timed.error = e.what();
  }
  timed.cpu_s = static_cast<double>(std::clock() - cpu0) / CLOCKS_PER_SEC;
  timed.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall0).count();
  return timed;
}

std::string found_label(const Timed& timed) {
  if (!timed.error.empty()) return "unknown";
  const auto& d = timed.result.diagnosis;
  if (d.verdict == "consistent") return "none";
  const bool known = std::find(kLabels.begin() + 1, kLabels.end() - 1, d.effect) != kLabels.end() - 1;
  return known ? d.effect : "unknown";
}

// effect_size.rms_over_noise of a truth document; -1 when absent or null.
double rms_over_noise(const nlohmann::json& truth) {
  const auto size = truth.find("effect_size");
  if (size == truth.end() || !size->is_object()) return -1.0;
  const auto ratio = size->find("rms_over_noise");
  return ratio != size->end() && ratio->is_number() ? ratio->get<double>() : -1.0;
}

std::string size_text(double ratio) {
  char text[32];
  if (ratio < 0) return "-";
  std::snprintf(text, sizeof text, "%.1f", ratio);
  return text;
}

// Truth x found counts over kLabels.
class Confusion {
 public:
  void add(const std::string& truth, const std::string& found) { ++counts_[{truth, found}]; }
  void print() const {
    std::printf("  %-14s", "truth \\ found");
    for (const std::string& label : kShortLabels) std::printf(" %7s", label.c_str());
    std::printf("\n");
    for (std::size_t row = 0; row + 1 < kLabels.size(); ++row) {
      std::printf("  %-14s", kLabels[row].c_str());
      for (const std::string& column : kLabels) {
        const auto it = counts_.find({kLabels[row], column});
        std::printf(" %7d", it == counts_.end() ? 0 : it->second);
      }
      std::printf("\n");
    }
  }

 private:
  std::map<std::pair<std::string, std::string>, int> counts_;
};

// ---- a. concealed families ------------------------------------------------------------------

struct Family {
  std::string label;
  std::string model;  // msm or fem
  fs::path directory;
};

// Named right, wrong names and misses per effect-size bin of the effect cases.
struct SizeBins {
  static constexpr double kEdges[] = {10.0, 30.0};  // rms/noise: < 10, 10-30, >= 30
  int right[3] = {0, 0, 0};
  int total[3] = {0, 0, 0};
  void add(double ratio, bool named_right) {
    const int bin = ratio < kEdges[0] ? 0 : (ratio < kEdges[1] ? 1 : 2);
    ++total[bin];
    right[bin] += named_right ? 1 : 0;
  }
  void print() const {
    std::printf("  Named right against effect size (rms/noise): < 10: %d/%d, 10-30: %d/%d, >= 30: %d/%d\n", right[0],
                total[0], right[1], total[1], right[2], total[2]);
  }
};

void concealed_family(const Family& family) {
  std::vector<fs::path> cases;
  std::error_code error;
  for (fs::directory_iterator it(family.directory, error), end; !error && it != end; it.increment(error)) {
    const std::string name = it->path().filename().string();
    if (it->is_directory() && name.rfind("case_", 0) == 0 && fs::exists(it->path() / "recording.json")) {
      cases.push_back(it->path());
    }
  }
  std::sort(cases.begin(), cases.end());
  std::printf("== a. Family %s, model %s: %zu cases in %s\n", family.label.c_str(), family.model.c_str(), cases.size(),
              family.directory.string().c_str());
  if (cases.empty()) {
    std::printf("  no case_* directory with a recording.json; section skipped\n\n");
    return;
  }
  std::printf("  %-8s %-16s %-13s %9s  %-15s %-13s %7s %8s %8s\n", "case", "scenario", "truth", "rms/noise", "verdict",
              "found", "improv", "wall s", "cpu s");
  Confusion confusion;
  SizeBins bins;
  int none_cases = 0, named_false_alarms = 0, unknown_on_none = 0, effect_cases = 0, named_right = 0, wrong_names = 0;
  double improvement_sum = 0, wall_total = 0, cpu_total = 0, wall_max = 0;
  for (const fs::path& dir : cases) {
    const std::string name = dir.filename().string();
    Timed timed;
    try {
      timed = timed_diagnose(pliant::host::read_recording(dir.string()), family.model);
    } catch (const std::exception& e) {
      timed.error = e.what();
    }
    std::ifstream in(dir / "truth.json");
    const nlohmann::json truth = nlohmann::json::parse(in, nullptr, false);
    const std::string effect = truth.is_object() ? truth.value("effect", "?") : "?";
    const std::string found = found_label(timed);
    const bool named = found != "none" && found != "unknown";
    const auto& d = timed.result.diagnosis;
    confusion.add(effect, found);
    if (effect == "none") {
      ++none_cases;
      named_false_alarms += named ? 1 : 0;
      unknown_on_none += found == "unknown" ? 1 : 0;
    } else {
      ++effect_cases;
      named_right += found == effect ? 1 : 0;
      wrong_names += named && found != effect ? 1 : 0;
      improvement_sum += found == effect ? d.improvement : 0.0;
      bins.add(truth.is_object() ? rms_over_noise(truth) : -1, found == effect);
    }
    wall_total += timed.wall_s;
    cpu_total += timed.cpu_s;
    wall_max = std::max(wall_max, timed.wall_s);
    std::printf("  %-8s %-16s %-13s %9s  %-15s %-13s %7.3f %8.2f %8.2f%s%s\n", name.c_str(),
                truth.is_object() ? truth.value("scenario", "?").c_str() : "?", effect.c_str(),
                size_text(truth.is_object() ? rms_over_noise(truth) : -1).c_str(),
                timed.error.empty() ? d.verdict.c_str() : "error", d.effect.c_str(), d.improvement, timed.wall_s,
                timed.cpu_s, timed.error.empty() ? "" : "  error: ", timed.error.c_str());
    std::fflush(stdout);
  }
  std::printf("\n  Confusion matrix (rows: truth, columns: found; none = consistent verdict):\n");
  confusion.print();
  std::printf("\n  Effect named right: %d / %d effect cases (issue 15 asks >= 90 %%)\n", named_right, effect_cases);
  std::printf("  Named false alarms: %d / %d no-effect cases (asks 0); unknown on no-effect: %d\n", named_false_alarms,
              none_cases, unknown_on_none);
  std::printf("  Wrong names on effect cases: %d\n", wrong_names);
  std::printf("  Mean held-out improvement over effect cases (0 where missed): %.3f (asks >= 0.5)\n",
              effect_cases > 0 ? improvement_sum / effect_cases : 0.0);
  bins.print();
  std::printf("  Runtime: total %.1f s wall (%.1f s CPU), per case mean %.2f s, max %.2f s wall\n\n", wall_total,
              cpu_total, wall_total / static_cast<double>(cases.size()), wall_max);
}

// LABEL:MODEL:DIR, or false.
bool parse_family(const std::string& text, Family& family) {
  const std::size_t first = text.find(':');
  const std::size_t second = first == std::string::npos ? first : text.find(':', first + 1);
  if (second == std::string::npos) return false;
  family.label = text.substr(0, first);
  family.model = text.substr(first + 1, second - first - 1);
  family.directory = text.substr(second + 1);
  return !family.label.empty() && (family.model == "msm" || family.model == "fem") && !family.directory.empty();
}

// ---- b. detection against effect size -------------------------------------------------------

// One effect's main parameter and how an amplitude a (1 = the effect's default) sets it from
// its default value p0; each reduces to no effect as a -> 0. The amplitudes run from well below
// the noise to plain on the sweep's scenes (effects saturate differently: friction and
// heterogeneity stop growing once the support slides freely or the region is soft).
struct SweepEffect {
  std::string effect;
  std::string parameter;
  double (*value)(double a, double p0);
  const char* meaning;
  std::vector<double> amplitudes;  // full sweep; --quick takes the 2nd and the 4th
};

const std::vector<SweepEffect> kSweepEffects = {
    {"plasticity",
     "creep",
     [](double a, double p0) { return a * p0; },
     "creep = a x default",
     {0.0025, 0.01, 0.04, 0.2, 1.0}},
    {"viscosity",
     "fraction",
     [](double a, double p0) { return a * p0; },
     "fraction = a x default",
     {0.05, 0.15, 0.5, 1.0, 1.8}},
    {"friction", "mu", [](double a, double p0) { return p0 / a; }, "1/mu = a x default", {0.1, 0.3, 1.0, 3.0, 30.0}},
    {"gravity", "g", [](double a, double p0) { return a * p0; }, "g = a x default", {0.05, 0.15, 0.5, 1.0, 3.0}},
    {"heterogeneity",
     "ratio",
     [](double a, double p0) { return 1.0 - a * (1.0 - p0); },
     "1 - ratio = a x default",
     {0.05, 0.15, 0.4, 1.0, 1.36}},
    {"stiffening", "k", [](double a, double p0) { return a * p0; }, "k = a x default", {0.05, 0.2, 1.0, 3.0, 10.0}},
};

// The sweep's scenes: a 2D ring (released by its protocol) and the 3D block released, pressed
// to 0.6 of its height so that stiffening and heterogeneity can stand well above the noise.
struct SweepScene {
  std::string scenario;
  bool release;
  double depth;  // 0 = the scenario's own
};
const std::vector<SweepScene> kSweepScenes = {{"ring_squeeze", false, 0.0}, {"block_press", true, 0.6}};
constexpr double kSweepNoise = 0.004;  // fraction of the particle spacing

ScenarioOptions sweep_options(const SweepScene& scene, const std::string& effect, std::uint64_t seed) {
  ScenarioOptions options;
  options.noise = kSweepNoise;
  options.release = scene.release;
  options.depth = scene.depth;
  options.seed = seed;
  options.effect = effect;
  return options;
}

// The default value of an effect's parameter in a scene, as the generator fills it in.
double default_parameter(const SweepScene& scene, const SweepEffect& sweep) {
  ScenarioOptions options = sweep_options(scene, sweep.effect, 1);
  options.noise = 0.0;
  const ScenarioResult probe = pliant::host::make_scenario(scene.scenario, options);
  return probe.truth.at("effect_parameters").at(sweep.parameter).get<double>();
}

int size_bin(double ratio) {
  if (ratio < 1) return 0;
  if (ratio < 3) return 1;
  if (ratio < 10) return 2;
  return 3;
}
const char* const kBinNames[] = {"<1", "1-3", "3-10", ">=10"};

struct Tally {
  int runs = 0, right = 0, wrong = 0, missed = 0;  // missed: consistent verdict
  void add(const std::string& truth, const std::string& found) {
    ++runs;
    if (found == truth)
      ++right;
    else if (found == "none")
      ++missed;
    else
      ++wrong;
  }
};

using Bins = std::array<Tally, 4>;

void print_tally_row(const std::string& label, const Bins& bins, const Tally& all) {
  std::printf("  %-14s", label.c_str());
  for (const Tally& t : bins) {
    if (t.runs == 0)
      std::printf(" %9s", "-");
    else
      std::printf(" %5d/%-3d", t.right, t.runs);
  }
  std::printf(" %5d/%-3d  wrong %d, missed %d\n", all.right, all.runs, all.wrong, all.missed);
}

void effect_size_sweep(bool quick) {
  const int controls = quick ? 1 : 3;
  std::printf("== b. Detection against effect size (%s sweep): noise %.3f of spacing, fixed seeds\n",
              quick ? "quick" : "full", kSweepNoise);
  std::printf("  scenes: ring_squeeze (2D), block_press released, depth 0.6 (3D); %d no-effect control(s) each\n",
              controls);
  std::printf("  amplitudes a (1 = the effect's default):\n");
  for (const SweepEffect& sweep : kSweepEffects) {
    std::printf("    %-14s %-24s", sweep.effect.c_str(), sweep.meaning);
    for (double a : sweep.amplitudes) std::printf(" %g", a);
    std::printf("\n");
  }
  std::printf("  %-12s %-13s %-20s %9s  %-15s %-13s %7s %8s\n", "scenario", "truth", "parameter", "rms/noise",
              "verdict", "found", "improv", "wall s");
  std::map<std::string, Bins> by_effect;
  std::map<std::string, Tally> effect_all;
  Bins bins;
  Tally all;
  int control_runs = 0, false_alarms = 0;
  double wall_total = 0;
  std::uint64_t seed = 5000;
  auto row = [&](const std::string& scenario, const std::string& effect, const std::string& parameter, double ratio,
                 const Timed& timed) {
    const auto& d = timed.result.diagnosis;
    std::printf("  %-12s %-13s %-20s %9s  %-15s %-13s %7.3f %8.2f%s%s\n", scenario.c_str(), effect.c_str(),
                parameter.c_str(), size_text(ratio).c_str(), timed.error.empty() ? d.verdict.c_str() : "error",
                d.effect.c_str(), d.improvement, timed.wall_s,
                timed.error.empty() ? "" : "  error: ", timed.error.c_str());
    std::fflush(stdout);
    wall_total += timed.wall_s;
  };
  for (const SweepScene& sweep_scene : kSweepScenes) {
    const std::string& scenario = sweep_scene.scenario;
    for (int c = 0; c < controls; ++c) {
      const ScenarioResult scene = pliant::host::make_scenario(scenario, sweep_options(sweep_scene, "", ++seed));
      const Timed timed = timed_diagnose(scene.recording);
      ++control_runs;
      false_alarms += found_label(timed) != "none" ? 1 : 0;
      row(scenario, "none", "-", -1, timed);
    }
    for (const SweepEffect& sweep : kSweepEffects) {
      const double p0 = default_parameter(sweep_scene, sweep);
      std::vector<double> amplitudes = sweep.amplitudes;
      if (quick) amplitudes = {sweep.amplitudes.at(1), sweep.amplitudes.at(3)};
      for (double a : amplitudes) {
        ScenarioOptions options = sweep_options(sweep_scene, sweep.effect, ++seed);
        const double value = sweep.value(a, p0);
        options.effect_parameters[sweep.parameter] = value;
        const ScenarioResult scene = pliant::host::make_scenario(scenario, options);
        const double ratio = rms_over_noise(scene.truth);
        const Timed timed = timed_diagnose(scene.recording);
        const std::string found = found_label(timed);
        const int bin = size_bin(ratio);
        by_effect[sweep.effect][static_cast<std::size_t>(bin)].add(sweep.effect, found);
        effect_all[sweep.effect].add(sweep.effect, found);
        bins[static_cast<std::size_t>(bin)].add(sweep.effect, found);
        all.add(sweep.effect, found);
        char parameter[48];
        std::snprintf(parameter, sizeof parameter, "%s=%.4g", sweep.parameter.c_str(), value);
        row(scenario, sweep.effect, parameter, ratio, timed);
      }
    }
  }
  std::printf("\n  Right effect named / runs, by truth effect_size.rms_over_noise:\n");
  std::printf("  %-14s", "effect");
  for (const char* bin : kBinNames) std::printf(" %9s", bin);
  std::printf(" %9s\n", "all");
  for (const SweepEffect& sweep : kSweepEffects) {
    print_tally_row(sweep.effect, by_effect[sweep.effect], effect_all[sweep.effect]);
  }
  print_tally_row("all effects", bins, all);
  std::printf("  wrong effect named per bin:");
  for (std::size_t b = 0; b < bins.size(); ++b) std::printf(" %s: %d", kBinNames[b], bins[b].wrong);
  std::printf("\n  missed (consistent) per bin:");
  for (std::size_t b = 0; b < bins.size(); ++b) std::printf(" %s: %d", kBinNames[b], bins[b].missed);
  std::printf("\n  False alarms on no-effect controls: %d / %d\n", false_alarms, control_runs);
  std::printf("  Sweep runtime: %.1f s wall over %d diagnoses\n\n", wall_total, all.runs + control_runs);
}

// ---- c. speed -------------------------------------------------------------------------------

struct SpeedCase {
  std::string label;
  std::string scenario;
  ScenarioOptions options;
  double budget_s;
};

void speed() {
  std::printf("== c. Speed: one diagnose_recording (default options), build type %s\n", PLIANT_BENCH_BUILD_TYPE);
  // foam_press with release lasts 6 s: 149 frame intervals make 150 frames.
  SpeedCase small{"2D foam_press 4 x 8", "foam_press", {}, 10.0};
  small.options.release = true;
  small.options.rate_hz = 149.0 / 6.0;
  // block_press with release lasts 5 s: 299 frame intervals make 300 frames of 10 x 10 x 5.
  SpeedCase large{"3D block_press 10 x 10 x 5", "block_press", {}, 120.0};
  large.options.release = true;
  large.options.rate_hz = 299.0 / 5.0;
  large.options.block_grid = {10, 10, 5};
  // The same two simulated with msm_alpha 0.5 and two MSM steps per frame: the baseline's
  // selection then fits msm_alpha and tries steps and radii (the budgets hold with it).
  SpeedCase small_lagging = small;
  small_lagging.label = "2D foam_press, alpha 0.5 x 2";
  SpeedCase large_lagging = large;
  large_lagging.label = "3D block_press, alpha 0.5 x 2";
  for (SpeedCase* c : {&small_lagging, &large_lagging}) {
    c->options.msm_alpha = 0.5;
    c->options.substeps = 2;
  }
  std::printf("  %-30s %9s %6s %9s %9s %8s  %s\n", "recording", "particles", "frames", "wall s", "cpu s", "budget s",
              "verdict (wall / cpu), baseline form");
  for (SpeedCase* c : {&small, &large, &small_lagging, &large_lagging}) {
    c->options.noise = kSweepNoise;
    c->options.seed = 7;
    const ScenarioResult scene = pliant::host::make_scenario(c->scenario, c->options);
    const Timed timed = timed_diagnose(scene.recording);
    const auto verdict = [&](double t) { return t <= c->budget_s ? "within" : "OVER"; };
    const auto& baseline = timed.result.diagnosis.baseline;
    std::printf(
        "  %-30s %9d %6d %9.2f %9.2f %8.0f  %s / %s, baseline after %.1f s, alpha %s, %d step(s), radius %.3g%s%s\n",
        c->label.c_str(), scene.recording.particle_count, scene.recording.frame_count(), timed.wall_s, timed.cpu_s,
        c->budget_s, verdict(timed.wall_s), verdict(timed.cpu_s), timed.baseline_wall_s,
        baseline.alpha_fitted ? "fitted" : "held", baseline.steps_per_frame, baseline.cluster_radius_factor,
        timed.error.empty() ? "" : "  error: ", timed.error.c_str());
    std::fflush(stdout);
  }
  std::printf("\n");
}

}  // namespace

int main(int argc, char** argv) {
  bool quick = false, speed_only = false;
  fs::path suite = PLIANT_CONCEALED_SUITE_DIR;
  const fs::path examples = PLIANT_EXAMPLES_DIR;
  std::vector<Family> families;
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    Family family;
    if (arg == "--quick") {
      quick = true;
    } else if (arg == "--speed-only") {
      speed_only = true;
    } else if (arg == "--suite" && i + 1 < argc) {
      suite = argv[++i];
    } else if (arg == "--family" && i + 1 < argc && parse_family(argv[i + 1], family)) {
      families.push_back(family);
      ++i;
    } else {
      std::fprintf(stderr,
                   "usage: diagnose_bench [--quick] [--speed-only] [--suite DIR] [--family LABEL:msm|fem:DIR]...\n");
      return arg == "--help" || arg == "-h" ? 0 : 2;
    }
  }
  if (families.empty()) {
    families = {{"own-simulator", "msm", suite},
                {"msm-world-sample", "msm", examples / "concealed_msm_world"},
                {"calculix-sample", "fem", examples / "concealed_calculix"},
                {"calculix-sample", "msm", examples / "concealed_calculix"}};
  }
  if (!speed_only) {
    for (const Family& family : families) concealed_family(family);
    effect_size_sweep(quick);
  }
  speed();
  return 0;
}

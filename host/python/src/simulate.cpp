// pliant.simulate: `pliant simulate` (host/cli/job_simulate.hpp), in memory and optionally written.
#include <cstdint>
#include <memory>
#include <optional>

#include <pybind11/stl.h>

#include "bindings.hpp"
#include "convert.hpp"
#include "job_call.hpp"
#include "job_simulate.hpp"
#include "exit_status.hpp"

namespace pliant::python {
namespace {

struct SimulateArguments {
  std::string scenario;
  py::handle output;
  double beta = 0, alpha = 0, noise = 0, cluster_radius = 0, occlusion = 0;
  long long seed = 0;
  int substeps = 0;
  std::optional<double> rate, depth;
  std::optional<std::string> effect;
  bool release = false, force = false;
};

cli::SimulateJob simulate_job(const SimulateArguments& a) {
  // The command line refuses a negative seed before it could wrap into a huge unsigned one.
  if (a.seed < 0) throw cli::UsageError("--seed must be >= 0");
  cli::SimulateJob job;
  job.scenario = a.scenario;
  if (!a.output.is_none()) job.output = path_of(a.output, "output");
  job.options.msm_beta = a.beta;
  job.options.msm_alpha = a.alpha;
  job.options.noise = a.noise;
  job.options.seed = static_cast<std::uint64_t>(a.seed);
  job.options.substeps = a.substeps;
  job.options.cluster_radius_factor = a.cluster_radius;
  job.options.occlusion = a.occlusion;
  job.options.release = a.release;
  job.rate = a.rate;
  job.depth = a.depth;
  job.effect = a.effect;
  job.force = a.force;
  return job;
}

py::tuple simulate(const SimulateArguments& arguments) {
  const cli::SimulateJob job = simulate_job(arguments);
  WarningLines warnings;
  host::ScenarioResult scenario = without_gil([&] { return cli::run_simulate_job(job); }, warnings);
  auto recording = std::make_shared<host::Recording>(std::move(scenario.recording));
  return py::make_tuple(py::cast(recording), to_python(scenario.truth));
}

const char* kDoc = R"doc(simulate(scenario, *, output=None, beta=0.5, alpha=1.0, noise=0.0, seed=1, rate=None,
effect=None, substeps=1, cluster_radius=1.5, occlusion=0.0, depth=None, release=False,
force=False) -> (Recording, dict)

A simulated recording with known ground truth, as `pliant simulate` makes it; returns the
recording and its truth (the truth.json document). output: also write both into that directory
(as the command does; not empty: only with force). The options are the command's: beta, alpha
(true msm_beta and msm_alpha), noise (position noise std over the particle spacing), seed (>= 0),
rate (frames/s; None: the scenario's own), effect ('NAME[:P=V,...]'), substeps, cluster_radius,
occlusion, depth, release. The GIL is released while it runs.)doc";

}  // namespace

void bind_simulate(py::module_& module) {
  const host::ScenarioOptions defaults;
  module.def(
      "simulate",
      [](const std::string& scenario, py::handle output, double beta, double alpha, double noise, long long seed,
         std::optional<double> rate, std::optional<std::string> effect, int substeps, double cluster_radius,
         double occlusion, std::optional<double> depth, bool release, bool force) {
        SimulateArguments a;
        a.scenario = scenario;
        a.output = output;
        a.beta = beta;
        a.alpha = alpha;
        a.noise = noise;
        a.seed = seed;
        a.rate = rate;
        a.effect = effect;
        a.substeps = substeps;
        a.cluster_radius = cluster_radius;
        a.occlusion = occlusion;
        a.depth = depth;
        a.release = release;
        a.force = force;
        return simulate(a);
      },
      py::arg("scenario"), py::kw_only(), py::arg("output") = py::none(), py::arg("beta") = defaults.msm_beta,
      py::arg("alpha") = defaults.msm_alpha, py::arg("noise") = defaults.noise,
      py::arg("seed") = static_cast<long long>(defaults.seed), py::arg("rate") = py::none(),
      py::arg("effect") = py::none(), py::arg("substeps") = defaults.substeps,
      py::arg("cluster_radius") = defaults.cluster_radius_factor, py::arg("occlusion") = defaults.occlusion,
      py::arg("depth") = py::none(), py::arg("release") = defaults.release, py::arg("force") = false, kDoc);
}

}  // namespace pliant::python

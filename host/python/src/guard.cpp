// pliant.GraspGuard: the controller's grasp guard (pliant/core/grasp_guard.hpp) on an object given
// by its rest particles, stepped cycle by cycle with dicts and NumPy arrays. The wrapper owns the
// object's MSM model and the guard's fixed memory; a cycle allocates nothing in the core.
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "bindings.hpp"
#include "convert.hpp"
#include "exit_status.hpp"
#include "guard_values.hpp"
#include "pliant/core/arena.hpp"
#include "pliant/core/grasp_guard.hpp"

namespace pliant::python {
namespace {

/// The object, how the jaws meet it, and the configuration, as given to the constructor.
struct GuardSetup {
  std::vector<double> rest;  ///< particle-major, m
  int dimension = 3;
  std::vector<double> axis;
  std::vector<int> jaw_a, jaw_b;
  double contact_band = 0.25;
  GraspGuardConfig config;
};

class Guard {
 public:
  virtual ~Guard() = default;
  virtual Status update(const GraspGuardInput& input, GraspGuardOutput& output) = 0;
  virtual Status measure(const double* positions, GraspStrainMeasurement& measurement) const = 0;
  virtual void reset() = 0;
  virtual void acknowledge_stop() = 0;
  virtual int unconverged_relaxations() const = 0;
};

template <int Dim>
class GuardOf final : public Guard {
 public:
  using Vec = Eigen::Matrix<double, Dim, 1>;
  explicit GuardOf(const GuardSetup& setup) : rest_(setup.rest) {
    const int n = static_cast<int>(rest_.size()) / Dim;
    for (int i = 0; i < n; ++i) all_.push_back(i);  // either jaw may touch any particle
    MsmModelConfig<Dim, double> model_config;
    model_config.particle_count = n;
    model_config.rest_positions = rest_.data();
    model_config.drivable_ids = all_.data();
    model_config.drivable_count = n;
    model_block_.resize(msm_model_workspace_size(model_config));
    if (model_block_.empty()) throw cli::UsageError("GraspGuard: these rest positions do not make an MSM model");
    Arena model_arena(model_block_.data(), model_block_.size());
    check(msm_model_init(model_arena, model_config, model_), "the object's MSM model");
    GraspObject<Dim, double> object;
    for (int d = 0; d < Dim; ++d) object.squeeze_axis(d) = setup.axis[static_cast<std::size_t>(d)];
    object.jaw_a_ids = setup.jaw_a.data();
    object.jaw_a_count = static_cast<int>(setup.jaw_a.size());
    object.jaw_b_ids = setup.jaw_b.data();
    object.jaw_b_count = static_cast<int>(setup.jaw_b.size());
    object.contact_band = setup.contact_band;
    guard_block_.assign(grasp_guard_workspace_size(model_, setup.config), 0);
    Arena guard_arena(guard_block_.data(), guard_block_.size());
    check(grasp_guard_init(guard_arena, model_, object, setup.config, guard_), "grasp_guard_init");
  }
  Status update(const GraspGuardInput& input, GraspGuardOutput& output) override {
    return grasp_guard_update(guard_, input, output);
  }
  Status measure(const double* positions, GraspStrainMeasurement& measurement) const override {
    std::vector<Vec> frame(rest_.size() / Dim);
    for (std::size_t i = 0; i < frame.size(); ++i) {
      for (int d = 0; d < Dim; ++d) frame[i](d) = positions[i * Dim + static_cast<std::size_t>(d)];
    }
    return grasp_guard_measure_strain(model_, guard_, frame.data(), measurement);
  }
  void reset() override { grasp_guard_reset(guard_); }
  void acknowledge_stop() override { grasp_guard_acknowledge_stop(guard_); }
  int unconverged_relaxations() const override { return guard_.unconverged_relaxations; }

 private:
  static void check(Status status, const char* what) {
    if (status == Status::ok) return;
    throw cli::UsageError(std::string("GraspGuard: ") + what + ": " + status_name(status) +
                          " (a configuration value out of its documented range, jaw ids out of range, empty or "
                          "shared between the jaws, or a zero squeeze axis or extent)");
  }
  std::vector<double> rest_;
  std::vector<int> all_;
  std::vector<unsigned char> model_block_;
  std::vector<unsigned char> guard_block_;
  MsmModel<Dim, double> model_;
  GraspGuard<Dim, double> guard_;
};

/// pliant.GraspGuard: the guard and the latest sample of each source (a cycle without a new
/// sample passes the previous one again, as a control loop holding its latest readings does).
class PyGraspGuard {
 public:
  explicit PyGraspGuard(const GuardSetup& setup)
      : particle_count_(static_cast<int>(setup.rest.size()) / setup.dimension), dimension_(setup.dimension) {
    py::gil_scoped_release release;  // init squeezes the model: about 0.1 s for 100 particles
    if (dimension_ == 2) {
      guard_ = std::make_unique<GuardOf<2>>(setup);
    } else {
      guard_ = std::make_unique<GuardOf<3>>(setup);
    }
  }

  py::dict update(double now_s, py::handle gripper, py::handle wrench, py::handle deformation, py::handle estimate) {
    if (!gripper.is_none()) read_sample(gripper, input_.gripper);
    if (!wrench.is_none()) read_sample(wrench, input_.wrench);
    if (!deformation.is_none()) read_sample(deformation, input_.deformation);
    if (!estimate.is_none()) read_sample(estimate, input_.estimate);
    input_.now_s = now_s;
    GraspGuardOutput output;
    {
      const std::lock_guard<std::mutex> lock(mutex_);
      (void)guard_->update(input_, output);  // not_initialized cannot happen: init succeeded
    }
    return output_dict(output);
  }

  py::dict measure_strain(py::handle positions) {
    const py::array_t<double> frame =
        real_array(positions, "positions", {particle_count_, dimension_}, "(n_particles, dim)");
    GraspStrainMeasurement measurement;
    Status status = Status::ok;
    {
      const std::lock_guard<std::mutex> lock(mutex_);
      status = guard_->measure(frame.data(), measurement);
    }
    py::dict out;
    out["strain"] = measurement.strain;
    out["cluster"] = measurement.cluster;
    out["clusters_measured"] = measurement.clusters_measured;
    out["clusters_skipped"] = measurement.clusters_skipped;
    out["status"] = status_name(status);
    return out;
  }

  void reset() {
    const std::lock_guard<std::mutex> lock(mutex_);
    guard_->reset();
  }
  void acknowledge_stop() {
    const std::lock_guard<std::mutex> lock(mutex_);
    guard_->acknowledge_stop();
  }
  int particle_count() const { return particle_count_; }
  int dimension() const { return dimension_; }
  int unconverged_relaxations() const { return guard_->unconverged_relaxations(); }

 private:
  int particle_count_;
  int dimension_;
  std::mutex mutex_;
  std::unique_ptr<Guard> guard_;
  GraspGuardInput input_;
};

GuardSetup guard_setup(py::handle rest_positions, py::handle squeeze_axis, py::handle jaw_a, py::handle jaw_b,
                       double contact_band, const py::kwargs& options) {
  GuardSetup setup;
  const py::array_t<double> rest = real_array(rest_positions, "rest_positions", {-1, -1}, "(n_particles, dim)");
  setup.dimension = static_cast<int>(rest.shape(1));
  if (setup.dimension != 2 && setup.dimension != 3) throw py::value_error("rest_positions: dim must be 2 or 3");
  if (rest.shape(0) < 2) throw py::value_error("rest_positions: the object needs at least 2 particles");
  setup.rest.assign(rest.data(), rest.data() + rest.size());
  const py::array_t<double> axis = real_array(squeeze_axis, "squeeze_axis", {setup.dimension}, "(dim,)");
  setup.axis.assign(axis.data(), axis.data() + axis.size());
  if (!jaw_a.is_none()) setup.jaw_a = id_list(jaw_a, "jaw_a");
  if (!jaw_b.is_none()) setup.jaw_b = id_list(jaw_b, "jaw_b");
  setup.contact_band = contact_band;
  setup.config = guard_config(options);
  return setup;
}

const char* kDoc =
    R"doc(GraspGuard(rest_positions, squeeze_axis, *, jaw_a=None, jaw_b=None, contact_band=0.25, **config)

The controller's grasp guard (docs/grasp_guard.md) on an object given by its rest particles:
rest_positions (n_particles, dim) in m, in the object's frame at first contact; squeeze_axis
(dim,) from jaw A toward jaw B; jaw_a, jaw_b: particle ids touching each jaw at first contact
(None: those within contact_band x spacing of the extremes along the axis). The object's MSM
model has every particle drivable and none fixed, with the default clusters. **config: the fields
of GraspGuardConfig by name (max_strain, max_force_n, contact_width_m, ...; enumerations by
name). Construction squeezes the model to tabulate the safe closure (about 0.1 s for 100
particles, without the GIL); pliant.UsageError when the core refuses the configuration.)doc";

const char* kUpdateDoc = R"doc(update(now, *, gripper=None, wrench=None, deformation=None, estimate=None) -> dict

One control cycle at monotonic time `now` (s). Each source is a dict of its latest sample, or
None to pass the previous one again:
  gripper      {'stamp', 'width' m, 'force' N, 'current' A, 'status', 'valid', 'bus_off', 'timeout'}
  wrench       {'stamp', 'wrench' (6,) Fx Fy Fz N Tx Ty Tz N m, 'status', 'valid', 'bus_off', 'timeout'}
  deformation  {'stamp', 'strain', 'status', 'valid', 'bus_off', 'timeout'}
  estimate     {'stamp', 'msm_beta', 'msm_beta_std', 'valid'}
In a dict, 'valid' defaults to True, 'bus_off' and 'timeout' to False; other keys left out keep
their previous values. Returns
GraspGuardOutput as a dict: 'verdict' ('ok', 'limit', 'stop'), 'reason', 'stop_action',
'reasons', 'fault_sources', 'in_contact', 'slip', and the numbers with their units in their
names (closure_m, safe_width_m, allowed_force_n, ...).)doc";

}  // namespace

void bind_guard(py::module_& module) {
  py::class_<PyGraspGuard>(module, "GraspGuard", kDoc)
      .def(py::init([](py::handle rest_positions, py::handle squeeze_axis, py::handle jaw_a, py::handle jaw_b,
                       double contact_band, const py::kwargs& options) {
             return std::make_unique<PyGraspGuard>(
                 guard_setup(rest_positions, squeeze_axis, jaw_a, jaw_b, contact_band, options));
           }),
           py::arg("rest_positions"), py::arg("squeeze_axis"), py::kw_only(), py::arg("jaw_a") = py::none(),
           py::arg("jaw_b") = py::none(), py::arg("contact_band") = 0.25)
      .def("update", &PyGraspGuard::update, py::arg("now"), py::kw_only(), py::arg("gripper") = py::none(),
           py::arg("wrench") = py::none(), py::arg("deformation") = py::none(), py::arg("estimate") = py::none(),
           kUpdateDoc)
      .def("measure_strain", &PyGraspGuard::measure_strain, py::arg("positions"),
           "measure_strain(positions) -> dict\n\nThe largest cluster strain of tracked positions (n_particles, dim) "
           "in m against the rest shape (NaN rows: unobserved): {'strain', 'cluster', 'clusters_measured', "
           "'clusters_skipped', 'status'}. Its 'strain' is what a deformation sample carries.")
      .def("reset", &PyGraspGuard::reset, "A new grasp: forgets contact, force fit and slip; clears a latched stop.")
      .def("acknowledge_stop", &PyGraspGuard::acknowledge_stop, "Clears a stop held by latch_stop.")
      .def_property_readonly("particle_count", &PyGraspGuard::particle_count)
      .def_property_readonly("dimension", &PyGraspGuard::dimension)
      .def_property_readonly("unconverged_relaxations", &PyGraspGuard::unconverged_relaxations);
}

}  // namespace pliant::python

#include "refine_output.hpp"

#include <cmath>
#include <cstdio>
#include <sstream>
#include <stdexcept>
#include <vector>

#include "atomic_write.hpp"
#include "pliant/host/fem/mesh_vtk_series.hpp"
#include "pliant/host/vtk_mesh.hpp"

namespace pliant::cli {
namespace {

using host::fem::FemFrame;

nlohmann::json number(double value) { return std::isfinite(value) ? nlohmann::json(value) : nlohmann::json(); }

std::string num(double value) {
  if (!std::isfinite(value)) return "?";
  char text[32];
  std::snprintf(text, sizeof text, "%.4g", value);
  return text;
}

const char* unit_of(const std::string& parameter) {
  if (parameter == "youngs_modulus") return " Pa";
  if (parameter == "density") return " kg/m^3";
  if (parameter == "rayleigh_alpha") return " 1/s";
  if (parameter == "rayleigh_beta") return " s";
  return "";
}

std::string row(const std::string& key, const std::string& value) {
  std::string line = "  " + key;
  if (line.size() < 19) line.append(19 - line.size(), ' ');
  return line + " " + value + "\n";
}

// How the model integrates the volume, and why (fem_model.hpp).
std::string volumetric_words(const host::fem::FemMaterial& material) {
  if (material.volumetric != host::fem::FemVolumetric::automatic) {
    return std::string(host::fem::to_string(material.volumetric)) + " (--volumetric)";
  }
  if (host::fem::resolved_volumetric(material) == host::fem::FemVolumetric::nodal_average) {
    return "nodal_average (averaged nodal pressure: poisson_ratio " + num(material.poisson_ratio) +
           " >= " + num(host::fem::kNodalAverageFromPoisson) + ", where the plain linear tetrahedron locks)";
  }
  return "element (poisson_ratio " + num(material.poisson_ratio) + " < " + num(host::fem::kNodalAverageFromPoisson) +
         ")";
}

host::TetMesh mesh_with_moduli(const RefineReport& r) {
  host::TetMesh mesh = r.problem->mesh;
  const Eigen::VectorXd& e = r.outcome->element_youngs_modulus_pa;
  if (e.size() == mesh.tet_count()) mesh.youngs_modulus.assign(e.data(), e.data() + e.size());
  return mesh;
}

}  // namespace

nlohmann::json material_card(const RefineReport& r) {
  const RefineOutcome& o = *r.outcome;
  nlohmann::json card;
  card["format"] = "pliant-material";
  card["version"] = 1;
  card["recording"] = r.recording->name;
  card["model"] = "fem";
  nlohmann::json parameters = nlohmann::json::object();
  for (const auto& [name, value] : r.recording->material) parameters[name] = value;  // given: unchanged
  for (const auto& [name, value] : o.estimated) parameters[name] = value;
  card["parameters"] = parameters;
  nlohmann::json uncertainty = nlohmann::json::object();
  for (const auto& [name, value] : o.uncertainty) uncertainty[name] = number(value);
  card["uncertainty"] = uncertainty;
  if (o.has_map) {
    nlohmann::json points = nlohmann::json::array();
    for (const Eigen::Vector3d& p : o.control_points_m) points.push_back({p.x(), p.y(), p.z()});
    nlohmann::json sds = nlohmann::json::array();
    for (double sd : o.control_youngs_modulus_sd_pa) sds.push_back(number(sd));
    card["material_map"] = {{"control_points", points},
                            {"youngs_modulus", o.control_youngs_modulus_pa},
                            {"uncertainty", sds},
                            {"kernel_width", o.kernel_width_m}};
  }
  if (!r.rest_shape_ref.empty()) card["rest_shape"] = r.rest_shape_ref;
  card["rms"] = number(o.rms_m);
  card["runtime_s"] = r.runtime_s;
  if (r.plan->estimator) card["estimator"] = to_string(*r.plan->estimator);
  card["volumetric"] = host::fem::to_string(host::fem::resolved_volumetric(r.problem->material));
  nlohmann::json assumed = nlohmann::json::object();
  for (const auto& [name, value] : o.assumed) assumed[name] = value;
  card["assumed"] = assumed;
  nlohmann::json diagnostics = o.diagnostics;
  diagnostics["rms_pairs"] = o.rms_pairs;
  diagnostics["free_rms"] = number(o.free_rms_m);
  diagnostics["free_rms_pairs"] = o.free_rms_pairs;
  diagnostics["converged"] = o.converged;
  card["diagnostics"] = diagnostics;
  return card;
}

std::string refine_summary(const RefineReport& r) {
  const RefineOutcome& o = *r.outcome;
  const host::fem::FemRecordingProblem& p = *r.problem;
  std::string text = r.recording->name + ": FEM material (" + std::to_string(p.mesh.point_count()) + " nodes, " +
                     std::to_string(p.mesh.tet_count()) + " tetrahedra, " + std::to_string(p.frames.size()) +
                     " frames; mesh: " + r.mesh_source + ")\n";
  if (r.plan->estimator) text += row("estimator", std::string(to_string(*r.plan->estimator)) + ": " + r.plan->reason);
  for (const auto& [name, value] : o.estimated) {
    const auto sd = o.uncertainty.find(name);
    const std::string spread = sd == o.uncertainty.end() ? "" : " ± " + num(sd->second);
    text +=
        row(name, num(value) + spread + unit_of(name) +
                      (o.has_map && name == "youngs_modulus" ? " (volume-weighted geometric mean of the map)" : ""));
  }
  for (const auto& [name, value] : r.recording->material) text += row(name, num(value) + unit_of(name) + " (given)");
  for (const auto& [name, value] : o.assumed) text += row(name, num(value) + unit_of(name) + " (assumed)");
  text += row("volumetric", volumetric_words(r.problem->material));
  if (o.has_map) {
    text += row("material_map", std::to_string(o.control_points_m.size()) + " control points, kernel width " +
                                    num(o.kernel_width_m) + " m");
    for (std::size_t i = 0; i < o.control_points_m.size(); ++i) {
      const Eigen::Vector3d& q = o.control_points_m[i];
      text += row("  [" + std::to_string(i) + "]", "at (" + num(q.x()) + ", " + num(q.y()) + ", " + num(q.z()) +
                                                       ") m: " + num(o.control_youngs_modulus_pa[i]) + " ± " +
                                                       num(o.control_youngs_modulus_sd_pa[i]) + " Pa");
    }
  }
  if (o.rest_shape) {
    const host::fem::RestShapeResult& s = *o.rest_shape;
    text += row("rest_shape", (r.rest_shape_ref.empty() ? std::string("estimated") : r.rest_shape_ref) + ": max sag " +
                                  num(s.max_sag_m) + " m, " + std::to_string(s.iterations) +
                                  " iterations, forward check " + num(s.forward_check_error_m) + " m" +
                                  (s.converged ? "" : ", NOT CONVERGED: " + s.message));
  }
  text += row("rms", num(o.rms_m) + " m over " + std::to_string(o.rms_pairs) + " observed (particle, frame) pairs" +
                         (o.free_rms_pairs > 0 ? "; free particles " + num(o.free_rms_m) + " m" : ""));
  const nlohmann::json& d = o.diagnostics;
  if (d.contains("force_rms") && d["force_rms"].is_number()) {
    std::string force = num(d["force_rms"].get<double>()) + " N";
    if (d.contains("force_offset")) {
      force += " (fitted offset " + num(d["force_offset"][0].get<double>()) + ", " +
               num(d["force_offset"][1].get<double>()) + ", " + num(d["force_offset"][2].get<double>()) + " N)";
    }
    text += row("force rms", force);
  }
  if (!o.fit_message.empty()) text += row("fit", o.fit_message);
  text += row("runtime", num(r.runtime_s) + " s");
  return text;
}

void write_rest_mesh(const std::string& path, const RefineReport& r) {
  const RefineOutcome& o = *r.outcome;
  if (!o.rest_shape) throw std::logic_error("write_rest_mesh without a rest shape");
  host::TetMesh mesh = o.has_map ? mesh_with_moduli(r) : r.problem->mesh;
  const Eigen::VectorXd& rest = o.rest_shape->rest_position_m;
  mesh.points.assign(rest.data(), rest.data() + rest.size());
  std::ostringstream text;
  host::write_vtk_tet_mesh(mesh, text);
  if (!text) throw std::runtime_error("cannot format " + path);
  write_file_atomically(path, text.str());
}

std::string write_refine_vtk(const std::string& directory, const RefineReport& r) {
  const RefineOutcome& o = *r.outcome;
  host::VtkSeriesOptions options;
  options.base_name = "refine";
  host::VtkSeriesWriter writer(directory, mesh_with_moduli(r), options);
  const Eigen::Index dofs = o.simulated_rest_m.size();
  for (const SimulatedFrame& s : o.simulated) {
    const FemFrame& frame = r.problem->frames[static_cast<std::size_t>(s.frame)];
    host::VtkSeriesFrame out;
    out.time_s = frame.time_s;
    out.positions.assign(s.position_m.data(), s.position_m.data() + dofs);
    std::vector<double> displacement(static_cast<std::size_t>(dofs));
    std::vector<double> observed(static_cast<std::size_t>(dofs));
    std::vector<double> residual(static_cast<std::size_t>(dofs));
    for (Eigen::Index i = 0; i < dofs; ++i) {
      const auto k = static_cast<std::size_t>(i);
      const double seen = frame.observed_position_m(i);
      displacement[k] = s.position_m(i) - o.simulated_rest_m(i);
      observed[k] = std::isfinite(seen) ? seen : s.position_m(i);
      residual[k] = observed[k] - s.position_m(i);
    }
    out.point_vectors = {{"displacement", std::move(displacement)},
                         {"observed_position", std::move(observed)},
                         {"residual", std::move(residual)}};
    writer.write_frame(out);
  }
  return writer.finish();
}

}  // namespace pliant::cli

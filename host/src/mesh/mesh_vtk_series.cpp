// VTK time series writer: .vtu frames + .pvd, or legacy .vtk frames + .vtk.series.
#include "pliant/host/fem/mesh_vtk_series.hpp"

#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <string>
#include <system_error>
#include <vector>

#include "mesh_text.hpp"
#include "pliant/host/vtk_mesh.hpp"

namespace pliant::host {
namespace {

namespace fs = std::filesystem;
using mesh_detail::fail_file;
using mesh_detail::format_double;

constexpr const char* kLabel = "VtkSeriesWriter";

bool valid_name(const std::string& name, bool allow_dot_dash) {
  if (name.empty() || name.size() > 64) return false;
  for (const char c : name) {
    const bool ok = (c >= 'A' && c <= 'Z') || (c >= 'a' && c <= 'z') || (c >= '0' && c <= '9') || c == '_' ||
                    (allow_dot_dash && (c == '.' || c == '-'));
    if (!ok) return false;
  }
  return name != "." && name != "..";
}

void check_arrays(const std::vector<VtkNamedArray>& arrays, std::size_t size_each, const char* kind,
                  const std::string& reserved) {
  for (std::size_t i = 0; i < arrays.size(); ++i) {
    const VtkNamedArray& array = arrays[i];
    if (!valid_name(array.name, false)) {
      fail_file(kLabel, std::string(kind) + " name '" + mesh_detail::printable(array.name) +
                            "' must be 1-64 characters from [A-Za-z0-9_]");
    }
    if (!reserved.empty() && array.name == reserved) {
      fail_file(kLabel, std::string(kind) + " name '" + reserved + "' is taken by the mesh's own array");
    }
    for (std::size_t j = 0; j < i; ++j) {
      if (arrays[j].name == array.name) {
        fail_file(kLabel, std::string(kind) + " name '" + array.name + "' appears twice");
      }
    }
    if (array.values.size() != size_each) {
      fail_file(kLabel, std::string(kind) + " '" + array.name + "' has " + std::to_string(array.values.size()) +
                            " values, expected " + std::to_string(size_each));
    }
    for (const double value : array.values) {
      if (!std::isfinite(value)) {
        fail_file(kLabel, std::string(kind) + " '" + array.name + "' has a non-finite value");
      }
    }
  }
}

// Values, `per_line` to a line, each line indented.
void append_values(std::string& out, const std::vector<double>& values, std::size_t per_line, const char* indent) {
  for (std::size_t i = 0; i < values.size(); i += per_line) {
    out += indent;
    for (std::size_t k = 0; k < per_line && i + k < values.size(); ++k) {
      if (k > 0) out.push_back(' ');
      out += format_double(values[i + k]);
    }
    out.push_back('\n');
  }
}

void write_file_atomically(const fs::path& path, const std::string& content) {
  fs::path temporary = path;
  temporary += ".tmp";
  {
    std::ofstream out(temporary, std::ios::binary | std::ios::trunc);
    if (!out) {
      throw std::runtime_error(std::string(kLabel) + ": cannot write " + temporary.string() + ": " +
                               std::strerror(errno));
    }
    out.write(content.data(), static_cast<std::streamsize>(content.size()));
    out.flush();
    if (!out) {
      throw std::runtime_error(std::string(kLabel) + ": write failed for " + temporary.string());
    }
  }
  std::error_code error;
  fs::rename(temporary, path, error);
  if (error) {
    fs::remove(temporary, error);
    throw std::runtime_error(std::string(kLabel) + ": cannot rename " + temporary.string() + " to " + path.string());
  }
}

std::string vtu_frame(const TetMesh& mesh, const VtkSeriesFrame& frame) {
  const std::size_t points = frame.positions.size() / 3;
  const std::size_t tets = mesh.tetrahedra.size() / 4;
  std::string out;
  out.reserve(64 * (points + tets) + 1024);
  out +=
      "<?xml version=\"1.0\"?>\n"
      "<VTKFile type=\"UnstructuredGrid\" version=\"1.0\" byte_order=\"LittleEndian\" "
      "header_type=\"UInt64\">\n"
      "  <UnstructuredGrid>\n"
      "    <FieldData>\n"
      "      <DataArray type=\"Float64\" Name=\"TimeValue\" NumberOfTuples=\"1\" "
      "format=\"ascii\">\n";
  out += "        " + format_double(frame.time_s) + "\n";
  out += "      </DataArray>\n    </FieldData>\n";
  out +=
      "    <Piece NumberOfPoints=\"" + std::to_string(points) + "\" NumberOfCells=\"" + std::to_string(tets) + "\">\n";
  out += "      <PointData";
  if (!frame.point_vectors.empty()) out += " Vectors=\"" + frame.point_vectors.front().name + "\"";
  out += ">\n";
  for (const VtkNamedArray& array : frame.point_vectors) {
    out +=
        "        <DataArray type=\"Float64\" Name=\"" + array.name + "\" NumberOfComponents=\"3\" format=\"ascii\">\n";
    append_values(out, array.values, 3, "          ");
    out += "        </DataArray>\n";
  }
  out += "      </PointData>\n      <CellData";
  const bool has_modulus = !mesh.youngs_modulus.empty();
  if (has_modulus) {
    out += " Scalars=\"youngs_modulus\"";
  } else if (!frame.cell_scalars.empty()) {
    out += " Scalars=\"" + frame.cell_scalars.front().name + "\"";
  }
  out += ">\n";
  if (has_modulus) {
    out += "        <DataArray type=\"Float64\" Name=\"youngs_modulus\" format=\"ascii\">\n";
    append_values(out, mesh.youngs_modulus, 6, "          ");
    out += "        </DataArray>\n";
  }
  for (const VtkNamedArray& array : frame.cell_scalars) {
    out += "        <DataArray type=\"Float64\" Name=\"" + array.name + "\" format=\"ascii\">\n";
    append_values(out, array.values, 6, "          ");
    out += "        </DataArray>\n";
  }
  out +=
      "      </CellData>\n      <Points>\n"
      "        <DataArray type=\"Float64\" Name=\"Points\" NumberOfComponents=\"3\" "
      "format=\"ascii\">\n";
  append_values(out, frame.positions, 3, "          ");
  out +=
      "        </DataArray>\n      </Points>\n      <Cells>\n"
      "        <DataArray type=\"Int64\" Name=\"connectivity\" format=\"ascii\">\n";
  for (std::size_t t = 0; t < tets; ++t) {
    out += "          ";
    for (std::size_t k = 0; k < 4; ++k) {
      if (k > 0) out.push_back(' ');
      out += std::to_string(mesh.tetrahedra[4 * t + k]);
    }
    out.push_back('\n');
  }
  out +=
      "        </DataArray>\n"
      "        <DataArray type=\"Int64\" Name=\"offsets\" format=\"ascii\">\n";
  for (std::size_t t = 0; t < tets; t += 8) {
    out += "          ";
    for (std::size_t k = t; k < tets && k < t + 8; ++k) {
      if (k > t) out.push_back(' ');
      out += std::to_string(4 * (k + 1));
    }
    out.push_back('\n');
  }
  out +=
      "        </DataArray>\n"
      "        <DataArray type=\"UInt8\" Name=\"types\" format=\"ascii\">\n";
  for (std::size_t t = 0; t < tets; t += 16) {
    out += "          ";
    for (std::size_t k = t; k < tets && k < t + 16; ++k) out += k > t ? " 10" : "10";
    out.push_back('\n');
  }
  out +=
      "        </DataArray>\n      </Cells>\n    </Piece>\n  </UnstructuredGrid>\n"
      "</VTKFile>\n";
  return out;
}

std::string legacy_frame(TetMesh& scratch, const VtkSeriesFrame& frame, std::size_t number) {
  scratch.points = frame.positions;
  std::ostringstream stream;
  write_vtk_tet_mesh(scratch, stream);
  std::string out = stream.str();
  const std::string title = "pliant rest mesh";
  const std::size_t at = out.find(title);
  if (at != std::string::npos) {
    out.replace(at, title.size(), "pliant frame " + std::to_string(number) + " time_s " + format_double(frame.time_s));
  }
  const std::size_t tets = scratch.tetrahedra.size() / 4;
  if (!frame.cell_scalars.empty()) {
    if (scratch.youngs_modulus.empty()) out += "CELL_DATA " + std::to_string(tets) + "\n";
    for (const VtkNamedArray& array : frame.cell_scalars) {
      out += "SCALARS " + array.name + " double 1\nLOOKUP_TABLE default\n";
      append_values(out, array.values, 1, "");
    }
  }
  if (!frame.point_vectors.empty()) {
    out += "POINT_DATA " + std::to_string(frame.positions.size() / 3) + "\n";
    // 3-component SCALARS rather than VECTORS: parse_vtk_tet_mesh reads these back, and
    // ParaView treats any 3-component array as a vector.
    for (const VtkNamedArray& array : frame.point_vectors) {
      out += "SCALARS " + array.name + " double 3\nLOOKUP_TABLE default\n";
      append_values(out, array.values, 3, "");
    }
  }
  return out;
}

}  // namespace

VtkSeriesWriter::VtkSeriesWriter(const std::string& directory, const TetMesh& mesh, const VtkSeriesOptions& options)
    : directory_(directory), mesh_(mesh), options_(options) {
  mesh_detail::check_writable(mesh_, kLabel);
  if (mesh_.tetrahedra.empty()) fail_file(kLabel, "the mesh has no tetrahedra");
  if (!mesh_.youngs_modulus.empty()) {
    if (mesh_.youngs_modulus.size() != mesh_.tetrahedra.size() / 4) {
      fail_file(kLabel, "youngs_modulus must be empty or hold one value per tetrahedron");
    }
    for (const double value : mesh_.youngs_modulus) {
      if (!(std::isfinite(value) && value > 0.0)) {
        fail_file(kLabel, "youngs_modulus values must be positive and finite");
      }
    }
  }
  if (!valid_name(options_.base_name, true)) {
    fail_file(kLabel, "base_name '" + mesh_detail::printable(options_.base_name) +
                          "' must be 1-64 characters from [A-Za-z0-9_.-]");
  }
  std::error_code error;
  fs::create_directories(directory_, error);
  if (error || !fs::is_directory(directory_)) {
    throw std::runtime_error(std::string(kLabel) + ": cannot create directory " + directory_ +
                             (error ? ": " + error.message() : std::string()));
  }
}

std::string VtkSeriesWriter::frame_file_name(std::size_t frame) const {
  std::string digits = std::to_string(frame);
  if (digits.size() < 6) digits.insert(0, 6 - digits.size(), '0');
  const char* extension = options_.format == VtkSeriesFormat::vtu_pvd ? ".vtu" : ".vtk";
  return options_.base_name + "_" + digits + extension;
}

std::string VtkSeriesWriter::write_frame(const VtkSeriesFrame& frame) {
  const std::size_t points = mesh_.points.size() / 3;
  const std::size_t tets = mesh_.tetrahedra.size() / 4;
  const std::size_t number = times_s_.size();
  if (!std::isfinite(frame.time_s)) fail_file(kLabel, "frame " + std::to_string(number) + ": time_s is not finite");
  if (!times_s_.empty() && !(frame.time_s > times_s_.back())) {
    fail_file(kLabel, "frame " + std::to_string(number) + ": time_s " + format_double(frame.time_s) +
                          " is not after the previous frame's " + format_double(times_s_.back()));
  }
  if (frame.positions.size() != 3 * points) {
    fail_file(kLabel, "frame " + std::to_string(number) + ": positions hold " + std::to_string(frame.positions.size()) +
                          " values, expected " + std::to_string(3 * points));
  }
  for (const double value : frame.positions) {
    if (!std::isfinite(value)) {
      fail_file(kLabel, "frame " + std::to_string(number) + ": a position is not finite");
    }
  }
  check_arrays(frame.point_vectors, 3 * points, "point vector", std::string());
  check_arrays(frame.cell_scalars, tets, "cell scalar",
               mesh_.youngs_modulus.empty() ? std::string() : std::string("youngs_modulus"));

  const std::string name = frame_file_name(number);
  const fs::path path = fs::path(directory_) / name;
  if (options_.format == VtkSeriesFormat::vtu_pvd) {
    write_file_atomically(path, vtu_frame(mesh_, frame));
  } else {
    TetMesh scratch;
    scratch.tetrahedra = mesh_.tetrahedra;
    scratch.youngs_modulus = mesh_.youngs_modulus;
    write_file_atomically(path, legacy_frame(scratch, frame, number));
  }
  times_s_.push_back(frame.time_s);
  files_.push_back(name);
  return path.string();
}

std::string VtkSeriesWriter::finish() {
  std::string out;
  fs::path path;
  if (options_.format == VtkSeriesFormat::vtu_pvd) {
    path = fs::path(directory_) / (options_.base_name + ".pvd");
    out =
        "<?xml version=\"1.0\"?>\n"
        "<VTKFile type=\"Collection\" version=\"0.1\" byte_order=\"LittleEndian\">\n"
        "  <Collection>\n";
    for (std::size_t i = 0; i < files_.size(); ++i) {
      out += "    <DataSet timestep=\"" + format_double(times_s_[i]) + "\" group=\"\" part=\"0\" file=\"" + files_[i] +
             "\"/>\n";
    }
    out += "  </Collection>\n</VTKFile>\n";
  } else {
    path = fs::path(directory_) / (options_.base_name + ".vtk.series");
    out = "{\n  \"file-series-version\" : \"1.0\",\n  \"files\" : [\n";
    for (std::size_t i = 0; i < files_.size(); ++i) {
      out += "    { \"name\" : \"" + files_[i] + "\", \"time\" : " + format_double(times_s_[i]) + " }" +
             (i + 1 < files_.size() ? ",\n" : "\n");
    }
    out += "  ]\n}\n";
  }
  write_file_atomically(path, out);
  return path.string();
}

std::string write_vtk_time_series(const std::string& directory, const TetMesh& mesh,
                                  const std::vector<VtkSeriesFrame>& frames, const VtkSeriesOptions& options) {
  VtkSeriesWriter writer(directory, mesh, options);
  for (const VtkSeriesFrame& frame : frames) writer.write_frame(frame);
  return writer.finish();
}

}  // namespace pliant::host

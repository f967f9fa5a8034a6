// particles.csv, wrench.csv and gripper.csv of recording format v1.
#include <array>
#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include "pliant/host/recording.hpp"
#include "pliant/host/text_fields.hpp"

namespace pliant::host {
namespace {

using detail::fail_at;
using detail::format_double;
using detail::NumberStatus;
using detail::printable;

// Reads the header line, which must equal `header` exactly.
void expect_header(detail::LineReader& lines, const std::string& label, const std::string& header,
                   const std::string& context) {
  std::string_view line;
  if (!lines.next(line)) fail_at(label, 1, "empty file, expected header '" + header + "'");
  if (line != header) {
    fail_at(label, 1, "header must be exactly '" + header + "'" + context + ", found '" + printable(line) + "'");
  }
}

// Reads the next data row into `fields`; false at end of text.
bool next_row(detail::LineReader& lines, const std::string& label, std::size_t column_count, const std::string& header,
              std::vector<std::string_view>& fields) {
  std::string_view line;
  if (!lines.next(line)) return false;
  if (line.empty()) fail_at(label, lines.line_number(), "empty line");
  detail::split_fields(line, ',', fields);
  if (fields.size() != column_count) {
    fail_at(label, lines.line_number(),
            "expected " + std::to_string(column_count) + " fields (" + header + "), found " +
                std::to_string(fields.size()));
  }
  return true;
}

bool is_nan_literal(std::string_view field) {
  if (!field.empty() && field.front() == '-') field.remove_prefix(1);
  return detail::equals_ignoring_case(field, "nan");
}

// A number that may be the literal nan (returned as a quiet NaN) but never infinite.
double coordinate_or_nan(std::string_view field, const std::string& label, std::size_t line, const char* column) {
  if (is_nan_literal(field)) return std::numeric_limits<double>::quiet_NaN();
  double value = 0.0;
  const NumberStatus status = detail::parse_double(field, value);
  if (status == NumberStatus::out_of_range) {
    fail_at(label, line, std::string(column) + ": number out of range '" + printable(field) + "'");
  }
  if (status != NumberStatus::ok || std::isnan(value)) {
    fail_at(label, line, std::string(column) + ": expected a number or nan, found '" + printable(field) + "'");
  }
  if (std::isinf(value)) {
    fail_at(label, line, std::string(column) + ": infinite value '" + printable(field) + "'");
  }
  return value;
}

double finite_value(std::string_view field, const std::string& label, std::size_t line, const char* column) {
  double value = 0.0;
  const NumberStatus status = detail::parse_double(field, value);
  if (status == NumberStatus::out_of_range) {
    fail_at(label, line, std::string(column) + ": number out of range '" + printable(field) + "'");
  }
  if (status != NumberStatus::ok) {
    fail_at(label, line, std::string(column) + ": expected a number, found '" + printable(field) + "'");
  }
  if (!std::isfinite(value)) {
    fail_at(label, line, std::string(column) + ": must be finite, found '" + printable(field) + "'");
  }
  return value;
}

// Rows of wrench.csv and gripper.csv: all columns finite, t strictly increasing.
template <std::size_t N>
std::vector<std::array<double, N>> parse_samples(std::string_view text, const std::string& label,
                                                 const std::array<const char*, N>& columns) {
  std::string header;
  for (const char* column : columns) header += (header.empty() ? "" : ",") + std::string(column);
  detail::LineReader lines(text);
  expect_header(lines, label, header, "");
  std::vector<std::array<double, N>> rows;
  std::vector<std::string_view> fields;
  while (next_row(lines, label, N, header, fields)) {
    const std::size_t line = lines.line_number();
    std::array<double, N> row{};
    for (std::size_t c = 0; c < N; ++c) row[c] = finite_value(fields[c], label, line, columns[c]);
    if (!rows.empty() && !(row[0] > rows.back()[0])) {
      fail_at(label, line,
              "t " + format_double(row[0]) + " is not after the previous row's t " + format_double(rows.back()[0]) +
                  " (t must be strictly increasing)");
    }
    rows.push_back(row);
  }
  return rows;
}

}  // namespace

bool Recording::observed(int frame, int id) const {
  for (int axis = 0; axis < dimension; ++axis) {
    if (!std::isfinite(position(frame, id, axis))) return false;
  }
  return true;
}

void parse_particles_csv(std::string_view text, const std::string& file_label, Recording& out) {
  if ((out.dimension != 2 && out.dimension != 3) || out.particle_count <= 0 ||
      out.particle_count > detail::kMaxParticles) {
    throw RecordingError(file_label + ": cannot be read without a valid dimension and particles.count");
  }
  const auto dimension = static_cast<std::size_t>(out.dimension);
  const auto count = static_cast<std::size_t>(out.particle_count);
  const std::size_t frame_size = count * dimension;
  const std::string header = dimension == 2 ? "t,id,x,y" : "t,id,x,y,z";
  static const char* const axis_names[] = {"x", "y", "z"};

  detail::LineReader lines(text);
  expect_header(lines, file_label, header, " for a " + std::to_string(dimension) + "D recording");

  std::vector<double> times;
  std::vector<double> positions;
  // Line of each particle's latest row: a row at or after the frame's first line is a repeat.
  std::vector<std::size_t> seen_line;
  std::size_t frame_start_line = 0;
  std::vector<std::string_view> fields;
  while (next_row(lines, file_label, 2 + dimension, header, fields)) {
    const std::size_t line = lines.line_number();
    const double t = finite_value(fields[0], file_label, line, "t");
    long long id = 0;
    const NumberStatus id_status = detail::parse_integer(fields[1], id);
    if (id_status == NumberStatus::not_a_number) {
      fail_at(file_label, line, "id: expected an integer, found '" + printable(fields[1]) + "'");
    }
    if (id_status == NumberStatus::out_of_range || id < 0 || id >= out.particle_count) {
      fail_at(file_label, line,
              "id " + printable(fields[1]) + " out of range 0.." + std::to_string(out.particle_count - 1));
    }
    double coordinates[3] = {0.0, 0.0, 0.0};
    for (std::size_t axis = 0; axis < dimension; ++axis) {
      coordinates[axis] = coordinate_or_nan(fields[2 + axis], file_label, line, axis_names[axis]);
    }

    if (times.empty() || t != times.back()) {
      if (!times.empty() && t < times.back()) {
        fail_at(file_label, line,
                "t " + format_double(t) + " is smaller than the previous frame's t " + format_double(times.back()) +
                    " (frames must appear in increasing t)");
      }
      if ((times.size() + 1) > detail::kMaxPositionValues / frame_size) {
        fail_at(file_label, line,
                "too many frames: " + std::to_string(times.size() + 1) + " frames of " + std::to_string(count) +
                    " particles exceed the limit of " + std::to_string(detail::kMaxPositionValues) +
                    " stored coordinates");
      }
      times.push_back(t);
      positions.resize(positions.size() + frame_size, std::numeric_limits<double>::quiet_NaN());
      frame_start_line = line;
    }
    const auto index = static_cast<std::size_t>(id);
    if (seen_line.empty()) seen_line.assign(count, 0);
    if (seen_line[index] >= frame_start_line) {
      fail_at(file_label, line,
              "duplicate id " + std::to_string(id) + " in the frame at t=" + format_double(t) + " (first at line " +
                  std::to_string(seen_line[index]) + ")");
    }
    seen_line[index] = line;
    double* slot = positions.data() + (times.size() - 1) * frame_size + index * dimension;
    for (std::size_t axis = 0; axis < dimension; ++axis) slot[axis] = coordinates[axis];
  }
  out.frame_times_s = std::move(times);
  out.positions = std::move(positions);
}

std::vector<WrenchSample> parse_wrench_csv(std::string_view text, const std::string& file_label) {
  const auto rows = parse_samples<7>(text, file_label, {"t", "fx", "fy", "fz", "tx", "ty", "tz"});
  std::vector<WrenchSample> samples(rows.size());
  for (std::size_t i = 0; i < rows.size(); ++i) {
    samples[i].t_s = rows[i][0];
    for (std::size_t axis = 0; axis < 3; ++axis) {
      samples[i].force_n[axis] = rows[i][1 + axis];
      samples[i].torque_nm[axis] = rows[i][4 + axis];
    }
  }
  return samples;
}

std::vector<GripperSample> parse_gripper_csv(std::string_view text, const std::string& file_label) {
  const auto rows = parse_samples<3>(text, file_label, {"t", "width", "force"});
  std::vector<GripperSample> samples(rows.size());
  for (std::size_t i = 0; i < rows.size(); ++i) {
    samples[i].t_s = rows[i][0];
    samples[i].width = rows[i][1];
    samples[i].force_n = rows[i][2];
  }
  return samples;
}

}  // namespace pliant::host

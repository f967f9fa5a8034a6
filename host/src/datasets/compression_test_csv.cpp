// Compression-test CSV parser (format in compression_test.hpp) and the linear modulus fit.
// Needs only the recording text helpers, so the fuzz target compiles it on its own.
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <stdexcept>
#include <string>
#include <system_error>
#include <vector>

#include "pliant/host/text_fields.hpp"
#include "pliant/host/fem/compression_test.hpp"

namespace pliant::host {
namespace {

using detail::fail_at;
using detail::format_double;
using detail::NumberStatus;
using detail::printable;

constexpr double kPi = 3.14159265358979323846;
constexpr double kMinLength_m = 1e-4;
constexpr double kMaxLength_m = 10.0;
constexpr double kMaxSpeed_m_per_s = 10.0;
constexpr double kMaxLoad_n = 1e7;
constexpr double kMaxTime_s = 1e9;
constexpr std::size_t kMaxColumns = 64;

// Six significant digits, for quantities quoted in messages after a unit conversion.
std::string short_number(double value) {
  char buffer[32];
  std::snprintf(buffer, sizeof buffer, "%.6g", value);
  return buffer;
}

[[noreturn]] void fail_file(const std::string& label, const std::string& cause) {
  throw RecordingError(label + ": " + cause);
}

bool is_blank(char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\v' || c == '\f'; }

std::string_view trim(std::string_view text) {
  while (!text.empty() && is_blank(text.front())) text.remove_prefix(1);
  while (!text.empty() && is_blank(text.back())) text.remove_suffix(1);
  return text;
}

// Lower case ASCII with runs of blanks folded into one space.
std::string folded(std::string_view text) {
  std::string out;
  bool blank = false;
  for (const char c : trim(text)) {
    if (is_blank(c)) {
      blank = true;
      continue;
    }
    if (blank) out.push_back(' ');
    blank = false;
    out.push_back(c >= 'A' && c <= 'Z' ? static_cast<char>(c - 'A' + 'a') : c);
  }
  return out;
}

// Metadata text kept in the result ends up in recording.json, whose writer needs valid UTF-8:
// control bytes and bytes outside a well-formed UTF-8 sequence become '?'.
std::string clean_text(std::string_view text) {
  std::string out;
  out.reserve(text.size());
  std::size_t i = 0;
  const auto byte = [&](std::size_t k) { return static_cast<unsigned char>(text[k]); };
  const auto continuation = [&](std::size_t k, unsigned char low, unsigned char high) {
    return k < text.size() && byte(k) >= low && byte(k) <= high;
  };
  while (i < text.size()) {
    const unsigned char c = byte(i);
    std::size_t length = 0;
    if (c < 0x80) {
      out.push_back(c < 0x20 || c == 0x7f ? '?' : static_cast<char>(c));
      ++i;
      continue;
    }
    if (c >= 0xC2 && c <= 0xDF) {
      length = continuation(i + 1, 0x80, 0xBF) ? 2 : 0;
    } else if (c >= 0xE0 && c <= 0xEF) {
      const unsigned char low = c == 0xE0 ? 0xA0 : 0x80;
      const unsigned char high = c == 0xED ? 0x9F : 0xBF;
      length = continuation(i + 1, low, high) && continuation(i + 2, 0x80, 0xBF) ? 3 : 0;
    } else if (c >= 0xF0 && c <= 0xF4) {
      const unsigned char low = c == 0xF0 ? 0x90 : 0x80;
      const unsigned char high = c == 0xF4 ? 0x8F : 0xBF;
      length =
          continuation(i + 1, low, high) && continuation(i + 2, 0x80, 0xBF) && continuation(i + 3, 0x80, 0xBF) ? 4 : 0;
    }
    if (length == 0) {
      out.push_back('?');
      ++i;
    } else {
      out.append(text.substr(i, length));
      i += length;
    }
  }
  return out;
}

// "Cylinder Diameter (mm)" -> name "cylinder diameter", unit "mm" (both folded).
struct NameAndUnit {
  std::string name;
  std::string unit;
};

NameAndUnit split_name_unit(std::string_view text) {
  text = trim(text);
  NameAndUnit out;
  if (!text.empty() && (text.back() == ')' || text.back() == ']')) {
    const char open = text.back() == ')' ? '(' : '[';
    const std::size_t at = text.rfind(open);
    if (at != std::string_view::npos) {
      out.unit = folded(text.substr(at + 1, text.size() - at - 2));
      text = text.substr(0, at);
    }
  }
  out.name = folded(text);
  return out;
}

// A number followed by an optional unit ("50mm", "0.05 m", "10"): the unit is returned folded.
double number_with_unit(std::string_view value, std::string& unit, const std::string& label, std::size_t line,
                        const std::string& what) {
  value = trim(value);
  double number = 0.0;
  const char* end = value.data() + value.size();
  const auto result = std::from_chars(value.data(), end, number);
  if (result.ec == std::errc::result_out_of_range) {
    fail_at(label, line, what + ": number out of range '" + printable(value) + "'");
  }
  if (result.ec != std::errc() || value.empty()) {
    fail_at(label, line, what + ": expected a number, found '" + printable(value) + "'");
  }
  if (!std::isfinite(number)) {
    fail_at(label, line, what + ": must be finite, found '" + printable(value) + "'");
  }
  unit = folded(std::string_view(result.ptr, static_cast<std::size_t>(end - result.ptr)));
  return number;
}

// The unit written after the value, else the one in parentheses after the key.
std::string chosen_unit(const std::string& after_value, const std::string& after_key, const std::string& label,
                        std::size_t line, const std::string& what) {
  if (!after_value.empty() && !after_key.empty() && after_value != after_key) {
    fail_at(label, line,
            what + ": two different units, '" + printable(after_key) + "' and '" + printable(after_value) + "'");
  }
  return after_value.empty() ? after_key : after_value;
}

double length_scale(const std::string& unit, const std::string& label, std::size_t line, const std::string& what) {
  if (unit == "mm") return 1e-3;
  if (unit == "cm") return 1e-2;
  if (unit == "m") return 1.0;
  if (unit.empty()) fail_at(label, line, what + ": unit missing (expected mm, cm or m)");
  fail_at(label, line, what + ": unknown unit '" + printable(unit) + "' (expected mm, cm or m)");
}

enum class Role { time, compression, load, engineering_strain, engineering_stress, true_strain, true_stress, ignored };

const char* role_name(Role role) {
  switch (role) {
    case Role::time: return "Time";
    case Role::compression: return "Compression";
    case Role::load: return "Load";
    case Role::engineering_strain: return "Engineering Strain";
    case Role::engineering_stress: return "Engineering Stress";
    case Role::true_strain: return "True Strain";
    case Role::true_stress: return "True Stress";
    case Role::ignored: break;
  }
  return "ignored";
}

Role role_of(const std::string& name) {
  if (name == "time") return Role::time;
  if (name == "compression") return Role::compression;
  if (name == "load") return Role::load;
  if (name == "engineering strain") return Role::engineering_strain;
  if (name == "engineering stress") return Role::engineering_stress;
  if (name == "true strain") return Role::true_strain;
  if (name == "true stress") return Role::true_stress;
  return Role::ignored;
}

// Factor from the column's unit to SI, or a failure naming the accepted units.
double column_scale(Role role, const std::string& unit, const std::string& label, std::size_t line) {
  const std::string what = role_name(role);
  const auto unknown = [&](const char* expected) {
    if (unit.empty()) fail_at(label, line, what + ": unit missing (expected " + expected + ")");
    fail_at(label, line, what + ": unknown unit '" + printable(unit) + "' (expected " + expected + ")");
  };
  switch (role) {
    case Role::time:
      if (unit == "s") return 1.0;
      if (unit == "ms") return 1e-3;
      if (unit == "min") return 60.0;
      unknown("s, ms or min");
      break;
    case Role::compression:
      if (unit == "mm") return 1e-3;
      if (unit == "cm") return 1e-2;
      if (unit == "m") return 1.0;
      unknown("mm, cm or m");
      break;
    case Role::load:
      if (unit == "n") return 1.0;
      if (unit == "kn") return 1e3;
      unknown("N or kN");
      break;
    case Role::engineering_strain:
    case Role::true_strain:
      if (unit.empty() || unit == "-" || unit == "mm/mm" || unit == "m/m") return 1.0;
      if (unit == "%") return 1e-2;
      unknown("-, mm/mm or %");
      break;
    case Role::engineering_stress:
    case Role::true_stress:
      if (unit == "pa") return 1.0;
      if (unit == "kpa") return 1e3;
      if (unit == "mpa" || unit == "n/mm^2" || unit == "n/mm2") return 1e6;
      unknown("Pa, kPa, MPa or N/mm^2");
      break;
    case Role::ignored: break;
  }
  return 1.0;
}

struct Column {
  Role role = Role::ignored;
  double scale = 1.0;
};

class Parser {
 public:
  Parser(std::string_view text, const std::string& label) : lines_(text), label_(label) { out_.label = label; }

  CompressionTest run() {
    std::string_view line;
    bool any_text = false;
    while (lines_.next(line)) {
      const std::string_view content = trim(line);
      if (content.empty()) continue;
      any_text = true;
      if (columns_.empty()) {
        header_or_metadata(content);
      } else {
        data_row(content);
      }
    }
    const std::size_t last = lines_.line_number() == 0 ? 1 : lines_.line_number();
    if (!any_text) fail_at(label_, last, "empty file");
    if (columns_.empty()) {
      fail_at(label_, last, "no column header (e.g. 'Time (s),Compression (mm),Load (N)')");
    }
    if (out_.row_count() == 0) fail_at(label_, last, "no data rows after the column header");
    if (out_.row_count() < 2) fail_at(label_, last, "only one data row; a test needs at least two");
    return std::move(out_);
  }

 private:
  void header_or_metadata(std::string_view content) {
    const std::size_t line = lines_.line_number();
    detail::split_fields(content, ',', fields_);
    const std::string_view first = trim(fields_[0]);
    if (fields_.size() >= 2) {
      for (const std::string_view field : fields_) {
        const Role role = role_of(split_name_unit(field).name);
        if (role == Role::time || role == Role::compression || role == Role::load) {
          column_header(line);
          return;
        }
      }
    }
    double number = 0.0;
    if (fields_.size() >= 2 && detail::parse_double(first, number) == NumberStatus::ok) {
      fail_at(label_, line, "data row before the column header (e.g. 'Time (s),Compression (mm),Load (N)')");
    }
    metadata(content, line);
  }

  void metadata(std::string_view content, std::size_t line) {
    while (!content.empty() && (content.back() == ';' || is_blank(content.back()))) content.remove_suffix(1);
    if (content.empty()) return;
    const std::size_t colon = content.find(':');
    if (colon == std::string_view::npos) {
      if (out_.sample_name.empty()) {
        out_.sample_name = clean_text(content);
      } else {
        out_.notes.push_back(clean_text(content));
      }
      return;
    }
    const NameAndUnit key = split_name_unit(content.substr(0, colon));
    const std::string_view value = trim(content.substr(colon + 1));
    const std::string& name = key.name;
    if (name == "cylinder diameter" || name == "diameter" || name == "specimen diameter") {
      out_.diameter_m = length(value, key.unit, line, "Cylinder Diameter", diameter_line_);
    } else if (name == "cylinder height" || name == "height" || name == "specimen height") {
      out_.height_m = length(value, key.unit, line, "Cylinder Height", height_line_);
    } else if (name == "speed" || name == "compression speed" || name == "crosshead speed" || name == "test speed") {
      speed(value, key.unit, line);
    } else if (name == "machine" || name == "testing machine") {
      once(machine_line_, line, "Machine");
      out_.machine = clean_text(value);
    } else if (name == "load cell") {
      once(load_cell_line_, line, "Load cell");
      out_.load_cell = clean_text(value);
    } else if (name == "sample" || name == "sample name" || name == "specimen" || name == "specimen name") {
      once(sample_line_, line, "Sample");
      if (!out_.sample_name.empty()) out_.notes.push_back(out_.sample_name);
      out_.sample_name = clean_text(value);
    } else {
      out_.other_metadata.emplace_back(clean_text(trim(content.substr(0, colon))), clean_text(value));
    }
  }

  void once(std::size_t& seen_at, std::size_t line, const char* what) {
    if (seen_at != 0) {
      fail_at(label_, line,
              std::string("duplicate '") + what + "' line (first at line " + std::to_string(seen_at) + ")");
    }
    seen_at = line;
  }

  double length(std::string_view value, const std::string& key_unit, std::size_t line, const char* what,
                std::size_t& seen_at) {
    once(seen_at, line, what);
    std::string unit;
    const double number = number_with_unit(value, unit, label_, line, what);
    const double metres = number * length_scale(chosen_unit(unit, key_unit, label_, line, what), label_, line, what);
    if (!(metres >= kMinLength_m && metres <= kMaxLength_m)) {
      fail_at(label_, line, std::string(what) + ": " + printable(value) + " is out of range (expected 0.1 mm to 10 m)");
    }
    return metres;
  }

  void speed(std::string_view value, const std::string& key_unit, std::size_t line) {
    once(speed_line_, line, "Speed");
    std::string unit;
    const double number = number_with_unit(value, unit, label_, line, "Speed");
    unit = chosen_unit(unit, key_unit, label_, line, "Speed");
    double scale = 0.0;
    if (unit == "mm/min") {
      scale = 1e-3 / 60.0;
    } else if (unit == "mm/s") {
      scale = 1e-3;
    } else if (unit == "m/min") {
      scale = 1.0 / 60.0;
    } else if (unit == "m/s") {
      scale = 1.0;
    } else if (unit.empty()) {
      fail_at(label_, line, "Speed: unit missing (expected mm/min, mm/s, m/min or m/s)");
    } else {
      fail_at(label_, line, "Speed: unknown unit '" + printable(unit) + "' (expected mm/min, mm/s, m/min or m/s)");
    }
    const double m_per_s = number * scale;
    if (!(m_per_s > 0.0 && m_per_s <= kMaxSpeed_m_per_s)) {
      fail_at(label_, line, "Speed: " + printable(value) + " is out of range (expected above 0, at most 10 m/s)");
    }
    out_.speed_m_per_s = m_per_s;
  }

  void column_header(std::size_t line) {
    if (diameter_line_ == 0) fail_at(label_, line, "missing 'Cylinder Diameter' line before the column header");
    if (height_line_ == 0) fail_at(label_, line, "missing 'Cylinder Height' line before the column header");
    if (fields_.size() > kMaxColumns) {
      fail_at(label_, line,
              "too many columns (" + std::to_string(fields_.size()) + ", at most " + std::to_string(kMaxColumns) + ")");
    }
    std::vector<Column> columns;
    bool seen[7] = {false, false, false, false, false, false, false};
    for (const std::string_view field : fields_) {
      const NameAndUnit header = split_name_unit(field);
      Column column;
      column.role = role_of(header.name);
      if (column.role != Role::ignored) {
        bool& already = seen[static_cast<int>(column.role)];
        if (already) {
          fail_at(label_, line, std::string("column '") + role_name(column.role) + "' appears twice");
        }
        already = true;
        column.scale = column_scale(column.role, header.unit, label_, line);
      }
      columns.push_back(column);
    }
    for (const Role role : {Role::time, Role::compression, Role::load}) {
      if (!seen[static_cast<int>(role)]) {
        fail_at(label_, line, std::string("column header has no '") + role_name(role) + "' column");
      }
    }
    columns_ = std::move(columns);
  }

  std::vector<double>* target(Role role) {
    switch (role) {
      case Role::time: return &out_.time_s;
      case Role::compression: return &out_.compression_m;
      case Role::load: return &out_.load_n;
      case Role::engineering_strain: return &out_.engineering_strain;
      case Role::engineering_stress: return &out_.engineering_stress_pa;
      case Role::true_strain: return &out_.true_strain;
      case Role::true_stress: return &out_.true_stress_pa;
      case Role::ignored: break;
    }
    return nullptr;
  }

  void data_row(std::string_view content) {
    const std::size_t line = lines_.line_number();
    detail::split_fields(content, ',', fields_);
    if (fields_.size() != columns_.size()) {
      fail_at(label_, line,
              "expected " + std::to_string(columns_.size()) + " fields as in the column header, found " +
                  std::to_string(fields_.size()));
    }
    if (out_.row_count() >= kMaxCompressionRows) {
      fail_at(label_, line, "more than " + std::to_string(kMaxCompressionRows) + " data rows");
    }
    double row[7] = {0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0};
    for (std::size_t c = 0; c < columns_.size(); ++c) {
      const Column& column = columns_[c];
      if (column.role == Role::ignored) continue;
      const std::string_view field = trim(fields_[c]);
      const std::string what = role_name(column.role);
      double value = 0.0;
      const NumberStatus status = detail::parse_double(field, value);
      if (status == NumberStatus::out_of_range) {
        fail_at(label_, line, what + ": number out of range '" + printable(field) + "'");
      }
      if (status != NumberStatus::ok) {
        fail_at(label_, line, what + ": expected a number, found '" + printable(field) + "'");
      }
      if (!std::isfinite(value)) fail_at(label_, line, what + ": must be finite, found '" + printable(field) + "'");
      row[static_cast<int>(column.role)] = value * column.scale;
    }
    const double t = row[static_cast<int>(Role::time)];
    const double compression = row[static_cast<int>(Role::compression)];
    const double load = row[static_cast<int>(Role::load)];
    if (!(std::fabs(t) <= kMaxTime_s)) {
      fail_at(label_, line, "Time: " + short_number(t) + " s is out of range (at most 1e9 s in magnitude)");
    }
    if (!out_.time_s.empty() && !(t > out_.time_s.back())) {
      fail_at(label_, line,
              "Time " + format_double(t) + " s is not after the previous row's " + format_double(out_.time_s.back()) +
                  " s (time must increase)");
    }
    if (!(std::fabs(compression) < out_.height_m)) {
      fail_at(label_, line,
              "Compression: " + short_number(compression * 1e3) + " mm is not below the specimen height of " +
                  short_number(out_.height_m * 1e3) + " mm");
    }
    if (!(std::fabs(load) <= kMaxLoad_n)) {
      fail_at(label_, line, "Load: " + short_number(load) + " N is out of range (at most 1e7 N in magnitude)");
    }
    for (std::size_t c = 0; c < columns_.size(); ++c) {
      const Role role = columns_[c].role;
      if (role != Role::ignored) target(role)->push_back(row[static_cast<int>(role)]);
    }
  }

  detail::LineReader lines_;
  const std::string& label_;
  CompressionTest out_;
  std::vector<std::string_view> fields_;
  std::vector<Column> columns_;  // empty until the column header
  std::size_t diameter_line_ = 0;
  std::size_t height_line_ = 0;
  std::size_t speed_line_ = 0;
  std::size_t machine_line_ = 0;
  std::size_t load_cell_line_ = 0;
  std::size_t sample_line_ = 0;
};

}  // namespace

double CompressionTest::cross_section_m2() const { return 0.25 * kPi * diameter_m * diameter_m; }

CompressionTest parse_compression_csv(std::string_view text, const std::string& file_label) {
  return Parser(text, file_label).run();
}

CompressionTest read_compression_csv(const std::string& path) {
  const std::string label = printable(path, 200);
  std::error_code error;
  const std::filesystem::file_status status = std::filesystem::status(path, error);
  if (status.type() == std::filesystem::file_type::not_found) fail_file(label, "no such file");
  if (error) fail_file(label, "cannot access: " + error.message());
  if (status.type() != std::filesystem::file_type::regular) fail_file(label, "not a regular file");
  const std::uintmax_t size = std::filesystem::file_size(path, error);
  if (error) fail_file(label, "cannot read: " + error.message());
  if (size > kMaxCompressionCsvBytes) {
    fail_file(label, "file too large (" + std::to_string(size) + " bytes, the limit is " +
                         std::to_string(kMaxCompressionCsvBytes) + ")");
  }
  std::ifstream in(path, std::ios::binary);
  if (!in) fail_file(label, std::string("cannot open: ") + std::strerror(errno));
  std::string text(static_cast<std::size_t>(size), '\0');
  in.read(text.data(), static_cast<std::streamsize>(size));
  if (in.gcount() != static_cast<std::streamsize>(size)) fail_file(label, "cannot read the whole file");
  return parse_compression_csv(text, label);
}

LinearModulusFit fit_linear_modulus(const CompressionTest& test, double from_strain, double to_strain) {
  if (!std::isfinite(from_strain) || !std::isfinite(to_strain) || !(from_strain < to_strain)) {
    throw std::invalid_argument("fit_linear_modulus: the strain window must be finite with from < to");
  }
  if (!(test.height_m > 0.0) || !(test.diameter_m > 0.0) || test.compression_m.size() != test.load_n.size()) {
    throw std::invalid_argument("fit_linear_modulus: the test has no valid geometry or columns");
  }
  const double area = test.cross_section_m2();
  std::vector<double> strain;
  std::vector<double> stress;
  for (std::size_t i = 0; i < test.compression_m.size(); ++i) {
    const double e = test.compression_m[i] / test.height_m;
    if (e >= from_strain && e <= to_strain) {
      strain.push_back(e);
      stress.push_back(test.load_n[i] / area);
    }
  }
  if (strain.size() < 2) {
    throw std::invalid_argument("fit_linear_modulus: fewer than two rows in the strain window [" +
                                format_double(from_strain) + ", " + format_double(to_strain) + "]");
  }
  const auto n = static_cast<double>(strain.size());
  double mean_e = 0.0;
  double mean_s = 0.0;
  for (std::size_t i = 0; i < strain.size(); ++i) {
    mean_e += strain[i];
    mean_s += stress[i];
  }
  mean_e /= n;
  mean_s /= n;
  double see = 0.0;
  double ses = 0.0;
  for (std::size_t i = 0; i < strain.size(); ++i) {
    see += (strain[i] - mean_e) * (strain[i] - mean_e);
    ses += (strain[i] - mean_e) * (stress[i] - mean_s);
  }
  if (!(see > 0.0)) {
    throw std::invalid_argument("fit_linear_modulus: all rows in the strain window have the same strain");
  }
  LinearModulusFit fit;
  fit.youngs_modulus_pa = ses / see;
  fit.intercept_pa = mean_s - fit.youngs_modulus_pa * mean_e;
  fit.rows = strain.size();
  return fit;
}

const char* to_string(PlatenContact contact) { return contact == PlatenContact::bonded ? "bonded" : "frictionless"; }

const char* to_string(LateralExpansion expansion) {
  return expansion == LateralExpansion::finite_strain ? "finite_strain" : "small_strain";
}

}  // namespace pliant::host

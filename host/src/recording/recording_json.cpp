// recording.json of recording format v1: syntax and per-key validation.
#include <algorithm>
#include <climits>
#include <cmath>
#include <cstdint>
#include <numeric>
#include <optional>
#include <set>
#include <string>
#include <utility>

#include "pliant/host/recording.hpp"
#include "pliant/host/text_fields.hpp"

namespace pliant::host {
namespace {

using detail::printable;
using nlohmann::json;

// meta is free-form, so copying or printing it recurses; a depth limit keeps the stack bounded.
constexpr int kMaxNesting = 100;

[[noreturn]] void fail_key(const std::string& label, const std::string& key, const std::string& cause) {
  throw RecordingError(label + ": " + key + ": " + cause);
}

[[noreturn]] void fail_position(const std::string& label, std::string_view text, std::size_t index,
                                const std::string& cause) {
  if (index > text.size()) index = text.size();
  std::size_t line = 1;
  std::size_t line_start = 0;
  for (std::size_t i = 0; i < index; ++i) {
    if (text[i] == '\n') {
      ++line;
      line_start = i + 1;
    }
  }
  throw RecordingError(label + ":" + std::to_string(line) + ":" + std::to_string(index - line_start + 1) + ": " +
                       cause);
}

// Index of the first byte outside string literals for which `stop(i)` holds, or npos. String
// tracking mirrors the JSON lexer on every prefix the real parser accepts, which is all that
// matters before it reports its own error.
template <typename Stop>
std::size_t find_outside_strings(std::string_view text, Stop&& stop) {
  bool in_string = false;
  bool escaped = false;
  for (std::size_t i = 0; i < text.size(); ++i) {
    const char c = text[i];
    if (in_string) {
      if (escaped) {
        escaped = false;
      } else if (c == '\\') {
        escaped = true;
      } else if (c == '"') {
        in_string = false;
      }
    } else if (c == '"') {
      in_string = true;
    } else if (stop(i)) {
      return i;
    }
  }
  return std::string_view::npos;
}

void check_nesting(std::string_view text, const std::string& label) {
  int depth = 0;
  const std::size_t at = find_outside_strings(text, [&](std::size_t i) {
    if (text[i] == '[' || text[i] == '{') return ++depth > kMaxNesting;
    if ((text[i] == ']' || text[i] == '}') && depth > 0) --depth;
    return false;
  });
  if (at != std::string_view::npos) {
    fail_position(label, text, at, "nested deeper than " + std::to_string(kMaxNesting) + " levels");
  }
}

bool is_number_char(char c) {
  return (c >= '0' && c <= '9') || c == '.' || c == 'e' || c == 'E' || c == '+' || c == '-';
}

// nlohmann reports a number too large for a double without its position; the message quotes
// the number, so the position is that of its first occurrence as a whole token.
std::size_t locate_quoted_number(std::string_view text, const std::string& message) {
  const std::size_t open = message.find('\'');
  const std::size_t close = open == std::string::npos ? open : message.find('\'', open + 1);
  if (close == std::string::npos || close == open + 1) return std::string_view::npos;
  const std::string_view token = std::string_view(message).substr(open + 1, close - open - 1);
  return find_outside_strings(text, [&](std::size_t i) {
    return text.substr(i, token.size()) == token && (i == 0 || !is_number_char(text[i - 1])) &&
           (i + token.size() == text.size() || !is_number_char(text[i + token.size()]));
  });
}

std::string parser_cause(const char* what) {
  const std::string message(what);
  std::size_t start = message.find("parse error");
  start = start == std::string::npos ? std::string::npos : message.find(": ", start);
  if (start == std::string::npos) {
    start = message.find("] ");
  }
  std::string cause = start == std::string::npos ? message : message.substr(start + 2);
  return printable(cause, 200);
}

json parse_document(std::string_view text, const std::string& label) {
  check_nesting(text, label);
  try {
    return json::parse(text.begin(), text.end());
  } catch (const json::parse_error& error) {
    fail_position(label, text, error.byte == 0 ? 0 : error.byte - 1, parser_cause(error.what()));
  } catch (const json::exception& error) {
    // A number too large for a double is the one non-syntax error the parser raises.
    const std::string cause = parser_cause(error.what());
    const std::size_t at = locate_quoted_number(text, error.what());
    if (at != std::string_view::npos) fail_position(label, text, at, cause);
    throw RecordingError(label + ": " + cause);
  }
}

std::optional<long long> integer_value(const json& value) {
  if (value.is_number_unsigned()) {
    const auto u = value.get<std::uint64_t>();
    return u > static_cast<std::uint64_t>(LLONG_MAX) ? LLONG_MAX : static_cast<long long>(u);
  }
  if (value.is_number_integer()) return value.get<std::int64_t>();
  return std::nullopt;
}

class Reader {
 public:
  Reader(const std::string& label, Recording& out) : label_(label), out_(out) {}

  void read(json& doc) {
    if (!doc.is_object()) fail_key(label_, "(top level)", "must be a JSON object");
    read_header(doc);
    read_gravity(doc);
    read_particles(doc);
    read_files(doc);
    read_wrench(doc);
    read_material(doc);
    if (auto it = doc.find("meta"); it != doc.end()) out_.meta = std::move(*it);
    static const std::set<std::string> known = {"format",    "version", "dimension", "length_unit", "gravity",
                                                "particles", "files",   "wrench",    "material",    "meta"};
    for (auto& item : doc.items()) {
      if (known.count(item.key()) != 0) continue;
      out_.warnings.push_back(label_ + ": unknown key '" + printable(item.key()) + "' kept but ignored");
      out_.unknown_keys[item.key()] = std::move(item.value());
    }
  }

 private:
  const json& required(const json& object, const char* key, const std::string& path) {
    const auto it = object.find(key);
    if (it == object.end()) fail_key(label_, path, "missing required key");
    return *it;
  }

  double finite_number(const json& value, const std::string& path) {
    if (!value.is_number()) fail_key(label_, path, "must be a number");
    const double v = value.get<double>();
    if (!std::isfinite(v)) fail_key(label_, path, "must be finite");
    return v;
  }

  int particle_id(const json& value, const std::string& path) {
    const auto id = integer_value(value);
    if (!id) fail_key(label_, path, "must be an integer particle id");
    if (*id < 0 || *id >= out_.particle_count) {
      fail_key(label_, path,
               "id " + std::to_string(*id) + " out of range 0.." + std::to_string(out_.particle_count - 1));
    }
    return static_cast<int>(*id);
  }

  void read_header(const json& doc) {
    const json& format = required(doc, "format", "format");
    if (!format.is_string() || format.get_ref<const std::string&>() != "pliant-recording") {
      fail_key(label_, "format", "must be \"pliant-recording\"");
    }
    const auto version = integer_value(required(doc, "version", "version"));
    if (!version || *version != 1) {
      fail_key(label_, "version", "must be 1 (this reader supports format version 1 only)");
    }
    const auto dimension = integer_value(required(doc, "dimension", "dimension"));
    if (!dimension || (*dimension != 2 && *dimension != 3)) {
      fail_key(label_, "dimension", "must be 2 or 3");
    }
    out_.dimension = static_cast<int>(*dimension);
    const json& unit = required(doc, "length_unit", "length_unit");
    if (!unit.is_string() ||
        (unit.get_ref<const std::string&>() != "m" && unit.get_ref<const std::string&>() != "px")) {
      fail_key(label_, "length_unit", "must be \"m\" or \"px\"");
    }
    out_.length_unit = unit.get<std::string>();
  }

  void read_gravity(const json& doc) {
    const auto it = doc.find("gravity");
    if (it == doc.end()) return;
    if (!it->is_array() || it->size() != static_cast<std::size_t>(out_.dimension)) {
      fail_key(label_, "gravity", "must be an array of " + std::to_string(out_.dimension) + " numbers");
    }
    std::vector<double> gravity;
    for (std::size_t i = 0; i < it->size(); ++i) {
      gravity.push_back(finite_number((*it)[i], "gravity[" + std::to_string(i) + "]"));
    }
    out_.gravity = std::move(gravity);
  }

  void read_particles(const json& doc) {
    const json& particles = required(doc, "particles", "particles");
    if (!particles.is_object()) fail_key(label_, "particles", "must be an object");
    for (const auto& item : particles.items()) {
      const std::string& key = item.key();
      if (key != "count" && key != "mass" && key != "fixed" && key != "driven") {
        fail_key(label_, "particles." + printable(key), "unknown key");
      }
    }
    const auto count = integer_value(required(particles, "count", "particles.count"));
    if (!count || *count <= 0) fail_key(label_, "particles.count", "must be a positive integer");
    if (*count > detail::kMaxParticles) {
      fail_key(label_, "particles.count", "must be at most " + std::to_string(detail::kMaxParticles));
    }
    out_.particle_count = static_cast<int>(*count);
    read_masses(particles);
    read_fixed(particles);
    read_driven(particles);
  }

  void read_masses(const json& particles) {
    const auto n = static_cast<std::size_t>(out_.particle_count);
    const auto it = particles.find("mass");
    if (it == particles.end()) {
      out_.masses.assign(n, 1.0);
      return;
    }
    if (it->is_number()) {
      const double mass = finite_number(*it, "particles.mass");
      if (!(mass > 0.0)) fail_key(label_, "particles.mass", "must be positive");
      out_.masses.assign(n, mass);
      return;
    }
    if (!it->is_array()) {
      fail_key(label_, "particles.mass", "must be a number or an array of numbers");
    }
    if (it->size() != n) {
      fail_key(label_, "particles.mass",
               "must have " + std::to_string(n) + " entries (particles.count), found " + std::to_string(it->size()));
    }
    out_.masses.clear();
    for (std::size_t i = 0; i < n; ++i) {
      const std::string path = "particles.mass[" + std::to_string(i) + "]";
      const double mass = finite_number((*it)[i], path);
      if (!(mass > 0.0)) fail_key(label_, path, "must be positive");
      out_.masses.push_back(mass);
    }
  }

  void read_fixed(const json& particles) {
    const auto it = particles.find("fixed");
    if (it == particles.end()) return;
    if (!it->is_array()) fail_key(label_, "particles.fixed", "must be an array of ids");
    std::set<int> seen;
    for (std::size_t i = 0; i < it->size(); ++i) {
      const std::string path = "particles.fixed[" + std::to_string(i) + "]";
      const int id = particle_id((*it)[i], path);
      if (!seen.insert(id).second) {
        fail_key(label_, path, "id " + std::to_string(id) + " listed twice");
      }
    }
    out_.fixed.assign(seen.begin(), seen.end());
  }

  double optional_bound(const json& entry, const char* key, const std::string& path, double absent) {
    const auto it = entry.find(key);
    return it == entry.end() ? absent : finite_number(*it, path + "." + key);
  }

  void read_driven(const json& particles) {
    const auto it = particles.find("driven");
    if (it == particles.end()) return;
    if (!it->is_array()) fail_key(label_, "particles.driven", "must be an array");
    const double inf = std::numeric_limits<double>::infinity();
    for (std::size_t i = 0; i < it->size(); ++i) {
      const json& entry = (*it)[i];
      const std::string path = "particles.driven[" + std::to_string(i) + "]";
      DrivenWindow window;
      if (entry.is_object()) {
        for (const auto& item : entry.items()) {
          if (item.key() != "id" && item.key() != "from" && item.key() != "to") {
            fail_key(label_, path + "." + printable(item.key()), "unknown key");
          }
        }
        window.id = particle_id(required(entry, "id", path + ".id"), path + ".id");
        window.from_s = optional_bound(entry, "from", path, -inf);
        window.to_s = optional_bound(entry, "to", path, inf);
        if (window.from_s > window.to_s) {
          fail_key(
              label_, path,
              "from " + detail::format_double(window.from_s) + " is after to " + detail::format_double(window.to_s));
        }
      } else {
        window.id = particle_id(entry, path);
      }
      if (std::binary_search(out_.fixed.begin(), out_.fixed.end(), window.id)) {
        fail_key(label_, path, "particle " + std::to_string(window.id) + " is also in particles.fixed");
      }
      out_.driven.push_back(window);
    }
    check_driven_overlaps();
  }

  // Windows are closed intervals; sorted by (id, from), a window overlaps an earlier one of the
  // same id exactly when it starts no later than the furthest end seen so far.
  void check_driven_overlaps() {
    const auto& driven = out_.driven;
    std::vector<std::size_t> order(driven.size());
    std::iota(order.begin(), order.end(), std::size_t{0});
    std::sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
      if (driven[a].id != driven[b].id) return driven[a].id < driven[b].id;
      if (driven[a].from_s != driven[b].from_s) return driven[a].from_s < driven[b].from_s;
      return a < b;
    });
    std::size_t furthest = 0;  // index of the window reaching furthest among this id's so far
    for (std::size_t k = 0; k < order.size(); ++k) {
      const DrivenWindow& window = driven[order[k]];
      if (k > 0 && driven[order[k - 1]].id == window.id) {
        if (window.from_s <= driven[furthest].to_s) {
          const std::size_t later = std::max(order[k], furthest);
          const std::size_t earlier = std::min(order[k], furthest);
          fail_key(label_, "particles.driven[" + std::to_string(later) + "]",
                   "window for particle " + std::to_string(window.id) + " overlaps particles.driven[" +
                       std::to_string(earlier) + "]");
        }
        if (window.to_s > driven[furthest].to_s) furthest = order[k];
      } else {
        furthest = order[k];
      }
    }
  }

  void read_files(const json& doc) {
    const json& files = required(doc, "files", "files");
    if (!files.is_object()) fail_key(label_, "files", "must be an object");
    if (files.find("particles") == files.end()) {
      fail_key(label_, "files.particles", "missing required key");
    }
    for (const auto& item : files.items()) {
      const std::string path = "files." + printable(item.key());
      if (!item.value().is_string()) fail_key(label_, path, "must be a string");
      const std::string& value = item.value().get_ref<const std::string&>();
      if (const char* problem = detail::relative_path_problem(value)) {
        fail_key(label_, path, std::string(problem) + ", found '" + printable(value) + "'");
      }
      out_.files[item.key()] = value;
    }
  }

  void read_wrench(const json& doc) {
    const auto it = doc.find("wrench");
    if (it != doc.end()) {
      if (!it->is_object()) fail_key(label_, "wrench", "must be an object");
      for (const auto& item : it->items()) {
        if (item.key() != "applied_to") {
          fail_key(label_, "wrench." + printable(item.key()), "unknown key");
        }
      }
      const auto applied = it->find("applied_to");
      if (applied != it->end()) {
        if (!applied->is_array() || applied->empty()) {
          fail_key(label_, "wrench.applied_to", "must be a non-empty array of ids");
        }
        std::set<int> seen;
        for (std::size_t i = 0; i < applied->size(); ++i) {
          const std::string path = "wrench.applied_to[" + std::to_string(i) + "]";
          const int id = particle_id((*applied)[i], path);
          if (!seen.insert(id).second) {
            fail_key(label_, path, "id " + std::to_string(id) + " listed twice");
          }
          out_.wrench_applied_to.push_back(id);
        }
      }
    }
    if (out_.files.count("wrench") != 0 && out_.wrench_applied_to.empty()) {
      fail_key(label_, "wrench.applied_to", "required when files.wrench is present");
    }
  }

  void read_material(const json& doc) {
    const auto it = doc.find("material");
    if (it == doc.end()) return;
    if (!it->is_object()) fail_key(label_, "material", "must be an object");
    for (const auto& item : it->items()) {
      out_.material[item.key()] = finite_number(item.value(), "material." + printable(item.key()));
    }
  }

  const std::string& label_;
  Recording& out_;
};

}  // namespace

void parse_recording_json(std::string_view text, const std::string& file_label, Recording& out) {
  json doc = parse_document(text, file_label);
  // Parse into a scratch recording so that `out` is untouched when the text is rejected.
  Recording parsed;
  Reader(file_label, parsed).read(doc);
  out.dimension = parsed.dimension;
  out.length_unit = std::move(parsed.length_unit);
  out.gravity = std::move(parsed.gravity);
  out.particle_count = parsed.particle_count;
  out.masses = std::move(parsed.masses);
  out.fixed = std::move(parsed.fixed);
  out.driven = std::move(parsed.driven);
  out.files = std::move(parsed.files);
  out.wrench_applied_to = std::move(parsed.wrench_applied_to);
  out.material = std::move(parsed.material);
  out.meta = std::move(parsed.meta);
  out.unknown_keys = std::move(parsed.unknown_keys);
  out.warnings = std::move(parsed.warnings);
}

}  // namespace pliant::host

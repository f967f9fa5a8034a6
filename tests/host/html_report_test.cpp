// Diagnosis HTML report: page structure, escaping, odd inputs (no data, NaN, size mismatches,
// huge maps) and the atomic file writer.
#include "pliant/host/diagnose/html_report.hpp"

#include <gtest/gtest.h>
#include <unistd.h>

#include <cctype>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <limits>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "pliant/host/diagnose/diagnosis.hpp"

namespace pliant::host {
namespace {

namespace fs = std::filesystem;
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

std::size_t count(const std::string& text, const std::string& needle) {
  std::size_t n = 0;
  for (std::size_t at = text.find(needle); at != std::string::npos; at = text.find(needle, at + needle.size())) {
    ++n;
  }
  return n;
}

bool contains(const std::string& text, const std::string& needle) { return text.find(needle) != std::string::npos; }

// A pressed 2D grid of `particles`, `frames` frames at 50 Hz; the last fifth is held out.
void synthetic(Diagnosis& d, DiagnosisEvidence& e, int particles, int frames) {
  std::uint32_t state = 11;
  const auto noise = [&state] {
    state = state * 1664525u + 1013904223u;
    return static_cast<double>(state >> 8) / static_cast<double>(1u << 24) - 0.5;
  };
  e = DiagnosisEvidence{};
  e.dimension = 2;
  e.particle_count = particles;
  e.length_unit = "mm";
  const auto cells = static_cast<std::size_t>(particles) * static_cast<std::size_t>(frames);
  e.residual_baseline.resize(cells);
  e.residual_augmented.resize(cells);
  e.observed.resize(2 * cells);
  e.simulated_baseline.resize(2 * cells);
  e.simulated_augmented.resize(2 * cells);
  for (int f = 0; f < frames; ++f) {
    e.frame_times_s.push_back(0.02 * f);
    e.held_out.push_back(f * 5 >= frames * 4 ? 1 : 0);
    for (int p = 0; p < particles; ++p) {
      const auto i = static_cast<std::size_t>(f) * static_cast<std::size_t>(particles) + static_cast<std::size_t>(p);
      const double dent = (p >= 12 && p < 20) ? 0.01 * f : 0.0;
      e.observed[2 * i] = p % 8;
      e.observed[2 * i + 1] = p / 8 - dent + 0.01 * noise();
      e.simulated_baseline[2 * i] = p % 8;
      e.simulated_baseline[2 * i + 1] = p / 8 - 0.5 * dent;
      e.simulated_augmented[2 * i] = p % 8;
      e.simulated_augmented[2 * i + 1] = p / 8 - dent;
      e.residual_baseline[i] = 0.5 * dent + 0.01 * std::fabs(noise());
      e.residual_augmented[i] = 0.01 * std::fabs(noise());
    }
  }
  e.signatures = {{"persistence_after_unload", 0.8}, {"rate_dependence", 0.1}};
  e.fixed = {0, 1};
  d = Diagnosis{};
  d.recording = "press_foam_3";
  d.baseline.parameters = {{"msm_alpha", 1.0}, {"msm_beta", 0.58}};
  d.baseline.parameter_std = {{"msm_beta", 0.01}};
  d.baseline.rms = 1.9;
  d.noise_rms = 0.2;
  d.verdict = "missing_physics";
  d.effect = "plasticity";
  d.explanation = "Particles 12-19 keep a dent after release.";
  d.location.particles = {12, 13, 14, 15, 16, 17, 18, 19};
  d.location.t_start = 1.0;
  d.location.t_end = 2.0;
  d.augmented.parameters = {{"msm_alpha", 1.0}, {"msm_beta", 0.61}, {"yield", 0.04}};
  d.augmented.parameter_std = {{"yield", 0.002}};
  d.augmented.rms = 0.31;
  d.improvement = 0.84;
  Candidate c;
  c.effect = "plasticity";
  c.rms = 0.31;
  c.bic = -8120.5;
  c.parameters = {{"yield", 0.04}};
  c.parameter_std = {{"yield", 0.002}};
  Candidate v;
  v.effect = "viscosity";
  v.rms = 1.2;
  v.bic = -6011.2;
  v.parameters = {{"damping", 3.0}};
  d.candidates = {c, v};
}

// True when some occurrence of `prefix` is followed by anything but `allowed`.
bool has_prefix_not_followed_by(const std::string& html, const std::string& prefix, char allowed) {
  for (std::size_t at = html.find(prefix); at != std::string::npos; at = html.find(prefix, at + 1)) {
    const std::size_t next = at + prefix.size();
    if (next >= html.size() || html[next] != allowed) return true;
  }
  return false;
}

// True when "nan" or "inf" appears as a whole word right after a number delimiter (quote, space,
// comma, parenthesis or an SVG path command), optionally with a minus sign.
bool has_non_finite_number(const std::string& html) {
  const std::string delimiters = "\" ,(MmhHvVl";
  for (const char* word : {"nan", "inf"}) {
    for (std::size_t at = html.find(word); at != std::string::npos; at = html.find(word, at + 1)) {
      std::size_t before = at;
      if (before > 0 && html[before - 1] == '-') --before;
      if (before == 0 || delimiters.find(html[before - 1]) == std::string::npos) continue;
      const std::size_t after = at + 3;
      const bool word_ends =
          after >= html.size() || !(std::isalnum(static_cast<unsigned char>(html[after])) || html[after] == '_');
      if (word_ends) return true;
    }
  }
  return false;
}

// Every <svg> opening tag, in order.
std::vector<std::string> svg_tags(const std::string& html) {
  std::vector<std::string> tags;
  for (std::size_t at = html.find("<svg"); at != std::string::npos; at = html.find("<svg", at + 4)) {
    tags.push_back(html.substr(at, html.find('>', at) - at + 1));
  }
  return tags;
}

// Checks shared by every page: well-formed plot wrappers, no script, nothing external.
void expect_self_contained(const std::string& html) {
  EXPECT_EQ(html.rfind("<!DOCTYPE html>", 0), 0u);
  EXPECT_TRUE(contains(html, "</html>"));
  EXPECT_FALSE(contains(html, "<script"));
  EXPECT_FALSE(contains(html, "<link"));
  EXPECT_FALSE(contains(html, "src="));
  EXPECT_FALSE(contains(html, "@import"));
  EXPECT_FALSE(has_prefix_not_followed_by(html, "href=\"", '#'));
  EXPECT_FALSE(has_prefix_not_followed_by(html, "url(", '#'));
  // No unprintable numbers leaked into coordinates or attribute values.
  EXPECT_FALSE(has_non_finite_number(html));
  const auto tags = svg_tags(html);
  EXPECT_EQ(tags.size(), count(html, "</svg>"));
  for (const std::string& tag : tags) {
    EXPECT_TRUE(contains(tag, "class=\"plot\"")) << tag;
    EXPECT_TRUE(contains(tag, "data-plot=\"")) << tag;
  }
  EXPECT_EQ(count(html, "<title>"), tags.size() + 1);  // one per plot plus the page's
}

std::vector<std::string> plot_names(const std::string& html) {
  std::vector<std::string> names;
  const std::string key = "data-plot=\"";
  for (std::size_t at = html.find(key); at != std::string::npos; at = html.find(key, at + 1)) {
    const std::size_t begin = at + key.size();
    const std::size_t end = html.find('"', begin);
    if (end == std::string::npos) break;
    names.push_back(html.substr(begin, end - begin));
  }
  return names;
}

TEST(HtmlReport, SyntheticPageHasEveryPlotAndTable) {
  Diagnosis d;
  DiagnosisEvidence e;
  synthetic(d, e, 32, 150);
  const std::string html = diagnosis_html(d, e);
  expect_self_contained(html);
  const std::vector<std::string> expected = {"residual_before", "residual_after", "trajectory_12", "trajectory_13",
                                             "trajectory_14",   "trajectory_15",  "trajectory_16", "trajectory_17"};
  EXPECT_EQ(plot_names(html), expected);  // at most six trajectories
  EXPECT_TRUE(contains(html, "Showing the first 6 of 8 located particles"));
  for (const char* table : {"summary", "candidates", "parameters", "signatures"}) {
    EXPECT_TRUE(contains(html, std::string("data-table=\"") + table + "\"")) << table;
  }
  // Header facts, units on the colour bar and axes, the chosen candidate, parameter shifts.
  EXPECT_TRUE(contains(html, "missing_physics"));
  EXPECT_TRUE(contains(html, "Particles 12-19 keep a dent after release."));
  EXPECT_TRUE(contains(html, "84 %"));
  EXPECT_TRUE(contains(html, "mean |residual| (mm)"));
  EXPECT_TRUE(contains(html, "time (s)"));
  EXPECT_TRUE(contains(html, "particle id"));
  EXPECT_TRUE(contains(html, "displacement y (mm)"));
  EXPECT_TRUE(contains(html, "plasticity (chosen)"));
  EXPECT_TRUE(contains(html, "0.04 &plusmn; 0.002"));
  EXPECT_TRUE(contains(html, "added by the effect"));
  EXPECT_TRUE(contains(html, "+0.03 (+5.17 %)"));
  EXPECT_TRUE(contains(html, "persistence_after_unload"));
  // Held-out frames are marked, unobserved cells have a hatch to show through.
  EXPECT_TRUE(contains(html, "frames held out of fitting"));
  EXPECT_TRUE(contains(html, "<pattern id=\"hatch-residual_before\""));
  EXPECT_TRUE(contains(html, "<pattern id=\"hatch-residual_after\""));
  EXPECT_FALSE(contains(html, "data-note=\"no-data\""));
}

TEST(HtmlReport, NoFramesOrNoParticlesGivesANoteInsteadOfPlots) {
  Diagnosis d;
  DiagnosisEvidence e;
  synthetic(d, e, 32, 0);
  std::string html = diagnosis_html(d, e);
  expect_self_contained(html);
  EXPECT_TRUE(contains(html, "data-note=\"no-data\""));
  EXPECT_TRUE(svg_tags(html).empty());
  EXPECT_TRUE(contains(html, "data-table=\"candidates\""));

  synthetic(d, e, 0, 20);
  html = diagnosis_html(d, e);
  expect_self_contained(html);
  EXPECT_TRUE(contains(html, "data-note=\"no-data\""));
  EXPECT_TRUE(svg_tags(html).empty());

  html = diagnosis_html(Diagnosis{}, DiagnosisEvidence{});
  expect_self_contained(html);
  EXPECT_TRUE(contains(html, "data-note=\"no-data\""));
}

TEST(HtmlReport, TextIsEscapedAndNaNIsShownAsMissing) {
  Diagnosis d;
  DiagnosisEvidence e;
  synthetic(d, e, 24, 60);
  const std::string hostile = "<script>alert(1)</script>&\"'";
  d.recording = "take<script>&\"";
  d.effect = hostile;
  d.explanation = hostile + "\x01";
  d.baseline.model = hostile;
  d.baseline.parameters[hostile] = 1.0;
  d.candidates[1].effect = hostile;
  e.length_unit = "<b>mm</b>";
  e.signatures[hostile] = kNaN;
  d.noise_rms = kNaN;
  d.improvement = kNaN;
  d.location.t_end = kNaN;
  d.augmented.parameter_std["yield"] = kNaN;
  for (std::size_t i = 0; i < e.residual_baseline.size(); i += 3) e.residual_baseline[i] = kNaN;
  for (std::size_t i = 0; i < e.observed.size(); i += 5) e.observed[i] = kNaN;
  // Particle 13 is never observed or simulated.
  for (std::size_t f = 0; f < 60; ++f) {
    for (std::size_t k = 0; k < 2; ++k) {
      const std::size_t i = (f * 24 + 13) * 2 + k;
      e.observed[i] = e.simulated_baseline[i] = e.simulated_augmented[i] = kNaN;
    }
  }
  e.residual_augmented.assign(e.residual_augmented.size(), kNaN);  // nothing observed after
  e.frame_times_s[7] = kNaN;  // times no longer usable: plots fall back to frame numbers

  const std::string html = diagnosis_html(d, e);
  expect_self_contained(html);
  EXPECT_FALSE(contains(html, "<script>"));
  EXPECT_FALSE(contains(html, "<b>mm"));
  EXPECT_FALSE(contains(html, "\x01"));
  EXPECT_TRUE(contains(html, "take&lt;script&gt;&amp;&quot;"));
  EXPECT_TRUE(contains(html, "&lt;script&gt;alert(1)&lt;/script&gt;&amp;&quot;&#39;"));
  EXPECT_TRUE(contains(html, "&lt;b&gt;mm&lt;/b&gt;"));
  EXPECT_TRUE(contains(html, "n/a"));
  EXPECT_TRUE(contains(html, "frame (times not monotonic)"));
  EXPECT_TRUE(contains(html, "never observed or simulated"));
  const auto names = plot_names(html);
  ASSERT_GE(names.size(), 2u);
  EXPECT_EQ(names[0], "residual_before");
  EXPECT_EQ(names[1], "residual_after");
}

TEST(HtmlReport, ConsistentVerdictStillDrawsBothMaps) {
  Diagnosis d;
  DiagnosisEvidence e;
  synthetic(d, e, 16, 40);
  d.verdict = "consistent";
  d.effect = "none";
  d.augmented = d.baseline;
  d.improvement = 0;
  d.location = Location{};
  d.candidates.clear();
  e.residual_augmented = e.residual_baseline;
  e.simulated_augmented = e.simulated_baseline;
  std::string html = diagnosis_html(d, e);
  expect_self_contained(html);
  EXPECT_EQ(plot_names(html), (std::vector<std::string>{"residual_before", "residual_after"}));
  EXPECT_TRUE(contains(html, "No particles were located"));
  EXPECT_TRUE(contains(html, "No candidate effects were tried"));

  // Augmented residual left empty by the producer: the baseline stands in for it.
  e.residual_augmented.clear();
  html = diagnosis_html(d, e);
  EXPECT_EQ(plot_names(html), (std::vector<std::string>{"residual_before", "residual_after"}));
}

TEST(HtmlReport, MismatchedArraysSkipPlotsWithoutCrashing) {
  Diagnosis d;
  DiagnosisEvidence e;
  synthetic(d, e, 10, 30);
  e.residual_augmented.resize(7);
  e.simulated_baseline.clear();
  e.held_out.resize(3);
  d.location.particles = {-4, 3, 3, 999};
  std::string html = diagnosis_html(d, e);
  expect_self_contained(html);
  EXPECT_EQ(plot_names(html), (std::vector<std::string>{"residual_before", "trajectory_3"}));
  EXPECT_TRUE(contains(html, "No augmented residual map"));
  EXPECT_TRUE(contains(html, "Some simulated trajectories are missing"));

  e.observed.resize(5);
  e.residual_baseline.clear();
  e.residual_augmented.clear();
  html = diagnosis_html(d, e);
  expect_self_contained(html);
  EXPECT_TRUE(plot_names(html).empty());
  EXPECT_TRUE(contains(html, "No residual map"));
  EXPECT_TRUE(contains(html, "No trajectories"));

  synthetic(d, e, 1, 1);  // a single cell
  d.location.particles = {0};
  html = diagnosis_html(d, e);
  expect_self_contained(html);
  EXPECT_EQ(plot_names(html), (std::vector<std::string>{"residual_before", "residual_after", "trajectory_0"}));
}

TEST(HtmlReport, HugeInputsAreBinnedToAFewMegabytes) {
  Diagnosis d;
  DiagnosisEvidence e;
  synthetic(d, e, 2000, 1000);  // 2M cells per map
  // Worst case for the run-length encoding: unrelated values in neighbouring cells.
  std::uint32_t state = 3;
  for (double& v : e.residual_baseline) {
    state = state * 1664525u + 1013904223u;
    v = static_cast<double>(state >> 8) / static_cast<double>(1u << 24);
  }
  const std::string html = diagnosis_html(d, e);
  expect_self_contained(html);
  EXPECT_LT(html.size(), std::size_t{5} << 20);
  EXPECT_TRUE(contains(html, "each cell shows the mean over a block"));
  EXPECT_EQ(plot_names(html).size(), 8u);
}

class ReportDirectory : public ::testing::Test {
 protected:
  void SetUp() override {
    root_ = fs::temp_directory_path() / ("pliant_html_report_test_" + std::to_string(::getpid()));
    fs::remove_all(root_);
  }
  void TearDown() override { fs::remove_all(root_); }
  fs::path root_;
};

TEST_F(ReportDirectory, WritesIndexHtmlIntoANewDirectory) {
  Diagnosis d;
  DiagnosisEvidence e;
  synthetic(d, e, 32, 150);
  const fs::path dir = root_ / "nested" / "report";
  write_diagnosis_report(d, e, dir.string());
  std::ifstream file(dir / "index.html", std::ios::binary);
  std::stringstream content;
  content << file.rdbuf();
  EXPECT_EQ(content.str(), diagnosis_html(d, e));
  std::size_t entries = 0;
  for (const auto& entry : fs::directory_iterator(dir)) {
    EXPECT_EQ(entry.path().filename(), "index.html");  // no temporary file left behind
    ++entries;
  }
  EXPECT_EQ(entries, 1u);
  // Writing again replaces the page.
  d.recording = "second";
  write_diagnosis_report(d, e, dir.string());
  std::ifstream again(dir / "index.html", std::ios::binary);
  std::stringstream second;
  second << again.rdbuf();
  EXPECT_TRUE(contains(second.str(), "second"));
}

TEST_F(ReportDirectory, IoFailureThrowsAOneLineError) {
  fs::create_directories(root_);
  const fs::path blocker = root_ / "a_file";
  std::ofstream(blocker) << "x";
  Diagnosis d;
  DiagnosisEvidence e;
  const std::string bad = (blocker / "report\nwith newline").string();
  try {
    write_diagnosis_report(d, e, bad);
    FAIL() << "expected std::runtime_error";
  } catch (const std::runtime_error& error) {
    const std::string message = error.what();
    EXPECT_FALSE(contains(message, "\n")) << message;
    EXPECT_TRUE(contains(message, "report directory")) << message;
  }
  // index.html exists as a directory: the rename cannot replace it.
  const fs::path dir = root_ / "occupied";
  fs::create_directories(dir / "index.html" / "child");
  EXPECT_THROW(write_diagnosis_report(d, e, dir.string()), std::runtime_error);
  for (const auto& entry : fs::directory_iterator(dir)) {
    EXPECT_EQ(entry.path().filename(), "index.html");
  }
}

}  // namespace
}  // namespace pliant::host

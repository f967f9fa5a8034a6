// Acceptance test of `pliant diagnose` on the concealed suite (examples/concealed/MANIFEST.md).
//
// One test per case directory found under PLIANT_CONCEALED_SUITE_DIR (a compile definition: the
// source tree's examples/concealed; an environment variable of the same name, when set and not
// empty, replaces it, e.g. to score a regenerated suite). Each runs diagnose_recording with default options on the
// recording and only then reads the case's truth.json, which nothing else in pliant reads:
// - truth "none": the verdict must be "consistent";
// - truth <effect>: the verdict must be "missing_physics", the effect named must be the truth's,
//   and the held-out improvement must be >= 0.5.
// Every case prints one line (truth, effect size, what was found) whether it passes or not, and
// a failure repeats that line, so a ctest log reads as a score sheet. Nothing here knows which
// case holds which answer: cases and answers are discovered at run time.
#include <gtest/gtest.h>

#include <algorithm>
#include <cctype>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "pliant/host/diagnose/diagnose.hpp"
#include "pliant/host/recording.hpp"
#include "pliant/host/scenarios.hpp"

#ifndef PLIANT_CONCEALED_SUITE_DIR
#error "PLIANT_CONCEALED_SUITE_DIR must name the concealed suite directory"
#endif

namespace pliant::host {
namespace {

namespace fs = std::filesystem;

fs::path suite_directory() {
  const char* override_dir = std::getenv("PLIANT_CONCEALED_SUITE_DIR");
  return override_dir != nullptr && *override_dir != '\0' ? fs::path(override_dir)
                                                          : fs::path(PLIANT_CONCEALED_SUITE_DIR);
}

const fs::path kSuite = suite_directory();

// Case directories: every directory in the suite whose name starts with "case_" and that holds
// a recording.json, in name order. Empty when the suite is missing (concealed_suite_files fails).
std::vector<std::string> case_names() {
  std::vector<std::string> names;
  std::error_code error;
  for (fs::directory_iterator it(kSuite, error), end; !error && it != end; it.increment(error)) {
    const std::string name = it->path().filename().string();
    if (it->is_directory() && name.rfind("case_", 0) == 0 && fs::exists(it->path() / "recording.json")) {
      names.push_back(name);
    }
  }
  std::sort(names.begin(), names.end());
  return names;
}

nlohmann::json read_truth(const fs::path& case_dir) {
  std::ifstream in(case_dir / "truth.json");
  if (!in) throw std::runtime_error("cannot open " + (case_dir / "truth.json").string());
  return nlohmann::json::parse(in);
}

// effect_size.rms_over_noise, or -1 when the truth has none (no effect, or no noise).
double rms_over_noise(const nlohmann::json& truth) {
  const auto size = truth.find("effect_size");
  if (size == truth.end() || !size->is_object()) return -1.0;
  const auto ratio = size->find("rms_over_noise");
  return ratio != size->end() && ratio->is_number() ? ratio->get<double>() : -1.0;
}

// The particles truth.json names for localisation: support_particles (friction) or
// region_particles (heterogeneity); empty for the other effects.
std::vector<int> truth_particles(const nlohmann::json& truth) {
  const nlohmann::json details = truth.value("effect_details", nlohmann::json::object());
  for (const char* key : {"support_particles", "region_particles"}) {
    if (details.contains(key) && details[key].is_array()) return details[key].get<std::vector<int>>();
  }
  return {};
}

std::string format_number(double value, int precision) {
  std::ostringstream text;
  text.setf(std::ios::fixed);
  text.precision(precision);
  text << value;
  return text.str();
}

// One line: what the generator hid and what diagnose found.
std::string score_line(const std::string& name, const nlohmann::json& truth, const Diagnosis& d, double runtime_s) {
  std::ostringstream line;
  const double size = rms_over_noise(truth);
  line << name << ": truth " << truth.value("effect", "?") << " (" << truth.value("scenario", "?") << ", rms/noise "
       << (size < 0 ? std::string("-") : format_number(size, 1)) << ", noise " << truth.value("noise_std", 0.0)
       << ")  found " << d.verdict << " / " << d.effect << "  baseline rms " << d.baseline.rms << ", augmented rms "
       << d.augmented.rms << ", improvement " << format_number(d.improvement, 3) << ", noise rms " << d.noise_rms
       << ", runtime " << format_number(runtime_s, 1) << " s";
  const std::vector<int> expected = truth_particles(truth);
  if (!expected.empty()) {
    const std::set<int> located(d.location.particles.begin(), d.location.particles.end());
    const auto hits = std::count_if(expected.begin(), expected.end(), [&](int id) { return located.count(id) > 0; });
    line << "  location: " << hits << " of " << expected.size() << " truth particles among " << located.size()
         << " located";
  }
  return line.str();
}

class concealed_suite : public ::testing::TestWithParam<std::string> {};

TEST(concealed_suite_files, SuiteIsPresentAndEveryTruthIsReadable) {
  const std::vector<std::string> names = case_names();
  ASSERT_FALSE(names.empty()) << "no case_* directory with a recording.json under " << kSuite;
  std::vector<std::string> known = effect_names();
  known.push_back("none");
  for (const std::string& name : names) {
    const nlohmann::json truth = read_truth(kSuite / name);
    const std::string effect = truth.value("effect", "");
    EXPECT_NE(std::find(known.begin(), known.end(), effect), known.end())
        << name << ": truth effect '" << effect << "' is not a known effect";
  }
}

TEST_P(concealed_suite, DiagnosisMatchesTheTruth) {
  const fs::path case_dir = kSuite / GetParam();
  const Recording recording = read_recording(case_dir.string());
  const DiagnoseResult result = diagnose_recording(recording, DiagnoseOptions{});
  const Diagnosis& d = result.diagnosis;
  // The answer is read only after the diagnosis has run.
  const nlohmann::json truth = read_truth(case_dir);
  const std::string effect = truth.at("effect").get<std::string>();
  const std::string line = score_line(GetParam(), truth, d, result.runtime_s);
  std::cout << "[ concealed] " << line << std::endl;
  RecordProperty("truth_effect", effect);
  RecordProperty("found", d.verdict + "/" + d.effect);
  SCOPED_TRACE(line);

  if (effect == "none") {
    EXPECT_EQ(d.verdict, "consistent") << "false alarm: no effect was simulated";
    return;
  }
  EXPECT_EQ(d.verdict, "missing_physics") << "missed: " << effect << " was simulated";
  EXPECT_EQ(d.effect, effect) << "wrong effect named";
  EXPECT_GE(d.improvement, 0.5) << "held-out improvement below 0.5";
}

// gtest names allow only letters, digits and underscores.
std::string test_name(const ::testing::TestParamInfo<std::string>& info) {
  std::string name = info.param;
  for (char& c : name) {
    if (!std::isalnum(static_cast<unsigned char>(c))) c = '_';
  }
  return name;
}

INSTANTIATE_TEST_SUITE_P(cases, concealed_suite, ::testing::ValuesIn(case_names()), test_name);
// A missing suite is reported by concealed_suite_files, not as a gtest setup error.
GTEST_ALLOW_UNINSTANTIATED_PARAMETERIZED_TEST(concealed_suite);

}  // namespace
}  // namespace pliant::host

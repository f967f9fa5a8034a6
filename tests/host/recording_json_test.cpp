// recording.json: malformed documents (one cause each) and the fields of valid ones.
#include <cmath>
#include <functional>
#include <limits>
#include <string>

#include "pliant/host/recording.hpp"
#include "recording_test_support.hpp"

namespace pliant::host::test {
namespace {

using nlohmann::json;

std::string parse_error(const std::string& text) {
  Recording recording;
  return error_of([&] { parse_recording_json(text, "recording.json", recording); });
}

json base_document() {
  return json::parse(R"({
    "format": "pliant-recording", "version": 1, "dimension": 2, "length_unit": "m",
    "particles": { "count": 4 },
    "files": { "particles": "particles.csv" }
  })");
}

// --- syntax errors: position computed from the parser's byte offset

struct SyntaxCase {
  const char* name;
  std::string text;
  const char* prefix;
  const char* cause;
};

void PrintTo(const SyntaxCase& c, std::ostream* out) { *out << c.name; }

class JsonSyntax : public ::testing::TestWithParam<SyntaxCase> {};

TEST_P(JsonSyntax, NamesLineColumnAndCause) {
  expect_message(parse_error(GetParam().text), GetParam().prefix, GetParam().cause);
}

INSTANTIATE_TEST_SUITE_P(
    Malformed, JsonSyntax,
    ::testing::Values(SyntaxCase{"MissingValue", R"({"format": })", "recording.json:1:12: ", "syntax error"},
                      SyntaxCase{"ErrorOnThirdLine", "{\n  \"format\": \"x\",\n  \"version\" 1\n}",
                                 "recording.json:3:13: ", "syntax error"},
                      SyntaxCase{"TrailingGarbage", "{}\n}", "recording.json:2:1: ", "syntax error"},
                      SyntaxCase{"Empty", "", "recording.json:1:1: ", "unexpected end of input"},
                      SyntaxCase{"InvalidUtf8", "{\"a\": \"\xff\"}", "recording.json:1:8: ", "UTF-8"},
                      SyntaxCase{"NestedTooDeep", "{\"meta\": " + std::string(200, '[') + std::string(200, ']') + "}",
                                 "recording.json:1:109: ", "nested deeper than 100 levels"},
                      SyntaxCase{"NumberOverflow", "{\"meta\": \"1e999\",\n \"format\": 1e999}",
                                 "recording.json:2:12: ", "number overflow parsing '1e999'"}),
    CaseName());

// --- semantic errors: key path and cause

struct KeyCase {
  const char* name;
  std::function<void(json&)> edit;
  const char* prefix;
  const char* cause;
};

void PrintTo(const KeyCase& c, std::ostream* out) { *out << c.name; }

class JsonKey : public ::testing::TestWithParam<KeyCase> {};

TEST_P(JsonKey, NamesKeyAndCause) {
  json doc = base_document();
  GetParam().edit(doc);
  expect_message(parse_error(doc.dump()), GetParam().prefix, GetParam().cause);
}

INSTANTIATE_TEST_SUITE_P(
    Malformed, JsonKey,
    ::testing::Values(
        KeyCase{"TopLevelNotObject", [](json& d) { d = json::array(); },
                "recording.json: (top level): ", "must be a JSON object"},
        KeyCase{"FormatMissing", [](json& d) { d.erase("format"); },
                "recording.json: format: ", "missing required key"},
        KeyCase{"FormatWrong", [](json& d) { d["format"] = "pliant"; },
                "recording.json: format: ", "must be \"pliant-recording\""},
        KeyCase{"VersionTwo", [](json& d) { d["version"] = 2; }, "recording.json: version: ", "must be 1"},
        KeyCase{"VersionString", [](json& d) { d["version"] = "1"; }, "recording.json: version: ", "must be 1"},
        KeyCase{"DimensionFour", [](json& d) { d["dimension"] = 4; }, "recording.json: dimension: ", "must be 2 or 3"},
        KeyCase{"LengthUnitMillimetre", [](json& d) { d["length_unit"] = "mm"; },
                "recording.json: length_unit: ", "must be \"m\" or \"px\""},
        KeyCase{"GravityWrongLength",
                [](json& d) {
                  d["gravity"] = {0.0, -9.81, 0.0};
                },
                "recording.json: gravity: ", "array of 2 numbers"},
        KeyCase{"GravityComponentText",
                [](json& d) {
                  d["gravity"] = {0.0, "down"};
                },
                "recording.json: gravity[1]: ", "must be a number"},
        KeyCase{"ParticlesMissing", [](json& d) { d.erase("particles"); },
                "recording.json: particles: ", "missing required key"},
        KeyCase{"CountZero", [](json& d) { d["particles"]["count"] = 0; },
                "recording.json: particles.count: ", "must be a positive integer"},
        KeyCase{"CountFractional", [](json& d) { d["particles"]["count"] = 2.5; },
                "recording.json: particles.count: ", "must be a positive integer"},
        KeyCase{"CountHuge", [](json& d) { d["particles"]["count"] = 20000000; },
                "recording.json: particles.count: ", "must be at most 10000000"},
        KeyCase{"MassNegative", [](json& d) { d["particles"]["mass"] = -1.0; },
                "recording.json: particles.mass: ", "must be positive"},
        KeyCase{"MassListWrongLength",
                [](json& d) {
                  d["particles"]["mass"] = {1.0, 2.0};
                },
                "recording.json: particles.mass: ", "must have 4 entries"},
        KeyCase{"MassListZeroEntry",
                [](json& d) {
                  d["particles"]["mass"] = {1.0, 0.0, 1.0, 1.0};
                },
                "recording.json: particles.mass[1]: ", "must be positive"},
        KeyCase{"FixedOutOfRange",
                [](json& d) {
                  d["particles"]["fixed"] = {0, 4};
                },
                "recording.json: particles.fixed[1]: ", "id 4 out of range 0..3"},
        KeyCase{"FixedDuplicate",
                [](json& d) {
                  d["particles"]["fixed"] = {1, 2, 1};
                },
                "recording.json: particles.fixed[2]: ", "id 1 listed twice"},
        KeyCase{"FixedNotInteger", [](json& d) { d["particles"]["fixed"] = {1.5}; },
                "recording.json: particles.fixed[0]: ", "must be an integer particle id"},
        KeyCase{"DrivenFromAfterTo",
                [](json& d) {
                  d["particles"]["driven"] = {{{"id", 3}, {"from", 2.0}, {"to", 1.0}}};
                },
                "recording.json: particles.driven[0]: ", "from 2 is after to 1"},
        KeyCase{"DrivenWindowsOverlap",
                [](json& d) {
                  d["particles"]["driven"] = {{{"id", 3}, {"from", 0.0}, {"to", 1.0}},
                                              {{"id", 3}, {"from", 1.0}, {"to", 2.0}}};
                },
                "recording.json: particles.driven[1]: ", "overlaps particles.driven[0]"},
        KeyCase{"DrivenWholeAndWindow",
                [](json& d) {
                  d["particles"]["driven"] = {{{"id", 3}, {"from", 5.0}}, 3};
                },
                "recording.json: particles.driven[1]: ", "overlaps particles.driven[0]"},
        KeyCase{"DrivenAlsoFixed",
                [](json& d) {
                  d["particles"]["fixed"] = {0, 1};
                  d["particles"]["driven"] = {1};
                },
                "recording.json: particles.driven[0]: ", "particle 1 is also in particles.fixed"},
        KeyCase{"DrivenMissingId",
                [](json& d) {
                  d["particles"]["driven"] = {{{"from", 1.0}}};
                },
                "recording.json: particles.driven[0].id: ", "missing required key"},
        KeyCase{"DrivenUnknownKey",
                [](json& d) {
                  d["particles"]["driven"] = {{{"id", 1}, {"form", 1.0}}};
                },
                "recording.json: particles.driven[0].form: ", "unknown key"},
        KeyCase{"ParticlesUnknownKey", [](json& d) { d["particles"]["fixd"] = {0}; },
                "recording.json: particles.fixd: ", "unknown key"},
        KeyCase{"FilesMissing", [](json& d) { d.erase("files"); }, "recording.json: files: ", "missing required key"},
        KeyCase{"FilesParticlesMissing",
                [](json& d) {
                  d["files"] = {{"wrench", "wrench.csv"}};
                },
                "recording.json: files.particles: ", "missing required key"},
        KeyCase{"FilesAbsolutePath", [](json& d) { d["files"]["particles"] = "/etc/passwd"; },
                "recording.json: files.particles: ", "must be relative"},
        KeyCase{"FilesParentDirectory", [](json& d) { d["files"]["video"] = "media/../../secret.mp4"; },
                "recording.json: files.video: ", "must not contain '..'"},
        KeyCase{"FilesNotString", [](json& d) { d["files"]["particles"] = 3; },
                "recording.json: files.particles: ", "must be a string"},
        KeyCase{"WrenchWithoutAppliedTo", [](json& d) { d["files"]["wrench"] = "wrench.csv"; },
                "recording.json: wrench.applied_to: ", "required when files.wrench is present"},
        KeyCase{"AppliedToOutOfRange", [](json& d) { d["wrench"] = {{"applied_to", {7}}}; },
                "recording.json: wrench.applied_to[0]: ", "id 7 out of range 0..3"},
        KeyCase{"MaterialNotNumber", [](json& d) { d["material"] = {{"poisson_ratio", "0.45"}}; },
                "recording.json: material.poisson_ratio: ", "must be a number"}),
    CaseName());

// --- valid documents

TEST(RecordingJson, ReadsEveryDeclaredField) {
  Recording r;
  parse_recording_json(R"({
    "format": "pliant-recording", "version": 1, "dimension": 3, "length_unit": "px",
    "gravity": [0, 0, -9.81],
    "particles": { "count": 5, "mass": [1, 2, 3, 4, 5], "fixed": [4, 0],
                   "driven": [2, {"id": 3, "to": 0.5}, {"id": 3, "from": 2, "to": 3}] },
    "files": { "particles": "p.csv", "wrench": "w.csv", "video": "media/cam.mp4" },
    "wrench": { "applied_to": [3] },
    "material": { "poisson_ratio": 0.45, "density": 1000 },
    "meta": { "object": "foam" }
  })",
                       "recording.json", r);
  EXPECT_EQ(r.dimension, 3);
  EXPECT_EQ(r.length_unit, "px");
  ASSERT_TRUE(r.gravity.has_value());
  EXPECT_EQ(*r.gravity, (std::vector<double>{0.0, 0.0, -9.81}));
  EXPECT_EQ(r.particle_count, 5);
  EXPECT_EQ(r.masses, (std::vector<double>{1, 2, 3, 4, 5}));
  EXPECT_EQ(r.fixed, (std::vector<int>{0, 4}));
  ASSERT_EQ(r.driven.size(), 3u);
  const double inf = std::numeric_limits<double>::infinity();
  EXPECT_EQ(r.driven[0].id, 2);
  EXPECT_EQ(r.driven[0].from_s, -inf);
  EXPECT_EQ(r.driven[0].to_s, inf);
  EXPECT_EQ(r.driven[1].id, 3);
  EXPECT_EQ(r.driven[1].from_s, -inf);
  EXPECT_EQ(r.driven[1].to_s, 0.5);
  EXPECT_EQ(r.driven[2].from_s, 2.0);
  EXPECT_EQ(r.driven[2].to_s, 3.0);
  EXPECT_EQ(r.files.at("particles"), "p.csv");
  EXPECT_EQ(r.files.at("video"), "media/cam.mp4");
  EXPECT_EQ(r.wrench_applied_to, (std::vector<int>{3}));
  EXPECT_EQ(r.material.at("poisson_ratio"), 0.45);
  EXPECT_EQ(r.material.at("density"), 1000.0);
  EXPECT_EQ(r.meta.at("object"), "foam");
  EXPECT_TRUE(r.warnings.empty());
}

TEST(RecordingJson, DisjointWindowsForOneParticleAreAccepted) {
  Recording r;
  json doc = base_document();
  doc["particles"]["driven"] = {{{"id", 1}, {"to", 1.0}},
                                {{"id", 1}, {"from", 1.5}, {"to", 2.0}},
                                {{"id", 2}, {"from", 0.0}},
                                {{"id", 1}, {"from", 3.0}}};
  parse_recording_json(doc.dump(), "recording.json", r);
  EXPECT_EQ(r.driven.size(), 4u);
}

TEST(RecordingJson, DefaultsAndSingleMass) {
  Recording r;
  parse_recording_json(kMinimalJson2D, "recording.json", r);
  EXPECT_EQ(r.masses, (std::vector<double>(4, 1.0)));
  EXPECT_FALSE(r.gravity.has_value());
  json doc = base_document();
  doc["particles"]["mass"] = 0.002;
  parse_recording_json(doc.dump(), "recording.json", r);
  EXPECT_EQ(r.masses, (std::vector<double>(4, 0.002)));
}

TEST(RecordingJson, UnknownTopLevelKeyIsKeptWithWarning) {
  Recording r;
  json doc = base_document();
  doc["calibration"] = {{"k", {1, 2, 3}}};
  parse_recording_json(doc.dump(), "recording.json", r);
  ASSERT_EQ(r.warnings.size(), 1u);
  EXPECT_NE(r.warnings[0].find("unknown key 'calibration'"), std::string::npos);
  EXPECT_EQ(r.unknown_keys.at("calibration").at("k").size(), 3u);
}

TEST(RecordingJson, RejectedDocumentLeavesRecordingUntouched) {
  Recording r;
  parse_recording_json(kMinimalJson2D, "recording.json", r);
  json doc = base_document();
  doc["particles"]["count"] = 9;
  doc["version"] = 3;
  EXPECT_THROW(parse_recording_json(doc.dump(), "recording.json", r), RecordingError);
  EXPECT_EQ(r.particle_count, 4);
}

}  // namespace
}  // namespace pliant::host::test

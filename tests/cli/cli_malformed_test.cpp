// Malformed recordings: `pliant estimate` exits 2 with one stderr line naming file and cause.
#include <gtest/gtest.h>

#include <functional>

#include "cli_test_support.hpp"

namespace pliant::cli_test {
namespace {

bool contains(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }

struct Malformed {
  std::string name;
  std::function<void(const fs::path& recording)> damage;
  std::vector<std::string> mentions;  // every one must appear in the single stderr line
};

std::ostream& operator<<(std::ostream& out, const Malformed& m) { return out << m.name; }

class cli_malformed : public ::testing::TestWithParam<Malformed> {};

TEST_P(cli_malformed, EstimateExitsTwoWithOneLine) {
  TempDir dir;
  const fs::path recording = dir.path() / "rec";
  write_tiny_recording(recording);
  GetParam().damage(recording);
  const CommandResult r = run_pliant("estimate " + quoted(recording.string()));
  EXPECT_EQ(r.status, 2);
  ASSERT_EQ(r.err_lines().size(), 1u) << r.err;
  EXPECT_EQ(r.err.rfind("pliant estimate: ", 0), 0u) << r.err;
  for (const std::string& part : GetParam().mentions) EXPECT_TRUE(contains(r.err, part)) << part << " in " << r.err;
  EXPECT_EQ(r.out, "");
}

const std::vector<Malformed> malformed_cases = {
    {"missing_recording_json",
     [](const fs::path& rec) { fs::remove(rec / "recording.json"); },
     {"recording.json", "no such file"}},
    {"json_syntax_error",
     [](const fs::path& rec) { replace_in_file(rec / "recording.json", "\"version\": 1,", "\"version\": 1"); },
     {"recording.json:4", "syntax error"}},
    {"unknown_format",
     [](const fs::path& rec) { replace_in_file(rec / "recording.json", "pliant-recording", "pliant-recordings"); },
     {"recording.json", "format"}},
    {"dimension_four",
     [](const fs::path& rec) { replace_in_file(rec / "recording.json", "\"dimension\": 2", "\"dimension\": 4"); },
     {"recording.json", "dimension", "2 or 3"}},
    {"count_not_integer",
     [](const fs::path& rec) { replace_in_file(rec / "recording.json", "\"count\": 4", "\"count\": 4.5"); },
     {"recording.json", "particles.count"}},
    {"path_escapes_directory",
     [](const fs::path& rec) {
       // A readable file really is there, so only the containment rule can reject it.
       write_text(rec.parent_path() / "x.csv", tiny_particles_csv());
       replace_in_file(rec / "recording.json", "\"particles.csv\"", "\"../x.csv\"");
     },
     {"recording.json", "files.particles", "../x.csv"}},
    {"missing_particles_csv",
     [](const fs::path& rec) { fs::remove(rec / "particles.csv"); },
     {"particles.csv", "no such file"}},
    {"wrong_header",
     [](const fs::path& rec) { replace_line(rec / "particles.csv", 1, "t,id,x,z"); },
     {"particles.csv:1:", "header", "t,id,x,z"}},
    {"id_out_of_range",
     [](const fs::path& rec) { replace_line(rec / "particles.csv", 7, "0.1,40,0,0.9"); },
     {"particles.csv:7:", "id 40", "out of range", "0..3"}},
    {"time_not_increasing",
     [](const fs::path& rec) { replace_line(rec / "particles.csv", 10, "0.05,0,0,0"); },
     {"particles.csv:10:", "increasing"}},
    {"not_a_number",
     [](const fs::path& rec) { replace_line(rec / "particles.csv", 5, "0,3,1,abc"); },
     {"particles.csv:5:", "abc"}},
    {"not_a_directory", [](const fs::path& rec) { fs::remove_all(rec); }, {"rec", "no such"}},
};

INSTANTIATE_TEST_SUITE_P(cli, cli_malformed, ::testing::ValuesIn(malformed_cases),
                         [](const ::testing::TestParamInfo<Malformed>& param_info) { return param_info.param.name; });

}  // namespace
}  // namespace pliant::cli_test

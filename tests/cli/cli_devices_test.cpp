// `pliant devices`: works with nothing connected (as here and in CI), in text and JSON.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include "cli_test_support.hpp"

namespace pliant::cli_test {
namespace {

TEST(CliDevices, ListsWhatIsThereAndSucceedsWithNothing) {
  const CommandResult text = run_pliant("devices");
  ASSERT_EQ(text.status, 0) << text.err;
  EXPECT_NE(text.out.find("CAN interfaces: "), std::string::npos) << text.out;
  EXPECT_NE(text.out.find("video devices: "), std::string::npos);
  EXPECT_NE(text.out.find("serial ports: "), std::string::npos);

  const CommandResult json = run_pliant("devices --json --all");
  ASSERT_EQ(json.status, 0) << json.err;
  const nlohmann::json j = nlohmann::json::parse(json.out);
  for (const char* key : {"usb", "can", "video", "serial", "notes"}) {
    ASSERT_TRUE(j.contains(key)) << key;
    EXPECT_TRUE(j[key].is_array()) << key;
  }
  for (const auto& row : j["usb"]) {
    EXPECT_TRUE(row.contains("id") && row.contains("handled_by")) << row.dump();
  }
  EXPECT_EQ(run_pliant("devices --bogus").status, 2);
}

}  // namespace
}  // namespace pliant::cli_test

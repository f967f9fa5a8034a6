// `pliant devices`: works with nothing connected (as here and in CI), in text and JSON, and lists
// the device schemes of the drivers in the build.
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
  // The device schemes this build's drivers registered, one line per category.
  EXPECT_NE(text.out.find("device schemes in this build"), std::string::npos) << text.out;
  for (const char* category : {"  colour camera: ", "  depth camera: ", "  force/torque sensor: ", "  gripper: "}) {
    EXPECT_NE(text.out.find(category), std::string::npos) << category;
  }

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
  for (const char* key : {"drivers", "schemes"}) {
    ASSERT_TRUE(j.contains(key)) << key;
    EXPECT_TRUE(j[key].is_array()) << key;
  }
  for (const auto& scheme : j["schemes"]) {
    for (const char* key : {"scheme", "category", "driver", "location", "description", "parameters"}) {
      EXPECT_TRUE(scheme.contains(key)) << key << " in " << scheme.dump();
    }
    bool listed = false;
    for (const auto& driver : j["drivers"]) listed = listed || driver == scheme["driver"];
    EXPECT_TRUE(listed) << scheme.dump();
  }
  EXPECT_EQ(run_pliant("devices --bogus").status, 2);
}

}  // namespace
}  // namespace pliant::cli_test

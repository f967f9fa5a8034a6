// `pliant batch` (host/cli/command_batch.hpp): where it looks for the fleet's Python package.
// The command itself runs end to end in tests/fleet.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "command_batch.hpp"

namespace pliant::cli {
namespace {

using Paths = std::vector<std::string>;

TEST(cli, BatchPythonPathBuiltInListWithoutOverride) {
  EXPECT_EQ(fleet_python_path(nullptr, "/src/host/python:/usr/lib/python3/dist-packages"),
            (Paths{"/src/host/python", "/usr/lib/python3/dist-packages"}));
}

TEST(cli, BatchPythonPathOverrideReplacesTheBuiltInList) {
  EXPECT_EQ(fleet_python_path("/opt/fleet", "/src/host/python"), (Paths{"/opt/fleet"}));
  EXPECT_EQ(fleet_python_path("/a:/b", "/src/host/python"), (Paths{"/a", "/b"}));
  EXPECT_EQ(fleet_python_path("", "/src/host/python"), Paths{});  // set but empty: nothing of ours
}

TEST(cli, BatchPythonPathEmptyEntriesAreDropped) {
  EXPECT_EQ(fleet_python_path("::/a::/b:", "unused"), (Paths{"/a", "/b"}));
  EXPECT_EQ(fleet_python_path(nullptr, ""), Paths{});
}

}  // namespace
}  // namespace pliant::cli

// TUM-style depth frame lists: the format as the benchmark writes it, and every malformed line.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>

#include "pliant/vision/depth_image.hpp"
#include "pliant/vision/depth_list.hpp"
#include "support/temp_dir.hpp"

namespace pliant::vision {
namespace {

std::string error_of(const std::string& text) {
  try {
    parse_depth_list(text, "depth.txt");
  } catch (const DepthError& error) {
    return error.what();
  }
  return "";
}

TEST(DepthList, ReadsTheTumFormat) {
  const std::string text =
      "# depth maps\n"
      "# file: 'rgbd_dataset_freiburg1_xyz.bag'\n"
      "# timestamp filename\n"
      "1305031102.160407 depth/1305031102.160407.png\n"
      "\n"
      "   \t\n"
      "1305031102.194330\tdepth/1305031102.194330.png\r\n"
      "  1305031102.226738   depth/1305031102.226738.png  ";
  const std::vector<DepthListEntry> list = parse_depth_list(text, "depth.txt");
  ASSERT_EQ(list.size(), 3u);
  EXPECT_DOUBLE_EQ(list[0].t_s, 1305031102.160407);
  EXPECT_EQ(list[0].path, "depth/1305031102.160407.png");
  EXPECT_EQ(list[1].path, "depth/1305031102.194330.png");
  EXPECT_DOUBLE_EQ(list[2].t_s, 1305031102.226738);
  EXPECT_EQ(list[2].path, "depth/1305031102.226738.png");
}

TEST(DepthList, MalformedLinesAreNamed) {
  EXPECT_EQ(error_of("1.0\n"), "depth.txt:1: expected 'timestamp filename', found 1 field(s)");
  EXPECT_EQ(error_of("# x\n1.0 a.png b.png\n"), "depth.txt:2: expected 'timestamp filename', found 3 field(s)");
  EXPECT_EQ(error_of("one a.png\n"), "depth.txt:1: timestamp 'one' is not a number");
  EXPECT_EQ(error_of("1.5x a.png\n"), "depth.txt:1: timestamp '1.5x' is not a number");
  EXPECT_EQ(error_of("nan a.png\n"), "depth.txt:1: timestamp 'nan' is not a number");
  EXPECT_EQ(error_of("1e999 a.png\n"), "depth.txt:1: timestamp '1e999' is not a number");
  EXPECT_EQ(error_of("2 a.png\n1 b.png\n"), "depth.txt:2: timestamp '1' does not follow the previous one");
  EXPECT_EQ(error_of("2 a.png\n2 b.png\n"), "depth.txt:2: timestamp '2' does not follow the previous one");
  EXPECT_EQ(error_of(std::string("1 a\x01.png\n")), "depth.txt:1: control character in file name 'a\\x01.png'");
  EXPECT_EQ(error_of(""), "depth.txt: no depth frame listed");
  EXPECT_EQ(error_of("# only comments\n\n"), "depth.txt: no depth frame listed");
  EXPECT_EQ(error_of(std::string("1 a.png\n\x7f b\n")), "depth.txt:2: timestamp '\\x7f' is not a number");
  // Long garbage is cut in the message.
  const std::string message = error_of(std::string(200, 'x') + " a.png\n");
  EXPECT_LT(message.size(), 100u);
  EXPECT_NE(message.find("..."), std::string::npos);
}

TEST(DepthList, RelativeNamesAreBesideTheList) {
  test_support::TempDir dir("pliant_depth_list_");
  std::filesystem::create_directories(dir.path() / "seq");
  std::ofstream(dir / "seq/depth.txt") << "0.0 depth/0.png\n0.1 /absolute/1.png\n";
  const std::vector<DepthListEntry> list = read_depth_list(dir / "seq/depth.txt");
  ASSERT_EQ(list.size(), 2u);
  EXPECT_EQ(list[0].path, (dir.path() / "seq" / "depth/0.png").string());
  EXPECT_EQ(list[1].path, "/absolute/1.png");
  EXPECT_THROW(read_depth_list(dir / "missing.txt"), DepthError);
}

}  // namespace
}  // namespace pliant::vision

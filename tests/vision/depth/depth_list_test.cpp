// Depth frame lists: the TUM format as the benchmark writes it, `pliant record`'s depth_frames.csv,
// and every malformed line of each.
#include <gtest/gtest.h>

#include <cmath>
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

constexpr const char* kRecordedHeader = "index,t,file,depth_scale_m,fx,fy,cx,cy\n";

TEST(DepthList, ReadsTheRecordersDepthFrames) {
  const std::string text = std::string(kRecordedHeader) +
                           "0,0.0334,depth/000000.png,0.001,570.34,570.34,319.5,239.5\r\n"
                           "\n"
                           "1,0.0667,depth/000001.png,0.0001,nan,nan,nan,nan\n";
  const std::vector<DepthListEntry> list = parse_depth_list(text, "depth_frames.csv");
  ASSERT_EQ(list.size(), 2u);
  EXPECT_DOUBLE_EQ(list[0].t_s, 0.0334);
  EXPECT_EQ(list[0].path, "depth/000000.png");
  EXPECT_DOUBLE_EQ(list[0].depth_scale_m, 0.001);
  EXPECT_DOUBLE_EQ(list[0].fx, 570.34);
  EXPECT_DOUBLE_EQ(list[0].cy, 239.5);
  EXPECT_DOUBLE_EQ(list[1].depth_scale_m, 1e-4);
  EXPECT_TRUE(std::isnan(list[1].fx) && std::isnan(list[1].fy) && std::isnan(list[1].cx) && std::isnan(list[1].cy));
  // A TUM list leaves them unknown.
  const std::vector<DepthListEntry> tum = parse_depth_list("0.5 a.png\n", "depth.txt");
  EXPECT_TRUE(std::isnan(tum[0].depth_scale_m) && std::isnan(tum[0].fx));
}

TEST(DepthList, MalformedRecordedRowsAreNamed) {
  auto error = [](const std::string& rows) {
    try {
      parse_depth_list(std::string(kRecordedHeader) + rows, "depth_frames.csv");
    } catch (const DepthError& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  EXPECT_EQ(error("0,0.1,a.png,0.001,1,1,1\n"),
            "depth_frames.csv:2: expected 8 fields (index,t,file,depth_scale_m,fx,fy,cx,cy), found 7");
  EXPECT_EQ(error("0,0.1,a.png,0.001,1,1,1,1,1\n"),
            "depth_frames.csv:2: expected 8 fields (index,t,file,depth_scale_m,fx,fy,cx,cy), found 9");
  EXPECT_EQ(error("x,0.1,a.png,0.001,1,1,1,1\n"), "depth_frames.csv:2: index 'x' is not a whole number");
  EXPECT_EQ(error("1.5,0.1,a.png,0.001,1,1,1,1\n"), "depth_frames.csv:2: index '1.5' is not a whole number");
  EXPECT_EQ(error("-1,0.1,a.png,0.001,1,1,1,1\n"), "depth_frames.csv:2: index '-1' is not a whole number");
  EXPECT_EQ(error("0,nan,a.png,0.001,1,1,1,1\n"), "depth_frames.csv:2: timestamp 'nan' is not a number");
  EXPECT_EQ(error("0,,a.png,0.001,1,1,1,1\n"), "depth_frames.csv:2: timestamp '' is not a number");
  EXPECT_EQ(error("0,0.2,a.png,0.001,1,1,1,1\n1,0.2,b.png,0.001,1,1,1,1\n"),
            "depth_frames.csv:3: timestamp '0.2' does not follow the previous one");
  EXPECT_EQ(error("0,0.1,,0.001,1,1,1,1\n"), "depth_frames.csv:2: empty file name");
  EXPECT_EQ(error(std::string("0,0.1,a\x02.png,0.001,1,1,1,1\n")),
            "depth_frames.csv:2: control character in file name 'a\\x02.png'");
  EXPECT_EQ(error("0,0.1,a.png,0,1,1,1,1\n"), "depth_frames.csv:2: depth_scale_m '0' is not a positive number");
  EXPECT_EQ(error("0,0.1,a.png,nan,1,1,1,1\n"), "depth_frames.csv:2: depth_scale_m 'nan' is not a positive number");
  EXPECT_EQ(error("0,0.1,a.png,0.001,1,one,1,1\n"), "depth_frames.csv:2: fy 'one' is neither a number nor nan");
  EXPECT_EQ(error("0,0.1,a.png,0.001,1,1,1, 1\n"), "depth_frames.csv:2: cy ' 1' is neither a number nor nan");
  EXPECT_EQ(error(""), "depth_frames.csv: no depth frame listed");
  EXPECT_EQ(error("\n\r\n"), "depth_frames.csv: no depth frame listed");
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

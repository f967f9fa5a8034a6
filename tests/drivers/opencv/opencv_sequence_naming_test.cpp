// Image-sequence naming: printf-style patterns parsed without snprintf, and natural file order.
#include <gtest/gtest.h>

#include <algorithm>
#include <string>
#include <vector>

#include "pliant/drivers/opencv/image_files.hpp"

namespace pliant::drivers::opencv_files {
namespace {

SequencePattern parse_ok(const std::string& text) {
  SequencePattern pattern;
  std::string error;
  EXPECT_TRUE(parse_sequence_pattern(text, pattern, error)) << text << ": " << error;
  return pattern;
}

std::string parse_error(const std::string& text) {
  SequencePattern pattern;
  std::string error;
  EXPECT_FALSE(parse_sequence_pattern(text, pattern, error)) << text;
  return error;
}

TEST(OpenCvSequenceNaming, FormatsLikePrintf) {
  EXPECT_EQ(sequence_name(parse_ok("frame_%04d.png"), 7), "frame_0007.png");
  EXPECT_EQ(sequence_name(parse_ok("frame_%04d.png"), 123456), "frame_123456.png");
  EXPECT_EQ(sequence_name(parse_ok("/tmp/a/%d.jpg"), 0), "/tmp/a/0.jpg");
  EXPECT_EQ(sequence_name(parse_ok("x%3i"), 5), "x  5");
  EXPECT_EQ(sequence_name(parse_ok("%u_end"), 42), "42_end");
  EXPECT_EQ(sequence_name(parse_ok("100%%_%02d.png"), 3), "100%_03.png");
  EXPECT_EQ(sequence_name(parse_ok("%020d"), 18446744073709551615ull), "18446744073709551615");
  EXPECT_EQ(sequence_name(parse_ok("a%0d"), 9), "a9");  // "0" flag without a width: no padding
}

TEST(OpenCvSequenceNaming, RejectsWhatIsNotOneIntegerConversion) {
  EXPECT_NE(parse_error("frames.png").find("no %d"), std::string::npos);
  EXPECT_NE(parse_error("%d_%d.png").find("more than one"), std::string::npos);
  EXPECT_NE(parse_error("frame_%s.png").find("only %d"), std::string::npos);
  EXPECT_NE(parse_error("frame_%n.png").find("only %d"), std::string::npos);
  EXPECT_NE(parse_error("frame_%.3d.png").find("only %d"), std::string::npos);
  EXPECT_NE(parse_error("frame_%-4d.png").find("only %d"), std::string::npos);
  EXPECT_NE(parse_error("frame_%").find("only %d"), std::string::npos);
  EXPECT_NE(parse_error("%123d").find("2 digits"), std::string::npos);
  EXPECT_NE(parse_error("%21d").find("above 20"), std::string::npos);
  EXPECT_NE(parse_error("100%%.png").find("no %d"), std::string::npos);
  EXPECT_NE(parse_error("").find("no %d"), std::string::npos);
}

TEST(OpenCvSequenceNaming, NaturalOrderComparesNumbersByValue) {
  std::vector<std::string> names = {"img_10.png", "img_2.png", "img_1.png", "img_02.png", "img_1a.png",
                                    "img_.png",   "b.png",     "a10b2.png", "a10b10.png", "a9.png"};
  std::sort(names.begin(), names.end(), [](const std::string& a, const std::string& b) { return natural_less(a, b); });
  const std::vector<std::string> want = {"a9.png",    "a10b2.png",  "a10b10.png", "b.png",      "img_.png",
                                         "img_1.png", "img_1a.png", "img_2.png",  "img_02.png", "img_10.png"};
  EXPECT_EQ(names, want);
  EXPECT_FALSE(natural_less("x", "x"));
  EXPECT_TRUE(natural_less("x", "x1"));
  EXPECT_FALSE(natural_less("x1", "x"));
  EXPECT_TRUE(natural_less("0099999999999999999999", "100000000000000000000000"));
}

TEST(OpenCvSequenceNaming, ImageExtensions) {
  EXPECT_TRUE(has_image_extension("a.png"));
  EXPECT_TRUE(has_image_extension("a.JPEG"));
  EXPECT_TRUE(has_image_extension("dir.x/a.b.TiF"));
  EXPECT_FALSE(has_image_extension("notes.txt"));
  EXPECT_FALSE(has_image_extension("png"));
  EXPECT_FALSE(has_image_extension("a."));
  EXPECT_FALSE(has_image_extension("a.pngx"));
}

}  // namespace
}  // namespace pliant::drivers::opencv_files

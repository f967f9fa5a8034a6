// Region options, grid seeding, and the role options and detection.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "pliant/vision/webcam_error.hpp"
#include "pliant/vision/webcam_grid.hpp"
#include "pliant/vision/webcam_roles.hpp"
#include "webcam_test_support.hpp"

namespace pliant::vision::webcam {
namespace {

bool contains(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }

template <typename F>
void expect_input_error(F&& f, const std::string& part) {
  try {
    f();
    ADD_FAILURE() << "no InputError; expected one containing '" << part << "'";
  } catch (const InputError& e) {
    EXPECT_TRUE(contains(e.what(), part)) << e.what();
  }
}

const cv::Size kFrame(320, 240);

TEST(webcam_grid, GridCellCentresSitHalfACellInside) {
  const ParticleGrid grid = seed_particles(parse_roi("40,60,240,120"), parse_grid("4x8"), kFrame);
  ASSERT_EQ(grid.size(), 32);
  EXPECT_EQ(grid.rows, 4);
  EXPECT_EQ(grid.cols, 8);
  EXPECT_DOUBLE_EQ(grid.spacing_x_px, 30);
  EXPECT_DOUBLE_EQ(grid.spacing_y_px, 30);
  // Pixels 40..279 span [39.5, 279.5]: first centre 39.5 + 15.
  EXPECT_DOUBLE_EQ(grid.positions[0].x, 54.5);
  EXPECT_DOUBLE_EQ(grid.positions[0].y, 74.5);
  EXPECT_DOUBLE_EQ(grid.positions[31].x, 264.5);
  EXPECT_DOUBLE_EQ(grid.positions[31].y, 164.5);
  EXPECT_EQ(grid.row[9], 1);
  EXPECT_EQ(grid.col[9], 1);
}

TEST(webcam_grid, SpacingFitsAsManyAsPossibleCentred) {
  GridSpec spec;
  spec.spacing_px = 50;
  const ParticleGrid grid = seed_particles(parse_roi("0,0,230,120"), spec, kFrame);
  EXPECT_EQ(grid.cols, 4);
  EXPECT_EQ(grid.rows, 2);
  // 4 x 50 = 200 of 230: 15 px margin on each side, first centre 15 + 25 - 0.5.
  EXPECT_DOUBLE_EQ(grid.positions[0].x, 39.5);
  EXPECT_DOUBLE_EQ(grid.positions[1].x - grid.positions[0].x, 50);
  // Grid and spacing together: exactly that grid, or an error when it does not fit.
  spec = parse_grid("2x3");
  spec.spacing_px = 50;
  EXPECT_EQ(seed_particles(parse_roi("0,0,230,120"), spec, kFrame).size(), 6);
  spec = parse_grid("3x5");
  spec.spacing_px = 50;
  expect_input_error([&] { seed_particles(parse_roi("0,0,230,120"), spec, kFrame); }, "do not fit");
}

TEST(webcam_grid, MaskKeepsTheSitesInside) {
  Region region;
  region.label = "mask.png";
  region.mask = cv::Mat::zeros(kFrame, CV_8UC1);
  cv::rectangle(region.mask, cv::Rect(40, 60, 240, 120), cv::Scalar(255), cv::FILLED);
  cv::rectangle(region.mask, cv::Rect(40, 60, 60, 60), cv::Scalar(0), cv::FILLED);  // a notch top-left
  const ParticleGrid grid = seed_particles(region, parse_grid("4x8"), kFrame);
  EXPECT_EQ(grid.size(), 32 - 4);
  EXPECT_EQ(grid.col[0], 2);  // row 0 starts after the notch
  EXPECT_EQ(grid.row[6], 1);
  EXPECT_EQ(grid.col[6], 2);
}

TEST(webcam_grid, UnusableRegionsAreRefused) {
  expect_input_error([] { seed_particles(parse_roi("10,10,0,5"), parse_grid("4x8"), kFrame); }, "empty region");
  expect_input_error([] { seed_particles(parse_roi("300,10,50,50"), parse_grid("2x2"), kFrame); },
                     "reaches outside the 320x240 frame");
  expect_input_error([] { seed_particles(parse_roi("-1,0,50,50"), parse_grid("2x2"), kFrame); }, "outside");
  expect_input_error([] { seed_particles(parse_roi("0,0,50,50"), parse_grid("1x2"), kFrame); }, "at least 3");
  expect_input_error([] { seed_particles(parse_roi("0,0,50,50"), GridSpec{}, kFrame); }, "give --grid");
  GridSpec tiny;
  tiny.spacing_px = 1;
  expect_input_error([&] { seed_particles(parse_roi("0,0,50,50"), tiny, kFrame); }, "at least 2 px");
  Region empty_mask;
  empty_mask.label = "m.png";
  empty_mask.mask = cv::Mat::zeros(kFrame, CV_8UC1);
  expect_input_error([&] { seed_particles(empty_mask, parse_grid("2x2"), kFrame); }, "m.png: empty region");
  Region small_mask = empty_mask;
  small_mask.mask = cv::Mat::ones(100, 100, CV_8UC1);
  expect_input_error([&] { seed_particles(small_mask, parse_grid("2x2"), kFrame); },
                     "m.png: mask is 100x100, the frames are 320x240");
}

TEST(webcam_grid, MalformedOptionTextIsRefused) {
  for (const char* text :
       {"", "1,2,3", "1,2,3,4,5", "a,b,c,d", "1,2,-3,4", "1,2,3,4x", "1.5,2,3,4", ",,,", "99999999999999,1,1,1"}) {
    expect_input_error([&] { parse_roi(text); }, "--roi: expected x,y,w,h");
  }
  for (const char* text : {"", "4", "4x", "x8", "4x8x2", "0x8", "4x-8", "4*8", "1001x1", "4 x 8"}) {
    expect_input_error([&] { parse_grid(text); }, "--grid: expected ROWSxCOLS");
  }
  EXPECT_EQ(parse_grid("4X8").cols, 8);
  test::TempDir dir;
  test::write_bytes(dir / "mask.png", "not an image");
  expect_input_error([&] { read_mask(dir / "mask.png"); }, "mask.png: cannot read the mask image");
  expect_input_error([&] { read_mask(dir / "missing.png"); }, "missing.png: no such file");
}

TEST(webcam_roles, OptionText) {
  EXPECT_EQ(parse_support("auto").kind, SupportSpec::Kind::detect);
  EXPECT_EQ(parse_support("none").kind, SupportSpec::Kind::none);
  EXPECT_EQ(parse_support("left").side, GridSide::left);
  EXPECT_EQ(parse_support("3,1,2").ids, (std::vector<int>{3, 1, 2}));
  for (const char* text : {"", "x", "1,,2", "-1", "1,a", "bottom,1", "99999999999"}) {
    expect_input_error([&] { parse_support(text); }, "--support: expected");
  }
  EXPECT_EQ(parse_driven("auto").kind, DrivenSpec::Kind::detect);
  EXPECT_EQ(parse_driven("17").id, 17);
  const DrivenSpec point = parse_driven("120.5,80");
  EXPECT_EQ(point.kind, DrivenSpec::Kind::point);
  EXPECT_DOUBLE_EQ(point.point.x, 120.5);
  for (const char* text : {"", "-2", "1,2,3", "a,b", "nan,1", "1e999,2", "1,"}) {
    expect_input_error([&] { parse_driven(text); }, "--driven: expected");
  }
}

TEST(webcam_roles, SidesAndDetection) {
  const ParticleGrid grid = seed_particles(parse_roi("40,60,240,120"), parse_grid("4x8"), kFrame);
  EXPECT_EQ(grid_side_particles(grid, GridSide::top), (std::vector<int>{0, 1, 2, 3, 4, 5, 6, 7}));
  EXPECT_EQ(grid_side_particles(grid, GridSide::bottom), (std::vector<int>{24, 25, 26, 27, 28, 29, 30, 31}));
  EXPECT_EQ(grid_side_particles(grid, GridSide::left), (std::vector<int>{0, 8, 16, 24}));
  EXPECT_EQ(grid_side_particles(grid, GridSide::right), (std::vector<int>{7, 15, 23, 31}));

  // A press from the right: the left column hardly moves, particle 15 moves most.
  std::vector<double> motion(32, 2.0);
  for (int id : {0, 8, 16, 24}) motion[static_cast<std::size_t>(id)] = 0.1;
  motion[15] = 9;
  motion[10] = 12;  // interior: not a contact candidate
  const ParticleRoles roles = choose_roles(grid, motion, SupportSpec{}, DrivenSpec{});
  EXPECT_TRUE(roles.support_detected);
  EXPECT_EQ(roles.support_side, GridSide::left);
  EXPECT_EQ(roles.support, (std::vector<int>{0, 8, 16, 24}));
  EXPECT_EQ(roles.driven, 15);
  EXPECT_TRUE(roles.driven_detected);

  // Given roles win; a driven particle on a given side leaves the supports.
  const ParticleRoles given = choose_roles(grid, motion, parse_support("bottom"), parse_driven("26"));
  EXPECT_EQ(given.support, (std::vector<int>{24, 25, 27, 28, 29, 30, 31}));
  EXPECT_EQ(given.driven, 26);
  EXPECT_FALSE(given.support_detected || given.driven_detected);
  EXPECT_EQ(choose_roles(grid, motion, parse_support("none"), parse_driven("60,70")).driven, 0);

  expect_input_error([&] { choose_roles(grid, motion, parse_support("1,32"), parse_driven("2")); },
                     "--support: particle 32 out of range 0..31");
  expect_input_error([&] { choose_roles(grid, motion, parse_support("1,2"), parse_driven("2")); },
                     "--driven: particle 2 is also given as a support");
  expect_input_error([&] { choose_roles(grid, motion, parse_support("none"), parse_driven("40")); }, "out of range");
  const std::vector<double> still(32, 0.2);
  expect_input_error([&] { choose_roles(grid, still, SupportSpec{}, parse_driven("3")); }, "nothing moved");
  EXPECT_EQ(choose_roles(grid, still, parse_support("bottom"), parse_driven("3")).driven, 3);
}

}  // namespace
}  // namespace pliant::vision::webcam

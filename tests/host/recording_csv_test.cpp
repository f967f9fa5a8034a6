// particles.csv, wrench.csv and gripper.csv: malformed tables (one cause each) and valid ones.
#include <cmath>
#include <string>

#include "pliant/host/recording.hpp"
#include "recording_test_support.hpp"

namespace pliant::host::test {
namespace {

enum class Table { particles_2d, particles_3d, wrench, gripper };

// Runs the parser for `table` over `text`, labelled "<table>.csv", for 4 particles.
std::string table_error(Table table, const std::string& text) {
  return error_of([&] {
    Recording r;
    r.particle_count = 4;
    switch (table) {
      case Table::particles_2d:
        r.dimension = 2;
        parse_particles_csv(text, "particles.csv", r);
        break;
      case Table::particles_3d:
        r.dimension = 3;
        parse_particles_csv(text, "particles.csv", r);
        break;
      case Table::wrench: parse_wrench_csv(text, "wrench.csv"); break;
      case Table::gripper: parse_gripper_csv(text, "gripper.csv"); break;
    }
  });
}

struct CsvCase {
  const char* name;
  Table table;
  std::string text;
  const char* prefix;
  const char* cause;
};

void PrintTo(const CsvCase& c, std::ostream* out) { *out << c.name; }

class CsvMalformed : public ::testing::TestWithParam<CsvCase> {};

TEST_P(CsvMalformed, NamesFileLineAndCause) {
  expect_message(table_error(GetParam().table, GetParam().text), GetParam().prefix, GetParam().cause);
}

const std::string kHead2 = "t,id,x,y\n";

INSTANTIATE_TEST_SUITE_P(
    Particles, CsvMalformed,
    ::testing::Values(
        CsvCase{"EmptyFile", Table::particles_2d, "", "particles.csv:1: ", "empty file"},
        CsvCase{"HeaderFor3DIn2D", Table::particles_2d, "t,id,x,y,z\n0,0,0,0,0\n",
                "particles.csv:1: ", "header must be exactly 't,id,x,y' for a 2D recording"},
        CsvCase{"HeaderWithSpaces", Table::particles_3d, "t, id, x, y, z\n",
                "particles.csv:1: ", "header must be exactly 't,id,x,y,z'"},
        CsvCase{"TooFewFields", Table::particles_2d, kHead2 + "0,0,0,0\n0,1,1\n",
                "particles.csv:3: ", "expected 4 fields (t,id,x,y), found 3"},
        CsvCase{"TooManyFields", Table::particles_2d, kHead2 + "0,0,0,0,0\n", "particles.csv:2: ", "expected 4 fields"},
        CsvCase{"TimeNotNumber", Table::particles_2d, kHead2 + "zero,0,0,0\n",
                "particles.csv:2: ", "t: expected a number, found 'zero'"},
        CsvCase{"TimeNan", Table::particles_2d, kHead2 + "nan,0,0,0\n", "particles.csv:2: ", "t: must be finite"},
        CsvCase{"IdFractional", Table::particles_2d, kHead2 + "0,1.5,0,0\n",
                "particles.csv:2: ", "id: expected an integer, found '1.5'"},
        CsvCase{"IdOutOfRange", Table::particles_2d, kHead2 + "0,0,0,0\n0,40,0,0\n",
                "particles.csv:3: ", "id 40 out of range 0..3"},
        CsvCase{"IdNegative", Table::particles_2d, kHead2 + "0,-1,0,0\n",
                "particles.csv:2: ", "id -1 out of range 0..3"},
        CsvCase{"CoordinateTrailingJunk", Table::particles_2d, kHead2 + "0,0,1.0abc,0\n",
                "particles.csv:2: ", "x: expected a number or nan, found '1.0abc'"},
        CsvCase{"CoordinateInfinite", Table::particles_3d, "t,id,x,y,z\n0,0,0,0,-inf\n",
                "particles.csv:2: ", "z: infinite value '-inf'"},
        CsvCase{"CoordinateEmpty", Table::particles_2d, kHead2 + "0,0,,0\n",
                "particles.csv:2: ", "x: expected a number or nan, found ''"},
        CsvCase{"CoordinateOverflow", Table::particles_2d, kHead2 + "0,0,0,1e999\n",
                "particles.csv:2: ", "y: number out of range"},
        CsvCase{"CoordinateLeadingSpace", Table::particles_2d, kHead2 + "0,0, 1,0\n",
                "particles.csv:2: ", "x: expected a number or nan, found ' 1'"},
        CsvCase{"TimeGoesBack", Table::particles_2d, kHead2 + "0,0,0,0\n1,0,0,0\n0.5,1,0,0\n",
                "particles.csv:4: ", "t 0.5 is smaller than the previous frame's t 1"},
        CsvCase{"FrameSplitByAnother", Table::particles_2d, kHead2 + "0,0,0,0\n1,0,0,0\n0,1,0,0\n",
                "particles.csv:4: ", "t 0 is smaller than the previous frame's t 1"},
        CsvCase{"DuplicateIdInFrame", Table::particles_2d, kHead2 + "0,0,0,0\n0,1,0,0\n0,0,5,5\n",
                "particles.csv:4: ", "duplicate id 0 in the frame at t=0 (first at line 2)"},
        CsvCase{"EmptyLineInside", Table::particles_2d, kHead2 + "0,0,0,0\n\n0,1,0,0\n",
                "particles.csv:3: ", "empty line"}),
    CaseName());

INSTANTIATE_TEST_SUITE_P(Samples, CsvMalformed,
                         ::testing::Values(CsvCase{"WrenchHeader", Table::wrench, "t,fx,fy,fz\n0,0,0,0\n",
                                                   "wrench.csv:1: ", "header must be exactly 't,fx,fy,fz,tx,ty,tz'"},
                                           CsvCase{"WrenchNan", Table::wrench, "t,fx,fy,fz,tx,ty,tz\n0,1,2,3,nan,0,0\n",
                                                   "wrench.csv:2: ", "tx: must be finite"},
                                           CsvCase{"WrenchRepeatedTime", Table::wrench,
                                                   "t,fx,fy,fz,tx,ty,tz\n0,1,2,3,0,0,0\n0,1,2,3,0,0,0\n",
                                                   "wrench.csv:3: ", "t 0 is not after the previous row's t 0"},
                                           CsvCase{"GripperFieldCount", Table::gripper, "t,width,force\n0,0.05\n",
                                                   "gripper.csv:2: ", "expected 3 fields (t,width,force), found 2"},
                                           CsvCase{"GripperTimeGoesBack", Table::gripper,
                                                   "t,width,force\n1,0.05,2\n0.5,0.04,3\n",
                                                   "gripper.csv:3: ", "t 0.5 is not after the previous row's t 1"},
                                           CsvCase{"GripperNotNumber", Table::gripper, "t,width,force\n1,wide,2\n",
                                                   "gripper.csv:2: ", "width: expected a number, found 'wide'"}),
                         CaseName());

// --- valid tables

Recording particles(int dimension, int count, const std::string& text) {
  Recording r;
  r.dimension = dimension;
  r.particle_count = count;
  parse_particles_csv(text, "particles.csv", r);
  return r;
}

TEST(ParticlesCsv, TwoDimensionalFrames) {
  const Recording r = particles(2, 4, kParticles2D);
  ASSERT_EQ(r.frame_count(), 2);
  EXPECT_EQ(r.frame_times_s, (std::vector<double>{0.0, 0.5}));
  ASSERT_EQ(r.positions.size(), 16u);
  EXPECT_EQ(r.position(1, 1, 0), 1.1);
  EXPECT_EQ(r.position(1, 3, 1), 1.0);
  for (int id = 0; id < 4; ++id) EXPECT_TRUE(r.observed(1, id));
}

TEST(ParticlesCsv, ThreeDimensionalRowsInAnyOrder) {
  const Recording r = particles(3, 2, "t,id,x,y,z\n0.1,1,4,5,6\n0.1,0,1,2,3\n0.2,0,-1e-3,2.5E2,.5\n");
  ASSERT_EQ(r.frame_count(), 2);
  EXPECT_EQ(r.position(0, 0, 2), 3.0);
  EXPECT_EQ(r.position(0, 1, 0), 4.0);
  EXPECT_EQ(r.position(1, 0, 0), -1e-3);
  EXPECT_EQ(r.position(1, 0, 1), 250.0);
  EXPECT_EQ(r.position(1, 0, 2), 0.5);
  EXPECT_FALSE(r.observed(1, 1));
}

TEST(ParticlesCsv, MissingRowsAndNanAreUnobserved) {
  const Recording r = particles(2, 3, "t,id,x,y\n0,0,1,1\n0,1,NaN,2\n0,2,nan,nan\n1,2,3,3\n");
  EXPECT_TRUE(r.observed(0, 0));
  EXPECT_FALSE(r.observed(0, 1));
  EXPECT_EQ(r.position(0, 1, 1), 2.0);
  EXPECT_TRUE(std::isnan(r.position(0, 1, 0)));
  EXPECT_FALSE(r.observed(0, 2));
  EXPECT_FALSE(r.observed(1, 0));
  EXPECT_FALSE(r.observed(1, 1));
  EXPECT_TRUE(r.observed(1, 2));
}

TEST(ParticlesCsv, CrlfBomAndMissingFinalNewline) {
  const Recording r = particles(2, 2, "\xEF\xBB\xBFt,id,x,y\r\n0,0,1,2\r\n0,1,3,4\r\n1,0,5,6");
  ASSERT_EQ(r.frame_count(), 2);
  EXPECT_EQ(r.position(0, 1, 1), 4.0);
  EXPECT_EQ(r.position(1, 0, 1), 6.0);
}

TEST(ParticlesCsv, HeaderOnlyHasNoFrames) { EXPECT_EQ(particles(2, 2, "t,id,x,y\n").frame_count(), 0); }

TEST(ParticlesCsv, ErrorLineCountsCrlfLines) {
  expect_message(table_error(Table::particles_2d, "t,id,x,y\r\n0,0,0,0\r\n0,9,0,0\r\n"),
                 "particles.csv:3: ", "id 9 out of range 0..3");
}

TEST(WrenchCsv, ReadsForceAndTorque) {
  const auto w = parse_wrench_csv("t,fx,fy,fz,tx,ty,tz\n0,1,2,3,4,5,6\n0.25,-1,-2,-3,-4,-5,-6\n", "wrench.csv");
  ASSERT_EQ(w.size(), 2u);
  EXPECT_EQ(w[1].t_s, 0.25);
  EXPECT_EQ(w[0].force_n[2], 3.0);
  EXPECT_EQ(w[0].torque_nm[0], 4.0);
  EXPECT_EQ(w[1].torque_nm[2], -6.0);
}

TEST(GripperCsv, ReadsWidthAndForce) {
  const auto g = parse_gripper_csv("t,width,force\r\n0,0.08,0\r\n0.5,0.05,12.5\r\n", "gripper.csv");
  ASSERT_EQ(g.size(), 2u);
  EXPECT_EQ(g[1].width, 0.05);
  EXPECT_EQ(g[1].force_n, 12.5);
}

}  // namespace
}  // namespace pliant::host::test

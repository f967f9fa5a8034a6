// Compression-test CSV parser: malformed files (one cause each, one-line messages naming file and
// line), accepted variants (CRLF, BOM, order, units) and the linear modulus fit.
#include <cmath>
#include <cstdint>
#include <random>
#include <string>

#include "pliant/host/fem/compression_test.hpp"
#include "recording_test_support.hpp"

namespace pliant::host::test {
namespace {

// An excerpt of examples/phantom_compression/source/EF10_0T_A1.csv: metadata on lines 1-7, the
// column header on line 8, rows from line 9.
const std::string kMeta =
    "EF10_0T_A_sample_1\n"
    "Compression test;\n"
    "Cylinder Diameter: 50mm;\n"
    "Cylinder Height: 30mm;\n"
    "Speed (mm/min): 10;\n"
    "Machine: INSTRON 5900;\n"
    "Load cell: 1kN;\n";
const std::string kHeader =
    "Time (s),Compression (mm),Load (N),Engineering Strain [-],Engineering Stress (kPa),True Strain [-],"
    "True Stress (kPa)\n";
const std::string kRows =
    "0.000000,0.000000,-0.009120,-0.000000,0.004645,0.000000,0.004645\n"
    "0.100000,0.007190,0.017780,-0.000240,-0.009055,-0.000240,-0.009053\n"
    "0.200000,0.027470,0.031020,-0.000916,-0.015798,-0.000916,-0.015784\n";
const std::string kValid = kMeta + kHeader + kRows;

// kValid with its line `number` (1-based) replaced by `line` (no newline).
std::string with_line(int number, const std::string& line) {
  std::string out;
  int current = 1;
  std::size_t start = 0;
  while (start < kValid.size()) {
    const std::size_t end = kValid.find('\n', start);
    out += current == number ? line : kValid.substr(start, end - start);
    out += '\n';
    start = end + 1;
    ++current;
  }
  return out;
}

// kValid without line `number`.
std::string without_line(int number) {
  std::string out = with_line(number, "\x01");
  out.erase(out.find("\x01\n"), 2);
  return out;
}

std::string parse_error(const std::string& text) {
  return error_of([&] { parse_compression_csv(text, "EF10_0T_A1.csv"); });
}

struct MalformedCase {
  std::string name;
  std::string text;
  std::string prefix;
  std::string cause;
};

void PrintTo(const MalformedCase& c, std::ostream* out) { *out << c.name; }

class CompressionCsvMalformed : public ::testing::TestWithParam<MalformedCase> {};

TEST_P(CompressionCsvMalformed, NamesFileLineAndCause) {
  expect_message(parse_error(GetParam().text), GetParam().prefix, GetParam().cause);
}

const std::string kRow9 = "0.000000,0.000000,-0.009120,-0.000000,0.004645,0.000000,0.004645";

INSTANTIATE_TEST_SUITE_P(
    Files, CompressionCsvMalformed,
    ::testing::Values(
        MalformedCase{"EmptyFile", "", "EF10_0T_A1.csv:1: ", "empty file"},
        MalformedCase{"OnlyBlankLines", "\n  \n\t\r\n", "EF10_0T_A1.csv:3: ", "empty file"},
        MalformedCase{"MetadataOnly", kMeta, "EF10_0T_A1.csv:7: ", "no column header"},
        MalformedCase{"HeaderOnly", kMeta + kHeader, "EF10_0T_A1.csv:8: ", "no data rows after the column header"},
        MalformedCase{"OneRow", kMeta + kHeader + kRow9 + "\n", "EF10_0T_A1.csv:9: ", "only one data row"},
        MalformedCase{"MissingDiameter", without_line(3),
                      "EF10_0T_A1.csv:7: ", "missing 'Cylinder Diameter' line before the column header"},
        MalformedCase{"MissingHeight", without_line(4), "EF10_0T_A1.csv:7: ", "missing 'Cylinder Height' line"},
        MalformedCase{"NegativeDiameter", with_line(3, "Cylinder Diameter: -50mm;"),
                      "EF10_0T_A1.csv:3: ", "Cylinder Diameter: -50mm is out of range (expected 0.1 mm to 10 m)"},
        MalformedCase{"ZeroHeight", with_line(4, "Cylinder Height: 0mm;"),
                      "EF10_0T_A1.csv:4: ", "Cylinder Height: 0mm is out of range"},
        MalformedCase{"AbsurdDiameter", with_line(3, "Cylinder Diameter: 50000mm;"),
                      "EF10_0T_A1.csv:3: ", "out of range"},
        MalformedCase{"DiameterWithoutUnit", with_line(3, "Cylinder Diameter: 50;"),
                      "EF10_0T_A1.csv:3: ", "Cylinder Diameter: unit missing (expected mm, cm or m)"},
        MalformedCase{"DiameterInInches", with_line(3, "Cylinder Diameter: 2 in;"),
                      "EF10_0T_A1.csv:3: ", "unknown unit 'in'"},
        MalformedCase{"DiameterNotANumber", with_line(3, "Cylinder Diameter: fifty mm;"),
                      "EF10_0T_A1.csv:3: ", "Cylinder Diameter: expected a number, found 'fifty mm'"},
        MalformedCase{"DiameterNan", with_line(3, "Cylinder Diameter: nan mm;"),
                      "EF10_0T_A1.csv:3: ", "Cylinder Diameter: must be finite"},
        MalformedCase{"TwoUnits", with_line(3, "Cylinder Diameter (mm): 5cm;"),
                      "EF10_0T_A1.csv:3: ", "two different units, 'mm' and 'cm'"},
        MalformedCase{"DuplicateHeight", with_line(5, "Cylinder Height: 31mm;"),
                      "EF10_0T_A1.csv:5: ", "duplicate 'Cylinder Height' line (first at line 4)"},
        MalformedCase{"SpeedUnknownUnit", with_line(5, "Speed: 10 furlongs;"),
                      "EF10_0T_A1.csv:5: ", "Speed: unknown unit 'furlongs'"},
        MalformedCase{"SpeedNegative", with_line(5, "Speed (mm/min): -10;"),
                      "EF10_0T_A1.csv:5: ", "Speed: -10 is out of range"},
        MalformedCase{"NonNumericCell", with_line(10, "0.1,abc,0.01778,0,0,0,0"),
                      "EF10_0T_A1.csv:10: ", "Compression: expected a number, found 'abc'"},
        MalformedCase{"EmptyCell", with_line(10, "0.1,,0.01778,0,0,0,0"),
                      "EF10_0T_A1.csv:10: ", "Compression: expected a number, found ''"},
        MalformedCase{"TooManyFields", with_line(10, "0.1,0.00719,0.01778,0,0,0,0,0"),
                      "EF10_0T_A1.csv:10: ", "expected 7 fields as in the column header, found 8"},
        MalformedCase{"TruncatedRow", kMeta + kHeader + kRow9 + "\n0.100000,0.00719",
                      "EF10_0T_A1.csv:10: ", "expected 7 fields as in the column header, found 2"},
        MalformedCase{"LoadNan", with_line(10, "0.1,0.00719,nan,0,0,0,0"),
                      "EF10_0T_A1.csv:10: ", "Load: must be finite, found 'nan'"},
        MalformedCase{"TimeInfinite", with_line(10, "inf,0.00719,0.01778,0,0,0,0"),
                      "EF10_0T_A1.csv:10: ", "Time: must be finite"},
        MalformedCase{"StressNan", with_line(10, "0.1,0.00719,0.01778,0,NaN,0,0"),
                      "EF10_0T_A1.csv:10: ", "Engineering Stress: must be finite"},
        MalformedCase{"NumberOutOfRange", with_line(10, "0.1,0.00719,1e999,0,0,0,0"),
                      "EF10_0T_A1.csv:10: ", "Load: number out of range '1e999'"},
        MalformedCase{"TimeRepeated", with_line(10, "0.0,0.00719,0.01778,0,0,0,0"),
                      "EF10_0T_A1.csv:10: ", "Time 0 s is not after the previous row's 0 s (time must increase)"},
        MalformedCase{"TimeBackwards", with_line(11, "0.05,0.02747,0.03102,0,0,0,0"),
                      "EF10_0T_A1.csv:11: ", "time must increase"},
        MalformedCase{"CompressionReachesHeight", with_line(11, "0.2,30.0,0.03102,0,0,0,0"),
                      "EF10_0T_A1.csv:11: ", "Compression: 30 mm is not below the specimen height of 30 mm"},
        MalformedCase{"AbsurdLoad", with_line(11, "0.2,0.02747,3e8,0,0,0,0"),
                      "EF10_0T_A1.csv:11: ", "Load: 3e+08 N is out of range"},
        MalformedCase{"DataBeforeHeader", kMeta + kRow9 + "\n",
                      "EF10_0T_A1.csv:8: ", "data row before the column header"},
        MalformedCase{"HeaderWithoutLoad", with_line(8, "Time (s),Compression (mm)"),
                      "EF10_0T_A1.csv:8: ", "column header has no 'Load' column"},
        MalformedCase{"HeaderColumnTwice", with_line(8, "Time (s),Compression (mm),Load (N),Load (kN),a,b,c"),
                      "EF10_0T_A1.csv:8: ", "column 'Load' appears twice"},
        MalformedCase{"LoadInPounds", with_line(8, "Time (s),Compression (mm),Load (lbf),a,b,c,d"),
                      "EF10_0T_A1.csv:8: ", "Load: unknown unit 'lbf' (expected N or kN)"},
        MalformedCase{"CompressionWithoutUnit", with_line(8, "Time (s),Compression,Load (N),a,b,c,d"),
                      "EF10_0T_A1.csv:8: ", "Compression: unit missing"},
        // A lone CR is not a line ending: the whole file is one line and no header is found.
        MalformedCase{"OldMacLineEndings", "x\rCylinder Diameter: 50mm\rCylinder Height: 30mm\r",
                      "EF10_0T_A1.csv:1: ", "no column header"}),
    CaseName());

void expect_excerpt(const CompressionTest& t) {
  EXPECT_EQ(t.label, "EF10_0T_A1.csv");
  EXPECT_EQ(t.sample_name, "EF10_0T_A_sample_1");
  ASSERT_EQ(t.notes.size(), 1u);
  EXPECT_EQ(t.notes[0], "Compression test");
  EXPECT_DOUBLE_EQ(t.diameter_m, 0.05);
  EXPECT_DOUBLE_EQ(t.height_m, 0.03);
  ASSERT_TRUE(t.speed_m_per_s.has_value());
  if (t.speed_m_per_s) {
    EXPECT_DOUBLE_EQ(*t.speed_m_per_s, 10e-3 / 60.0);
  }
  EXPECT_EQ(t.machine, "INSTRON 5900");
  EXPECT_EQ(t.load_cell, "1kN");
  EXPECT_TRUE(t.other_metadata.empty());
  ASSERT_EQ(t.row_count(), 3u);
  EXPECT_DOUBLE_EQ(t.time_s[1], 0.1);
  EXPECT_DOUBLE_EQ(t.compression_m[2], 0.02747e-3);
  EXPECT_DOUBLE_EQ(t.load_n[0], -0.00912);
  ASSERT_EQ(t.engineering_strain.size(), 3u);
  ASSERT_EQ(t.engineering_stress_pa.size(), 3u);
  ASSERT_EQ(t.true_strain.size(), 3u);
  ASSERT_EQ(t.true_stress_pa.size(), 3u);
  EXPECT_DOUBLE_EQ(t.engineering_strain[1], -0.00024);
  EXPECT_DOUBLE_EQ(t.engineering_stress_pa[1], -9.055);
  EXPECT_DOUBLE_EQ(t.true_stress_pa[2], -15.784);
  EXPECT_NEAR(t.cross_section_m2(), 1.9634954084936207e-3, 1e-15);
}

TEST(CompressionCsv, ReadsThePhantomFormat) { expect_excerpt(parse_compression_csv(kValid, "EF10_0T_A1.csv")); }

TEST(CompressionCsv, AcceptsCrlfLineEndings) {
  std::string crlf;
  for (const char c : kValid) {
    if (c == '\n') crlf += '\r';
    crlf += c;
  }
  expect_excerpt(parse_compression_csv(crlf, "EF10_0T_A1.csv"));
}

TEST(CompressionCsv, AcceptsByteOrderMarkBlankLinesAndPadding) {
  const std::string text = "\xEF\xBB\xBF" + kMeta + "\n  \n" + kHeader + "\n" +
                           "  0.000000 , 0.000000,-0.009120,-0.000000,0.004645,0.000000,0.004645\t\n" +
                           "0.100000,0.007190,0.017780,-0.000240,-0.009055,-0.000240,-0.009053\n\n" +
                           "0.200000,0.027470,0.031020,-0.000916,-0.015798,-0.000916,-0.015784\n\n\n";
  expect_excerpt(parse_compression_csv(text, "EF10_0T_A1.csv"));
}

TEST(CompressionCsv, MetadataInAnyOrderWithOtherUnitsAndOptionalLinesMissing) {
  const std::string text =
      "Operator: J. Doe;\n"
      "  height (mm) : 30 ;\n"
      "Sample: cyl-7\n"
      "DIAMETER: 0.05 m;\n"
      "Speed: 0.5 mm/s;\n"
      "Time (s),Compression (mm),Load (N)\n"
      "0,0,0\n1,0.5,1.5\n";
  const CompressionTest t = parse_compression_csv(text, "lab.csv");
  EXPECT_EQ(t.sample_name, "cyl-7");
  EXPECT_DOUBLE_EQ(t.height_m, 0.03);
  EXPECT_DOUBLE_EQ(t.diameter_m, 0.05);
  ASSERT_TRUE(t.speed_m_per_s.has_value());
  if (t.speed_m_per_s) {
    EXPECT_DOUBLE_EQ(*t.speed_m_per_s, 0.5e-3);
  }
  EXPECT_EQ(t.machine, "");
  EXPECT_EQ(t.load_cell, "");
  ASSERT_EQ(t.other_metadata.size(), 1u);
  EXPECT_EQ(t.other_metadata[0].first, "Operator");
  EXPECT_EQ(t.other_metadata[0].second, "J. Doe");
  EXPECT_TRUE(t.engineering_strain.empty());
  EXPECT_TRUE(t.true_stress_pa.empty());
  EXPECT_DOUBLE_EQ(t.compression_m[1], 0.5e-3);
}

TEST(CompressionCsv, ColumnsFoundByNameWithTheirUnits) {
  const std::string text =
      "Cylinder Height: 3cm\nCylinder Diameter: 50mm\n"
      "Time (ms),Remark,Load (kN),Compression (m),Engineering Stress (MPa),Engineering Strain (%)\n"
      "0,a,0,0,0,0\n500,b,0.002,0.001,0.001,3.3\n";
  const CompressionTest t = parse_compression_csv(text, "lab.csv");
  ASSERT_EQ(t.row_count(), 2u);
  EXPECT_DOUBLE_EQ(t.height_m, 0.03);
  EXPECT_DOUBLE_EQ(t.time_s[1], 0.5);
  EXPECT_DOUBLE_EQ(t.load_n[1], 2.0);
  EXPECT_DOUBLE_EQ(t.compression_m[1], 0.001);
  EXPECT_DOUBLE_EQ(t.engineering_stress_pa[1], 1000.0);
  EXPECT_DOUBLE_EQ(t.engineering_strain[1], 0.033);
  EXPECT_FALSE(t.speed_m_per_s.has_value());
  EXPECT_EQ(t.sample_name, "");

  // Time need not come first; a metadata value with commas is not a column header.
  const CompressionTest u = parse_compression_csv(
      "Machine: INSTRON 5900, frame 2, time-based;\nCylinder Height: 30mm\nCylinder Diameter: 50mm\n"
      "Load (N),Compression (mm),Time (s)\n0,0,0\n1.5,0.5,1\n",
      "lab.csv");
  EXPECT_EQ(u.machine, "INSTRON 5900, frame 2, time-based");
  ASSERT_EQ(u.row_count(), 2u);
  EXPECT_DOUBLE_EQ(u.time_s[1], 1.0);
  EXPECT_DOUBLE_EQ(u.load_n[1], 1.5);
  EXPECT_DOUBLE_EQ(u.compression_m[1], 0.5e-3);
}

TEST(CompressionCsv, MetadataTextIsMadeSafeForJson) {
  const std::string text =
      "bad\xC3(name\x01\nCylinder Diameter: 50mm\nCylinder Height: 30mm\nMachine: caf\xC3\xA9\n" + kHeader + kRows;
  const CompressionTest t = parse_compression_csv(text, "x.csv");
  EXPECT_EQ(t.sample_name, "bad?(name?");
  EXPECT_EQ(t.machine, "caf\xC3\xA9");
}

TEST(CompressionCsv, EveryTruncationFailsCleanlyOrParses) {
  for (std::size_t length = 0; length <= kValid.size(); ++length) {
    const std::string message = parse_error(kValid.substr(0, length));
    if (message != "<no error>") {
      EXPECT_EQ(message.rfind("EF10_0T_A1.csv:", 0), 0u) << "length " << length << ": " << message;
      EXPECT_EQ(message.find('\n'), std::string::npos) << message;
    }
  }
}

TEST(CompressionCsv, RandomByteChangesFailCleanlyOrParse) {
  std::mt19937 random(20260630);
  std::uniform_int_distribution<std::size_t> position(0, kValid.size() - 1);
  std::uniform_int_distribution<int> byte(0, 255);
  for (int trial = 0; trial < 3000; ++trial) {
    std::string text = kValid;
    for (int k = 0; k < 1 + trial % 4; ++k) text[position(random)] = static_cast<char>(byte(random));
    const std::string message = parse_error(text);
    if (message != "<no error>") {
      EXPECT_EQ(message.rfind("EF10_0T_A1.csv", 0), 0u) << message;
      EXPECT_EQ(message.find('\n'), std::string::npos) << message;
    }
  }
}

TEST(CompressionCsv, ReadsFilesAndNamesMissingOnes) {
  TempDir dir;
  const std::string path = dir.write("EF10_0T_A1.csv", kValid).string();
  const CompressionTest t = read_compression_csv(path);
  EXPECT_EQ(t.label, path);
  EXPECT_EQ(t.row_count(), 3u);
  const std::string missing = dir.str() + "/nothing.csv";
  expect_message(error_of([&] { read_compression_csv(missing); }), missing + ": ", "no such file");
  expect_message(error_of([&] { read_compression_csv(dir.str()); }), dir.str() + ": ", "not a regular file");
  const std::string bad = dir.write("bad.csv", with_line(10, "0.1,x,0,0,0,0,0")).string();
  expect_message(error_of([&] { read_compression_csv(bad); }), bad + ":10: ", "Compression: expected a number");
}

TEST(CompressionCsv, LinearModulusFitRecoversAStraightLine) {
  CompressionTest t;
  t.diameter_m = 0.05;
  t.height_m = 0.03;
  const double modulus_pa = 60e3;
  for (int i = 0; i <= 100; ++i) {
    const double strain = 0.002 * i;
    t.time_s.push_back(i);
    t.compression_m.push_back(strain * t.height_m);
    t.load_n.push_back((modulus_pa * strain + 150.0) * t.cross_section_m2());
  }
  const LinearModulusFit fit = fit_linear_modulus(t, 0.02, 0.10);
  EXPECT_NEAR(fit.youngs_modulus_pa, modulus_pa, 1e-6 * modulus_pa);
  EXPECT_NEAR(fit.intercept_pa, 150.0, 1e-6);
  EXPECT_EQ(fit.rows, 41u);
  EXPECT_THROW(fit_linear_modulus(t, 0.5, 0.6), std::invalid_argument);
  EXPECT_THROW(fit_linear_modulus(t, 0.1, 0.02), std::invalid_argument);
}

}  // namespace
}  // namespace pliant::host::test

#include "msim/io/csv.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <stdexcept>

#include "msim/core/error.hpp"
#include "scratch_dir.hpp"

namespace msim::io {
namespace {

using test::expectInputError;
using test::readBytes;
using test::scratchDir;
using test::writeText;

TEST(Csv, FormatsIntegersWithoutDecimalsAndOthersExactly) {
  EXPECT_EQ(formatCsvNumber(42.0), "42");
  EXPECT_EQ(formatCsvNumber(-7.0), "-7");
  EXPECT_EQ(formatCsvNumber(0.1), "0.1");
  EXPECT_EQ(formatCsvNumber(1e300), "1e+300");
  EXPECT_EQ(formatCsvNumber(std::numeric_limits<double>::infinity()), "inf");
}

TEST(Csv, WriterAppearsOnlyOnCommitAndRoundTrips) {
  const auto dir = scratchDir();
  const auto path = dir / "stats.csv";
  const double third = 1.0 / 3.0;
  {
    CsvWriter csv(path, {"step", "time", "mass"});
    csv.addRow({0, 0.0, third});
    csv.addRow({1, 0.125, 2.5e-17});
    EXPECT_FALSE(std::filesystem::exists(path));
    csv.commit();
  }
  EXPECT_EQ(readBytes(path).substr(0, 22), "step,time,mass\n0,0,0.3");
  const CsvTable table = readCsv(path);
  ASSERT_EQ(table.columns, (std::vector<std::string>{"step", "time", "mass"}));
  ASSERT_EQ(table.rows.size(), 2u);
  EXPECT_EQ(table.rows[0][2], third);  // bit-exact
  EXPECT_EQ(table.column("mass")[1], 2.5e-17);
  EXPECT_EQ(std::distance(std::filesystem::directory_iterator(dir), {}), 1);
}

TEST(Csv, UncommittedWriterLeavesNothing) {
  const auto dir = scratchDir();
  {
    CsvWriter csv(dir / "stats.csv", {"a"});
    csv.addRow({1.0});
  }
  EXPECT_TRUE(std::filesystem::is_empty(dir));
}

TEST(Csv, RejectsRowOfWrongWidth) {
  const auto dir = scratchDir();
  CsvWriter csv(dir / "stats.csv", {"a", "b"});
  EXPECT_THROW(csv.addRow({1.0}), std::invalid_argument);
}

TEST(Csv, ReaderErrorsNameFileAndLine) {
  const auto dir = scratchDir();
  writeText(dir / "bad.csv", "a,b\n1,2\n3,x\n");
  expectInputError([&] { readCsv(dir / "bad.csv"); }, {"bad.csv:3", "'b'"});
  writeText(dir / "short.csv", "a,b\n1\n");
  expectInputError([&] { readCsv(dir / "short.csv"); }, {"short.csv:2", "expected 2 fields"});
  expectInputError([&] { readCsv(dir / "missing.csv"); }, {"missing.csv"});
}

}  // namespace
}  // namespace msim::io

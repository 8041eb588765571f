// Numbers written by output::CsvWriter read back exactly (shortest round trip, std::to_chars).
#include <gtest/gtest.h>

#include <charconv>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <random>
#include <sstream>

#include "feeddrive/output/csv.hpp"

namespace fs = std::filesystem;
using namespace feeddrive::output;

TEST(CsvWriter, EveryDoubleReadsBackExactly) {
  std::mt19937_64 rng(11);
  std::vector<double> values = {0.0,
                                -0.0,
                                1.0,
                                0.1,
                                1e-300,
                                5e-324,
                                std::numeric_limits<double>::max(),
                                -2.2250738585072014e-308,
                                std::numeric_limits<double>::infinity()};
  for (int i = 0; i < 100000; ++i) {
    std::uint64_t bits = rng();
    double v;
    std::memcpy(&v, &bits, sizeof v);
    if (std::isfinite(v)) values.push_back(v);
  }
  const fs::path p = fs::temp_directory_path() / ("csv_test_" + std::to_string(::getpid()) + ".csv");
  {
    CsvWriter w(p, {"v"});
    for (double v : values) w.row(&v, 1);
    w.close();
    EXPECT_EQ(w.rows(), values.size());
  }
  std::ifstream in(p);
  std::string line;
  std::getline(in, line);
  EXPECT_EQ(line, "v");
  for (double v : values) {
    ASSERT_TRUE(std::getline(in, line));
    ASSERT_LE(line.size(), kMaxNumberChars);
    double back = 0;
    const auto res = std::from_chars(line.data(), line.data() + line.size(), back);
    ASSERT_EQ(res.ptr, line.data() + line.size()) << line;
    EXPECT_EQ(std::memcmp(&back, &v, sizeof v), 0) << line;  // bit for bit, -0 included
  }
  fs::remove(p);
}

TEST(CsvWriter, ShortestForm) {
  EXPECT_EQ(number_text(0.1), "0.1");
  EXPECT_EQ(number_text(1e-06), "1e-06");
  EXPECT_EQ(number_text(-3.0), "-3");
  EXPECT_EQ(number_text(std::nan("")), "nan");
}

// feeddrive-fit's data options (fit/data.hpp): units per column role, separators, decimal
// commas and columns by index, on hand-made CSV text (pure logic, no fit).
#include <gtest/gtest.h>

#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>

#include "feeddrive/fit/data.hpp"
#include "feeddrive/fit/sanity.hpp"

namespace feeddrive::fit {
namespace {

TEST(FitUnits, EveryUnitIsAFactorToSI) {
  const Units u = parse_units("t=ms,x=mm,xd=um,force=kN,u=mV");
  EXPECT_DOUBLE_EQ(u.t, 1e-3);
  EXPECT_DOUBLE_EQ(u.x, 1e-3);
  EXPECT_DOUBLE_EQ(u.xd, 1e-6);
  EXPECT_DOUBLE_EQ(u.force, 1e3);
  EXPECT_DOUBLE_EQ(u.u, 1e-3);
  EXPECT_DOUBLE_EQ(parse_units("t=us").t, 1e-6);
  EXPECT_DOUBLE_EQ(parse_units("t=s").t, 1.0);
  EXPECT_DOUBLE_EQ(parse_units("x=nm").x, 1e-9);
  EXPECT_DOUBLE_EQ(parse_units("x=um").x, 1e-6);
  EXPECT_DOUBLE_EQ(parse_units("x=m").x, 1.0);
  EXPECT_DOUBLE_EQ(parse_units("force=mN").force, 1e-3);
  EXPECT_DOUBLE_EQ(parse_units("force=N").force, 1.0);
  EXPECT_DOUBLE_EQ(parse_units("u=V").u, 1.0);
  EXPECT_DOUBLE_EQ(parse_units("x=counts:5e-8").x, 5e-8);  // a 50 nm encoder
  for (const std::string bad : {"x=inch", "speed=mm", "x=", "x=counts:-1", "x=counts:abc", "t"})
    EXPECT_THROW(parse_units(bad), DataError) << bad;
  // a velocity column (a logger's file often has one): the fit uses none, and says so with the
  // roles it does use (issue 20's review: "unknown role 'v'" left the user guessing)
  for (const std::string v : {"v=mm", "x=mm,velocity=mm/s", "speed=m"}) {
    try {
      parse_units(v);
      ADD_FAILURE() << v << " was accepted";
    } catch (const DataError& e) {
      const std::string m = e.what();
      EXPECT_NE(m.find("the fit uses no velocity column (it takes the motion from the position)"), std::string::npos)
          << m;
      EXPECT_NE(m.find("the roles are t (time), x (position), xd (reference), force (thrust), u (command)"),
                std::string::npos)
          << m;
    }
  }
  try {
    parse_units("t=ms,x=furlong");
  } catch (const DataError& e) {
    EXPECT_NE(std::string(e.what()).find("'x=furlong': unknown unit 'furlong' for x"), std::string::npos) << e.what();
  }
  // the unit a factor names (sanity.hpp's hints)
  EXPECT_EQ(unit_name("x", 1e-3), "mm");
  EXPECT_EQ(unit_name("t", 1e-6), "us");
  EXPECT_EQ(unit_name("force", 1e3), "kN");
  EXPECT_EQ(unit_name("force", 1e6), "");
}

// `text` as the file logger.csv in a fresh folder, read by load_csv (the fit reads files only);
// the folder is removed afterwards, also when load_csv throws.
MeasuredData load_text(const std::string& text, const CsvOptions& o) {
  namespace fs = std::filesystem;
  struct Folder {
    fs::path dir = fs::temp_directory_path() / ("fd_fit_data_test_" + std::to_string(::getpid()));
    Folder() { fs::create_directories(dir); }
    ~Folder() { fs::remove_all(dir); }
  } folder;
  const std::string path = (folder.dir / "logger.csv").string();
  std::ofstream(path) << text;
  return load_csv(path, o);
}

// 60 rows of "time_ms;pos_mm;force_N" with decimal commas: t = k ms, x = 0.5 k mm, F = 1.5 N.
std::string logger_text(const std::string& header = "time_ms;pos_mm;force_N") {
  std::string s = header + "\n";
  for (int k = 0; k < 60; ++k) s += std::to_string(k) + ";" + std::to_string(k / 2) + (k % 2 ? ",5" : ",0") + ";1,5\n";
  return s;
}

TEST(FitCsv, SemicolonsDecimalCommasUnitsAndColumnIndex) {
  CsvOptions o;
  o.separator = ';';
  o.decimal_comma = true;
  o.units = parse_units("t=ms,x=mm");
  o.time_column = "time_ms";
  o.position_column = "pos_mm";
  const MeasuredData d = load_text(logger_text(), o);
  ASSERT_EQ(d.size(), 60u);
  EXPECT_EQ(d.input_kind, InputKind::kForce);
  EXPECT_DOUBLE_EQ(d.t[7], 7e-3);
  EXPECT_NEAR(d.x[7], 3.5e-3, 1e-15);
  EXPECT_DOUBLE_EQ(d.input[7], 1.5);
  EXPECT_EQ(d.lines[7], 9);  // the header is line 1
  // by index: the 1st, 2nd and 3rd columns
  o.time_column = "1";
  o.position_column = "2";
  o.force_column = "3";
  const MeasuredData e = load_text(logger_text("a;b;c"), o);
  EXPECT_DOUBLE_EQ(e.t[7], 7e-3);
  EXPECT_EQ(e.position_name, "b");
  EXPECT_EQ(e.input_kind, InputKind::kForce);
  // a decimal point in a decimal-comma file is refused with its line and column
  o.time_column = "time_ms";
  o.position_column = "pos_mm";
  o.force_column = "force_N";
  std::string bad = logger_text();
  bad.replace(bad.find("1,5"), 3, "1.5");
  try {
    load_text(bad, o);
    ADD_FAILURE() << "a decimal point was accepted";
  } catch (const DataError& err) {
    EXPECT_NE(std::string(err.what()).find("/logger.csv:2:"), std::string::npos) << err.what();
    EXPECT_NE(std::string(err.what()).find("not a number with a decimal comma"), std::string::npos) << err.what();
  }
}

}  // namespace
}  // namespace feeddrive::fit

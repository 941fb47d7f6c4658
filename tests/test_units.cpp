#include <cstdint>
#include <limits>

#include <gtest/gtest.h>

#include "core/errors.hpp"
#include "core/units.hpp"
#include "formats/network.hpp"

using namespace hemotree;

TEST(Units, PlainNumbersAreSI) {
  EXPECT_DOUBLE_EQ(parse_quantity("0.001", Dimension::length, "x"), 1e-3);
  EXPECT_DOUBLE_EQ(parse_quantity("7e-6", Dimension::length, "x"), 7e-6);
}

TEST(Units, CommonUnitsConvertToSI) {
  EXPECT_DOUBLE_EQ(parse_quantity("1mm", Dimension::length, "x"), 1e-3);
  EXPECT_DOUBLE_EQ(parse_quantity("7um", Dimension::length, "x"), 7e-6);
  EXPECT_DOUBLE_EQ(parse_quantity("7 \xC2\xB5m", Dimension::length, "x"), 7e-6);
  EXPECT_DOUBLE_EQ(parse_quantity("10mmHg", Dimension::pressure, "x"), 1333.22);
  EXPECT_DOUBLE_EQ(parse_quantity("1.74ml/min", Dimension::flow, "x"), 1.74e-6 / 60);
  EXPECT_DOUBLE_EQ(parse_quantity("300ms", Dimension::time, "x"), 0.3);
}

TEST(Units, ClassBoundariesGivenInMicrometresStayOnTheirSide) {
  // 10 * 1e-6 is 9.999999999999999e-06: a capillary. Dividing by 1e6 gives exactly 10e-6.
  EXPECT_EQ(classify(parse_quantity("10um", Dimension::length, "x")), VesselClass::arteriole);
  EXPECT_EQ(classify(parse_quantity("100um", Dimension::length, "x")), VesselClass::small_artery);
  EXPECT_EQ(classify(parse_quantity("500um", Dimension::length, "x")), VesselClass::artery);
}

TEST(Units, BadQuantitiesAreRefusedByName) {
  EXPECT_THROW(parse_quantity("", Dimension::length, "--min-diameter"), InputError);
  EXPECT_THROW(parse_quantity("abc", Dimension::length, "--min-diameter"), InputError);
  EXPECT_THROW(parse_quantity("1mmHg", Dimension::length, "--min-diameter"), InputError);
  try {
    parse_quantity("7parsec", Dimension::length, "--min-diameter");
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("--min-diameter"), std::string::npos);
    EXPECT_NE(std::string(e.what()).find("parsec"), std::string::npos);
  }
}

TEST(Units, NonFiniteAndOverflowingQuantitiesAreRefused) {
  for (const char* text : {"inf", "nan", "-inf", "1e400", "infinity"})
    EXPECT_THROW(parse_quantity(text, Dimension::flow, "--mean-flow"), InputError) << text;
  // Finite as typed, infinite in SI: refused, never passed on as inf.
  EXPECT_THROW(parse_quantity("1e308mmHg", Dimension::pressure, "--venous-pressure"), InputError);
  EXPECT_THROW(parse_quantity("4/3", Dimension::dimensionless, "--alpha"), InputError);
}

TEST(Units, ARangeIsCheckedAndStatedInTheFlagsUnit) {
  const Interval flow{1e-18, 0.1};
  EXPECT_DOUBLE_EQ(parse_quantity("1.74ml/min", Dimension::flow, "--mean-flow", flow, "ml/min"),
                   1.74e-6 / 60);
  try {
    parse_quantity("1e300", Dimension::flow, "--mean-flow", flow, "ml/min");
    FAIL();
  } catch (const InputError& e) {
    EXPECT_STREQ(e.what(), "--mean-flow: '1e300' lies outside the accepted range [6e-11, 6e+06] ml/min");
  }
  const Interval alpha{1, 2, true, false};
  EXPECT_EQ(describe(alpha, ""), "(1, 2]");
  EXPECT_THROW(parse_number("1", "--alpha", alpha), InputError);
  EXPECT_DOUBLE_EQ(parse_number("2", "--alpha", alpha), 2.0);
  EXPECT_EQ(describe(Interval{3e-6, 2.6e-2, false, true}, "um"), "[3, 26000) um");
}

TEST(Units, IntegersNeitherWrapNorSaturate) {
  constexpr std::uint64_t max = std::numeric_limits<std::uint64_t>::max();
  EXPECT_EQ(parse_count("18446744073709551615", "--seed", 0, max), max);
  EXPECT_EQ(parse_count("0", "--seed", 0, max), 0u);
  // CLI11 read both as 2^64 - 1: the same tree for two different mistakes.
  for (const char* text : {"-1", "99999999999999999999", "1.5", "1e3", "0x10", "", " 1"})
    EXPECT_THROW(parse_count(text, "--seed", 0, max), InputError) << text;
  try {
    parse_count("-1", "--seed", 0, max);
    FAIL();
  } catch (const InputError& e) {
    EXPECT_STREQ(e.what(),
                 "--seed: '-1' is negative; the accepted range is 0..18446744073709551615");
  }
  EXPECT_THROW(parse_count("0", "--budget", 1, 10), InputError);
  EXPECT_EQ(parse_integer("-3", "--keep-subtree", -5, 5), -3);
  EXPECT_THROW(parse_integer("9223372036854775808", "--keep-subtree",
                             std::numeric_limits<std::int64_t>::min(),
                             std::numeric_limits<std::int64_t>::max()),
               InputError);
}

TEST(Units, NumbersInMessagesAreNeverCutShortAndCarryTheirUnit) {
  // vprune printed 1e300 Pa as "7500637554192106004601778229205" (a %.2f cut at 31 characters).
  EXPECT_EQ(format_quantity(1e300, "mmHg"), "7.50064e+297 mmHg");
  EXPECT_EQ(format_quantity(81142.17 * pascal_per_mmhg, "mmHg"), "81142.2 mmHg");
  EXPECT_EQ(format_quantity(1.74e-6 / 60, "ml/min"), "1.74 ml/min");
  EXPECT_EQ(format_quantity(60e-6, "um"), "60 um");
  EXPECT_EQ(format_rounded(-1.7976931348623157e308), "-1.79769e+308");
}

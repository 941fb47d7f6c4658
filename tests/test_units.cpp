#include <gtest/gtest.h>

#include "cli/errors.hpp"
#include "cli/units.hpp"
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

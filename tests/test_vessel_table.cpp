// The columnar table every per-vessel output is written from: each row read back from its
// JSON text gives the stored values bit for bit, nulls where a value is not finite or absent.
#include <cmath>
#include <functional>
#include <limits>
#include <span>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "formats/quoting.hpp"
#include "solver/vessel_table.hpp"

using namespace hemotree;

namespace {
std::string appended(const std::function<void(std::string&)>& append) {
  std::string text;
  append(text);
  return text;
}
std::string json_row(const VesselTable& t, std::size_t row) {
  return appended([&](std::string& text) { t.append_json_row(text, row); });
}

VesselTable table() {
  VesselTable t(3);
  t.add_integer("id", {7, -2, 40000000000});
  t.add_text("model", {1, 0, 1}, {"1d", "0d"});
  t.add_integer("degree", {VesselTable::null_integer, 7, VesselTable::null_integer});
  t.add_number("mean_pressure", {0.1 + 0.2, 1e-300, -3.0});
  t.add_number("pwv", {std::numeric_limits<double>::quiet_NaN(), std::numeric_limits<double>::infinity(), 5e-7});
  return t;
}
}  // namespace

TEST(VesselTable, JsonRowsReadBackBitForBit) {
  const VesselTable t = table();
  for (std::size_t row = 0; row < t.rows(); ++row) {
    const auto j = nlohmann::json::parse(json_row(t, row));
    EXPECT_EQ(j["id"].get<std::int64_t>(), t.find("id")->integer[row]);
    EXPECT_EQ(j["model"].get<std::string>(), row == 1 ? "1d" : "0d");
    EXPECT_EQ(j["degree"].is_null(), row != 1);
    EXPECT_EQ(j["mean_pressure"].get<double>(), t.find("mean_pressure")->number[row]);  // exact
    EXPECT_TRUE(j["mean_pressure"].is_number_float());  // -3.0, not -3
    EXPECT_EQ(j["pwv"].is_null(), row != 2);
  }
}

TEST(VesselTable, CsvFieldsAreTheShortestTextOfTheDouble) {
  EXPECT_EQ(appended([](std::string& text) { append_csv_number(text, 0.1 + 0.2); }), "0.30000000000000004");
  EXPECT_EQ(appended([](std::string& text) { append_csv_number(text, -3.0); }), "-3");
  EXPECT_EQ(appended([](std::string& text) { append_csv_number(text, std::nan("")); }), "");
  EXPECT_EQ(appended([](std::string& text) { append_json_number(text, -3.0); }), "-3.0");
  EXPECT_EQ(appended([](std::string& text) { append_json_number(text, 1e-300); }), "1e-300");
}

TEST(VesselTable, CsvRowsHoldTheSameNumbersAndEmptyNulls) {
  const VesselTable t = table();
  EXPECT_EQ(appended([&](std::string& text) { t.append_csv_row(text, 0); }), "7,0d,,0.30000000000000004,\n");
  EXPECT_EQ(appended([&](std::string& text) { t.append_csv_row(text, 1); }), "-2,1d,7,1e-300,\n");
  EXPECT_EQ(appended([&](std::string& text) { t.append_csv_row(text, 2); }), "40000000000,0d,,-3,5e-07\n");
  VesselTable quoted(1);
  quoted.add_text("class", {0}, {"a,b"});
  EXPECT_EQ(appended([&](std::string& text) { quoted.append_csv_row(text, 0); }), "\"a,b\"\n");
}

TEST(VesselTable, RefusesAColumnOfAnotherLength) {
  VesselTable t(2);
  EXPECT_THROW(t.add_number("x", {1.0}), std::invalid_argument);
  EXPECT_THROW(t.add_text("c", {0, 2}, {"a", "b"}), std::invalid_argument);
  EXPECT_EQ(t.find("x"), nullptr);
}

// Any string a user can give reaches column names (a tracer's) and labels: the JSON row still
// parses and gives it back (control characters escaped, bytes that are not UTF-8 replaced),
// and a CSV field is quoted where it must be (hostile-inputs 07).
TEST(VesselTable, AnyNameOrLabelKeepsTheRowJson) {
  for (const std::string& name : {std::string("a\nb"), std::string("q\"uote\\"), std::string("t\tab\x01"),
                                  std::string("caf\xc3\xa9"), std::string("bad\xff")}) {
    VesselTable t(1);
    t.add_number(name + "_arrival_time", {1.5});
    t.add_text("class", {0}, {name});
    const std::string text = json_row(t, 0);
    nlohmann::json j;
    ASSERT_NO_THROW(j = nlohmann::json::parse(text)) << text;
    if (name != "bad\xff") {
      EXPECT_EQ(j[name + "_arrival_time"].get<double>(), 1.5);
      EXPECT_EQ(j["class"].get<std::string>(), name);
    } else {
      EXPECT_EQ(j["class"].get<std::string>(), "bad\xef\xbf\xbd");  // U+FFFD
    }
  }
}

TEST(Quoting, CsvFieldsQuotedOnlyWhereTheyMustBe) {
  EXPECT_EQ(csv_field("p vessel 3 x 0.5 [Pa]"), "p vessel 3 x 0.5 [Pa]");
  EXPECT_EQ(csv_field("a,b"), "\"a,b\"");
  EXPECT_EQ(csv_field("say \"hi\""), "\"say \"\"hi\"\"\"");
  EXPECT_EQ(csv_field("two\nlines"), "\"two\nlines\"");
  EXPECT_EQ(json_quoted("a\"b\n"), "\"a\\\"b\\n\"");
}

TEST(VesselTable, AViewReadsTheRecordsWhereTheyLieAsAHeldColumnWould) {
  // The same values held, viewed whole, and viewed as a field of records 24 bytes apart: the
  // same rows, and the same whole column (the spaced one copied, the contiguous one itself).
  struct Record {
    double a, mean, b;
  };
  const std::vector<Record> records{{1, 0.1 + 0.2, 2}, {3, -3.0, 4}, {5, std::numeric_limits<double>::quiet_NaN(), 6}};
  const std::vector<double> means{0.1 + 0.2, -3.0, std::numeric_limits<double>::quiet_NaN()};
  const std::vector<std::int64_t> ids{7, -2, VesselTable::null_integer};
  VesselTable held(3), viewed(3);
  held.add_integer("id", ids);
  held.add_number("mean", means);
  viewed.add_integer_view("id", ids);
  viewed.add_number_view("mean", std::span<const Record>(records), &Record::mean);
  for (std::size_t row = 0; row < 3; ++row) {
    EXPECT_EQ(json_row(viewed, row), json_row(held, row));
    EXPECT_EQ(appended([&](std::string& text) { viewed.append_csv_row(text, row); }),
              appended([&](std::string& text) { held.append_csv_row(text, row); }));
  }
  EXPECT_EQ(json_row(viewed, 1), R"({"id":-2,"mean":-3.0})");
  std::vector<double> scratch;
  const std::span<const double> mean = viewed.find("mean")->numbers(scratch);
  ASSERT_EQ(mean.size(), 3u);
  EXPECT_EQ(mean.data(), scratch.data());  // spaced apart: copied
  EXPECT_EQ(mean[0], 0.1 + 0.2);
  EXPECT_TRUE(std::isnan(mean[2]));
  std::vector<std::int64_t> unused;
  EXPECT_EQ(viewed.find("id")->integers(unused).data(), ids.data());  // contiguous: itself
  EXPECT_TRUE(unused.empty());
  EXPECT_THROW(viewed.add_number_view("short", std::span<const double>(means).first(2)), std::invalid_argument);
}

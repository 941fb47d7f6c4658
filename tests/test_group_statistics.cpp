// summary.json's "statistics": per class, model, generation and diameter bin, the count and
// the nearest-rank median, 5th and 95th percentiles of four quantities. Checked against a
// direct calculation on a small chain of vessels; the groups are described in parallel, and
// any count of threads gives the same JSON.
#include <cmath>
#include <cstdint>
#include <limits>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "formats/network.hpp"
#include "solver/run_report.hpp"
#include "solver/vessel_table.hpp"

using namespace hemotree;

namespace {

// n vessels in a chain, diameters from 5 um to 1 mm, generation v % 3; the table's class
// "arteriole" for even v and "capillary" for odd, a third label no vessel has.
struct Case {
  Network net;
  VesselTable table;
};
Case chain(std::size_t n) {
  Case c;
  c.net.add_node(0);
  std::vector<std::uint8_t> vessel_class(n), model(n, 0);
  std::vector<double> pressure(n), pi(n), flow(n), wss(n);
  for (std::size_t v = 0; v < n; ++v) {
    c.net.add_node(static_cast<std::int64_t>(v + 1));
    const double diameter = 5e-6 * std::pow(200.0, static_cast<double>(v) / static_cast<double>(n - 1));
    c.net.add_vessel(static_cast<std::int64_t>(v), static_cast<std::int32_t>(v), static_cast<std::int32_t>(v + 1), 1e-3,
                     diameter, 1e-6, 1e6, static_cast<std::int32_t>(v % 3));
    vessel_class[v] = static_cast<std::uint8_t>(v % 2);
    pressure[v] = 1000.0 + static_cast<double>((v * 7919) % n);  // a permutation of 1000 .. 1000 + n - 1
    pi[v] = v % 5 == 0 ? std::numeric_limits<double>::quiet_NaN() : static_cast<double>(v);  // null: not counted
    flow[v] = -static_cast<double>(v);
    wss[v] = 1.0;
  }
  c.table = VesselTable(n);
  c.table.add_text("class", vessel_class, {"arteriole", "capillary", "artery"});
  c.table.add_text("model", model, {"0d"});
  c.table.add_number("mean_pressure", pressure);
  c.table.add_number("pulsatility_index", pi);
  c.table.add_number("mean_flow", flow);
  c.table.add_number("mean_wss", wss);
  return c;
}

}  // namespace

TEST(GroupStatistics, NearestRankPercentilesPerGroup) {
  const std::size_t n = 1001;  // prime to 7919: the pressures are 1000 .. 2000 in another order
  const Case c = chain(n);
  const nlohmann::json s = group_statistics(c.net, c.table, 1);
  // The model's one group holds every vessel: nearest ranks round(f (n - 1)) of 1000 .. 2000.
  const nlohmann::json& all = s["by_model"]["0d"];
  EXPECT_EQ(all["vessels"], n);
  EXPECT_EQ(all["mean_pressure"]["median"], 1500.0);
  EXPECT_EQ(all["mean_pressure"]["p5"], 1050.0);
  EXPECT_EQ(all["mean_pressure"]["p95"], 1950.0);
  // PI is null at every fifth vessel: 800 values 1 .. 1000 without the multiples of 5.
  std::vector<double> pi;
  for (std::size_t v = 0; v < n; ++v)
    if (v % 5 != 0) pi.push_back(static_cast<double>(v));
  EXPECT_EQ(all["pulsatility_index"]["median"], pi[static_cast<std::size_t>(std::llround(0.5 * (pi.size() - 1)))]);
  EXPECT_EQ(all["mean_flow"]["p5"], -950.0);  // -v: the 5th percentile is the 95th of v
  // Classes by label; the label no vessel has is no group.
  EXPECT_EQ(s["by_class"]["arteriole"]["vessels"], 501);
  EXPECT_EQ(s["by_class"]["capillary"]["vessels"], 500);
  EXPECT_FALSE(s["by_class"].contains("artery"));
  EXPECT_EQ(s["by_generation"].size(), 3u);
  EXPECT_EQ(s["by_generation"][1]["generation"], 1);
  EXPECT_EQ(s["by_generation"][1]["vessels"], 334);  // v = 1, 4, ..., 1000
  // Diameter bins a factor sqrt(2) wide cover 5 um .. 1 mm, each vessel in one.
  std::size_t binned = 0;
  for (const nlohmann::json& bin : s["by_diameter"]) binned += bin["vessels"].get<std::size_t>();
  EXPECT_EQ(binned, n);
  EXPECT_DOUBLE_EQ(s["by_diameter"][0]["diameter_to"].get<double>() / s["by_diameter"][0]["diameter_from"].get<double>(),
                   std::sqrt(2.0));
}

TEST(GroupStatistics, TheSameForAnyThreads) {
  const Case c = chain(5000);
  const std::string one = group_statistics(c.net, c.table, 1).dump();
  for (const int threads : {2, 3}) EXPECT_EQ(group_statistics(c.net, c.table, threads).dump(), one) << threads;
}

// summary.json's per-boundary member, written entry by entry (solver/run_report.hpp:
// SummaryArray), has the bytes of the same member held as a JSON tree, wherever its name sorts
// among the run's facts: first, between two, last; empty; with strings that need escaping.
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include <unistd.h>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "solver/run_report.hpp"

using namespace hemotree;

namespace {

std::string read_file(const std::filesystem::path& file) {
  std::ifstream in(file, std::ios::binary);
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

nlohmann::json entry(std::size_t i) {
  nlohmann::json e = {{"node", static_cast<long long>(100 + i)}, {"type", i % 2 ? "R" : "flow"}, {"flow", -1.25e-13 * double(i)}};
  if (i % 3 == 0) e["hematocrit"] = 0.45;
  return e;
}

std::string written(const nlohmann::json& run, const SummaryArray& array) {
  const auto file = std::filesystem::temp_directory_path() / ("summary-writer-" + std::to_string(::getpid()) + ".json");
  write_summary(file, run, VesselTable(), CycleSummary(), array);
  std::string bytes = read_file(file);
  std::filesystem::remove(file);
  return bytes;
}

}  // namespace

TEST(SummaryWriter, AStreamedMemberHasTheBytesOfTheTree) {
  for (const std::string name : {"aaa", "boundaries", "mmm", "zzz"})
    for (const std::size_t size : {std::size_t{0}, std::size_t{1}, std::size_t{7}}) {
      const nlohmann::json run = {{"tool", "hemosolve"},
                                  {"cycles", 3},
                                  {"error", "a \"quoted\"\nline"},
                                  {"elements_of_degree", {{"2", 350}, {"7", 85}}},
                                  {"statistics", {{"capillary", {{"count", 5}}}}}};
      nlohmann::json whole = run;
      whole[name] = nlohmann::json::array();
      for (std::size_t i = 0; i < size; ++i) whole[name].push_back(entry(i));
      EXPECT_EQ(written(run, {name, size, entry}), written(whole, {})) << name << ", " << size << " entries";
    }
}

TEST(SummaryWriter, AMemberGivenTwiceIsRefused) {
  const nlohmann::json run = {{"tool", "hemosolve"}, {"boundaries", nlohmann::json::array()}};
  EXPECT_THROW(written(run, {"boundaries", 1, entry}), std::logic_error);
}

// vstats: descriptive statistics of a vascular network, as a table or as JSON.
#include <iostream>
#include <optional>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "core/errors.hpp"
#include "cli/setting_words.hpp"
#include "cli/tool.hpp"
#include "formats/network_io.hpp"
#include "partition/partition.hpp"
#include "stats/network_stats.hpp"

int main(int argc, char** argv) {
  CLI::App app{"Counts, totals and per-generation diameter quartiles of a vascular network.",
               "vstats"};
  std::string input = "-";
  bool json = false;
  int ranks = 0;
  app.add_option("NET", input, "network file (vnet, JSON or HDF5); - reads standard input")
      ->capture_default_str();
  app.add_flag("--json", json, "print the statistics as JSON instead of a table");
  app.add_option("--partition", ranks,
                 "also split the vessels over this many ranks as a distributed run would (whole subtrees on "
                 "trees, METIS on other graphs; a cost of one a vessel) and say the balance and the cut nodes");
  app.set_version_flag("--version", HEMOTREE_VERSION);

  return hemotree::run_tool(app, argc, argv, hemotree::vstats_words(), [&] {
    const hemotree::Network net = hemotree::read_network(input);
    const hemotree::NetworkStats stats = hemotree::compute_stats(net);
    std::optional<hemotree::Partition> partition;
    if (app.count("--partition"))
      partition = hemotree::partition_network(net, std::vector<double>(net.vessel_count(), 1.0), ranks);
    if (json) {
      nlohmann::json out = hemotree::to_json(stats);
      if (partition)
        out["partition"] = {{"ranks", partition->ranks},
                            {"method", hemotree::to_string(partition->method)},
                            {"vessels", partition->vessels},
                            {"cost", partition->cost},
                            {"imbalance", partition->imbalance()},
                            {"cut_nodes", partition->cut_nodes}};
      if (partition->method == hemotree::Partition::Method::subtrees) {
        out["partition"]["top_vessels"] = partition->top.size();
        out["partition"]["top_rank"] = partition->top_spread ? nlohmann::json(nullptr) : nlohmann::json(partition->top_rank);
      }
      std::cout << out.dump(2) << '\n';
    } else {
      hemotree::print_table(stats, std::cout, hemotree::vstats_words());
      if (partition) std::cout << "\npartition (a cost of one a vessel): " << hemotree::describe(*partition) << '\n';
    }
    // A full disk or a closed pipe must not pass for success.
    std::cout.flush();
    if (!std::cout) throw hemotree::IoError("cannot write to standard output");
    return 0;
  });
}

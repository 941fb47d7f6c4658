// vstats: descriptive statistics of a vascular network, as a table or as JSON.
#include <iostream>
#include <string>

#include <CLI/CLI.hpp>

#include "core/errors.hpp"
#include "cli/setting_words.hpp"
#include "cli/tool.hpp"
#include "formats/network_io.hpp"
#include "stats/network_stats.hpp"

int main(int argc, char** argv) {
  CLI::App app{"Counts, totals and per-generation diameter quartiles of a vascular network.",
               "vstats"};
  std::string input = "-";
  bool json = false;
  app.add_option("NET", input, "network file (vnet JSON); - reads standard input")
      ->capture_default_str();
  app.add_flag("--json", json, "print the statistics as JSON instead of a table");
  app.set_version_flag("--version", HEMOTREE_VERSION);

  return hemotree::run_tool(app, argc, argv, [&] {
    const hemotree::Network net = hemotree::read_network(input);
    const hemotree::NetworkStats stats = hemotree::compute_stats(net);
    if (json)
      std::cout << hemotree::to_json(stats).dump(2) << '\n';
    else
      hemotree::print_table(stats, std::cout, hemotree::vstats_words());
    // A full disk or a closed pipe must not pass for success.
    std::cout.flush();
    if (!std::cout) throw hemotree::IoError("cannot write to standard output");
    return 0;
  });
}

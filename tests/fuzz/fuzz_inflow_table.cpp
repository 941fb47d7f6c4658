// The measured inflow table (vprune --inflow-table FILE) on hostile bytes. The table's
// reader lives in vprune's main, so the harness runs vprune in process (vprune.cpp with
// -Dmain=tool_main) on the 13-vessel fixture tree: exit status 0, 1 or 2, and a network it
// writes must read back with an inflow fit to run (finite samples, a positive mean flow).
#include <cmath>
#include <cstdint>
#include <string>

#include "formats/network_io.hpp"
#include "tool_runner.hpp"

using namespace hemotree;
using hemotree::fuzz::finding;

namespace {
fuzz::ToolRunner* runner = nullptr;
}

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  fuzz::keep_report_channel();
  runner = new fuzz::ToolRunner();
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  runner->reset();
  fuzz::write_file(runner->folder() / "table.csv", std::string_view(reinterpret_cast<const char*>(data), size));
  const int status = runner->run("vprune", {"tree.json", "--budget", "5", "--inflow-table", "table.csv",
                                            "--period", "1s", "-o", "pruned.json"});
  if (status != 0) return 0;
  auto net_result = fuzz::outcome("read_network", [&] { return read_network("pruned.json"); });
  auto& net = net_result.first;
  auto& refusal = net_result.second;
  if (!net) finding("vprune wrote a network (from an inflow table) that its reader refuses: " + refusal.message);
  if (!net->inlet) finding("vprune wrote a network without its inlet");
  const Waveform& w = net->inlet->waveform;
  for (std::size_t k = 0; k < w.time.size(); ++k)
    if (!std::isfinite(w.time[k]) || !std::isfinite(w.value[k]))
      finding("an accepted inflow table holds a non-finite sample at row " + std::to_string(k));
  const double mean = w.mean_value();
  if (!(std::isfinite(mean) && mean > 0))
    finding("an accepted inflow table has a mean flow of " + std::to_string(mean) + " m^3/s");
  return 0;
}

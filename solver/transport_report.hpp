// What a pulsatile run reports of the red cells and tracers it carried (docs/transport.md):
// their columns per vessel (summary.json, vessels.csv, VTK) and their blocks in summary.json.
#pragma once

#include <string>

#include <nlohmann/json.hpp>

#include "formats/network.hpp"
#include "solver/flow_transport.hpp"
#include "solver/vessel_table.hpp"

namespace hemotree {

// Adds to results each tracer's landmarks (NAME_arrival_time, _peak_time, _peak,
// _mean_transit_time, and the vessels' generation) and, where the red cells are reported,
// discharge_hematocrit, tube_hematocrit, discharge_hematocrit_min/_max; to run_info the
// "tracers" and "red_cell_transport" blocks. cells: the last cycle's red cells (empty before
// one, viewed by the table: they must outlive it); change: their largest change from the
// cycle before (NaN before two); step: the transport's step [s].
void report_transport(const Network& net, const FlowTransport::Outcome& transport, const RedCellCycle& cells, double change,
                      double step, VesselTable& results, nlohmann::json& run_info);

// One line on the red cells: their range over the vessels, the widest swing within the
// cycle and the largest change of a cycle mean.
std::string red_cell_line(const Network& net, const RedCellCycle& cells, double change);

}  // namespace hemotree

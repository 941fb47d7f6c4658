// One row per vessel, for spreadsheets and data frames. Endpoints are written as node ids
// (the ids of the network file), not as positions in the node arrays.
#include "formats/exports.hpp"

namespace hemotree {

void write_csv(const Network& net, OutputStream& out) {
  out << "id,from,to,length_m,diameter_m,wall_thickness_m,youngs_modulus_pa,generation,class\n";
  for (std::size_t v = 0; v < net.vessel_count(); ++v) {
    out << net.id[v] << ',' << net.node_id[net.from[v]] << ',' << net.node_id[net.to[v]] << ','
        << net.length[v] << ',' << net.diameter[v] << ',' << net.wall_thickness[v] << ','
        << net.youngs_modulus[v] << ',' << net.generation[v] << ','
        << to_string(net.vessel_class[v]) << '\n';
  }
}

}  // namespace hemotree

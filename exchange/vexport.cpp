// vexport: writes a vnet network in another program's format: Secomb's network.dat (NetFlow)
// or openBF's YAML model with its inlet table (docs/import.md); or in the other form of vnet
// (json, h5: the same network, provenance included) or one of the tools' exports (vtk,
// graphml, dot, csv).
#include <filesystem>
#include <string>

#include <CLI/CLI.hpp>

#include "core/errors.hpp"
#include "cli/tool.hpp"
#include "core/units.hpp"
#include "exchange/openbf.hpp"
#include "exchange/secomb.hpp"
#include "formats/exports.hpp"
#include "formats/network_io.hpp"

using namespace hemotree;

namespace {

// openBF names its inflow file in the YAML: it goes beside it, OUT's stem + "_inlet.dat".
std::string inlet_path_for(const std::string& output) {
  const std::filesystem::path out(output);
  return (out.parent_path() / (out.stem().string() + "_inlet.dat")).string();
}

// What network.dat leaves out of a network that has it, said once each.
void note_what_secomb_drops(const Network& net) {
  note("note: network.dat holds segments, node coordinates and steady boundary pressures and flows; not written: "
       "wall thickness and Young's modulus (NetFlow's flow is steady)" +
       std::string(net.beta.empty() ? "" : ", the tube laws' beta"));
  if (net.blood)
    note("note: blood not written: NetFlow takes it from its RheolParams.dat (here plasma viscosity " +
         format_quantity(net.blood->plasma_viscosity, "cP") + ", mean cell volume " +
         format_rounded(net.blood->mean_cell_volume * 1e18) + " fl)");
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"Writes a vnet network in another program's format.", "vexport"};
  std::string format, input = "-", output = "-";
  app.add_option("FORMAT", format,
                 "secomb (NetFlow's network.dat), openbf (YAML, with an inlet table beside it), json or h5 "
                 "(vnet's two forms: the network as it is), vtk, graphml, dot or csv")
      ->required();
  app.add_option("NET", input, "network file (vnet, JSON or HDF5); - reads standard input")->capture_default_str();
  app.add_option("-o,--output", output,
                 "output file; - for standard output (secomb only: openbf writes its inlet table beside the YAML, "
                 "as OUT's name + _inlet.dat)")
      ->capture_default_str();
  app.set_version_flag("--version", std::string("vexport ") + HEMOTREE_VERSION);

  return run_tool(app, argc, argv, [&] {
    const auto export_format = parse_export_format(format);
    if (format != "secomb" && format != "openbf" && !export_format)
      throw InputError("FORMAT must be secomb, openbf, json, h5, vtk, graphml, dot or csv (got '" + format + "')");
    if (format == "openbf" && (output.empty() || output == "-"))
      throw InputError("vexport openbf needs -o FILE.yaml: its inlet table is written beside it");

    const Network net = read_network(input);
    OutputStream out(output);
    // The writers name the vessel or node the format cannot hold; the network's file goes first.
    try {
      if (export_format) {
        write_network_as(net, *export_format, out);
      } else if (format == "secomb") {
        write_secomb(net, out);
        note_what_secomb_drops(net);
      } else {
        const std::string inlet = inlet_path_for(output);
        write_openbf(net, out, inlet);
        note("note: inlet table written to " + inlet);
      }
    } catch (const InputError& e) {
      throw InputError((input == "-" ? std::string("standard input") : input) + ": " + e.what());
    }
    out.commit();
    return 0;
  });
}

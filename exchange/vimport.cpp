// vimport: reads a network another program wrote (Secomb's network.dat, openBF's YAML, VTK
// centerlines, GraphML, networkx JSON) and writes it as vnet JSON, saying on stderr what it
// assumed wherever the file is silent (docs/import.md).
#include <optional>
#include <string>

#include <CLI/CLI.hpp>

#include "core/errors.hpp"
#include "cli/setting_words.hpp"
#include "cli/tool.hpp"
#include "core/units.hpp"
#include "exchange/graph_formats.hpp"
#include "exchange/openbf.hpp"
#include "exchange/secomb.hpp"
#include "exchange/vtk_centerline.hpp"
#include "formats/field_ranges.hpp"
#include "formats/largest_part.hpp"
#include "formats/exports.hpp"
#include "formats/network_io.hpp"

using namespace hemotree;

namespace {

Interval accepted(const FieldRange& r) { return Interval{r.min, r.max}; }

// What --help says of a range: "in [0.01, 100] s".
std::string in(const FieldRange& r, std::string_view unit) { return "in " + describe(accepted(r), unit); }

// Mean cell volumes are given in femtolitres ("55" or "55fl"), the unit every haematology
// table uses; units.hpp has no volumes.
double parse_mean_cell_volume(std::string text) {
  if (text.size() > 2 && text.compare(text.size() - 2, 2, "fl") == 0) text.resize(text.size() - 2);
  const FieldRange& r = ranges::mean_cell_volume;
  return 1e-18 * parse_number(text, "--mean-cell-volume [fl]", Interval{r.min * 1e18, r.max * 1e18});
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"Reads a network in another program's format and writes it as vnet JSON.", "vimport"};
  std::string format, input, output = "-";
  bool keep_largest_part = false, as_documented = false;
  std::string youngs_text, wall_ratio_text, mcv_text, plasma_text, hematocrit_text, radius_array, unit_text;
  app.add_option("FORMAT", format,
                 "secomb (network.dat), openbf (YAML), vtk (centerlines, .vtp or legacy .vtk), graphml, "
                 "networkx (node-link JSON)")
      ->required();
  app.add_option("FILE", input, "the file to read")->required();
  app.add_option("-o,--output", output, "output file (vnet: HDF5 if named *.h5, else JSON), - for standard output")->capture_default_str();
  app.add_option("--youngs-modulus", youngs_text,
                 "Young's modulus of every vessel whose file gives none, " + in(ranges::youngs_modulus, "Pa") +
                     " (default: hemotree's E(D) table)")
      ->group("Walls");
  app.add_option("--wall-ratio", wall_ratio_text,
                 "wall thickness h = ratio x D for every vessel whose file gives none, in (0, 1] "
                 "(default: hemotree's per-class wall law)")
      ->group("Walls");
  app.add_option("--mean-cell-volume", mcv_text,
                 "blood's mean red-cell volume [fl], in [15, 200] (human 92, rat 55)")
      ->group("Blood");
  app.add_option("--plasma-viscosity", plasma_text, "plasma viscosity, " + in(ranges::viscosity, "mPa s"))
      ->group("Blood");
  app.add_option("--hematocrit", hematocrit_text, "blood's discharge hematocrit, " + in(ranges::hematocrit, ""))
      ->group("Blood");
  app.add_option("--radius-array", radius_array,
                 "vtk: the point array of radii (default " + CenterlineOptions{}.radius_array + ")");
  app.add_option("--unit", unit_text,
                 "vtk, graphml, networkx: the length unit of the file's coordinates, lengths and radii (m, cm, mm, "
                 "um; VMTK models are usually in mm; default m, or a graph's own \"unit\" attribute)");
  app.add_flag("--keep-largest-part", keep_largest_part,
               "keep only the connected part with the most vessels, dropping the fragments (ids unchanged)");
  app.add_flag("--as-documented", as_documented,
               "openbf: read the model as openBF's documentation describes it (default: as openBF's code computes "
               "it; the notes name each difference)");
  app.set_version_flag("--version", std::string("vimport ") + HEMOTREE_VERSION);

  return run_tool(app, argc, argv, vimport_words(), [&] {
    // ---- every flag, before any work ---------------------------------------------------
    if (format != "secomb" && format != "openbf" && format != "vtk" && format != "graphml" && format != "networkx")
      throw InputError("FORMAT must be secomb, openbf, vtk, graphml or networkx (got '" + format + "')");
    if (!radius_array.empty() && format != "vtk") throw InputError("--radius-array applies to FORMAT vtk only");
    if (as_documented && format != "openbf") throw InputError("--as-documented applies to FORMAT openbf only");
    if (!unit_text.empty() && (format == "secomb" || format == "openbf"))
      throw InputError("--unit applies to FORMAT vtk, graphml and networkx only (" + format + " files have their units)");

    ImportOptions options;
    options.note = [](const std::string& line) { note("note: " + in_words(line, vimport_words())); };
    nlohmann::json parameters = nlohmann::json::object();
    if (as_documented) parameters["as_documented"] = true;
    if (!youngs_text.empty()) {
      options.youngs_modulus = parse_quantity(youngs_text, Dimension::pressure, "--youngs-modulus",
                                              accepted(ranges::youngs_modulus), "Pa");
      parameters["youngs_modulus"] = *options.youngs_modulus;
    }
    if (!wall_ratio_text.empty()) {
      options.wall_ratio = parse_number(wall_ratio_text, "--wall-ratio", Interval{0, 1, true, false});
      parameters["wall_ratio"] = *options.wall_ratio;
    }
    std::optional<double> mean_cell_volume, plasma_viscosity, hematocrit;
    if (!mcv_text.empty()) mean_cell_volume = parse_mean_cell_volume(mcv_text);
    if (!plasma_text.empty())
      plasma_viscosity = parse_quantity(plasma_text, Dimension::viscosity, "--plasma-viscosity",
                                        accepted(ranges::viscosity), "mPa s");
    if (!hematocrit_text.empty())
      hematocrit = parse_number(hematocrit_text, "--hematocrit", accepted(ranges::hematocrit));
    CenterlineOptions centerline;
    GraphOptions graph;
    if (!unit_text.empty()) {
      double metres = 0;
      try {
        metres = parse_quantity("1" + unit_text, Dimension::length, "--unit");
      } catch (const InputError&) {
        metres = 0;
      }
      if (!(metres >= 1e-9 && metres <= 1))
        throw InputError("--unit must be a length unit: m, cm, mm, um or nm (got '" + unit_text + "')");
      centerline.length_unit = metres;
      graph.length_unit = metres;
      parameters["unit"] = unit_text;
    }
    if (!radius_array.empty()) {
      centerline.radius_array = radius_array;
      parameters["radius_array"] = radius_array;
    }

    // ---- read ----------------------------------------------------------------------------
    Network net = format == "secomb"   ? read_secomb(input, options)
                  : format == "openbf" ? read_openbf(input, options,
                                                     as_documented ? OpenbfReading::documented : OpenbfReading::code)
                  : format == "vtk"    ? read_vtk_centerline(input, options, centerline)
                  : format == "graphml" ? read_graphml(input, options, graph)
                                        : read_node_link_json(input, options, graph);
    if (keep_largest_part) {
      DroppedParts dropped;
      net = largest_connected_part(net, &dropped);
      options.note(describe(net, dropped));
      parameters["keep_largest_part"] = true;
    }

    // ---- blood: the file's, with what the flags set --------------------------------------
    if (mean_cell_volume || plasma_viscosity || hematocrit) {
      const bool from_file = net.blood.has_value();
      Blood blood = net.blood.value_or(Blood{});
      std::string set;
      const auto add = [&](const std::string& what) { set += (set.empty() ? "" : ", ") + what; };
      if (mean_cell_volume) {
        blood.mean_cell_volume = *mean_cell_volume;
        parameters["mean_cell_volume"] = *mean_cell_volume;
        add("mean cell volume " + format_rounded(*mean_cell_volume * 1e18) + " fl");
      }
      if (plasma_viscosity) {
        blood.plasma_viscosity = *plasma_viscosity;
        parameters["plasma_viscosity"] = *plasma_viscosity;
        add("plasma viscosity " + format_quantity(*plasma_viscosity, "mPa s"));
      }
      if (hematocrit) {
        blood.hematocrit = *hematocrit;
        parameters["hematocrit"] = *hematocrit;
        add("hematocrit " + format_rounded(*hematocrit));
      }
      net.blood = blood;
      options.note("blood: " + set + " from the flags; the rest " +
                   (from_file ? "from the file" : "hemotree's defaults (vnet format, \"blood\")"));
    } else if (!net.blood) {
      options.note(std::string("the file gives no blood properties: none written, so later tools take hemotree's "
                               "defaults (human blood, plasma viscosity 1 mPa s, hematocrit 0.45)") +
                   (format == "secomb"
                        ? "; NetFlow's rat blood is --mean-cell-volume 55 --plasma-viscosity 1.0466cP"
                        : ""));
    }

    // ---- provenance and output -------------------------------------------------------------
    stamp_import_provenance(net, format, input, parameters);

    OutputStream out(output);
    write_network_as(net, output_format("", output), out);
    out.commit();
    return 0;
  });
}

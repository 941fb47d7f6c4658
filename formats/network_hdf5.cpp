// The vnet network as HDF5 (docs/network-format.md, "HDF5"): the same content as the JSON
// form, columns per node and per vessel instead of an object each, the small members
// (provenance, blood, inlet, boundaries at nodes, members passed through) as their JSON text.
// A reader checks everything the JSON reader checks, naming the dataset and the row.
#include <algorithm>
#include <span>
#include <stdexcept>
#include <cmath>
#include <string>
#include <vector>

#include "core/errors.hpp"
#include "formats/field_ranges.hpp"
#include "formats/hdf5_file.hpp"
#include "formats/network_io.hpp"
#include "formats/network_slice.hpp"
#include "formats/node_index.hpp"
#include "formats/topology.hpp"

namespace hemotree {

namespace {

const hdf5::EnumNames class_names{{"artery", "small_artery", "arteriole", "capillary"}};
const hdf5::EnumNames outlet_type_names{{"RCR", "R", "reflection"}};
constexpr double unset = std::numeric_limits<double>::quiet_NaN();

std::uint8_t outlet_type_value(BoundaryType type) {
  switch (type) {
    case BoundaryType::rcr: return 0;
    case BoundaryType::resistance: return 1;
    default: return 2;
  }
}

// One column of the outlets, gathered from their structs.
template <class Field>
std::vector<double> outlet_column(const std::vector<Outlet>& outlets, Field field) {
  std::vector<double> column(outlets.size());
  for (std::size_t k = 0; k < outlets.size(); ++k) column[k] = outlets[k].*field;
  return column;
}

nlohmann::json parsed_json(const hdf5::File& file, const std::string& path) {
  const std::string text = file.read_text(path);
  try {
    return nlohmann::json::parse(text);
  } catch (const nlohmann::json::exception& e) {
    file.fail(path, std::string("not JSON text (") + e.what() + ")");
  }
}

class Hdf5Reader {
 public:
  explicit Hdf5Reader(const hdf5::File& file) : file_(file) {}

  // The whole network.
  Network read() {
    read_head();
    read_nodes();
    read_vessels();
    read_outlets();
    read_small_members();
    return std::move(net_);
  }

  // Its topology: every node's and vessel's id, every vessel's ends, the small members.
  Network read_topology() {
    read_head();
    read_node_ids();
    read_vessel_ends();
    read_small_members();
    return std::move(net_);
  }

  // The vessels at rows `vessels` of the topology's, and the nodes they touch.
  NetworkSlice read_slice(const Network& topology, std::span<const std::int32_t> vessels) {
    topology_ = &topology;
    slice_.vessel_row.assign(vessels.begin(), vessels.end());
    for (std::size_t k = 0; k < vessels.size(); ++k)
      if (vessels[k] < 0 || static_cast<std::size_t>(vessels[k]) >= topology.vessel_count() ||
          (k > 0 && vessels[k] <= vessels[k - 1]))
        throw std::invalid_argument("read_network_slice: the rows must increase within the vessels");
    std::vector<std::int32_t>& nodes = slice_.node_row;
    for (const std::int32_t v : vessels) {
      nodes.push_back(topology.from[static_cast<std::size_t>(v)]);
      nodes.push_back(topology.to[static_cast<std::size_t>(v)]);
    }
    std::sort(nodes.begin(), nodes.end());
    nodes.erase(std::unique(nodes.begin(), nodes.end()), nodes.end());
    read_head();
    read_nodes();
    read_vessels();
    read_outlets();
    read_small_members();
    slice_.net = std::move(net_);
    return std::move(slice_);
  }

 private:
  bool sliced() const { return topology_ != nullptr; }
  const std::vector<std::int32_t>* vessel_pick() const { return sliced() ? &slice_.vessel_row : nullptr; }
  const std::vector<std::int32_t>* node_pick() const { return sliced() ? &slice_.node_row : nullptr; }
  // The file's row of the k-th vessel or node read.
  std::size_t vessel_row(std::size_t k) const { return sliced() ? static_cast<std::size_t>(slice_.vessel_row[k]) : k; }
  std::size_t node_row(std::size_t k) const { return sliced() ? static_cast<std::size_t>(slice_.node_row[k]) : k; }
  template <class T>
  static std::vector<T> picked(const std::vector<T>& whole, const std::vector<std::int32_t>& pick) {
    std::vector<T> out(pick.size());
    for (std::size_t k = 0; k < pick.size(); ++k) out[k] = whole[static_cast<std::size_t>(pick[k])];
    return out;
  }

  template <class Convert>
  auto converted(const std::string& path, Convert convert) -> decltype(convert(nlohmann::json())) {
    const nlohmann::json value = parsed_json(file_, path);
    try {
      return convert(value);
    } catch (const InputError& e) {
      file_.fail(path, e.what());
    }
  }

  void read_head() {
    check_identity();
    if (file_.exists("/provenance")) {
      net_.provenance = parsed_json(file_, "/provenance");
      if (!net_.provenance.is_object()) file_.fail("/provenance", "must be a JSON object");
    }
    if (file_.exists("/extra")) {
      net_.extra = parsed_json(file_, "/extra");
      if (!net_.extra.is_object()) file_.fail("/extra", "must be a JSON object");
      // The format's own members have places of their own; here they would be written twice.
      for (const char* own : {"format", "version", "provenance", "blood", "inlet", "boundaries", "nodes", "vessels"})
        if (net_.extra.contains(own))
          file_.fail("/extra", std::string("holds \"") + own + "\", a member of the format's own");
    }
  }

  void read_small_members() {
    if (file_.exists("/blood")) net_.blood = converted("/blood", blood_from_json);
    if (file_.exists("/inlet")) {
      net_.inlet = converted("/inlet", inlet_from_json);
      const Network& whole = sliced() ? *topology_ : net_;
      if (whole.index_of(net_.inlet->vessel) < 0) file_.fail("/inlet", "unknown vessel " + std::to_string(net_.inlet->vessel));
      // A slice holds the inlet where it holds its vessel.
      if (sliced() && net_.index_of(net_.inlet->vessel) < 0) net_.inlet.reset();
    }
    read_boundaries();
  }

  void check_identity() {
    const auto format = file_.text_attribute("format");
    if (!format || *format != "vnet")
      file_.fail("/", "the attribute \"format\" must be \"vnet\": this is not a hemotree network file");
    const auto version = file_.integer_attribute("version");
    if (!version)
      file_.fail("/", "missing the attribute \"version\" (this build reads versions 1 to " +
                          std::to_string(vnet_version) + ")");
    if (*version < 1 || *version > vnet_version)
      file_.fail("/", "network format version " + std::to_string(*version) +
                          " is not supported (this build reads up to " + std::to_string(vnet_version) + ")");
  }

  std::string vessel_name(std::size_t v) const { return "vessel " + std::to_string(net_.id[v]); }

  // A real column (of rows whole rows; a slice's rows of it): every value in range, or
  // (optional columns) NaN where not given.
  std::vector<double> reals(const std::string& path, std::size_t rows, const FieldRange& range,
                            bool may_be_unset, bool of_vessels) const {
    const std::vector<std::int32_t>* pick = of_vessels ? vessel_pick() : node_pick();
    std::vector<double> values = pick ? file_.read_reals(path, rows, *pick) : file_.read_reals(path, rows);
    const std::string field = path.substr(path.rfind('/') + 1);
    for (std::size_t i = 0; i < values.size(); ++i) {
      if (range.contains(values[i]) || (may_be_unset && std::isnan(values[i]))) continue;
      const std::string row = of_vessels ? vessel_name(i) : "node " + std::to_string(net_.node_id[i]);
      file_.fail(path, "row " + std::to_string(of_vessels ? vessel_row(i) : node_row(i)) + " (" + row +
                           "): " + out_of_range(field, range, values[i]));
    }
    return values;
  }

  void check_unique(const std::vector<std::int64_t>& ids, const std::string& path, const char* what) const {
    if (const auto twice = NodeIndex(ids).repeat())
      file_.fail(path, std::string(what) + " id " + std::to_string(twice->id) + " appears twice: rows " +
                           std::to_string(twice->first) + " and " + std::to_string(twice->second));
  }

  void read_node_ids() {
    net_.node_id = file_.read_integers("/nodes/id");
    if (net_.node_count() > max_elements) file_.fail("/nodes/id", "more than " + std::to_string(max_elements) + " nodes");
    check_unique(net_.node_id, "/nodes/id", "node");
  }

  // A slice's nodes' ids are the topology's (whose reading checked them all).
  void read_nodes() {
    if (sliced()) {
      net_.node_id = picked(topology_->node_id, slice_.node_row);
    } else {
      read_node_ids();
    }
    const std::size_t n = sliced() ? topology_->node_count() : net_.node_count();
    const int coordinates = file_.exists("/nodes/x") + file_.exists("/nodes/y") + file_.exists("/nodes/z");
    if (coordinates != 0 && coordinates != 3) file_.fail("/nodes", "has all of x, y, z or none");
    if (coordinates == 3) {
      net_.x = reals("/nodes/x", n, ranges::coordinate, false, false);
      net_.y = reals("/nodes/y", n, ranges::coordinate, false, false);
      net_.z = reals("/nodes/z", n, ranges::coordinate, false, false);
    }
  }

  std::vector<std::int32_t> node_indices(const std::string& path, std::size_t rows) const {
    const std::vector<std::int64_t> given = file_.read_integers(path, rows);
    std::vector<std::int32_t> indices(given.size());
    const auto nodes = static_cast<std::int64_t>(net_.node_count());
    for (std::size_t v = 0; v < given.size(); ++v) {
      if (given[v] < 0 || given[v] >= nodes)
        file_.fail(path, "row " + std::to_string(v) + " (" + vessel_name(v) + "): a row of /nodes, in [0, " +
                             std::to_string(nodes - 1) + "] (got " + std::to_string(given[v]) + ")");
      indices[v] = static_cast<std::int32_t>(given[v]);
    }
    return indices;
  }

  void read_vessel_ends() {
    net_.id = file_.read_integers("/vessels/id");
    const std::size_t n = net_.vessel_count();
    if (n > max_elements) file_.fail("/vessels/id", "more than " + std::to_string(max_elements) + " vessels");
    check_unique(net_.id, "/vessels/id", "vessel");
    net_.from = node_indices("/vessels/from_node", n);
    net_.to = node_indices("/vessels/to_node", n);
    for (std::size_t v = 0; v < n; ++v)
      if (net_.from[v] == net_.to[v])
        file_.fail("/vessels/to_node", "row " + std::to_string(v) + " (" + vessel_name(v) +
                                           "): begins and ends at the same node");
  }

  // A slice's vessels' ids and ends are the topology's, its ends numbered among its nodes.
  void slice_vessel_ends() {
    net_.id = picked(topology_->id, slice_.vessel_row);
    auto local = [&](std::int32_t node) {
      const auto& rows = slice_.node_row;
      return static_cast<std::int32_t>(std::lower_bound(rows.begin(), rows.end(), node) - rows.begin());
    };
    net_.from.resize(net_.id.size());
    net_.to.resize(net_.id.size());
    for (std::size_t k = 0; k < net_.id.size(); ++k) {
      const auto v = static_cast<std::size_t>(slice_.vessel_row[k]);
      net_.from[k] = local(topology_->from[v]);
      net_.to[k] = local(topology_->to[v]);
    }
  }

  void read_vessels() {
    if (sliced()) {
      slice_vessel_ends();
    } else {
      read_vessel_ends();
    }
    const std::size_t n = net_.vessel_count(), whole = sliced() ? topology_->vessel_count() : n;
    net_.length = reals("/vessels/length", whole, ranges::length, false, true);
    net_.diameter = reals("/vessels/diameter", whole, ranges::diameter, false, true);
    auto optional_reals = [&](const std::string& path, const FieldRange& range) {
      return file_.exists(path) ? reals(path, whole, range, true, true) : std::vector<double>(n, unset);
    };
    net_.wall_thickness = optional_reals("/vessels/wall_thickness", ranges::wall_thickness);
    net_.youngs_modulus = optional_reals("/vessels/youngs_modulus", ranges::youngs_modulus);
    if (file_.exists("/vessels/distal_diameter"))
      net_.distal_diameter = reals("/vessels/distal_diameter", whole, ranges::diameter, true, true);
    const bool beta = file_.exists("/vessels/beta");
    if (beta != file_.exists("/vessels/reference_pressure"))
      file_.fail("/vessels", "give \"beta\" and \"reference_pressure\" together");
    if (beta) {
      net_.beta = reals("/vessels/beta", whole, ranges::beta, true, true);
      net_.reference_pressure = reals("/vessels/reference_pressure", whole, ranges::pressure, true, true);
      for (std::size_t v = 0; v < n; ++v)
        if (std::isnan(net_.beta[v]) != std::isnan(net_.reference_pressure[v]))
          file_.fail("/vessels/beta", "row " + std::to_string(vessel_row(v)) + " (" + vessel_name(v) +
                                          "): give \"beta\" and \"reference_pressure\" together");
    }
    net_.vessel_class.resize(n);
    for (std::size_t v = 0; v < n; ++v) net_.vessel_class[v] = classify(net_.diameter[v]);
    if (file_.exists("/vessels/class")) {
      const std::vector<std::uint8_t> given = sliced() ? file_.read_enum("/vessels/class", class_names, whole, *vessel_pick())
                                                       : file_.read_enum("/vessels/class", class_names, whole);
      for (std::size_t v = 0; v < n; ++v)
        if (given[v] != static_cast<std::uint8_t>(net_.vessel_class[v]))
          file_.fail("/vessels/class",
                     "row " + std::to_string(vessel_row(v)) + " (" + vessel_name(v) + "): class \"" +
                         class_names.names[given[v]] + "\" does not match its diameter (" +
                         std::string(to_string(net_.vessel_class[v])) + ")");
    }
    if (file_.exists("/vessels/generation")) {
      const std::vector<std::int64_t> given = sliced() ? file_.read_integers("/vessels/generation", whole, *vessel_pick())
                                                       : file_.read_integers("/vessels/generation", whole);
      net_.generation.resize(n);
      for (std::size_t v = 0; v < n; ++v) {
        if (given[v] < 0 || given[v] >= static_cast<std::int64_t>(whole))
          file_.fail("/vessels/generation", "row " + std::to_string(vessel_row(v)) + " (" + vessel_name(v) +
                                                "): \"generation\" must lie in [0, " + std::to_string(whole - 1) +
                                                "] (the vessel count - 1) (got " + std::to_string(given[v]) + ")");
        net_.generation[v] = static_cast<std::int32_t>(given[v]);
      }
    } else if (sliced()) {
      net_.generation = picked(generations_from_inlets(*topology_), slice_.vessel_row);
    } else if (n > 0) {
      net_.generation = generations_from_inlets(net_);
    }
  }

  // The columns hold every model's parameters; a row's type says which of them it uses, and
  // only those are checked and kept (the others are 0, as a JSON outlet read without them).
  // A slice keeps the outlets of its vessels (their rows of the columns).
  void read_outlets() {
    if (!file_.exists("/outlets/vessel")) return;
    const std::size_t n = file_.rows("/outlets/vessel");
    const std::vector<std::int64_t> vessel = file_.read_integers("/outlets/vessel", n);
    const auto vessels = static_cast<std::int64_t>(sliced() ? topology_->vessel_count() : net_.vessel_count());
    for (std::size_t k = 0; k < n; ++k) {
      const std::string row = "row " + std::to_string(k);
      if (vessel[k] < 0 || vessel[k] >= vessels)
        file_.fail("/outlets/vessel", row + ": a row of /vessels, in [0, " + std::to_string(vessels - 1) +
                                          "] (got " + std::to_string(vessel[k]) + ")");
      if (k > 0 && vessel[k] <= vessel[k - 1])
        file_.fail("/outlets/vessel", row + ": outlets are sorted by vessel, one a vessel at most (got " +
                                          std::to_string(vessel[k]) + " after " + std::to_string(vessel[k - 1]) + ")");
    }
    // The outlets read (all, or a slice's), each with its vessel among those read.
    std::vector<std::int32_t> rows, at_vessel;
    if (sliced()) {
      const std::vector<std::int32_t>& mine = slice_.vessel_row;
      for (std::size_t k = 0, j = 0; k < n; ++k) {
        while (j < mine.size() && mine[j] < vessel[k]) ++j;
        if (j < mine.size() && mine[j] == vessel[k]) {
          rows.push_back(static_cast<std::int32_t>(k));
          at_vessel.push_back(static_cast<std::int32_t>(j));
        }
      }
    }
    const std::vector<std::int32_t>* pick = sliced() ? &rows : nullptr;
    auto reals_of = [&](const char* name) {
      const std::string path = std::string("/outlets/") + name;
      return pick ? file_.read_reals(path, n, *pick) : file_.read_reals(path, n);
    };
    const std::vector<std::uint8_t> type = pick ? file_.read_enum("/outlets/type", outlet_type_names, n, *pick)
                                                : file_.read_enum("/outlets/type", outlet_type_names, n);
    const std::vector<double> r1 = reals_of("R1"), c = reals_of("C"), r2 = reals_of("R2"), r = reals_of("R"),
                              p_out = reals_of("p_out"), coefficient = reals_of("coefficient");
    net_.outlets.resize(pick ? pick->size() : n);
    for (std::size_t i = 0; i < net_.outlets.size(); ++i) {
      const std::size_t k = pick ? static_cast<std::size_t>(rows[i]) : i;
      const std::size_t v = pick ? static_cast<std::size_t>(at_vessel[i]) : static_cast<std::size_t>(vessel[k]);
      const std::string at = "row " + std::to_string(k) + " (" + vessel_name(v) + ")";
      auto checked = [&](const char* name, const std::vector<double>& column, const FieldRange& range) {
        if (!range.contains(column[i]))
          file_.fail(std::string("/outlets/") + name, at + ": " + out_of_range(name, range, column[i]));
        return column[i];
      };
      Outlet& o = net_.outlets[i];
      o.vessel = static_cast<std::int32_t>(v);
      if (type[i] == outlet_type_value(BoundaryType::rcr)) {
        o.type = BoundaryType::rcr;
        o.r1 = checked("R1", r1, ranges::rcr_part);
        o.c = checked("C", c, ranges::compliance);
        o.r2 = checked("R2", r2, ranges::rcr_part);
        o.p_out = checked("p_out", p_out, ranges::pressure);
        if (!(o.r1 + o.r2 >= ranges::resistance.min))
          file_.fail("/outlets/R1", at + ": RCR needs R1 + R2 >= " + format_number(ranges::resistance.min) +
                                        " Pa s/m^3 (got " + format_number(o.r1 + o.r2) + ")");
      } else if (type[i] == outlet_type_value(BoundaryType::resistance)) {
        o.type = BoundaryType::resistance;
        o.r = checked("R", r, ranges::resistance);
        o.p_out = checked("p_out", p_out, ranges::pressure);
      } else if (type[i] == outlet_type_value(BoundaryType::reflection)) {
        o.type = BoundaryType::reflection;
        o.reflection = checked("coefficient", coefficient, ranges::reflection);
      } else {
        file_.fail("/outlets/type", at + ": an outlet type of none of the names RCR, R, reflection");
      }
    }
  }

  // As in JSON: the list of boundaries at nodes, nodes named by id (a slice's: those at its
  // nodes).
  void read_boundaries() {
    if (!file_.exists("/boundaries")) return;
    const nlohmann::json list = parsed_json(file_, "/boundaries");
    if (!list.is_array()) file_.fail("/boundaries", "must be a JSON list");
    const NodeIndex index(net_.node_id);
    const NodeIndex whole(sliced() ? topology_->node_id : std::vector<std::int64_t>{});
    for (std::size_t k = 0; k < list.size(); ++k) {
      const std::string where = "boundaries[" + std::to_string(k) + "]";
      std::int64_t node_id = 0;
      NodeBoundary b;
      try {
        b = boundary_from_json(list[k], where, node_id);
      } catch (const InputError& e) {
        file_.fail("/boundaries", e.what());
      }
      if (sliced() && whole.find(node_id, topology_->node_count()) < 0)
        file_.fail("/boundaries", where + ": unknown node " + std::to_string(node_id));
      b.node = index.find(node_id, net_.node_count());
      if (b.node < 0 && sliced()) continue;  // another slice's
      if (b.node < 0) file_.fail("/boundaries", where + ": unknown node " + std::to_string(node_id));
      net_.boundaries.push_back(std::move(b));
    }
    try {
      sort_boundaries_by_node(net_);
    } catch (const InputError& e) {
      file_.fail("/boundaries", e.what());
    }
  }

  static constexpr std::size_t max_elements = std::numeric_limits<std::int32_t>::max();
  const hdf5::File& file_;
  Network net_;
  const Network* topology_ = nullptr;  // a slice's
  NetworkSlice slice_;
};

}  // namespace

void write_network_hdf5(const Network& net, OutputStream& out) {
  // Every member by name (as Network::shrink_to_fit): a member added to Network stops this
  // from compiling until it is written here.
  const auto& [node_id, x, y, z, id, from, to, length, diameter, wall_thickness, youngs_modulus, generation,
               vessel_class, beta, reference_pressure, distal_diameter, blood, inlet, outlets, boundaries,
               provenance, extra] = net;
  hdf5::write_through(out, [&](hdf5::File& file) {
    file.write_attribute("format", "vnet");
    file.write_attribute("version", std::int64_t{format_version_needed(net)});
    file.write_text("/provenance", provenance.dump());
    if (!extra.empty()) file.write_text("/extra", extra.dump());
    if (blood) file.write_text("/blood", to_json(*blood).dump());
    if (inlet) file.write_text("/inlet", to_json(*inlet).dump());
    if (!boundaries.empty()) {
      nlohmann::json list = nlohmann::json::array();
      for (const NodeBoundary& b : boundaries) list.push_back(to_json(b, node_id[static_cast<std::size_t>(b.node)]));
      file.write_text("/boundaries", list.dump());
    }
    file.write("/nodes/id", std::span<const std::int64_t>(node_id));
    if (net.has_coordinates()) {
      file.write("/nodes/x", std::span<const double>(x));
      file.write("/nodes/y", std::span<const double>(y));
      file.write("/nodes/z", std::span<const double>(z));
    }
    file.write("/vessels/id", std::span<const std::int64_t>(id));
    file.write("/vessels/from_node", std::span<const std::int32_t>(from));
    file.write("/vessels/to_node", std::span<const std::int32_t>(to));
    file.write("/vessels/length", std::span<const double>(length));
    file.write("/vessels/diameter", std::span<const double>(diameter));
    if (!distal_diameter.empty()) file.write("/vessels/distal_diameter", std::span<const double>(distal_diameter));
    file.write("/vessels/wall_thickness", std::span<const double>(wall_thickness));
    file.write("/vessels/youngs_modulus", std::span<const double>(youngs_modulus));
    file.write("/vessels/generation", std::span<const std::int32_t>(generation));
    static_assert(sizeof(VesselClass) == 1);
    file.write_enum("/vessels/class",
                    std::span(reinterpret_cast<const std::uint8_t*>(vessel_class.data()), vessel_class.size()),
                    class_names);
    if (!beta.empty()) {
      file.write("/vessels/beta", std::span<const double>(beta));
      file.write("/vessels/reference_pressure", std::span<const double>(reference_pressure));
    }
    if (!outlets.empty()) {
      std::vector<std::int32_t> vessel(outlets.size());
      std::vector<std::uint8_t> type(outlets.size());
      for (std::size_t k = 0; k < outlets.size(); ++k) {
        vessel[k] = outlets[k].vessel;
        type[k] = outlet_type_value(outlets[k].type);
      }
      file.write("/outlets/vessel", std::span<const std::int32_t>(vessel));
      file.write_enum("/outlets/type", type, outlet_type_names);
      file.write("/outlets/R1", outlet_column(outlets, &Outlet::r1));
      file.write("/outlets/C", outlet_column(outlets, &Outlet::c));
      file.write("/outlets/R2", outlet_column(outlets, &Outlet::r2));
      file.write("/outlets/R", outlet_column(outlets, &Outlet::r));
      file.write("/outlets/p_out", outlet_column(outlets, &Outlet::p_out));
      file.write("/outlets/coefficient", outlet_column(outlets, &Outlet::reflection));
    }
  });
}

Network read_network_hdf5(const hdf5::File& file) { return Hdf5Reader(file).read(); }

Network read_network_topology_hdf5(const hdf5::File& file) { return Hdf5Reader(file).read_topology(); }

NetworkSlice read_network_slice_hdf5(const hdf5::File& file, const Network& topology,
                                     std::span<const std::int32_t> vessels) {
  return Hdf5Reader(file).read_slice(topology, vessels);
}

}  // namespace hemotree

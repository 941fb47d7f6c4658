// GraphML and node-link JSON: each file is read into a RawGraph (nodes and edges with the
// attributes hemotree knows, each already checked for its type), and one builder turns that
// into a network, so that both formats map attributes, ids and units the same way.
#include "exchange/graph_formats.hpp"

#include <algorithm>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <map>
#include <optional>
#include <set>
#include <sstream>
#include <string>
#include <unordered_map>
#include <vector>

#include <boost/property_tree/ptree.hpp>
#include <boost/property_tree/xml_parser.hpp>
#include <nlohmann/json.hpp>

#include "core/errors.hpp"
#include "core/setting_error.hpp"
#include "formats/field_ranges.hpp"
#include "formats/topology.hpp"

namespace hemotree {

namespace {

const double unset = std::nan("");

// An attribute's value as the file gives it: GraphML text, or a JSON scalar.
struct Value {
  std::string text;  // for messages
  std::optional<double> number;
  std::optional<std::int64_t> integer;
  bool is_string = false;
};

std::optional<std::int64_t> parse_integer(std::string_view text) {
  std::int64_t v = 0;
  const auto r = std::from_chars(text.data(), text.data() + text.size(), v);
  if (r.ec != std::errc() || r.ptr != text.data() + text.size() || text.empty()) return std::nullopt;
  return v;
}

std::optional<double> parse_real(std::string_view text) {
  double v = 0;
  const auto r = std::from_chars(text.data(), text.data() + text.size(), v);
  if (r.ec != std::errc() || r.ptr != text.data() + text.size() || text.empty() || !std::isfinite(v))
    return std::nullopt;
  return v;
}

std::string trimmed(const std::string& s) {
  const auto b = s.find_first_not_of(" \t\r\n");
  if (b == std::string::npos) return "";
  return s.substr(b, s.find_last_not_of(" \t\r\n") - b + 1);
}

Value from_text(const std::string& raw) {
  Value v;
  v.text = trimmed(raw);
  v.integer = parse_integer(v.text);
  v.number = v.integer ? std::optional<double>(double(*v.integer)) : parse_real(v.text);
  v.is_string = !v.number;
  return v;
}

Value from_json(const nlohmann::json& j) {
  Value v;
  if (j.is_string()) {
    v.text = j.get<std::string>();
    v.is_string = true;
  } else {
    v.text = j.dump();
    if (j.is_number_integer()) {
      v.integer = j.get<std::int64_t>();
      v.number = double(*v.integer);
    } else if (j.is_number()) {
      const double d = j.get<double>();
      if (std::isfinite(d)) v.number = d;
      if (d == std::floor(d) && std::fabs(d) < 9e15) v.integer = static_cast<std::int64_t>(d);
    }
  }
  return v;
}

struct RawNode {
  std::string where;  // "node 'n3'" or "nodes[3]"
  std::string key;    // the file's node id, as text
  std::optional<std::int64_t> key_integer;
  std::optional<std::int64_t> id;  // an "id" attribute (hemotree's GraphML export)
  double x = unset, y = unset, z = unset;
};

struct RawEdge {
  std::string where;
  std::string source, target;
  std::optional<std::string> key;  // GraphML's edge id, node-link's multigraph key
  std::optional<std::int64_t> id;
  double length = unset, diameter = unset, radius = unset, distal_diameter = unset, distal_radius = unset;
  double wall_thickness = unset, youngs_modulus = unset;
  std::optional<std::int64_t> generation;
  std::optional<std::string> vessel_class;
};

struct RawGraph {
  std::string path, format;  // "graphml" or "node-link"
  bool directed = true;
  std::optional<std::string> unit;
  std::vector<RawNode> nodes;
  std::vector<RawEdge> edges;
  std::set<std::string> ignored_node, ignored_edge, ignored_graph;  // attribute names

  [[noreturn]] void fail(const std::string& where, const std::string& what) const {
    throw_input_error(path + ": " + where + ": " + what);
  }
  double number(const std::string& where, const std::string& name, const Value& v) const {
    if (!v.number) fail(where, "\"" + name + "\" must be a number (got \"" + v.text + "\")");
    return *v.number;
  }
  std::int64_t integer(const std::string& where, const std::string& name, const Value& v) const {
    if (!v.integer) fail(where, "\"" + name + "\" must be an integer (got \"" + v.text + "\")");
    return *v.integer;
  }

  void set_node(RawNode& n, const std::string& name, const Value& v) {
    if (name == "x") n.x = number(n.where, name, v);
    else if (name == "y") n.y = number(n.where, name, v);
    else if (name == "z") n.z = number(n.where, name, v);
    else if (name == "id") n.id = integer(n.where, name, v);
    else ignored_node.insert(name);
  }
  void set_edge(RawEdge& e, const std::string& name, const Value& v) {
    if (name == "length") e.length = number(e.where, name, v);
    else if (name == "diameter") e.diameter = number(e.where, name, v);
    else if (name == "radius") e.radius = number(e.where, name, v);
    else if (name == "distal_diameter") e.distal_diameter = number(e.where, name, v);
    else if (name == "distal_radius") e.distal_radius = number(e.where, name, v);
    else if (name == "wall_thickness") e.wall_thickness = number(e.where, name, v);
    else if (name == "youngs_modulus") e.youngs_modulus = number(e.where, name, v);
    else if (name == "id") e.id = integer(e.where, name, v);
    else if (name == "generation") e.generation = integer(e.where, name, v);
    else if (name == "class") e.vessel_class = v.text;
    else ignored_edge.insert(name);
  }
  void set_graph(const std::string& name, const Value& v) {
    if (name == "unit" || name == "units" || name == "length_unit") unit = v.text;
    else ignored_graph.insert(name);
  }
};

// --- GraphML ---------------------------------------------------------------------------------

using boost::property_tree::ptree;

// Attribute names hold dots ("attr.name"): the path separator is '/'.
std::string attribute(const ptree& element, const std::string& name) {
  return element.get<std::string>(ptree::path_type("<xmlattr>/" + name, '/'), "");
}
bool has_attribute(const ptree& element, const std::string& name) {
  return element.get_child_optional(ptree::path_type("<xmlattr>/" + name, '/')).has_value();
}

struct Key {
  std::string domain;  // node, edge, graph, all
  std::string name;    // attr.name, else the key's id
  std::optional<std::string> default_value;
};

RawGraph parse_graphml(const std::string& path) {
  RawGraph g;
  g.path = path;
  g.format = "graphml";
  ptree tree;
  const std::string text = read_whole_file(path);
  refuse_deep_xml(path, text);  // before the recursive parser: deep nesting would overflow its stack
  try {
    std::istringstream in(text);
    boost::property_tree::read_xml(in, tree, boost::property_tree::xml_parser::no_comments);
  } catch (const boost::property_tree::xml_parser_error& e) {
    throw InputError(path + ":" + std::to_string(e.line()) + ": not well-formed XML: " + e.message());
  }
  const auto root = tree.get_child_optional("graphml");
  if (!root) g.fail("graphml", "missing: the root element must be <graphml>");

  std::map<std::string, Key> keys;
  for (const auto& [tag, k] : *root) {
    if (tag != "key") continue;
    const std::string id = attribute(k, "id");
    if (id.empty()) g.fail("graphml/key", "a <key> without an id");
    Key key{attribute(k, "for"), attribute(k, "attr.name"), std::nullopt};
    if (key.domain.empty()) key.domain = "all";
    if (key.name.empty()) key.name = id;
    if (const auto d = k.get_child_optional("default")) key.default_value = d->data();
    if (!keys.emplace(id, key).second) g.fail("graphml/key[id=" + id + "]", "declared twice");
  }
  if (root->count("graph") != 1)
    g.fail("graphml", std::to_string(root->count("graph")) + " <graph> elements: hemotree reads one network");
  const ptree& graph = root->get_child("graph");
  g.directed = attribute(graph, "edgedefault") != "undirected";

  // Applies an element's <data>, then the declared defaults of the keys it lacks.
  auto read_data = [&](const ptree& element, const std::string& where, const std::string& domain, auto&& set) {
    std::set<std::string> seen;
    for (const auto& [tag, d] : element) {
      if (tag != "data") continue;
      const std::string id = attribute(d, "key");
      const auto k = keys.find(id);
      if (k == keys.end()) g.fail(where, "<data key=\"" + id + "\"> names no declared <key>");
      if (k->second.domain != domain && k->second.domain != "all")
        g.fail(where, "<data key=\"" + id + "\"> is declared for " + k->second.domain + ", not " + domain);
      set(k->second.name, from_text(d.data()));
      seen.insert(id);
    }
    for (const auto& [id, k] : keys)
      if (k.default_value && (k.domain == domain || k.domain == "all") && !seen.count(id))
        set(k.name, from_text(*k.default_value));
  };

  read_data(graph, "graphml/graph", "graph", [&](const std::string& name, const Value& v) { g.set_graph(name, v); });
  for (const auto& [tag, element] : graph) {
    if (tag == "node") {
      RawNode n;
      n.key = attribute(element, "id");
      n.where = "node '" + n.key + "'";
      if (n.key.empty()) g.fail("graphml/graph/node[" + std::to_string(g.nodes.size()) + "]", "a <node> without an id");
      n.key_integer = parse_integer(n.key);
      if (element.count("graph")) g.fail(n.where, "holds a nested <graph>: hemotree reads flat networks");
      if (element.count("port")) g.fail(n.where, "has <port>s: hemotree's vessels join nodes, not ports");
      read_data(element, n.where, "node", [&](const std::string& name, const Value& v) { g.set_node(n, name, v); });
      g.nodes.push_back(std::move(n));
    } else if (tag == "edge") {
      RawEdge e;
      e.source = attribute(element, "source");
      e.target = attribute(element, "target");
      if (has_attribute(element, "id")) e.key = attribute(element, "id");
      e.where = "edge " + (e.key ? "'" + *e.key + "'" : std::to_string(g.edges.size())) + " (" + e.source + " -> " +
                e.target + ")";
      if (e.source.empty() || e.target.empty()) g.fail(e.where, "needs both a source and a target");
      if (has_attribute(element, "sourceport") || has_attribute(element, "targetport"))
        g.fail(e.where, "joins ports: hemotree's vessels join nodes, not ports");
      if (element.count("graph")) g.fail(e.where, "holds a nested <graph>: hemotree reads flat networks");
      read_data(element, e.where, "edge", [&](const std::string& name, const Value& v) { g.set_edge(e, name, v); });
      g.edges.push_back(std::move(e));
    } else if (tag == "hyperedge") {
      g.fail("graphml/graph/hyperedge", "hyperedges join more than two nodes; a vessel joins two");
    } else if (tag != "data" && tag != "desc" && tag != "<xmlattr>") {
      g.fail("graphml/graph/" + tag, "an element GraphML's graph does not hold");
    }
  }
  return g;
}

// --- node-link JSON ----------------------------------------------------------------------------

// Where nlohmann's parser stops on text: a second pass that builds nothing, since only a
// syntax error carries its byte in the exception, a number overflow does not.
std::size_t json_error_line(const std::string& text) {
  struct Locator final : nlohmann::json_sax<nlohmann::json> {
    std::size_t byte = 0;
    bool null() override { return true; }
    bool boolean(bool) override { return true; }
    bool number_integer(number_integer_t) override { return true; }
    bool number_unsigned(number_unsigned_t) override { return true; }
    bool number_float(number_float_t, const string_t&) override { return true; }
    bool string(string_t&) override { return true; }
    bool binary(binary_t&) override { return true; }
    bool start_object(std::size_t) override { return true; }
    bool key(string_t&) override { return true; }
    bool end_object() override { return true; }
    bool start_array(std::size_t) override { return true; }
    bool end_array() override { return true; }
    bool parse_error(std::size_t position, const std::string&, const nlohmann::json::exception&) override {
      byte = position;  // just past the offending token
      return false;
    }
  } locator;
  nlohmann::json::sax_parse(text, &locator);
  const std::size_t end = std::min(locator.byte, text.size());
  const auto last = text.begin() + static_cast<long>(end > 0 ? end - 1 : 0);
  return 1 + static_cast<std::size_t>(std::count(text.begin(), last, '\n'));
}

// nlohmann's message without its "[json.exception.parse_error.101] parse error at line 3,
// column 5:" prefix (the caller names the line), and what a double holds after an overflow.
std::string json_error_text(const nlohmann::json::exception& e) {
  std::string what = e.what();
  if (const auto at = what.find("syntax error"); at != std::string::npos) return "not JSON: " + what.substr(at);
  if (const auto at = what.find("] "); at != std::string::npos) what = what.substr(at + 2);
  if (e.id == 406) what += ": numbers must lie within +-1.8e308 (a double)";
  return what;
}

RawGraph parse_node_link(const std::string& path) {
  RawGraph g;
  g.path = path;
  g.format = "node-link";
  const std::string text = read_whole_file(path);
  nlohmann::json doc;
  try {
    doc = nlohmann::json::parse(text);
  } catch (const nlohmann::json::exception& e) {
    // Any exception of parsing is the file's: a syntax error (parse_error) and a number
    // beyond a double ("1e400", out_of_range 406) alike.
    throw InputError(path + ":" + std::to_string(json_error_line(text)) + ": " + json_error_text(e));
  }
  if (!doc.is_object()) g.fail("the document", "must be a JSON object (networkx.node_link_data)");
  if (doc.contains("links") && doc.contains("edges"))
    g.fail("the document", "has both \"links\" and \"edges\": networkx writes one of them");
  const std::string edges_name = doc.contains("edges") ? "edges" : "links";
  if (!doc.contains("nodes") || !doc["nodes"].is_array()) g.fail("the document", "needs a \"nodes\" array");
  if (!doc.contains(edges_name) || !doc[edges_name].is_array())
    g.fail("the document", "needs a \"links\" (networkx < 3.4) or \"edges\" array");
  if (doc.contains("directed")) {
    if (!doc["directed"].is_boolean()) g.fail("\"directed\"", "must be true or false");
    g.directed = doc["directed"].get<bool>();
  }
  if (doc.contains("graph")) {
    if (!doc["graph"].is_object()) g.fail("\"graph\"", "must be an object of graph attributes");
    for (const auto& [name, value] : doc["graph"].items()) {
      if (value.is_structured()) g.ignored_graph.insert(name);
      else g.set_graph(name, from_json(value));
    }
  }
  for (const auto& [name, value] : doc.items())
    if (name != "nodes" && name != edges_name && name != "directed" && name != "multigraph" && name != "graph")
      g.ignored_graph.insert(name);

  // A node id as text: JSON strings as they are, numbers as JSON writes them.
  auto key_text = [](const nlohmann::json& j) { return j.is_string() ? j.get<std::string>() : j.dump(); };
  const auto& nodes = doc["nodes"];
  for (std::size_t i = 0; i < nodes.size(); ++i) {
    RawNode n;
    n.where = "nodes[" + std::to_string(i) + "]";
    if (!nodes[i].is_object() || !nodes[i].contains("id")) g.fail(n.where, "must be an object with an \"id\"");
    const auto& id = nodes[i]["id"];
    if (id.is_structured()) g.fail(n.where, "\"id\" must be a number or a string");
    n.key = key_text(id);
    n.key_integer = id.is_number_integer() ? std::optional(id.get<std::int64_t>()) : parse_integer(n.key);
    for (const auto& [name, value] : nodes[i].items()) {
      if (name == "id") continue;
      if (value.is_structured()) g.ignored_node.insert(name);
      else g.set_node(n, name, from_json(value));
    }
    g.nodes.push_back(std::move(n));
  }
  const auto& links = doc[edges_name];
  for (std::size_t i = 0; i < links.size(); ++i) {
    RawEdge e;
    e.where = edges_name + "[" + std::to_string(i) + "]";
    const auto& l = links[i];
    if (!l.is_object() || !l.contains("source") || !l.contains("target"))
      g.fail(e.where, "must be an object with a \"source\" and a \"target\"");
    e.source = key_text(l["source"]);
    e.target = key_text(l["target"]);
    e.where += " (" + e.source + " -> " + e.target + ")";
    for (const auto& [name, value] : l.items()) {
      if (name == "source" || name == "target") continue;
      if (name == "key") e.key = key_text(value);
      else if (value.is_structured()) g.ignored_edge.insert(name);
      else g.set_edge(e, name, from_json(value));
    }
    g.edges.push_back(std::move(e));
  }
  return g;
}

// --- the network --------------------------------------------------------------------------------

std::optional<double> metres_per(const std::string& unit) {
  static const std::map<std::string, double> units = {
      {"m", 1},       {"metre", 1},     {"meter", 1},       {"metres", 1},          {"meters", 1},
      {"cm", 1e-2},   {"mm", 1e-3},     {"um", 1e-6},       {"\xC2\xB5m", 1e-6},    {"micron", 1e-6},
      {"microns", 1e-6}, {"micrometre", 1e-6}, {"micrometer", 1e-6}, {"nm", 1e-9}};
  const auto u = units.find(unit);
  return u == units.end() ? std::nullopt : std::optional(u->second);
}

std::string plural(std::size_t n, const char* one, const char* many) {
  return std::to_string(n) + " " + (n == 1 ? one : many);
}

std::string some(const std::set<std::string>& names) {
  std::string s;
  for (const auto& n : names) s += (s.empty() ? "" : ", ") + n;
  return s;
}

// Ids for a list of things from their keys: the keys themselves when all are distinct
// integers, else their numbers when all are one prefix and distinct integers ("n0", "n1",
// as Boost and yEd write them), else nothing (the caller numbers them in order).
std::optional<std::vector<std::int64_t>> ids_from_keys(const std::vector<std::string>& keys, std::string& how) {
  if (keys.empty()) return std::vector<std::int64_t>{};
  auto distinct = [](std::vector<std::int64_t> ids) {
    std::sort(ids.begin(), ids.end());
    return std::adjacent_find(ids.begin(), ids.end()) == ids.end();
  };
  std::vector<std::int64_t> ids;
  for (const auto& k : keys) {
    const auto v = parse_integer(k);
    if (!v) break;
    ids.push_back(*v);
  }
  if (ids.size() == keys.size() && distinct(ids)) {
    how = "the file's ids";
    return ids;
  }
  const std::string& first = keys.front();
  const std::size_t digits = first.find_last_not_of("0123456789") + 1;
  if (digits == 0 || digits == first.size()) return std::nullopt;
  const std::string prefix = first.substr(0, digits);
  ids.clear();
  for (const auto& k : keys) {
    if (k.size() <= prefix.size() || k.compare(0, prefix.size(), prefix) != 0) return std::nullopt;
    const auto v = parse_integer(std::string_view(k).substr(prefix.size()));
    if (!v || k[prefix.size()] == '-' || k[prefix.size()] == '+') return std::nullopt;
    ids.push_back(*v);
  }
  if (!distinct(ids)) return std::nullopt;
  how = "the file's ids without their prefix '" + prefix + "'";
  return ids;
}

void check_range(const RawGraph& g, const std::string& where, const char* field, const FieldRange& range,
                 double value, const std::string& hint) {
  if (!range.contains(value)) g.fail(where, out_of_range(field, range, value) + hint);
}

// The length unit: the caller's, the file's, or metres; `hint` closes a message about a length
// out of range.
struct LengthUnit {
  double u;                     // metres per unit of the file
  std::string unit_from, hint;  // where it came from, for the note
};

LengthUnit length_unit(const RawGraph& g, const GraphOptions& graph_options) {
  double u = 1;
  std::string unit_from = "metres, the default";
  if (g.unit) {
    const auto f = metres_per(*g.unit);
    if (!f) g.fail("graph attribute \"unit\"", "\"" + *g.unit + "\" is not a length unit (m, cm, mm, um, nm)");
    if (graph_options.length_unit && *graph_options.length_unit != *f)
      g.fail("graph attribute \"unit\"", "\"" + *g.unit + "\" contradicts the unit given (" +
                                             format_number(*graph_options.length_unit) + " m)");
    u = *f;
    unit_from = *g.unit + ", the file's \"unit\"";
  } else if (graph_options.length_unit) {
    u = *graph_options.length_unit;
    unit_from = format_number(u) + " m, as given";
  }
  if (!(u > 0) || !std::isfinite(u)) g.fail("the length unit", "must be a positive number of metres");
  const std::string hint = u == 1 ? " (lengths read in metres: a \"unit\" graph attribute or vimport " + placeholder("unit") +
                                        " sets another)"
                                  : " (lengths read in units of " + format_number(u) + " m)";
  return {u, unit_from, hint};
}

// Node ids: "id" attributes when every node has one, else from the file's node ids (their
// numbers), else the file's order, its ids kept in provenance "node_names"; `node_how` says which.
std::vector<std::int64_t> node_ids_of(const RawGraph& g, Network& net, std::string& node_how) {
  std::vector<std::string> node_keys;
  for (const auto& n : g.nodes) node_keys.push_back(n.key);
  std::vector<std::int64_t> node_ids;
  const bool id_attributes =
      !g.nodes.empty() && std::all_of(g.nodes.begin(), g.nodes.end(), [](const RawNode& n) { return n.id.has_value(); });
  if (id_attributes) {
    std::map<std::int64_t, std::size_t> seen;
    for (std::size_t i = 0; i < g.nodes.size(); ++i) {
      if (const auto [it, fresh] = seen.emplace(*g.nodes[i].id, i); !fresh)
        g.fail(g.nodes[i].where, "its \"id\" " + std::to_string(*g.nodes[i].id) + " is also that of " +
                                     g.nodes[it->second].where);
      node_ids.push_back(*g.nodes[i].id);
    }
    node_how = "their \"id\" attributes";
  } else if (auto ids = ids_from_keys(node_keys, node_how)) {
    node_ids = std::move(*ids);
  } else {
    for (std::size_t i = 0; i < g.nodes.size(); ++i) node_ids.push_back(static_cast<std::int64_t>(i));
    node_how = "numbered in the file's order (its ids are kept in provenance \"node_names\")";
    net.provenance["node_names"] = node_keys;
  }
  return node_ids;
}

// Vessel ids: "id" attributes when every edge has one, else the file's edge ids or keys,
// else the order of the file.
void set_vessel_ids(const RawGraph& g, Network& net, std::string& vessel_how) {
  const bool edge_id_attributes =
      !g.edges.empty() && std::all_of(g.edges.begin(), g.edges.end(), [](const RawEdge& e) { return e.id.has_value(); });
  std::vector<std::string> edge_keys;
  for (const auto& e : g.edges)
    if (e.key) edge_keys.push_back(*e.key);
  if (edge_id_attributes) {
    std::map<std::int64_t, std::size_t> seen;
    for (std::size_t k = 0; k < g.edges.size(); ++k) {
      if (const auto [it, fresh] = seen.emplace(*g.edges[k].id, k); !fresh)
        g.fail(g.edges[k].where, "its \"id\" " + std::to_string(*g.edges[k].id) + " is also that of " +
                                     g.edges[it->second].where);
      net.id[k] = *g.edges[k].id;
    }
    vessel_how = "their \"id\" attributes";
  } else if (auto ids = edge_keys.size() == g.edges.size() ? ids_from_keys(edge_keys, vessel_how) : std::nullopt) {
    net.id = std::move(*ids);
  } else {
    for (std::size_t k = 0; k < g.edges.size(); ++k) net.id[k] = static_cast<std::int64_t>(k);
    vessel_how = "numbered in the file's order";
  }
}

Network build_network(RawGraph& g, const ImportOptions& options, const GraphOptions& graph_options) {
  const std::string edge_word = g.format == "graphml" ? "edge" : "link";
  const LengthUnit unit = length_unit(g, graph_options);
  const double u = unit.u;
  const std::string& unit_from = unit.unit_from;
  const std::string& hint = unit.hint;

  Network net;
  std::unordered_map<std::string, std::int32_t> index;
  for (std::size_t i = 0; i < g.nodes.size(); ++i)
    if (!index.emplace(g.nodes[i].key, static_cast<std::int32_t>(i)).second)
      g.fail(g.nodes[i].where, "its id \"" + g.nodes[i].key + "\" appears twice");
  std::string node_how;
  const std::vector<std::int64_t> node_ids = node_ids_of(g, net, node_how);

  // Coordinates: all nodes or none (z = 0 for a plane layout).
  const auto placed = [](const RawNode& n) { return !std::isnan(n.x) && !std::isnan(n.y); };
  const std::size_t with_xy = static_cast<std::size_t>(std::count_if(g.nodes.begin(), g.nodes.end(), placed));
  const bool coordinates = with_xy == g.nodes.size() && with_xy > 0;
  std::size_t flat = 0;
  for (std::size_t i = 0; i < g.nodes.size(); ++i) {
    RawNode& n = g.nodes[i];
    if (coordinates) {
      if (std::isnan(n.z)) {
        n.z = 0;
        ++flat;
      }
      check_range(g, n.where, "x", ranges::coordinate, u * n.x, hint);
      check_range(g, n.where, "y", ranges::coordinate, u * n.y, hint);
      check_range(g, n.where, "z", ranges::coordinate, u * n.z, hint);
      net.add_node(node_ids[i], u * n.x, u * n.y, u * n.z);
    } else {
      net.add_node(node_ids[i]);
    }
  }

  // Vessels. An edgeless graph would make a network of none, which no tool can use.
  if (g.edges.empty())
    g.fail("the graph", "has no " + edge_word + " (" + plural(g.nodes.size(), "node", "nodes") +
                            "): a network needs one vessel at least");
  std::size_t straight = 0, from_radius = 0, tapered = 0;
  const bool generations = !g.edges.empty() && std::all_of(g.edges.begin(), g.edges.end(),
                                                           [](const RawEdge& e) { return e.generation.has_value(); });
  for (const RawEdge& e : g.edges)
    if (!generations && e.generation)
      g.fail(e.where, "has a \"generation\" but others have none; either every edge has one or none does");
  std::vector<double> distal(g.edges.size(), unset);
  for (std::size_t k = 0; k < g.edges.size(); ++k) {
    const RawEdge& e = g.edges[k];
    const auto a = index.find(e.source), b = index.find(e.target);
    if (a == index.end()) g.fail(e.where, "its source \"" + e.source + "\" is no node of the graph");
    if (b == index.end()) g.fail(e.where, "its target \"" + e.target + "\" is no node of the graph");
    if (a->second == b->second) g.fail(e.where, "begins and ends at the same node; a vessel joins two");
    const RawNode &p = g.nodes[static_cast<std::size_t>(a->second)], &q = g.nodes[static_cast<std::size_t>(b->second)];
    double length = e.length;
    if (std::isnan(length)) {
      if (!placed(p) || !placed(q))
        g.fail(e.where, "no \"length\", and its nodes have no coordinates (x, y) to measure it");
      length = std::hypot(q.x - p.x, q.y - p.y, (std::isnan(q.z) ? 0 : q.z) - (std::isnan(p.z) ? 0 : p.z));
      ++straight;
    }
    double diameter = e.diameter;
    if (std::isnan(diameter)) {
      if (std::isnan(e.radius)) g.fail(e.where, "has neither \"diameter\" nor \"radius\"");
      diameter = 2 * e.radius;
      ++from_radius;
    } else if (!std::isnan(e.radius) && std::fabs(2 * e.radius - diameter) > 1e-9 * diameter) {
      g.fail(e.where, "\"diameter\" " + format_number(diameter) + " is not twice \"radius\" " + format_number(e.radius));
    }
    double distal_diameter = std::isnan(e.distal_diameter) ? 2 * e.distal_radius : e.distal_diameter;
    check_range(g, e.where, "length", ranges::length, u * length, hint);
    check_range(g, e.where, "diameter", ranges::diameter, u * diameter, hint);
    if (!std::isnan(distal_diameter)) {
      check_range(g, e.where, "distal_diameter", ranges::diameter, u * distal_diameter, hint);
      distal[k] = u * distal_diameter;
      ++tapered;
    }
    const double wall = u * e.wall_thickness;
    if (!std::isnan(wall)) check_range(g, e.where, "wall_thickness", ranges::wall_thickness, wall, hint);
    if (!std::isnan(e.youngs_modulus))
      check_range(g, e.where, "youngs_modulus", ranges::youngs_modulus, e.youngs_modulus, "");
    if (e.vessel_class) {
      const auto c = parse_vessel_class(*e.vessel_class);
      if (!c) g.fail(e.where, "unknown \"class\" \"" + *e.vessel_class + "\"");
      if (*c != classify(u * diameter))
        g.fail(e.where, "\"class\" \"" + *e.vessel_class + "\" does not match its diameter (" +
                            std::string(to_string(classify(u * diameter))) + ")");
    }
    std::int32_t generation = 0;
    if (e.generation) {
      if (*e.generation < 0 || *e.generation >= static_cast<std::int64_t>(g.edges.size()))
        g.fail(e.where, "\"generation\" must lie in [0, " + std::to_string(g.edges.size() - 1) +
                            "] (the vessel count - 1) (got " + std::to_string(*e.generation) + ")");
      generation = static_cast<std::int32_t>(*e.generation);
    }
    net.add_vessel(0, a->second, b->second, u * length, u * diameter, wall, e.youngs_modulus, generation);
  }
  if (tapered > 0) net.distal_diameter = std::move(distal);

  std::string vessel_how;
  set_vessel_ids(g, net, vessel_how);

  if (!generations) net.generation = generations_from_inlets(net);  // breadth first from the inlets
  net.provenance["tool"] = "vimport";
  net.provenance["format"] = g.format;
  net.provenance["source"] = g.path;

  options.note("read " + plural(g.nodes.size(), "node", "nodes") + " and " +
               plural(g.edges.size(), (edge_word).c_str(), (edge_word + "s").c_str()) + "; lengths in " + unit_from +
               "; node ids: " + node_how + "; vessel ids: " + vessel_how);
  if (!g.directed) options.note("an undirected graph: each vessel runs from the edge's source to its target, as written");
  if (straight > 0)
    options.note("length of " + plural(straight, "vessel", "vessels") + " without one: the straight distance between its nodes");
  if (from_radius > 0) options.note("diameter of " + plural(from_radius, "vessel", "vessels") + ": twice its \"radius\"");
  if (!coordinates && with_xy > 0)
    options.note("node coordinates dropped: only " + std::to_string(with_xy) + " of " +
                 std::to_string(g.nodes.size()) + " nodes have x and y");
  if (flat > 0) options.note("z = 0 for " + plural(flat, "node", "nodes") + " without one (a plane layout)");
  if (!g.ignored_graph.empty()) options.note("graph attributes not imported: " + some(g.ignored_graph));
  if (!g.ignored_node.empty()) options.note("node attributes not imported: " + some(g.ignored_node));
  if (!g.ignored_edge.empty()) options.note("edge attributes not imported: " + some(g.ignored_edge));
  fill_missing_walls(net, options);
  return net;
}

}  // namespace

Network read_graphml(const std::string& path, const ImportOptions& options, const GraphOptions& graph) {
  RawGraph g = parse_graphml(path);
  return build_network(g, options, graph);
}

Network read_node_link_json(const std::string& path, const ImportOptions& options, const GraphOptions& graph) {
  RawGraph g = parse_node_link(path);
  return build_network(g, options, graph);
}

}  // namespace hemotree

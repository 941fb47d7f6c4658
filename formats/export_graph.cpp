// GraphML and Graphviz dot through Boost.Graph's own writers. The network becomes a
// compressed sparse row graph (nodes are vertices, vessels are directed edges from -> to)
// whose edges remember which vessel they are; the writers read the network's arrays in
// place through read-only dynamic properties. Edges come out grouped by source node, each
// with its vessel id.
#include <cstdint>
#include <cstdlib>
#include <ostream>
#include <streambuf>
#include <string>
#include <typeinfo>
#include <utility>
#include <vector>

#include <boost/graph/compressed_sparse_row_graph.hpp>
#include <boost/graph/graphml.hpp>
#include <boost/graph/graphviz.hpp>
#include <boost/make_shared.hpp>
#include <boost/property_map/dynamic_property_map.hpp>

#include "formats/exports.hpp"

namespace hemotree {

namespace {

// The CSR graph groups edges by source node, so an edge's position is not its vessel's:
// each edge carries its vessel index instead.
struct VesselRef {
  std::size_t vessel;
};
using Graph = boost::compressed_sparse_row_graph<boost::directedS, boost::no_property, VesselRef,
                                                 boost::no_property, std::uint32_t, std::uint32_t>;
using Vertex = boost::graph_traits<Graph>::vertex_descriptor;
using Edge = boost::graph_traits<Graph>::edge_descriptor;

Graph build_graph(const Network& net) {
  std::vector<std::pair<Vertex, Vertex>> ends(net.vessel_count());
  std::vector<VesselRef> refs(net.vessel_count());
  for (std::size_t v = 0; v < net.vessel_count(); ++v) {
    ends[v] = {static_cast<Vertex>(net.from[v]), static_cast<Vertex>(net.to[v])};
    refs[v] = {v};
  }
  return Graph(boost::edges_are_unsorted_multi_pass, ends.begin(), ends.end(), refs.begin(),
               static_cast<Vertex>(net.node_count()));
}

// Text of a property value. Boost's own adaptor goes through an ostringstream with its
// default 6 significant digits; reals here keep the network format's 9.
std::string property_text(double value) {
  char text[32];
  return std::string(text, format_real(text, value));
}
std::string property_text(long long value) { return std::to_string(value); }
std::string property_text(int value) { return std::to_string(value); }
std::string property_text(const std::string& value) { return value; }

// One network array seen as a read-only dynamic property keyed by vertex or edge. Value
// must be a type Boost's GraphML writer names (double, long long, int, std::string) so the
// declared attr.type is right.
template <class Key, class Value, class Read>
class NetworkProperty final : public boost::dynamic_property_map {
 public:
  explicit NetworkProperty(Read read) : read_(std::move(read)) {}
  boost::any get(const boost::any& key) override { return value_at(key); }
  std::string get_string(const boost::any& key) override { return property_text(value_at(key)); }
  void put(const boost::any&, const boost::any&) override {
    throw boost::dynamic_const_put_error();
  }
  const std::type_info& key() const override { return typeid(Key); }
  const std::type_info& value() const override { return typeid(Value); }

 private:
  Value value_at(const boost::any& key) const { return Value(read_(boost::any_cast<Key>(key))); }
  Read read_;
};

template <class Key, class Value, class Read>
void add_property(boost::dynamic_properties& dp, const std::string& name, Read read) {
  dp.insert(name, boost::make_shared<NetworkProperty<Key, Value, Read>>(std::move(read)));
}

// Vertex properties: node id (also the vertex name in dot) and coordinates when present.
// Edge properties: the vessel's fields, class by name.
boost::dynamic_properties network_properties(const Network& net, const Graph& g) {
  boost::dynamic_properties dp;
  add_property<Vertex, long long>(dp, "id", [&net](Vertex n) { return net.node_id[n]; });
  if (net.has_coordinates()) {
    add_property<Vertex, double>(dp, "x", [&net](Vertex n) { return net.x[n]; });
    add_property<Vertex, double>(dp, "y", [&net](Vertex n) { return net.y[n]; });
    add_property<Vertex, double>(dp, "z", [&net](Vertex n) { return net.z[n]; });
  }
  auto vessel = [&g](Edge e) { return g[e].vessel; };
  add_property<Edge, long long>(dp, "id", [&net, vessel](Edge e) { return net.id[vessel(e)]; });
  add_property<Edge, double>(dp, "length",
                             [&net, vessel](Edge e) { return net.length[vessel(e)]; });
  add_property<Edge, double>(dp, "diameter",
                             [&net, vessel](Edge e) { return net.diameter[vessel(e)]; });
  if (!net.distal_diameter.empty())
    add_property<Edge, double>(dp, "distal_diameter",
                               [&net, vessel](Edge e) { return net.diameter_at_to(vessel(e)); });
  add_property<Edge, double>(dp, "wall_thickness",
                             [&net, vessel](Edge e) { return net.wall_thickness[vessel(e)]; });
  add_property<Edge, double>(dp, "youngs_modulus",
                             [&net, vessel](Edge e) { return net.youngs_modulus[vessel(e)]; });
  add_property<Edge, int>(dp, "generation",
                          [&net, vessel](Edge e) { return net.generation[vessel(e)]; });
  add_property<Edge, std::string>(dp, "class", [&net, vessel](Edge e) {
    // The class of the diameter as written: one a hair below a class boundary is written at
    // the boundary by the 9 digits, and a reader checks the class against what it reads (a
    // fuzzed network was refused by hemotree's own GraphML reader).
    const std::size_t v = vessel(e);
    const VesselClass written = classify(std::strtod(property_text(net.diameter[v]).c_str(), nullptr));
    return std::string(to_string(written == classify(net.diameter[v]) ? net.vessel_class[v] : written));
  });
  return dp;
}

// Boost's writers want a std::ostream: this one forwards every character to the
// OutputStream, which does the buffering. Having no buffer of its own, it makes the
// writers' std::endl flushes free and never holds the document in memory.
class OutputStreamBuf final : public std::streambuf {
 public:
  explicit OutputStreamBuf(OutputStream& out) : out_(out) {}

 protected:
  int_type overflow(int_type c) override {
    if (!traits_type::eq_int_type(c, traits_type::eof())) out_ << traits_type::to_char_type(c);
    return traits_type::not_eof(c);
  }
  std::streamsize xsputn(const char* s, std::streamsize n) override {
    out_.write(std::string_view(s, static_cast<std::size_t>(n)));
    return n;
  }

 private:
  OutputStream& out_;
};

template <class Write>
void write_through_ostream(OutputStream& out, Write write) {
  OutputStreamBuf buffer(out);
  std::ostream os(&buffer);
  // A failed write throws IoError inside the stream; with badbit in the exception mask the
  // stream rethrows it instead of quietly setting a flag.
  os.exceptions(std::ios::badbit);
  write(os);
}

}  // namespace

void write_graphml(const Network& net, OutputStream& out) {
  const Graph g = build_graph(net);
  const boost::dynamic_properties dp = network_properties(net, g);
  write_through_ostream(out, [&](std::ostream& os) { boost::write_graphml(os, g, dp, true); });
}

void write_dot(const Network& net, OutputStream& out) {
  const Graph g = build_graph(net);
  const boost::dynamic_properties dp = network_properties(net, g);
  write_through_ostream(out, [&](std::ostream& os) { boost::write_graphviz_dp(os, g, dp, "id"); });
}

}  // namespace hemotree

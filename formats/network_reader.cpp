// Reads the vnet format with the streaming pull parser: nodes and vessels go straight into
// the flat arrays, members in any order, unknown members skipped (old readers stay
// compatible with newer files).
#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <limits>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "cli/errors.hpp"
#include "formats/json_pull.hpp"
#include "formats/network_io.hpp"
#include "formats/topology.hpp"

namespace hemotree {

namespace {

using Token = JsonPull::Token;
constexpr double unset = std::numeric_limits<double>::quiet_NaN();

void expect(JsonPull& in, Token wanted, const char* context) {
  if (in.next() != wanted)
    in.fail(std::string("expected ") + std::string(to_string(wanted)) + " " + context +
            ", found " + std::string(to_string(in.token())));
}

// `where` names the object for messages; it is a callable so that the name is built only
// when something is wrong (building it for every member cost 6 % of reading a full tree).
template <class Where>
double read_number(JsonPull& in, std::string_view member, const Where& where) {
  if (in.next() != Token::number)
    in.fail(std::string(where()) + ": \"" + std::string(member) + "\" must be a number");
  return in.number();
}

template <class Where>
std::int64_t read_integer(JsonPull& in, std::string_view member, const Where& where) {
  if (in.next() != Token::number)
    in.fail(std::string(where()) + ": \"" + std::string(member) + "\" must be an integer");
  return in.integer();
}

// Vessels refer to nodes by id; ids are resolved to indices once both lists are read.
struct NodeIndex {
  std::vector<std::pair<std::int64_t, std::int32_t>> sorted;  // (id, index) by id
  bool identity = true;  // ids 0..n-1 in order, the usual case: no search needed

  explicit NodeIndex(const std::vector<std::int64_t>& ids) {
    for (std::size_t i = 0; i < ids.size(); ++i)
      if (ids[i] != static_cast<std::int64_t>(i)) identity = false;
    if (identity) return;
    sorted.reserve(ids.size());
    for (std::size_t i = 0; i < ids.size(); ++i)
      sorted.emplace_back(ids[i], static_cast<std::int32_t>(i));
    std::sort(sorted.begin(), sorted.end());
  }
  std::size_t size() const { return identity ? 0 : sorted.size(); }
  // -1 when unknown
  std::int32_t find(std::int64_t id, std::size_t count) const {
    if (identity) return id >= 0 && id < static_cast<std::int64_t>(count)
                             ? static_cast<std::int32_t>(id) : -1;
    auto it = std::lower_bound(sorted.begin(), sorted.end(), std::make_pair(id, std::int32_t{0}));
    return it != sorted.end() && it->first == id ? it->second : -1;
  }
};

class Reader {
 public:
  Reader(JsonPull& in, std::string source) : in_(in), source_(std::move(source)) {}

  Network read() {
    expect(in_, Token::begin_object, "at the start of a network file");
    bool seen_format = false, seen_nodes = false, seen_vessels = false;
    while (in_.next() == Token::key) {
      std::string key(in_.text());
      if (key == "format") {
        if (in_.next() != Token::string || in_.text() != "vnet")
          in_.fail("\"format\" must be \"vnet\": this is not a hemotree network file");
        seen_format = true;
      } else if (key == "version") {
        std::int64_t version = read_integer(in_, "version", [] { return "network"; });
        if (version < 1 || version > vnet_version)
          in_.fail("network format version " + std::to_string(version) +
                   " is not supported (this build reads up to " +
                   std::to_string(vnet_version) + ")");
      } else if (key == "provenance") {
        in_.next();
        net_.provenance = in_.read_value();
      } else if (key == "blood") {
        in_.next();
        net_.blood = blood_from_json(in_.read_value());
      } else if (key == "inlet") {
        in_.next();
        net_.inlet = inlet_from_json(in_.read_value());
      } else if (key == "nodes") {
        read_nodes();
        seen_nodes = true;
      } else if (key == "vessels") {
        read_vessels();
        seen_vessels = true;
      } else {
        in_.next();
        net_.extra[key] = in_.read_value();  // passed through to the next stage
      }
    }
    if (in_.token() != Token::end_object) in_.fail("expected a member name or '}'");
    if (in_.next() != Token::end_of_input) in_.fail("unexpected content after the network");
    if (!seen_format) throw InputError(in_source() + ": missing \"format\": \"vnet\"");
    if (!seen_vessels) throw InputError(in_source() + ": missing \"vessels\"");
    resolve_nodes(seen_nodes);
    finish_generations();
    if (!net_.beta.empty()) {
      net_.beta.resize(net_.vessel_count(), unset);
      net_.reference_pressure.resize(net_.vessel_count(), unset);
    }
    if (net_.inlet && net_.index_of(net_.inlet->vessel) < 0)
      throw InputError(source_ + ": inlet: unknown vessel " + std::to_string(net_.inlet->vessel));
    return std::move(net_);
  }

 private:
  std::string in_source() const { return source_; }

  void read_nodes() {
    expect(in_, Token::begin_array, "for \"nodes\"");
    std::size_t n = 0;
    int with_coordinates = -1;  // unknown until the first node
    while (in_.next() != Token::end_array) {
      if (in_.token() != Token::begin_object) in_.fail("each node must be an object");
      auto where = [&] { return "nodes[" + std::to_string(n) + "]"; };
      std::int64_t node = 0;
      bool has_id = false;
      double p[3] = {unset, unset, unset};
      while (in_.next() == Token::key) {
        std::string_view key = in_.text();
        if (key == "id") {
          node = read_integer(in_, "id", where);
          has_id = true;
        } else if (key.size() == 1 && key[0] >= 'x' && key[0] <= 'z') {
          const int axis = key[0] - 'x';
          p[axis] = read_number(in_, key == "x" ? "x" : key == "y" ? "y" : "z", where);
        } else {
          in_.next();
          in_.skip_value();
        }
      }
      if (!has_id) in_.fail(where() + ": missing \"id\"");
      const bool coords = !std::isnan(p[0]) && !std::isnan(p[1]) && !std::isnan(p[2]);
      if (!coords && (!std::isnan(p[0]) || !std::isnan(p[1]) || !std::isnan(p[2])))
        in_.fail(where() + ": a node has all of x, y, z or none");
      if (with_coordinates < 0) with_coordinates = coords;
      if (coords != static_cast<bool>(with_coordinates))
        in_.fail(where() + ": either every node has coordinates or none does");
      if (coords) net_.add_node(node, p[0], p[1], p[2]);
      else net_.add_node(node);
      ++n;
    }
  }

  void read_vessels() {
    expect(in_, Token::begin_array, "for \"vessels\"");
    std::size_t n = 0;
    while (in_.next() != Token::end_array) {
      if (in_.token() != Token::begin_object) in_.fail("each vessel must be an object");
      read_vessel(n++);
    }
  }

  void read_vessel(std::size_t n) {
    std::int64_t vid = 0, from = 0, to = 0, generation = -1;
    double length = unset, diameter = unset, wall = unset, modulus = unset;
    double beta = unset, reference_pressure = unset;
    bool has_id = false, has_from = false, has_to = false, has_class = false;
    std::optional<nlohmann::json> outlet;
    VesselClass given_class{};
    auto where = [&] {
      return has_id ? "vessel " + std::to_string(vid) : "vessels[" + std::to_string(n) + "]";
    };
    while (in_.next() == Token::key) {
      std::string_view key = in_.text();
      if (key == "id") { vid = read_integer(in_, key, where); has_id = true; }
      else if (key == "from") { from = read_integer(in_, "from", where); has_from = true; }
      else if (key == "to") { to = read_integer(in_, "to", where); has_to = true; }
      else if (key == "length") length = read_number(in_, "length", where);
      else if (key == "diameter") diameter = read_number(in_, "diameter", where);
      else if (key == "wall_thickness") wall = read_number(in_, "wall_thickness", where);
      else if (key == "youngs_modulus") modulus = read_number(in_, "youngs_modulus", where);
      else if (key == "generation") generation = read_integer(in_, "generation", where);
      else if (key == "beta") beta = read_number(in_, "beta", where);
      else if (key == "reference_pressure")
        reference_pressure = read_number(in_, "reference_pressure", where);
      else if (key == "class") {
        if (in_.next() != Token::string) in_.fail(where() + ": \"class\" must be a string");
        auto c = parse_vessel_class(in_.text());
        if (!c) in_.fail(where() + ": unknown class \"" + std::string(in_.text()) + "\"");
        given_class = *c;
        has_class = true;
      } else if (key == "outlet") {
        in_.next();
        outlet = in_.read_value();
      } else {
        in_.next();
        in_.skip_value();
      }
    }
    if (!has_id) in_.fail(where() + ": missing \"id\"");
    if (!has_from) in_.fail(where() + ": missing \"from\"");
    if (!has_to) in_.fail(where() + ": missing \"to\"");
    if (std::isnan(length)) in_.fail(where() + ": missing \"length\"");
    if (std::isnan(diameter)) in_.fail(where() + ": missing \"diameter\"");
    if (!(length > 0)) in_.fail(where() + ": length must be positive");
    if (!(diameter > 0)) in_.fail(where() + ": diameter must be positive");
    if (!std::isnan(wall) && !(wall > 0)) in_.fail(where() + ": wall_thickness must be positive");
    if (!std::isnan(modulus) && !(modulus > 0))
      in_.fail(where() + ": youngs_modulus must be positive");
    if (has_class && given_class != classify(diameter))
      in_.fail(where() + ": class \"" + std::string(to_string(given_class)) +
               "\" does not match its diameter (" + std::string(to_string(classify(diameter))) +
               ")");
    if (!std::isnan(beta) && !(beta > 0)) in_.fail(where() + ": beta must be positive");
    if (std::isnan(beta) != std::isnan(reference_pressure))
      in_.fail(where() + ": give \"beta\" and \"reference_pressure\" together");
    if ((generation >= 0) != generations_given_ && n > 0)
      in_.fail(where() + ": either every vessel has a \"generation\" or none does");
    generations_given_ = generation >= 0;
    // Node ids for now; resolve_nodes() turns them into indices.
    const std::size_t index = net_.add_vessel(vid, 0, 0, length, diameter, wall, modulus,
                                              static_cast<std::int32_t>(generation));
    if (!std::isnan(beta) || !net_.beta.empty()) {
      net_.beta.resize(index, unset);
      net_.reference_pressure.resize(index, unset);
      net_.beta.push_back(beta);
      net_.reference_pressure.push_back(reference_pressure);
    }
    if (outlet) {
      try {
        net_.outlets.push_back(outlet_from_json(*outlet, where() + ": outlet"));
      } catch (const InputError& e) {
        in_.fail(e.what());
      }
      net_.outlets.back().vessel = static_cast<std::int32_t>(index);
    }
    from_id_.push_back(from);
    to_id_.push_back(to);
  }

  void resolve_nodes(bool nodes_given) {
    if (!nodes_given) {
      // Nodes may be left out of hand-written files: they are the vessels' end points.
      std::vector<std::int64_t> ids(from_id_);
      ids.insert(ids.end(), to_id_.begin(), to_id_.end());
      std::sort(ids.begin(), ids.end());
      ids.erase(std::unique(ids.begin(), ids.end()), ids.end());
      for (std::int64_t id : ids) net_.add_node(id);
    }
    const NodeIndex index(net_.node_id);
    if (!index.identity) {
      for (std::size_t i = 1; i < index.sorted.size(); ++i)
        if (index.sorted[i].first == index.sorted[i - 1].first)
          throw InputError(source_ + ": node id " + std::to_string(index.sorted[i].first) +
                           " appears twice");
    }
    const std::size_t count = net_.node_count();
    for (std::size_t v = 0; v < net_.vessel_count(); ++v) {
      const std::int32_t a = index.find(from_id_[v], count), b = index.find(to_id_[v], count);
      const std::string name = "vessel " + std::to_string(net_.id[v]);
      if (a < 0) throw InputError(source_ + ": " + name + ": unknown node " + std::to_string(from_id_[v]));
      if (b < 0) throw InputError(source_ + ": " + name + ": unknown node " + std::to_string(to_id_[v]));
      if (a == b) throw InputError(source_ + ": " + name + ": begins and ends at the same node");
      net_.from[v] = a;
      net_.to[v] = b;
    }
  }

  void finish_generations() {
    if (generations_given_ || net_.vessel_count() == 0) return;
    net_.generation = generations_from_inlets(net_);
  }

  JsonPull& in_;
  std::string source_;
  Network net_;
  std::vector<std::int64_t> from_id_, to_id_;
  bool generations_given_ = false;
};

Network read_with(JsonPull& in, const std::string& source) { return Reader(in, source).read(); }

}  // namespace

Network read_network(std::FILE* in, const std::string& source) {
  return read_network(in, source, JsonPull::buffer_size);
}

Network read_network(std::FILE* in, const std::string& source, std::size_t buffer_bytes) {
  JsonPull pull(in, source, buffer_bytes);
  return read_with(pull, source);
}

Network parse_network(std::string_view text, const std::string& source) {
  JsonPull pull(text, source);
  return read_with(pull, source);
}

Network read_network(const std::string& path) {
  if (path.empty() || path == "-") return read_network(stdin, "standard input");
  std::unique_ptr<std::FILE, int (*)(std::FILE*)> file(std::fopen(path.c_str(), "rb"),
                                                        &std::fclose);
  if (!file) throw IoError("cannot open " + path + ": " + std::strerror(errno));
  return read_network(file.get(), path);
}

}  // namespace hemotree

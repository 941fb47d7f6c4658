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

#include <sys/stat.h>

#include "core/errors.hpp"
#include "formats/field_ranges.hpp"
#include "formats/hdf5_file.hpp"
#include "formats/json_pull.hpp"
#include "formats/node_index.hpp"
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
// Member names are literals, never the key's text(): that view dies with the next() that
// reads the value (it points into the parser's buffer, which a refill or a longer string
// overwrites).
template <class Where>
double read_number(JsonPull& in, const char* member, const FieldRange& range,
                   const Where& where) {
  if (in.next() != Token::number)
    in.fail(std::string(where()) + ": \"" + member + "\" must be a number");
  const double value = in.number();
  if (!range.contains(value)) in.fail(std::string(where()) + ": " + out_of_range(member, range, value));
  return value;
}

template <class Where>
std::int64_t read_integer(JsonPull& in, const char* member, const Where& where) {
  if (in.next() != Token::number)
    in.fail(std::string(where()) + ": \"" + member + "\" must be an integer");
  return in.integer();
}

// Where a token was, to report it after the parser has moved on.
struct Position {
  std::size_t line = 0, column = 0;
  static Position of(const JsonPull& in) { return {in.line(), in.column()}; }
};

class Reader {
 public:
  Reader(JsonPull& in, std::string source) : in_(in), source_(std::move(source)) {}

  Network read() {
    expect(in_, Token::begin_object, "at the start of a network file");
    bool seen_format = false, seen_version = false, seen_nodes = false, seen_vessels = false;
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
        seen_version = true;
      } else if (key == "provenance") {
        in_.next();
        // Later stages add to it: anything but an object would fail there, not here.
        if (in_.token() != Token::begin_object) in_.fail("\"provenance\" must be an object");
        net_.provenance = in_.read_value();
      } else if (key == "blood") {
        in_.next();
        const Position at = Position::of(in_);
        net_.blood = from_json(blood_from_json, at);
      } else if (key == "inlet") {
        in_.next();
        const Position at = Position::of(in_);
        net_.inlet = from_json(inlet_from_json, at);
      } else if (key == "boundaries") {
        in_.next();
        if (in_.token() != Token::begin_array) in_.fail("\"boundaries\" must be a list");
        boundaries_at_ = Position::of(in_);
        boundaries_json_ = in_.read_value();
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
    if (!seen_format) throw InputError(source_ + ": missing \"format\": \"vnet\"");
    // Required by the format: without it a future reader could not tell version 1 files
    // from later ones.
    if (!seen_version)
      throw InputError(source_ + ": missing \"version\" (this build reads versions 1 to " +
                       std::to_string(vnet_version) + ")");
    if (!seen_vessels) throw InputError(source_ + ": missing \"vessels\"");
    check_unique_vessel_ids();
    resolve_nodes(seen_nodes);
    finish_generations();
    if (!net_.beta.empty()) {
      net_.beta.resize(net_.vessel_count(), unset);
      net_.reference_pressure.resize(net_.vessel_count(), unset);
    }
    if (!net_.distal_diameter.empty()) net_.distal_diameter.resize(net_.vessel_count(), unset);
    if (net_.inlet && net_.index_of(net_.inlet->vessel) < 0)
      throw InputError(source_ + ": inlet: unknown vessel " + std::to_string(net_.inlet->vessel));
    read_boundaries();
    net_.shrink_to_fit();
    return std::move(net_);
  }

 private:
  [[noreturn]] void fail_at(const Position& at, const std::string& message) const {
    throw JsonError(source_ + ":" + std::to_string(at.line) + ":" + std::to_string(at.column) +
                    ": " + message);
  }

  // Reads the current value as JSON and converts it, the conversion's InputError placed at
  // the value's start.
  template <class Convert>
  auto from_json(Convert convert, const Position& at) -> decltype(convert(nlohmann::json())) {
    const nlohmann::json value = in_.read_value();
    try {
      return convert(value);
    } catch (const InputError& e) {
      fail_at(at, e.what());
    }
  }

  // Boundaries name nodes by id: read once the nodes are known, sorted by node, and checked
  // against the tree's inlet and outlets (one condition per node).
  void read_boundaries() {
    if (boundaries_json_.is_null()) return;
    const NodeIndex index(net_.node_id);
    net_.boundaries.reserve(boundaries_json_.size());
    for (std::size_t k = 0; k < boundaries_json_.size(); ++k) {
      std::int64_t node_id = 0;
      NodeBoundary b;
      try {
        b = boundary_from_json(boundaries_json_[k], "boundaries[" + std::to_string(k) + "]", node_id);
      } catch (const InputError& e) {
        fail_at(boundaries_at_, e.what());
      }
      b.node = index.find(node_id, net_.node_count());
      if (b.node < 0)
        throw InputError(source_ + ": boundaries[" + std::to_string(k) + "]: unknown node " + std::to_string(node_id));
      net_.boundaries.push_back(std::move(b));
    }
    try {
      sort_boundaries_by_node(net_);
    } catch (const InputError& e) {
      throw InputError(source_ + ": " + e.what());
    }
  }

  void read_nodes() {
    expect(in_, Token::begin_array, "for \"nodes\"");
    std::size_t n = 0;
    int with_coordinates = -1;  // unknown until the first node
    while (in_.next() != Token::end_array) {
      if (in_.token() != Token::begin_object) in_.fail("each node must be an object");
      if (n >= max_elements) in_.fail("more than " + std::to_string(max_elements) + " nodes");
      std::int64_t node = 0;
      bool has_id = false;
      auto where = [&] {
        return has_id ? "node " + std::to_string(node) : "nodes[" + std::to_string(n) + "]";
      };
      double p[3] = {unset, unset, unset};
      while (in_.next() == Token::key) {
        const std::string_view key = in_.text();  // compared before the next next() only
        if (key == "id") {
          node = read_integer(in_, "id", where);
          has_id = true;
        } else if (key.size() == 1 && key[0] >= 'x' && key[0] <= 'z') {
          const int axis = key[0] - 'x';
          static constexpr const char* names[] = {"x", "y", "z"};
          p[axis] = read_number(in_, names[axis], ranges::coordinate, where);
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
      if (n >= max_elements) in_.fail("more than " + std::to_string(max_elements) + " vessels");
      read_vessel(n++);
    }
  }

  void read_vessel(std::size_t n) {
    std::int64_t vid = 0, from = 0, to = 0, generation = 0;
    double length = unset, diameter = unset, wall = unset, modulus = unset;
    double beta = unset, reference_pressure = unset, distal_diameter = unset;
    bool has_id = false, has_from = false, has_to = false, has_class = false;
    bool has_generation = false;
    Position generation_at;
    std::optional<nlohmann::json> outlet;
    VesselClass given_class{};
    auto where = [&] {
      return has_id ? "vessel " + std::to_string(vid) : "vessels[" + std::to_string(n) + "]";
    };
    while (in_.next() == Token::key) {
      // The key's view is only compared, before the value's next(): see read_number.
      const std::string_view key = in_.text();
      if (key == "id") { vid = read_integer(in_, "id", where); has_id = true; }
      else if (key == "from") { from = read_integer(in_, "from", where); has_from = true; }
      else if (key == "to") { to = read_integer(in_, "to", where); has_to = true; }
      else if (key == "length") length = read_number(in_, "length", ranges::length, where);
      else if (key == "diameter") diameter = read_number(in_, "diameter", ranges::diameter, where);
      else if (key == "distal_diameter")
        distal_diameter = read_number(in_, "distal_diameter", ranges::diameter, where);
      else if (key == "wall_thickness")
        wall = read_number(in_, "wall_thickness", ranges::wall_thickness, where);
      else if (key == "youngs_modulus")
        modulus = read_number(in_, "youngs_modulus", ranges::youngs_modulus, where);
      else if (key == "generation") {
        generation = read_integer(in_, "generation", where);
        generation_at = Position::of(in_);
        has_generation = true;
        // The vessel count bounds it from above once every vessel is read.
        if (generation < 0 || generation > ranges::max_generation)
          in_.fail(where() + ": \"generation\" must lie in [0, vessel count - 1] (got " +
                   std::to_string(generation) + ")");
      } else if (key == "beta") beta = read_number(in_, "beta", ranges::beta, where);
      else if (key == "reference_pressure")
        reference_pressure = read_number(in_, "reference_pressure", ranges::pressure, where);
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
    if (has_class && given_class != classify(diameter))
      in_.fail(where() + ": class \"" + std::string(to_string(given_class)) +
               "\" does not match its diameter (" + std::string(to_string(classify(diameter))) +
               ")");
    if (std::isnan(beta) != std::isnan(reference_pressure))
      in_.fail(where() + ": give \"beta\" and \"reference_pressure\" together");
    if (n > 0 && has_generation != generations_given_)
      in_.fail(where() + (has_generation ? ": has a \"generation\" but vessels[0] has none"
                                         : ": missing \"generation\" (vessels[0] has one)") +
               "; either every vessel has a \"generation\" or none does");
    generations_given_ = has_generation;
    if (has_generation && generation > deepest_) {
      deepest_ = generation;
      deepest_at_ = generation_at;
    }
    // Node ids for now; resolve_nodes() turns them into indices.
    const std::size_t index = net_.add_vessel(vid, 0, 0, length, diameter, wall, modulus,
                                              static_cast<std::int32_t>(generation));
    if (!std::isnan(beta) || !net_.beta.empty()) {
      net_.beta.resize(index, unset);
      net_.reference_pressure.resize(index, unset);
      net_.beta.push_back(beta);
      net_.reference_pressure.push_back(reference_pressure);
    }
    if (!std::isnan(distal_diameter) || !net_.distal_diameter.empty()) {
      net_.distal_diameter.resize(index, unset);
      net_.distal_diameter.push_back(distal_diameter);
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

  // Ids name vessels in results and between stages: two vessels with one id would be
  // merged or written twice downstream.
  void check_unique_vessel_ids() const {
    if (const auto twice = NodeIndex(net_.id).repeat())
      throw InputError(source_ + ": vessel id " + std::to_string(twice->id) + " appears twice: vessels[" +
                       std::to_string(twice->first) + "] and vessels[" + std::to_string(twice->second) + "]");
  }

  void resolve_nodes(bool nodes_given) {
    if (!nodes_given) {
      // Nodes may be left out of hand-written files: they are the vessels' end points.
      std::vector<std::int64_t> ids(from_id_);
      ids.insert(ids.end(), to_id_.begin(), to_id_.end());
      std::sort(ids.begin(), ids.end());
      ids.erase(std::unique(ids.begin(), ids.end()), ids.end());
      if (ids.size() > max_elements)
        throw InputError(source_ + ": more than " + std::to_string(max_elements) + " nodes");
      for (std::int64_t id : ids) net_.add_node(id);
    }
    const NodeIndex index(net_.node_id);
    if (const auto twice = index.repeat())
      throw InputError(source_ + ": node id " + std::to_string(twice->id) + " appears twice: nodes[" +
                       std::to_string(twice->first) + "] and nodes[" + std::to_string(twice->second) + "]");
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
    if (net_.vessel_count() == 0) return;
    if (!generations_given_) {
      net_.generation = generations_from_inlets(net_);
      return;
    }
    // A generation counts vessels from a root, so none can reach the vessel count; a
    // larger label is corrupt, and would make per-generation tables of that many rows.
    const auto count = static_cast<std::int64_t>(net_.vessel_count());
    if (deepest_ >= count) {
      const auto v = std::find(net_.generation.begin(), net_.generation.end(), deepest_) -
                     net_.generation.begin();
      fail_at(deepest_at_, "vessel " + std::to_string(net_.id[static_cast<std::size_t>(v)]) +
                               ": \"generation\" must lie in [0, " + std::to_string(count - 1) +
                               "] (the vessel count - 1) (got " + std::to_string(deepest_) +
                               ")");
    }
  }

  // Indices are 32-bit (from, to, outlets); beyond that a file is not a network we can hold.
  static constexpr std::size_t max_elements = std::numeric_limits<std::int32_t>::max();

  JsonPull& in_;
  std::string source_;
  Network net_;
  std::vector<std::int64_t> from_id_, to_id_;
  bool generations_given_ = false;
  std::int64_t deepest_ = -1;  // the largest generation read, and where
  Position deepest_at_;
  nlohmann::json boundaries_json_;  // read after the nodes
  Position boundaries_at_;
};

Network read_with(JsonPull& in, const std::string& source) { return Reader(in, source).read(); }

}  // namespace

namespace {

// HDF5 files begin with 0x89, which no JSON text does (a UTF-8 byte order mark begins with
// 0xEF): one byte tells the forms apart, and ungetc puts it back for the JSON reader.
bool begins_hdf5(std::FILE* in) {
  const int first = std::getc(in);
  if (first == EOF) return false;
  std::ungetc(first, in);
  return first == hdf5::signature[0];
}

Network read_hdf5_stream(std::FILE* in, const std::string& source) {
  return read_network_hdf5(hdf5::File::open_stream(in, source));
}

}  // namespace

Network read_network(std::FILE* in, const std::string& source) {
  if (begins_hdf5(in)) return read_hdf5_stream(in, source);
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
  // A regular HDF5 file is read in place; one from a pipe through memory.
  struct stat status{};
  if (begins_hdf5(file.get()) && ::fstat(::fileno(file.get()), &status) == 0 && S_ISREG(status.st_mode)) {
    file.reset();
    return read_network_hdf5(hdf5::File::open(path));
  }
  return read_network(file.get(), path);
}

}  // namespace hemotree

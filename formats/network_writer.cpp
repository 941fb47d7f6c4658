// Writes the vnet format: one node or vessel per line, so that the file greps and diffs
// well. Lines are formatted in parallel blocks and written in order, so the output is
// byte-identical whatever the number of threads.
#include <algorithm>
#include <charconv>
#include <cmath>
#include <exception>
#include <string>
#include <vector>

#include "formats/network_io.hpp"

namespace hemotree {

namespace {

constexpr std::size_t block = 1 << 16;  // lines formatted per task

void append_real(std::string& s, double v) {
  char text[32];
  s.append(text, format_real(text, v));
}

void append_integer(std::string& s, long long v) { s += std::to_string(v); }

// The class follows from the diameter, and readers check that they agree. A diameter
// within rounding of a class boundary (9.9999999996e-6 against 10 um) would be written as
// the boundary itself and read back in the next class: there the shortest exact form is
// written instead (at most 17 digits), so that what is written reads back the same.
void append_diameter(std::string& s, double d) {
  constexpr double boundaries[] = {artery_min_diameter, small_artery_min_diameter,
                                   arteriole_min_diameter};
  bool near = false;
  for (double b : boundaries) near = near || std::abs(d - b) <= 1e-8 * b;
  if (!near) return append_real(s, d);
  char text[32];
  const auto result = std::to_chars(text, text + sizeof text, d);
  s.append(text, result.ptr);
}

void append_node(std::string& s, const Network& net, std::size_t n) {
  s += "{\"id\":";
  append_integer(s, net.node_id[n]);
  if (net.has_coordinates()) {
    s += ",\"x\":";
    append_real(s, net.x[n]);
    s += ",\"y\":";
    append_real(s, net.y[n]);
    s += ",\"z\":";
    append_real(s, net.z[n]);
  }
  s += '}';
}

void append_vessel(std::string& s, const Network& net, std::size_t v,
                   const std::vector<std::int32_t>& outlet_of) {
  s += "{\"id\":";
  append_integer(s, net.id[v]);
  s += ",\"from\":";
  append_integer(s, net.node_id[net.from[v]]);
  s += ",\"to\":";
  append_integer(s, net.node_id[net.to[v]]);
  s += ",\"length\":";
  append_real(s, net.length[v]);
  s += ",\"diameter\":";
  append_diameter(s, net.diameter[v]);
  if (net.is_tapered(v)) {
    s += ",\"distal_diameter\":";
    append_real(s, net.distal_diameter[v]);
  }
  // Optional members a hand-written file may lack (NaN here) are left out again.
  if (!std::isnan(net.wall_thickness[v])) {
    s += ",\"wall_thickness\":";
    append_real(s, net.wall_thickness[v]);
  }
  if (!std::isnan(net.youngs_modulus[v])) {
    s += ",\"youngs_modulus\":";
    append_real(s, net.youngs_modulus[v]);
  }
  s += ",\"generation\":";
  append_integer(s, net.generation[v]);
  s += ",\"class\":\"";
  s += to_string(net.vessel_class[v]);
  s += '"';
  if (!net.beta.empty() && !std::isnan(net.beta[v])) {
    s += ",\"beta\":";
    append_real(s, net.beta[v]);
    s += ",\"reference_pressure\":";
    append_real(s, net.reference_pressure[v]);
  }
  if (!outlet_of.empty() && outlet_of[v] >= 0) {
    s += ",\"outlet\":";
    s += to_json(net.outlets[static_cast<std::size_t>(outlet_of[v])]).dump();
  }
  s += '}';
}

// Writes count lines produced by append_line, comma-separated, in parallel blocks.
template <class AppendLine>
void write_lines(OutputStream& out, std::size_t count, AppendLine append_line) {
  const std::size_t blocks = (count + block - 1) / block;
  std::string text;
  std::exception_ptr error;
#pragma omp parallel for ordered schedule(static, 1) firstprivate(text)
  for (std::size_t b = 0; b < blocks; ++b) {
    text.clear();
    std::exception_ptr made;  // a block's text (an allocation) may fail too
    try {
      const std::size_t end = std::min(count, (b + 1) * block);
      for (std::size_t i = b * block; i < end; ++i) {
        append_line(text, i);
        text += i + 1 < count ? ",\n" : "\n";
      }
    } catch (...) {
      made = std::current_exception();
    }
#pragma omp ordered
    {
      // Exceptions must not cross the parallel region: keep the first, rethrow after.
      if (!error && made) error = made;
      if (!error) {
        try {
          out.write(text);
        } catch (...) {
          error = std::current_exception();
        }
      }
    }
  }
  if (error) std::rethrow_exception(error);
}

}  // namespace

int format_version_needed(const Network& net) {
  bool tapered = false;
  for (std::size_t v = 0; v < net.distal_diameter.size() && !tapered; ++v) tapered = net.is_tapered(v);
  return net.boundaries.empty() && !tapered ? 1 : 2;
}

void write_network(const Network& net, OutputStream& out) {
  // The oldest version that holds the content, so that older readers read what they can.
  out << "{\n\"format\": \"vnet\",\n\"version\": " << format_version_needed(net) << ",\n";
  out << "\"provenance\": " << net.provenance.dump() << ",\n";
  if (net.blood) out << "\"blood\": " << to_json(*net.blood).dump() << ",\n";
  if (net.inlet) out << "\"inlet\": " << to_json(*net.inlet).dump() << ",\n";
  if (!net.boundaries.empty()) {
    out << "\"boundaries\": [\n";
    for (std::size_t k = 0; k < net.boundaries.size(); ++k) {
      const NodeBoundary& b = net.boundaries[k];
      out << to_json(b, net.node_id[static_cast<std::size_t>(b.node)]).dump()
          << (k + 1 < net.boundaries.size() ? ",\n" : "\n");
    }
    out << "],\n";
  }
  for (const auto& [key, value] : net.extra.items())
    out << nlohmann::json(key).dump() << ": " << value.dump() << ",\n";
  out << "\"nodes\": [\n";
  write_lines(out, net.node_count(),
              [&](std::string& s, std::size_t n) { append_node(s, net, n); });
  out << "],\n\"vessels\": [\n";
  std::vector<std::int32_t> outlet_of;  // outlet index per vessel, -1 for none
  if (!net.outlets.empty()) {
    outlet_of.assign(net.vessel_count(), -1);
    for (std::size_t k = 0; k < net.outlets.size(); ++k)
      outlet_of[static_cast<std::size_t>(net.outlets[k].vessel)] = static_cast<std::int32_t>(k);
  }
  write_lines(out, net.vessel_count(),
              [&](std::string& s, std::size_t v) { append_vessel(s, net, v, outlet_of); });
  out << "]\n}\n";
}

}  // namespace hemotree

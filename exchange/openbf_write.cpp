// openBF's YAML model and inlet table, written from a Network: what openBF cannot express is
// refused with the node or vessel at fault (docs/import.md).
#include <charconv>
#include <filesystem>

#include "exchange/openbf_model.hpp"

namespace hemotree {

namespace openbf {

namespace {

namespace fs = std::filesystem;

// A real as YAML 1.1 reads a float (Julia's YAML.jl among them): with a decimal point, and an
// exponent with its sign ("1.0e-13", not "1e-13", which YAML 1.1 reads as a string).
std::string yaml_real(double value) {
  char text[40];
  const auto result = std::to_chars(text, text + sizeof text, value);
  std::string s(text, result.ptr);
  const auto e = s.find('e');
  const std::string mantissa = s.substr(0, e);
  std::string exponent = e == std::string::npos ? "" : s.substr(e + 1);
  std::string out = mantissa;
  if (mantissa.find('.') == std::string::npos) out += ".0";
  if (!exponent.empty()) out += "e" + (exponent[0] == '-' || exponent[0] == '+' ? exponent : "+" + exponent);
  return out;
}

std::string yaml_string(const std::string& s) {
  std::string out = "\"";
  for (const char c : s) {
    if (c == '"' || c == '\\') out += '\\';
    if (static_cast<unsigned char>(c) < 0x20) {
      out += ' ';
      continue;
    }
    out += c;
  }
  return out + "\"";
}

// The inlet's waveform as openBF's table: from t = 0 to t = period, the last row repeating the
// first. A table is copied (with a row at t = 0 where it starts later, its value interpolated
// there, which the periodic table has exactly); a half sine is sampled at 200 points over its
// systole (the linear interpolation between them is within 1.3e-4 of the peak), then zero; a
// constant flow is two rows.
std::vector<std::pair<double, double>> inlet_rows(const Waveform& w) {
  std::vector<std::pair<double, double>> rows;
  switch (w.shape) {
    case Waveform::Shape::table:
      if (w.time.front() > 0) rows.emplace_back(0.0, w(0.0));
      for (std::size_t k = 0; k < w.time.size(); ++k) rows.emplace_back(w.time[k], w.value[k]);
      break;
    case Waveform::Shape::half_sine: {
      constexpr int samples = 200;
      for (int k = 0; k <= samples; ++k) {
        const double t = w.systole * k / samples;
        rows.emplace_back(t, k == samples ? 0.0 : w(t));
      }
      break;
    }
    case Waveform::Shape::constant:
      rows.emplace_back(0.0, w.mean);
      break;
  }
  rows.emplace_back(w.period, rows.front().second);
  return rows;
}

// openBF's one external pressure: the reference pressure of the vessels whose tube law is
// given by beta, else what an import from openBF recorded, else 0.
double openbf_external_pressure(const Network& net) {
  const std::size_t nv = net.vessel_count();
  const auto vessel_name = [&](std::size_t v) { return "vessel " + std::to_string(net.id[v]); };
  const auto has_beta = [&](std::size_t v) { return !net.beta.empty() && !std::isnan(net.beta[v]); };
  double pext = net.provenance.contains("external_pressure") && net.provenance["external_pressure"].is_number()
                    ? net.provenance["external_pressure"].get<double>()
                    : 0.0;
  std::optional<std::size_t> first_beta;
  for (std::size_t v = 0; v < nv; ++v) {
    if (!has_beta(v)) continue;
    if (!first_beta) first_beta = v, pext = net.reference_pressure[v];
    if (net.reference_pressure[v] != pext)
      throw InputError(vessel_name(v) + ": reference_pressure " + format_number(net.reference_pressure[v]) +
                       " Pa differs from " + vessel_name(*first_beta) + "'s " + format_number(pext) +
                       " Pa; openBF's Pext is one for the network");
  }
  if (first_beta)
    for (std::size_t v = 0; v < nv; ++v)
      if (!has_beta(v) && pext != 0)
        throw InputError(vessel_name(v) + ": no beta, where " + vessel_name(*first_beta) + "'s reference_pressure " +
                         format_number(pext) + " Pa would become openBF's Pext for every vessel");
  return pext;
}

// A tube law given by beta is openBF's thin wall with E h0 = 3 beta A0 / (4 sqrt(pi)) at the
// vessel's `from` end: h0 is the vessel's (or openBF's law), E follows, or stays the vessel's
// where beta is that E and h0's (an import from openBF). Along a tapered vessel hemotree's
// given beta goes as 1 / D^2, as openBF's documented law with h0 and E fixed.
std::string vessel_yaml(const Network& net, std::size_t v, const std::vector<std::int64_t>& number,
                        const std::vector<const Outlet*>& outlet_of, const nlohmann::json* labels, double pext,
                        double whole) {
  const auto has_beta = [&](std::size_t i) { return !net.beta.empty() && !std::isnan(net.beta[i]); };
  const auto vessel_name = [&](std::size_t i) { return "vessel " + std::to_string(net.id[i]); };
  double youngs_modulus = net.youngs_modulus[v], wall = net.wall_thickness[v];
  if (has_beta(v)) {
    const double r = net.diameter[v] / 2;
    if (std::isnan(wall)) wall = avolio_wall_thickness(r);
    const bool own = !std::isnan(youngs_modulus) &&
                     std::abs(openbf_beta(youngs_modulus, wall, r) - net.beta[v]) <= 1e-12 * net.beta[v];
    if (!own) youngs_modulus = 3 * net.beta[v] * std::numbers::pi * r * r / (4 * std::sqrt(std::numbers::pi) * wall);
  }
  if (std::isnan(youngs_modulus))
    throw InputError(vessel_name(v) + ": no Young's modulus; openBF needs E for every vessel");
  const bool own_label = labels && (*labels)[v].is_string() && !(*labels)[v].get<std::string>().empty();
  std::string y = "  - label: " + yaml_string(own_label ? (*labels)[v].get<std::string>() : "v" + std::to_string(net.id[v])) + "\n";
  y += "    sn: " + std::to_string(number[static_cast<std::size_t>(net.from[v])]) + "\n";
  y += "    tn: " + std::to_string(number[static_cast<std::size_t>(net.to[v])]) + "\n";
  y += "    L: " + yaml_real(net.length[v]) + "\n";
  y += "    E: " + yaml_real(youngs_modulus) + "\n";
  if (net.is_tapered(v))
    y += "    Rp: " + yaml_real(net.diameter[v] / 2) + "\n    Rd: " + yaml_real(net.distal_diameter[v] / 2) + "\n";
  else
    y += "    R0: " + yaml_real(net.diameter[v] / 2) + "\n";
  if (!std::isnan(wall)) y += "    h0: " + yaml_real(wall) + "\n";
  if (pext != 0) y += "    Pext: " + yaml_real(pext) + "\n";
  y += "    gamma_profile: " + std::to_string(static_cast<long long>(whole)) + "\n";
  if (const Outlet* o = outlet_of[v]) {
    switch (o->type) {
      case BoundaryType::rcr:
        // openBF reads R1 = 0 as a reflection outlet and R2 = 0 as a two-element Windkessel.
        if (o->r1 == 0 || o->r2 == 0)
          throw InputError(vessel_name(v) + ": an RCR outlet with R" + (o->r1 == 0 ? "1" : "2") +
                           " = 0, which openBF reads as another outlet");
        y += "    R1: " + yaml_real(o->r1) + "\n    R2: " + yaml_real(o->r2) + "\n    Cc: " + yaml_real(o->c) + "\n";
        if (o->p_out != 0) y += "    Pout: " + yaml_real(o->p_out) + "\n";
        break;
      case BoundaryType::resistance:
        throw InputError(vessel_name(v) + ": a resistance (R) outlet; openBF has Windkessels and reflection only");
      case BoundaryType::reflection:
        y += "    Rt: " + yaml_real(o->reflection) + "\n";
        break;
      case BoundaryType::flow:
      case BoundaryType::pressure:
        break;  // not outlet models
    }
  }
  return y;
}

}  // namespace

}  // namespace openbf

void write_openbf(const Network& net, OutputStream& out, const std::string& inlet_path) {
  using namespace openbf;
  const std::size_t nv = net.vessel_count(), nn = net.node_count();
  std::vector<std::vector<std::size_t>> leaving(nn), entering(nn);
  for (std::size_t v = 0; v < nv; ++v) {
    leaving[static_cast<std::size_t>(net.from[v])].push_back(v);
    entering[static_cast<std::size_t>(net.to[v])].push_back(v);
  }
  const auto node_name = [&](std::size_t n) { return "node " + std::to_string(net.node_id[n]); };
  const auto vessel_name = [&](std::size_t v) { return "vessel " + std::to_string(net.id[v]); };

  // openBF's boundaries: one flow inlet at node 1 into one vessel, and a 0D outlet at the end of
  // every vessel that no other vessel continues.
  std::optional<std::size_t> inlet_node;
  const Waveform* inflow = nullptr;
  std::vector<const Outlet*> outlet_of(nv, nullptr);
  const std::vector<NodeBoundary> boundaries = node_boundaries(net);
  std::vector<Outlet> node_outlets;
  node_outlets.reserve(boundaries.size());
  for (const NodeBoundary& b : boundaries) {
    const auto n = static_cast<std::size_t>(b.node);
    if (!std::isnan(b.hematocrit))
      throw InputError(node_name(n) + ": an inflow hematocrit: openBF's blood has none");
    if (b.type == BoundaryType::pressure)
      throw InputError(node_name(n) + ": a pressure boundary: openBF prescribes only the inflow at its inlet node");
    if (b.type == BoundaryType::flow) {
      if (inlet_node)
        throw InputError(node_name(n) + ": a second flow boundary (the first at " + node_name(*inlet_node) +
                         "): openBF has one inlet");
      if (leaving[n].size() != 1 || !entering[n].empty())
        throw InputError(node_name(n) + ": openBF's inlet feeds one vessel leaving the node, and none entering it");
      inlet_node = n;
      inflow = &b.waveform;
      continue;
    }
    if (entering[n].size() != 1 || !leaving[n].empty())
      throw InputError(node_name(n) + ": a " + std::string(to_string(b.type)) +
                       " outlet where vessels do not end singly; openBF puts an outlet at the end of one vessel");
    node_outlets.push_back(b.outlet);
    outlet_of[entering[n].front()] = &node_outlets.back();
  }
  if (!inlet_node) throw InputError("openBF needs an inflow at its inlet node; the network has none");

  // openBF feeds node 1: the ids stay where the inlet is node 1 and all are positive, else
  // the nodes are numbered 1 (the inlet), 2, 3, ... in their order.
  bool keep_ids = net.node_id[*inlet_node] == 1;
  for (std::size_t n = 0; n < nn && keep_ids; ++n) keep_ids = net.node_id[n] >= 1;
  std::vector<std::int64_t> number(nn);
  for (std::size_t n = 0, next = 2; n < nn; ++n)
    number[n] = keep_ids ? net.node_id[n] : n == *inlet_node ? 1 : static_cast<std::int64_t>(next++);

  for (std::size_t n = 0; n < nn; ++n) {
    if (n != *inlet_node && entering[n].empty() && !leaving[n].empty())
      throw InputError(node_name(n) + ": vessels leave it but none enters it, and it is not the inlet");
    if (leaving[n].empty() && !entering[n].empty() && !outlet_of[entering[n].front()])
      throw InputError(node_name(n) + ": " + vessel_name(entering[n].front()) +
                       " ends here without an outlet (openBF would make it non-reflecting)");
  }

  const Blood blood = net.blood.value_or(Blood{});
  const double gamma = profile_of_alpha(blood.alpha);
  const double whole = std::round(gamma);
  if (std::abs(gamma - whole) > 1e-9 * std::max(1.0, whole))
    throw InputError("blood alpha " + format_number(blood.alpha) + " is the profile exponent gamma = " +
                     format_number(gamma) + "; openBF takes a whole number (gamma_profile)");

  const std::string project = net.provenance.contains("project_name") && net.provenance["project_name"].is_string()
                                  ? net.provenance["project_name"].get<std::string>()
                                  : fs::path(out.name()).stem().string();
  const nlohmann::json* labels = net.provenance.contains("labels") && net.provenance["labels"].is_array() &&
                                         net.provenance["labels"].size() == nv
                                     ? &net.provenance["labels"]
                                     : nullptr;
  const double pext = openbf_external_pressure(net);

  // The YAML names the inlet file relative to its own folder (openBF looks there).
  std::string inlet_name = inlet_path;
  if (out.name() != "standard output") {
    const fs::path folder = fs::absolute(fs::path(out.name())).parent_path();
    inlet_name = fs::absolute(fs::path(inlet_path)).lexically_normal().lexically_relative(folder.lexically_normal()).string();
  }

  std::string y;
  y += "# openBF model written by hemotree";
  if (net.provenance.contains("source") && net.provenance["source"].is_string())
    for (const char c : " from " + net.provenance["source"].get<std::string>()) y += c == '\n' || c == '\r' ? ' ' : c;
  y += "\n";
  if (blood.rheology != Rheology::newtonian)
    y += "# hemotree's blood was " + std::string(to_string(blood.rheology)) +
         "; openBF's is Newtonian: mu is its newtonian_viscosity\n";
  y += "project_name: " + yaml_string(project) + "\n";
  y += "inlet_file: " + yaml_string(inlet_name) + "\n";
  y += "write_results: [\"P\", \"Q\", \"u\"]\n";
  y += "solver:\n  Ccfl: 0.9\n  cycles: 100\n  jump: 100\n  convergence_tolerance: 1.0\n";
  y += "blood:\n  rho: " + yaml_real(blood.density) + "\n  mu: " + yaml_real(blood.newtonian_viscosity) + "\n";
  y += "network:\n";
  out << y;

  for (std::size_t v = 0; v < nv; ++v) out << vessel_yaml(net, v, number, outlet_of, labels, pext, whole);

  OutputStream table(inlet_path);
  for (const auto& [t, q] : inlet_rows(*inflow)) table << yaml_real(t) << ' ' << yaml_real(q) << '\n';
  table.commit();
}

}  // namespace hemotree

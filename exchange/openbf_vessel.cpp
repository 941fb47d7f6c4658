// One vessel of an openBF model, as openBF reads it: its keys read, refused with a reason, or
// ignored.
#include "exchange/openbf_model.hpp"

namespace hemotree::openbf {

namespace {

// Settings of openBF's solver and output that do not change the model: ignored, and named in
// one note.
const std::set<std::string, std::less<>> ignored_vessel_keys = {"M", "to_save", "initial_pressure",
                                                                "initial_flow", "inlet number"};

// The keys of a vessel that hemotree reads, refuses with a reason, or ignores.
const std::set<std::string, std::less<>> vessel_keys = {
    "label", "sn", "tn", "L", "E", "R0", "Rp", "Rd", "h0", "Pext", "gamma_profile", "gamma profile",
    "R1", "R2", "Cc", "Rt", "Pout", "outlet", "inlet_impedance_matching", "visco-elastic", "phi", "inlet",
    "inlet file", "M", "to_save", "initial_pressure", "initial_flow", "inlet number"};

std::string unknown_vessel_key(const std::string& key) {
  return vessel_keys.contains(key) ? ""
                                   : "\"" + key + "\" is not an openBF vessel key that hemotree reads or may safely ignore";
}
}  // namespace

VesselModel read_vessel(const Source& source, const YAML::Node& node, std::size_t position,
                        std::set<std::string, std::less<>>& ignored, std::deque<Fields>& keep) {
  const Fields& f = keep.emplace_back(source, node, "vessel " + std::to_string(position), unknown_vessel_key);
  VesselModel v;
  v.mark = node.Mark();
  v.label = f.text(f.require("label"));
  const auto node_number = [&](const Entry& e) {
    const std::int64_t n = f.integer(e);
    if (n < 1) f.fail(e, "\"" + e.key + "\" must be a node number from 1 (got " + std::to_string(n) + ")");
    return n;
  };
  v.sn = node_number(f.require("sn"));
  v.tn = node_number(f.require("tn"));
  if (v.sn == v.tn) f.fail(f.require("tn"), "\"sn\" and \"tn\" are both node " + std::to_string(v.sn));
  v.length = f.number(f.require("L"), ranges::length);
  v.youngs_modulus = f.number(f.require("E"), ranges::youngs_modulus);

  // openBF: Rp = Rp or R0, Rd = Rd or Rp; a radius needs R0 or Rp.
  const Entry* r0 = f.find("R0");
  const Entry* rp = f.find("Rp");
  const Entry* rd = f.find("Rd");
  if (!r0 && !rp) {
    if (rd) f.fail(*rd, "\"Rd\" needs \"Rp\", the radius at \"sn\"");
    f.missing("\"R0\" (or \"Rp\" and \"Rd\"), the lumen radius");
  }
  if (r0 && (rp || rd)) f.fail(rp ? *rp : *rd, "give \"R0\" or \"Rp\" and \"Rd\", not both");
  v.rp = f.number(rp ? *rp : *r0, radius_range);
  v.rd = rd ? f.number(*rd, radius_range) : v.rp;

  if (const Entry* e = f.find("h0")) v.wall = f.number(*e, ranges::wall_thickness);
  if (const Entry* e = f.find("Pext")) {
    v.external_pressure = f.number(*e, ranges::pressure);
    v.external_pressure_mark = e->mark;
  }
  if (const Entry* e = f.find("gamma_profile", "gamma profile")) {
    v.profile = f.number(*e, profile_range);
    v.profile_spaced = e->key == "gamma profile";
    v.profile_mark = e->mark;
  }

  for (const Entry& e : f.entries()) {
    const std::string& k = e.key;
    if (k == "label" || k == "sn" || k == "tn" || k == "L" || k == "E" || k == "R0" || k == "Rp" ||
        k == "Rd" || k == "h0" || k == "Pext" || k == "gamma_profile" || k == "gamma profile") {
      continue;
    } else if (ignored_vessel_keys.contains(k)) {
      ignored.insert(k);
    } else if (k == "R1" || k == "R2" || k == "Cc" || k == "Rt" || k == "Pout" || k == "outlet") {
      if (!v.first_outlet_key) v.first_outlet_key = &e;
      v.outlet_keys[k] = &e;
      if (k == "R1") v.r1 = f.number(e, ranges::rcr_part);
      else if (k == "R2") v.r2 = f.number(e, ranges::rcr_part);
      else if (k == "Cc") v.cc = f.number(e, ranges::compliance);
      else if (k == "Rt") v.rt = f.number(e, ranges::reflection);
      else if (k == "Pout") v.pout = f.number(e, ranges::pressure);
      else {
        v.outlet_kind = f.text(e);
        if (v.outlet_kind != "wk2" && v.outlet_kind != "wk3" && v.outlet_kind != "reflection")
          f.fail(e, "\"outlet\" must be wk2, wk3 or reflection (got \"" + v.outlet_kind + "\")");
      }
    } else if (k == "inlet_impedance_matching") {
      if (f.boolean(e))
        f.fail(e, "inlet_impedance_matching (R1 following the vessel's impedance as it distends) is "
                  "not modelled by hemotree, whose RCR outlets have fixed R1");
    } else if (k == "visco-elastic") {
      if (f.boolean(e)) f.fail(e, "a visco-elastic wall (\"visco-elastic\": true) is not modelled by hemotree");
    } else if (k == "phi") {
      if (f.number(e) != 0) f.fail(e, "a visco-elastic wall (\"phi\") is not modelled by hemotree");
    } else if (k == "inlet") {
      const std::string type = f.text(e);
      if (type != "Q")
        f.fail(e, "\"inlet\": " + type + ": hemotree's openBF inlet is a flow (Q) waveform");
      v.inlet = true;
      v.inlet_mark = e.mark;
    } else if (k == "inlet file") {
      v.inlet_file = f.text(e);
    } else {
      f.fail(e, "\"" + k + "\" is listed in vessel_keys but not read");  // a slip between the two lists
    }
  }
  if (v.inlet && v.inlet_file.empty()) f.missing("\"inlet file\" for its \"inlet\"");
  if (!v.inlet && !v.inlet_file.empty()) f.fail(*f.find("inlet file"), "\"inlet file\" without \"inlet\"");
  return v;
}
}  // namespace hemotree::openbf

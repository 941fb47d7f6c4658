// openBF's YAML models, read into a Network and written from one. What each key means is
// openBF's own reading of it (src/vessel.jl, network.jl, solver.jl, boundary_conditions.jl of
// openBF 2.x), or, where that code departs from openBF's documentation (docs/src/man/config.md)
// and on request, the documentation's; docs/import.md has the table and the differences.
#include "exchange/openbf.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <deque>
#include <filesystem>
#include <fstream>
#include <functional>
#include <limits>
#include <map>
#include <numbers>
#include <optional>
#include <set>
#include <sstream>
#include <string_view>
#include <unordered_set>
#include <vector>

#include <yaml-cpp/eventhandler.h>
#include <yaml-cpp/yaml.h>

#include "core/errors.hpp"
#include "core/setting_error.hpp"
#include "formats/field_ranges.hpp"

namespace hemotree {

namespace {

namespace fs = std::filesystem;

constexpr double unset = std::numeric_limits<double>::quiet_NaN();

// --- openBF's physics where the model leaves something out ---------------------------------

// openBF's wall thickness where a vessel gives no h0: Avolio's (1980) fit as openBF writes it
// (vessel.jl, the radius in metres): h0 = R (a e^(b R) + c e^(d R)).
double avolio_wall_thickness(double radius) {
  constexpr double a = 0.2802, b = -5.053e2, c = 0.1324, d = -0.1114e2;  // b, d [1/m]
  return radius * (a * std::exp(b * radius) + c * std::exp(d * radius));
}

// openBF's thin-wall law (Poisson ratio 1/2): at the reference area the wave speed is
// c0 = sqrt(beta / (2 rho)) with beta = 4/3 E h0 / R0, and the characteristic impedance is
// rho c0 / A0.
double characteristic_impedance(double density, double youngs_modulus, double wall, double radius) {
  const double c0 = std::sqrt(2.0 / 3.0 * youngs_modulus * wall / (density * radius));
  return density * c0 / (std::numbers::pi * radius * radius);
}

// That law as hemotree's p = p_ext + beta (sqrt(A) - sqrt(A0)): beta = 4 E h0 / (3 sqrt(pi) R0^2)
// [Pa/m] (openBF's own beta, sqrt(pi / A0) h0 E / (1 - 1/4), is this times sqrt(A0)).
double openbf_beta(double youngs_modulus, double wall, double radius) {
  return 4 * youngs_modulus * wall / (3 * std::sqrt(std::numbers::pi) * radius * radius);
}

// A velocity profile u ~ 1 - (r/R)^gamma (openBF's gamma_profile) has the momentum-flux
// coefficient alpha = (gamma + 2) / (gamma + 1); its friction 2 pi mu (gamma + 2) u / rho is
// hemotree's alpha / (alpha - 1) = gamma + 2.
double alpha_of_profile(double gamma) { return (gamma + 2) / (gamma + 1); }
double profile_of_alpha(double alpha) { return (2 - alpha) / (alpha - 1); }

// The accepted ranges of openBF's radii and profile exponent, from hemotree's diameters and
// alpha: alpha >= 1.001 is gamma <= 999, kept a unit inside so that alpha's rounding stays in.
constexpr FieldRange radius_range{ranges::diameter.min / 2, ranges::diameter.max / 2, "m"};
constexpr FieldRange profile_range{0, 998, ""};

// openBF's default profile exponent (vessel.jl: get(config, "gamma_profile", 2)): parabolic.
constexpr double default_profile = 2;

// --- the YAML file and its messages --------------------------------------------------------

struct Entry {
  std::string key;
  YAML::Mark mark;  // the key's
  YAML::Node value;
};

// The model's file, named in every message with the line at fault.
struct Source {
  std::string path;

  [[noreturn]] void fail(const YAML::Mark& mark, const std::string& what) const {
    if (mark.line < 0) throw InputError(path + ": " + what);
    throw InputError(path + ":" + std::to_string(mark.line + 1) + ": " + what);
  }
};

// A YAML mapping's entries in file order; refuses anything else, keys it does not know (with
// `unknown`, checked first, so that a file of many unknown keys is refused at the first) and
// keys given twice (a hash set: many keys cost linear time).
class Fields {
 public:
  // `unknown(key)`: the message for a key this mapping does not have, "" where it has it.
  using Unknown = std::function<std::string(const std::string&)>;

  Fields(const Source& source, const YAML::Node& node, std::string what, const Unknown& unknown = {})
      : source_(source), what_(std::move(what)), mark_(node.Mark()) {
    if (!node.IsMap()) source_.fail(mark_, what_ + " must be a mapping of keys to values");
    std::unordered_set<std::string> seen;
    for (const auto& item : node) {
      if (!item.first.IsScalar()) source_.fail(item.first.Mark(), what_ + ": a key must be a plain name");
      Entry e{item.first.as<std::string>(), item.first.Mark(), item.second};
      if (unknown) {
        const std::string why = unknown(e.key);
        if (!why.empty()) source_.fail(e.mark, what_ + ": " + why);
      }
      if (!seen.insert(e.key).second) source_.fail(e.mark, what_ + ": \"" + e.key + "\" given twice");
      entries_.push_back(std::move(e));
    }
  }

  const std::vector<Entry>& entries() const { return entries_; }
  const YAML::Mark& mark() const { return mark_; }
  const std::string& what() const { return what_; }

  const Entry* find(std::string_view key) const {
    for (const Entry& e : entries_)
      if (e.key == key) return &e;
    return nullptr;
  }
  // A key openBF spelled two ways (openBF 1.x wrote "gamma profile", 2.x "gamma_profile").
  const Entry* find(std::string_view key, std::string_view other) const {
    const Entry* a = find(key);
    const Entry* b = find(other);
    if (a && b) source_.fail(b->mark, what_ + ": \"" + b->key + "\" repeats \"" + a->key + "\"");
    return a ? a : b;
  }
  const Entry& require(std::string_view key) const {
    if (const Entry* e = find(key)) return *e;
    missing(std::string("\"") + std::string(key) + "\"");
  }
  [[noreturn]] void missing(const std::string& what) const { source_.fail(mark_, what_ + ": missing " + what); }

  [[noreturn]] void fail(const Entry& e, const std::string& what) const {
    source_.fail(e.mark, what_ + ": " + what);
  }

  double number(const Entry& e) const {
    double v = unset;
    if (!e.value.IsScalar() || !YAML::convert<double>::decode(e.value, v))
      fail(e, "\"" + e.key + "\" must be a number");
    return v;
  }
  double number(const Entry& e, const FieldRange& range) const {
    const double v = number(e);
    if (!range.contains(v)) fail(e, out_of_range(e.key, range, v));
    return v;
  }
  std::int64_t integer(const Entry& e) const {
    long long v = 0;
    if (!e.value.IsScalar() || !YAML::convert<long long>::decode(e.value, v))
      fail(e, "\"" + e.key + "\" must be an integer");
    return v;
  }
  bool boolean(const Entry& e) const {
    bool v = false;
    if (!e.value.IsScalar() || !YAML::convert<bool>::decode(e.value, v))
      fail(e, "\"" + e.key + "\" must be true or false");
    return v;
  }
  std::string text(const Entry& e) const {
    if (!e.value.IsScalar()) fail(e, "\"" + e.key + "\" must be a plain value");
    return e.value.as<std::string>();
  }

 private:
  const Source& source_;
  std::string what_;
  YAML::Mark mark_;
  std::vector<Entry> entries_;
};

// --- reading files with bounds ------------------------------------------------------------

// openBF's models and inlet tables are small text files (ADAN56's model is 30 kB, its table 22
// rows). Caps on what is read keep a wrong name (a device, a pipe, a file that never ends, a
// huge one) from taking memory and time without bound: far above any model, and below what
// yaml-cpp's nodes (tens of bytes of memory per byte of YAML) can hold comfortably.
constexpr std::size_t model_cap = std::size_t{8} << 20;   // bytes
constexpr std::size_t inlet_cap = std::size_t{64} << 20;  // bytes
constexpr std::size_t line_cap = 4096;                    // bytes of one inlet-table line

// The whole of a regular file of at most `cap` bytes. `named` names it in the IoError of a file
// that cannot be read; `kind` says what the file should be ("an inlet table").
std::string read_capped(const std::string& path, const std::string& named, const std::string& kind, std::size_t cap) {
  const std::string limit = kind + " is a text file of at most " + std::to_string(cap >> 20) + " MB";
  std::error_code error;
  const fs::file_status status = fs::status(path, error);
  if (error || !fs::exists(status))
    throw IoError("cannot read " + named + ": " + (error ? error.message() : std::string("no such file")));
  // Before opening: opening a pipe waits for a writer.
  if (!fs::is_regular_file(status)) throw InputError(path + ": not a regular file; " + limit);
  std::ifstream in(path, std::ios::binary);
  if (!in) throw IoError("cannot read " + named + ": " + std::strerror(errno));
  std::string text;
  std::vector<char> block(1 << 16);
  while (in) {
    in.read(block.data(), static_cast<std::streamsize>(block.size()));
    const auto got = static_cast<std::size_t>(in.gcount());
    if (text.size() + got > cap) throw InputError(path + ": larger than " + std::to_string(cap >> 20) + " MB; " + limit);
    text.append(block.data(), got);
  }
  if (in.bad()) throw IoError("cannot read " + named + ": " + std::strerror(errno));
  return text;
}

// What a document holds, as the parser's events tell it: whether it has any content, where it
// starts and where its last event lies (to see that the parser moves on).
struct DocumentScan : YAML::EventHandler {
  bool content = false;
  YAML::Mark first_content, last;
  void seen(const YAML::Mark& m, bool is_content) {
    last = m;
    if (is_content && !content) first_content = m;
    content |= is_content;
  }
  void OnDocumentStart(const YAML::Mark& m) override { seen(m, false); }
  void OnDocumentEnd() override {}
  void OnNull(const YAML::Mark& m, YAML::anchor_t) override { seen(m, false); }
  void OnAlias(const YAML::Mark& m, YAML::anchor_t) override { seen(m, true); }
  void OnScalar(const YAML::Mark& m, const std::string&, YAML::anchor_t, const std::string&) override { seen(m, true); }
  void OnSequenceStart(const YAML::Mark& m, const std::string&, YAML::anchor_t, YAML::EmitterStyle::value) override {
    seen(m, true);
  }
  void OnSequenceEnd() override {}
  void OnMapStart(const YAML::Mark& m, const std::string&, YAML::anchor_t, YAML::EmitterStyle::value) override {
    seen(m, true);
  }
  void OnMapEnd() override {}
};

// The model: one YAML document. A second one (after "---") would be dropped, so it is refused.
// The documents are walked by the parser's events rather than YAML::LoadAll: yaml-cpp 0.7 makes
// no progress on a ',' where a document should start (",a"), returning one more empty document
// at the same place for ever, and LoadAll then allocated until memory ran out (fuzzing found it).
YAML::Node load_yaml(const std::string& path) {
  const std::string text = read_capped(path, path, "an openBF model", model_cap);
  YAML::Node model;
  try {
    model = YAML::Load(text);
    std::istringstream in(text);
    YAML::Parser parser(in);
    int previous = -1;  // where the last document's last event lay
    for (std::size_t k = 0;; ++k) {
      DocumentScan scan;
      if (!parser.HandleNextDocument(scan)) break;
      if (k > 0 && scan.content)
        Source{path}.fail(scan.first_content, "a second YAML document (after \"---\"); an openBF model is one "
                                      "document, and hemotree reads nothing it would drop");
      if (k > 0 && scan.last.pos <= previous)
        Source{path}.fail(scan.last, "not valid YAML: the parser makes no progress here (a ',' or a ']' "
                                     "where a document should start?)");
      previous = scan.last.pos;
    }
  } catch (const YAML::Exception& e) {
    // yaml-cpp's own message carries "yaml-cpp: error at line L, column C: "; keep its reason.
    Source{path}.fail(e.mark, "not valid YAML: " + e.msg);
  }
  return model;
}

// --- one vessel, as openBF reads it --------------------------------------------------------

// Settings of openBF's solver and output that do not change the model: ignored, and named in
// one note.
const std::set<std::string, std::less<>> ignored_vessel_keys = {"M", "to_save", "initial_pressure",
                                                                "initial_flow", "inlet number"};

struct VesselModel {
  YAML::Mark mark;
  std::string label;
  std::int64_t sn = 0, tn = 0;
  double length = 0, rp = 0, rd = 0, youngs_modulus = 0;
  double wall = unset;                // h0, NaN: openBF's law
  double external_pressure = 0;       // Pext
  YAML::Mark external_pressure_mark;  // where Pext was given
  std::optional<double> profile;      // gamma_profile, or openBF 1.x's "gamma profile"
  bool profile_spaced = false;        // given as "gamma profile", which openBF 2.x does not read
  YAML::Mark profile_mark;
  // The outlet's keys, NaN where absent; `outlet` (wk2, wk3, reflection) only names the kind.
  double r1 = unset, r2 = unset, cc = unset, rt = unset, pout = unset;
  std::string outlet_kind;
  const Entry* first_outlet_key = nullptr;
  std::map<std::string, const Entry*, std::less<>> outlet_keys;
  // openBF 1.x put the inlet on a vessel: "inlet: Q" and "inlet file".
  bool inlet = false;
  std::string inlet_file;
  YAML::Mark inlet_mark;
};

bool has_outlet(const VesselModel& v) { return v.first_outlet_key != nullptr; }

// The keys of a vessel that hemotree reads, refuses with a reason, or ignores.
const std::set<std::string, std::less<>> vessel_keys = {
    "label", "sn", "tn", "L", "E", "R0", "Rp", "Rd", "h0", "Pext", "gamma_profile", "gamma profile",
    "R1", "R2", "Cc", "Rt", "Pout", "outlet", "inlet_impedance_matching", "visco-elastic", "phi", "inlet",
    "inlet file", "M", "to_save", "initial_pressure", "initial_flow", "inlet number"};

std::string unknown_vessel_key(const std::string& key) {
  return vessel_keys.contains(key) ? ""
                                   : "\"" + key + "\" is not an openBF vessel key that hemotree reads or may safely ignore";
}

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

// Three significant digits, for a figure a note reports.
std::string three_digits(double value) {
  char text[32];
  std::snprintf(text, sizeof text, "%.3g", value);
  return format_number(std::strtod(text, nullptr));
}

// --- the inlet table -----------------------------------------------------------------------

// openBF's inlet file: two columns, t [s] and Q [m^3/s], over one cardiac cycle whose period is
// the last time (network.jl: cardiac_period = input_data[end, 1]); the flow at t is interpolated
// linearly at t mod period. hemotree's table wraps from its last sample to its first, so the
// sample at t = period (the next cycle's t = 0) is dropped.
struct Row {
  double t, q;
  std::size_t line;
};

std::vector<Row> read_rows(const std::string& path, const std::string& named_by) {
  const std::string text = read_capped(path, "the inlet file " + path + " (" + named_by + ")", "an inlet table", inlet_cap);
  std::vector<Row> rows;
  std::size_t number = 0;
  for (std::size_t start = 0; start < text.size();) {
    const std::size_t stop = std::min(text.find('\n', start), text.size());
    ++number;
    if (stop - start > line_cap)
      throw InputError(path + ":" + std::to_string(number) + ": a line longer than " + std::to_string(line_cap) +
                       " characters; an inlet table has two numbers a line, t [s] and Q [m^3/s]");
    double row[2];
    std::size_t count = 0;
    const char* c = text.data() + start;
    const char* end = text.data() + stop;
    start = stop + 1;
    while (true) {
      while (c < end && (*c == ' ' || *c == '\t' || *c == '\r' || *c == ',')) ++c;
      if (c == end) break;
      double value = 0;
      const auto [next, error] = std::from_chars(c, end, value);
      if (error != std::errc() || count == 2 || !std::isfinite(value)) count = 3;
      if (count == 3) break;
      row[count++] = value;
      c = next;
    }
    if (count == 0) continue;
    if (count != 2) throw InputError(path + ":" + std::to_string(number) + ": expected two numbers, t [s] and Q [m^3/s]");
    rows.push_back({row[0], row[1], number});
  }
  return rows;
}

// The flow openBF reads at time t in [0, period] (boundary_conditions.jl, inlet_from_data):
// the first pair of consecutive rows, in file order, whose times enclose t, interpolated
// linearly. A pair that goes back in time encloses nothing, and a pair only counts beyond the
// latest time of the rows before it (earlier pairs cover everything up to there), so openBF's
// reading is a chain of pieces: each pair that reaches past the running latest time gives the
// piece from there to its end. Found by bisection, so that a long table costs n log n.
class OpenbfFlow {
 public:
  explicit OpenbfFlow(const std::vector<Row>& rows) {
    double latest = rows.front().t;
    for (std::size_t k = 0; k + 1 < rows.size(); ++k)
      if (rows[k + 1].t > latest) {
        pieces_.push_back({rows[k + 1].t, &rows[k], &rows[k + 1]});
        latest = rows[k + 1].t;
      }
  }
  double operator()(double t) const {
    const auto p = std::lower_bound(pieces_.begin(), pieces_.end(), t,
                                    [](const Piece& piece, double time) { return piece.end < time; });
    if (p == pieces_.end()) return std::numeric_limits<double>::quiet_NaN();
    const Row &a = *p->from, &b = *p->to;
    return a.q + (t - a.t) * (b.q - a.q) / (b.t - a.t);
  }

 private:
  struct Piece {
    double end;
    const Row *from, *to;
  };
  std::vector<Piece> pieces_;
};

Waveform read_inlet_table(const std::string& path, const std::string& named_by, const ImportOptions& options) {
  const std::vector<Row> rows = read_rows(path, named_by);
  // openBF interpolates between a row and the next, so it needs two rows: t = 0 and the period
  // (two rows with one flow are a constant inflow, as vexport writes it).
  if (rows.size() < 2) throw InputError(path + ": an inlet table needs at least 2 rows, t = 0 and the period");
  if (rows.front().t != 0)
    throw InputError(path + ":" + std::to_string(rows.front().line) + ": openBF's inlet table starts at t = 0 (got " +
                     format_number(rows.front().t) + " s)");
  const double period = rows.back().t;
  // Digitised tables can step back in time (the circle of Willis' does, four times). hemotree
  // keeps the rows that advance and says how far that lies from openBF's reading.
  Waveform w;
  w.shape = Waveform::Shape::table;
  w.period = period;
  std::vector<std::size_t> backward;
  for (const Row& r : rows) {
    if (!w.time.empty() && !(r.t > w.time.back())) {
      if (r.line == rows.back().line || r.t == w.time.back())
        throw InputError(path + ":" + std::to_string(r.line) + ": times must increase (" + format_number(r.t) +
                         " s after " + format_number(w.time.back()) + " s)" +
                         (r.line == rows.back().line ? "; the last row's is the period" : ""));
      backward.push_back(r.line);
      continue;
    }
    w.time.push_back(r.t);
    w.value.push_back(r.q);
  }
  if (!(period > 0)) throw InputError(path + ": the period (the last time) must be positive");
  const double last = w.value.back();
  w.time.pop_back();
  w.value.pop_back();
  // Two rows leave one sample; hemotree's table needs two: openBF's flow at mid-period joins it
  // (the same flow where the two rows give one, a constant inflow).
  if (w.time.size() == 1) {
    w.time.push_back(period / 2);
    w.value.push_back((w.value.front() + last) / 2);
  }
  check_waveform(w, path);
  if (!backward.empty()) {
    std::string lines;
    // A few line numbers say where; a table that steps back everywhere is told by its count.
    for (std::size_t k = 0; k < std::min<std::size_t>(backward.size(), 10); ++k)
      lines += (lines.empty() ? "" : ", ") + std::to_string(backward[k]);
    if (backward.size() > 10) lines += " and " + std::to_string(backward.size() - 10) + " more";
    const OpenbfFlow openbf(rows);
    double deviation = 0;
    constexpr int samples = 20000;
    for (int k = 0; k < samples; ++k) {
      const double t = period * k / samples;
      deviation = std::max(deviation, std::abs(w(t) - openbf(t)));
    }
    for (const Row& r : rows)
      if (r.t < period) deviation = std::max(deviation, std::abs(w(r.t) - openbf(r.t)));
    options.note("inlet table " + path + ": rows " + lines + " go back in time and are left out; the flow then " +
                 "differs from openBF's reading by at most " + three_digits(deviation) + " m^3/s (" +
                 three_digits(100 * deviation / w.peak()) + " % of the peak)");
  }
  if (last != w.value.front())
    options.note("inlet table " + path + ": its flow at the period (" + format_number(last) +
                 " m^3/s) differs from that at t = 0 (" + format_number(w.value.front()) +
                 "); hemotree's periodic table joins the last but one row to t = 0");
  return w;
}

fs::path beside(const std::string& yaml_path, const std::string& name) {
  const fs::path p(name);
  return p.is_absolute() ? p : fs::path(yaml_path).parent_path() / p;
}

std::string plural(std::size_t n, std::string_view what) {
  return std::to_string(n) + " " + std::string(what) + (n == 1 ? "" : "s");
}

// --- the network ---------------------------------------------------------------------------

struct Topology {
  std::map<std::int64_t, std::vector<std::size_t>> leaving, entering;  // node id -> vessel positions
};

Topology topology_of(const std::vector<VesselModel>& vessels) {
  Topology t;
  for (std::size_t k = 0; k < vessels.size(); ++k) {
    t.leaving[vessels[k].sn].push_back(k);
    t.entering[vessels[k].tn].push_back(k);
  }
  return t;
}

// Generations: the number of vessels between the inlet node and a vessel's nearer end.
// openBF networks need not be trees (the circle of Willis closes a loop), so this is a
// breadth-first search over the undirected graph; a vessel it cannot reach is refused.
std::vector<std::int32_t> generations(const Source& source, const std::vector<VesselModel>& vessels,
                                      std::int64_t inlet_node) {
  std::map<std::int64_t, std::vector<std::size_t>> touching;
  for (std::size_t k = 0; k < vessels.size(); ++k) {
    touching[vessels[k].sn].push_back(k);
    touching[vessels[k].tn].push_back(k);
  }
  std::map<std::int64_t, std::int32_t> depth{{inlet_node, 0}};
  std::deque<std::int64_t> queue{inlet_node};
  while (!queue.empty()) {
    const std::int64_t n = queue.front();
    queue.pop_front();
    for (std::size_t k : touching[n]) {
      const std::int64_t other = vessels[k].sn == n ? vessels[k].tn : vessels[k].sn;
      if (depth.emplace(other, depth[n] + 1).second) queue.push_back(other);
    }
  }
  std::vector<std::int32_t> g(vessels.size());
  for (std::size_t k = 0; k < vessels.size(); ++k) {
    const auto a = depth.find(vessels[k].sn), b = depth.find(vessels[k].tn);
    if (a == depth.end())
      source.fail(vessels[k].mark, "vessel " + std::to_string(k + 1) + " (" + vessels[k].label +
                                       ") is not connected to the inlet node " + std::to_string(inlet_node));
    g[k] = std::min(a->second, b->second);
  }
  return g;
}

}  // namespace

Network read_openbf(const std::string& path, const ImportOptions& options, OpenbfReading reading) {
  const bool as_coded = reading == OpenbfReading::code;
  const Source source{path};
  const YAML::Node root = load_yaml(path);
  if (!root.IsMap()) source.fail(root.Mark(), "an openBF model is a mapping with \"network\", \"blood\" and \"solver\"");
  const Fields top(source, root, "model", [](const std::string& key) -> std::string {
    static const std::set<std::string, std::less<>> known = {
        "project_name", "project name", "inlet_file", "write_results", "output_directory", "solver", "blood", "network"};
    return known.contains(key) ? "" : "\"" + key + "\" is not an openBF key that hemotree reads or may safely ignore";
  });

  std::set<std::string, std::less<>> ignored;
  std::string project_name, inlet_file;
  YAML::Mark inlet_file_mark;
  double density = unset, viscosity = unset;
  std::vector<VesselModel> vessels;
  std::deque<Fields> vessel_fields;  // the vessels' entries, which VesselModel points into

  for (const Entry& e : top.entries()) {
    if (e.key == "project_name" || e.key == "project name") {
      project_name = top.text(e);
    } else if (e.key == "inlet_file") {
      inlet_file = top.text(e);
      inlet_file_mark = e.mark;
    } else if (e.key == "write_results" || e.key == "output_directory") {
      ignored.insert(e.key);
    } else if (e.key == "solver") {
      const Fields solver(source, e.value, "solver", [](const std::string& key) -> std::string {
        static const std::set<std::string, std::less<>> known = {"Ccfl", "cycles", "jump", "convergence_tolerance",
                                                                 "convergence tolerance"};
        return known.contains(key) ? "" : "\"" + key + "\" is not an openBF solver setting that hemotree knows";
      });
      for (const Entry& s : solver.entries()) ignored.insert(s.key);
    } else if (e.key == "blood") {
      const Fields blood(source, e.value, "blood", [](const std::string& key) -> std::string {
        return key == "rho" || key == "mu" ? "" : "\"" + key + "\" is not an openBF blood key (rho, mu)";
      });
      density = blood.number(blood.require("rho"), ranges::density);
      viscosity = blood.number(blood.require("mu"), ranges::viscosity);
    } else if (e.key == "network") {
      if (!e.value.IsSequence() || e.value.size() == 0)
        top.fail(e, "\"network\" must be a list of vessels");
      for (std::size_t k = 0; k < e.value.size(); ++k)
        vessels.push_back(read_vessel(source, e.value[k], k + 1, ignored, vessel_fields));
    }
  }
  top.require("network");
  top.require("blood");

  // One velocity profile and one external pressure for the whole network: hemotree has one
  // blood.alpha and one interstitial pressure. openBF 2.x's code reads "gamma_profile" only:
  // where a file spells it "gamma profile" (openBF 1.x), the code takes its default.
  std::size_t spaced_profiles = 0;
  const auto profile_of = [&](const VesselModel& v) {
    return as_coded && v.profile_spaced ? default_profile : v.profile.value_or(default_profile);
  };
  for (const VesselModel& v : vessels) spaced_profiles += v.profile_spaced;
  const double profile = profile_of(vessels.front());
  const double external_pressure = vessels.front().external_pressure;
  for (std::size_t k = 1; k < vessels.size(); ++k) {
    const VesselModel& v = vessels[k];
    if (profile_of(v) != profile)
      source.fail(v.profile.has_value() ? v.profile_mark : v.mark,
                  "vessel " + std::to_string(k + 1) + ": gamma_profile " + format_number(profile_of(v)) +
                      " differs from vessel 1's " + format_number(profile) +
                      ": hemotree has one velocity profile (blood alpha) for the network");
    if (v.external_pressure != external_pressure)
      source.fail(v.external_pressure_mark.line >= 0 ? v.external_pressure_mark : v.mark,
                  "vessel " + std::to_string(k + 1) + ": Pext " + format_number(v.external_pressure) +
                      " Pa differs from vessel 1's " + format_number(external_pressure) +
                      " Pa: hemotree takes one external pressure for the network");
  }

  // The inlet: openBF 2.x feeds node 1 from inlet_file (default PROJECT_inlet.dat); 1.x marked
  // the vessel with "inlet: Q" and named its file there.
  const Topology topo = topology_of(vessels);
  std::size_t inlet_vessel = vessels.size();
  std::string inlet_named_by;
  for (std::size_t k = 0; k < vessels.size(); ++k) {
    if (!vessels[k].inlet) continue;
    if (inlet_vessel != vessels.size())
      source.fail(vessels[k].inlet_mark, "vessel " + std::to_string(k + 1) +
                                             ": a second inlet; hemotree's openBF import takes one");
    if (!inlet_file.empty())
      source.fail(vessels[k].inlet_mark, "vessel " + std::to_string(k + 1) + ": \"inlet\" with a top-level inlet_file");
    inlet_vessel = k;
    inlet_file = vessels[k].inlet_file;
    inlet_named_by = "named on " + path + ":" + std::to_string(vessels[k].inlet_mark.line + 1);
  }
  if (inlet_vessel == vessels.size()) {
    const auto at_one = topo.leaving.find(1);
    if (at_one == topo.leaving.end())
      source.fail(top.mark(), "no vessel has \"sn\": 1, the node openBF feeds from the inlet file");
    if (at_one->second.size() > 1)
      source.fail(vessels[at_one->second[1]].mark,
                  "vessels " + std::to_string(at_one->second[0] + 1) + " and " + std::to_string(at_one->second[1] + 1) +
                      " both leave the inlet node 1; openBF's inlet feeds one vessel");
    inlet_vessel = at_one->second.front();
    if (inlet_file.empty()) {
      if (project_name.empty())
        source.fail(top.mark(), "no inlet_file and no project_name to name PROJECT_inlet.dat");
      inlet_file = project_name + "_inlet.dat";
      inlet_named_by = "openBF's default for project_name " + project_name;
    } else {
      inlet_named_by = "named on " + path + ":" + std::to_string(inlet_file_mark.line + 1);
    }
  }
  const std::int64_t inlet_node = vessels[inlet_vessel].sn;
  if (topo.entering.contains(inlet_node))
    source.fail(vessels[topo.entering.at(inlet_node).front()].mark,
                "vessel " + std::to_string(topo.entering.at(inlet_node).front() + 1) + ": ends at the inlet node " +
                    std::to_string(inlet_node));
  // Every other node is entered by a vessel (openBF has no other source of flow), and an
  // outlet node by exactly one (its 0D model sits at that vessel's end).
  for (const auto& [node, from_here] : topo.leaving)
    if (node != inlet_node && !topo.entering.contains(node))
      source.fail(vessels[from_here.front()].mark,
                  "node " + std::to_string(node) + ": vessels leave it but none enters it, and it is not the inlet");
  for (const auto& [node, into] : topo.entering)
    if (!topo.leaving.contains(node) && into.size() > 1)
      source.fail(vessels[into[1]].mark, "node " + std::to_string(node) + ": vessels " + std::to_string(into[0] + 1) +
                                             " and " + std::to_string(into[1] + 1) +
                                             " end there and none leaves it; openBF has no outlet shared by two vessels");
  const std::vector<std::int32_t> generation = generations(source, vessels, inlet_node);

  Network net;
  std::map<std::int64_t, std::int32_t> node_index;
  for (const auto& v : vessels) node_index.emplace(v.sn, 0), node_index.emplace(v.tn, 0);
  net.reserve(vessels.size(), node_index.size());
  for (auto& [id, index] : node_index) index = net.add_node(id);

  Blood blood;
  blood.density = density;
  blood.rheology = Rheology::newtonian;
  blood.newtonian_viscosity = viscosity;
  blood.alpha = alpha_of_profile(profile);
  // openBF's code writes its momentum flux with alpha = 1 whatever the profile, which sets
  // its friction only (docs/import.md).
  if (as_coded) blood.momentum_flux_coefficient = 1;
  net.blood = blood;

  std::size_t law_walls = 0, tapered_law_walls = 0, ratio_walls = 0, open_ends = 0, wk2 = 0, wk3_without_r2 = 0;
  std::size_t tapers = 0;
  nlohmann::json labels = nlohmann::json::array();
  for (std::size_t k = 0; k < vessels.size(); ++k) {
    const VesselModel& v = vessels[k];
    const std::string name = "vessel " + std::to_string(k + 1);
    // openBF's code (vessel.jl) sets the radius of cell i to Rp + (Rd - Rp) / (M - 1) (i - 1) dx:
    // a slope per cell taken as one per metre, so that along the vessel the radius changes by
    // (Rd - Rp) dx, dx <= 1 mm, a thousandth of Rd - Rp or less. Its tapered vessels are
    // uniform at Rp; its documentation tapers them linearly from Rp to Rd.
    tapers += v.rd != v.rp;
    const double rd = as_coded ? v.rp : v.rd;
    double wall = v.wall;
    if (std::isnan(wall)) {
      // openBF evaluates its law along the vessel: at Rp in its code; one thickness per vessel,
      // as documented, is its value at the mean radius (openBF 1.x's choice).
      if (options.wall_ratio) {
        wall = *options.wall_ratio * 2 * v.rp;
        ++ratio_walls;
      } else {
        wall = avolio_wall_thickness((v.rp + rd) / 2);
        ++law_walls;
        if (v.rp != rd) ++tapered_law_walls;
      }
      if (!ranges::wall_thickness.contains(wall))
        source.fail(v.mark, name + ": the wall thickness openBF derives from the radius, " +
                                out_of_range("h0", ranges::wall_thickness, wall));
    }
    net.add_vessel(static_cast<std::int64_t>(k + 1), node_index.at(v.sn), node_index.at(v.tn), v.length, 2 * v.rp,
                   wall, v.youngs_modulus, generation[k]);
    if (rd != v.rp) {
      net.distal_diameter.resize(k, unset);
      net.distal_diameter.push_back(2 * rd);
    }
    // openBF's tube law is the thin wall's (Poisson ratio 1/2) at its external pressure, given
    // here as beta so that no option of hemosolve (its thick-wall law above h/D = 0.1, its one
    // external pressure) changes it; a tapered vessel's beta follows 1 / D^2 (E h constant).
    const double beta = openbf_beta(v.youngs_modulus, wall, v.rp);
    if (!ranges::beta.contains(beta))
      source.fail(v.mark, name + ": openBF's tube law 4 E h0 / (3 sqrt(pi) R^2) gives " + out_of_range("beta", ranges::beta, beta));
    net.beta.push_back(beta);
    net.reference_pressure.push_back(v.external_pressure);
    labels.push_back(v.label);

    // The outlet: at a vessel whose end no vessel leaves. openBF decides by the keys given
    // (vessel.jl), "outlet" only names the kind: R1, R2 and Cc a three-element Windkessel;
    // R1 and Cc alone a two-element one; Rt (or nothing) a reflection coefficient (0 by
    // default: non-reflecting). The two-element Windkessel's R1 is, in openBF's documentation,
    // the total resistance, split into the vessel's characteristic impedance Z and R1 - Z; its
    // code keeps R1 before the compliance and puts R2 = R1 - Z beyond it (total 2 R1 - Z).
    const bool terminal = !topo.leaving.contains(v.tn);
    if (!terminal) {
      if (has_outlet(v))
        source.fail(v.first_outlet_key->mark, name + ": outlet key \"" + v.first_outlet_key->key +
                                                  "\" on a vessel whose end node " + std::to_string(v.tn) +
                                                  " other vessels leave");
      continue;
    }
    // Messages point at the key at fault, or at the vessel for one missing.
    const auto fail = [&](std::string_view key, const std::string& what) {
      const auto e = v.outlet_keys.find(key);
      source.fail(e != v.outlet_keys.end() ? e->second->mark : v.mark, name + ": " + what);
    };
    Outlet o;
    o.vessel = static_cast<std::int32_t>(k);
    const bool windkessel = !std::isnan(v.r1) || !std::isnan(v.r2) || !std::isnan(v.cc);
    if (windkessel) {
      if (!std::isnan(v.rt)) fail("Rt", "give a Windkessel (R1, R2, Cc) or a reflection coefficient (Rt), not both");
      if (v.outlet_kind == "reflection") fail("outlet", "\"outlet\": reflection with Windkessel keys (R1, R2, Cc)");
      if (std::isnan(v.r1)) fail("", "a Windkessel outlet needs \"R1\"");
      if (std::isnan(v.cc)) fail("", "a Windkessel outlet needs \"Cc\"");
      o.type = BoundaryType::rcr;
      o.c = v.cc;
      o.p_out = std::isnan(v.pout) ? 0.0 : v.pout;
      if (!std::isnan(v.r2) && v.r2 != 0) {
        if (v.outlet_kind == "wk2") fail("outlet", "\"outlet\": wk2 with \"R2\" (a two-element Windkessel has one resistance)");
        if (v.r1 == 0) fail("R1", "\"R1\" = 0: openBF reads a zero proximal resistance as a reflection outlet");
        o.r1 = v.r1;
        o.r2 = v.r2;
      } else {
        // Z at the vessel's last cell: at Rd as documented, at (about) Rp in the code.
        const double z = characteristic_impedance(density, v.youngs_modulus,
                                                  std::isnan(v.wall) ? avolio_wall_thickness(rd) : v.wall, rd);
        if (!(v.r1 > z))
          fail("R1", "\"R1\" " + format_number(v.r1) + " Pa s/m^3 of a two-element Windkessel is not above the vessel's "
               "characteristic impedance Z = " + format_number(z) + " Pa s/m^3, so R2 = R1 - Z would not be positive");
        o.r1 = as_coded ? v.r1 : z;
        o.r2 = v.r1 - z;
        ++wk2;
        if (v.outlet_kind == "wk3") ++wk3_without_r2;
      }
    } else {
      if (!std::isnan(v.pout)) fail("Pout", "\"Pout\" belongs to a Windkessel outlet (R1, R2, Cc)");
      if (v.outlet_kind == "wk2" || v.outlet_kind == "wk3") fail("outlet", "\"outlet\": " + v.outlet_kind + " without R1 and Cc");
      o.type = BoundaryType::reflection;
      o.reflection = std::isnan(v.rt) ? 0.0 : v.rt;
      if (!has_outlet(v)) ++open_ends;
    }
    net.outlets.push_back(o);
  }
  if (!net.distal_diameter.empty()) net.distal_diameter.resize(vessels.size(), unset);

  Inlet inlet;
  inlet.vessel = static_cast<std::int64_t>(inlet_vessel + 1);
  inlet.waveform = read_inlet_table(beside(path, inlet_file).string(), inlet_named_by, options);
  net.inlet = inlet;

  net.provenance = {{"tool", "vimport"}, {"format", "openbf"}, {"source", path}, {"labels", labels}};
  if (!project_name.empty()) net.provenance["project_name"] = project_name;
  net.provenance["external_pressure"] = external_pressure;

  // What was assumed, one line each.
  // Where openBF's code and its documentation part, one line each: what was built, and how to
  // get the other reading (docs/import.md).
  const std::string reading_note = as_coded ? " (openBF's code; " + placeholder("as_documented") + " for its documentation's reading)"
                                            : " (openBF's documentation; its code differs: vimport's default)";
  if (tapers > 0)
    options.note(plural(tapers, "tapered vessel") + " (Rp != Rd): " +
                 (as_coded ? "uniform at Rp, as openBF's code builds them (its radius changes by (Rd - Rp) dx, dx <= 1 mm, "
                             "along the vessel), where its documentation tapers them linearly to Rd"
                           : "tapered linearly from Rp to Rd, as openBF documents them; its code keeps them uniform at Rp") +
                 reading_note);
  if (spaced_profiles > 0)
    options.note("\"gamma profile\" (openBF 1.x's spelling) on " + plural(spaced_profiles, "vessel") + ": " +
                 (as_coded ? "not read by openBF 2.x's code, which takes its default gamma_profile 2 (friction 8 pi mu, "
                             "blood alpha 4/3), where the documented key gives gamma " +
                                 format_number(vessels.front().profile.value_or(default_profile))
                           : "read as the profile exponent gamma (blood alpha " + three_digits(blood.alpha) +
                                 "), which openBF 2.x's code ignores for its default 2") +
                 reading_note);
  if (wk2 > 0)
    options.note(plural(wk2, "two-element Windkessel outlet") + " (R1 and Cc" +
                 (wk3_without_r2 > 0 ? ", " + std::to_string(wk3_without_r2) + " of them marked wk3 without R2" : "") +
                 "): " +
                 (as_coded ? "R1 kept before the compliance and R2 = R1 - Z beyond it, Z the vessel's characteristic "
                             "impedance (total 2 R1 - Z), as openBF's code builds them; its documentation makes R1 the "
                             "total, split into Z and R1 - Z"
                           : "R1 taken as the total resistance, split into the vessel's characteristic impedance Z and "
                             "R1 - Z, as openBF documents it; its code adds R2 = R1 - Z to R1") +
                 reading_note);
  if (law_walls > 0)
    options.note("wall thickness from openBF's law h0 = R (0.2802 e^(-505.3 R) + 0.1324 e^(-11.14 R)) [R in m] for " +
                 plural(law_walls, "vessel") +
                 (tapered_law_walls > 0 ? " (at the mean radius for the " + plural(tapered_law_walls, "tapered vessel") + ")"
                  : as_coded && tapers > 0 ? " (at Rp, as openBF's code has it, for the tapered ones)"
                                           : std::string()));
  if (ratio_walls > 0)
    options.note("wall thickness h = " + format_number(*options.wall_ratio) + " D for " + plural(ratio_walls, "vessel") +
                 " without h0 (" + placeholder("wall_ratio") + ")");
  if (open_ends > 0)
    options.note(plural(open_ends, "outlet") + " without outlet keys: openBF's default, non-reflecting (Rt = 0)");
  options.note("tube laws: openBF's thin wall, each vessel's beta = 4 E h0 / (3 sqrt(pi) R^2) at its reference_pressure, "
               "openBF's external pressure Pext = " + format_number(external_pressure) +
               " Pa; hemosolve's " + placeholder("thick_wall_ratio") + " and " + placeholder("external_pressure") +
               " do not change them");
  options.note(as_coded ? "momentum flux: alpha = 1 (blood momentum_flux_coefficient), as openBF's code has it; the "
                         "friction and the wall shear stress from the profile (blood alpha " + three_digits(blood.alpha) + ")" +
                             reading_note
                       : "momentum flux: blood alpha " + three_digits(blood.alpha) +
                             " in the flux as in the friction, as openBF documents the profile; its code takes 1 in "
                             "the flux" + reading_note);
  if (!ignored.empty()) {
    std::string list;
    for (const std::string& k : ignored) list += (list.empty() ? "" : ", ") + k;
    options.note("openBF solver and output settings ignored: " + list);
  }
  fill_missing_walls(net, options);
  return net;
}

// --- writing -------------------------------------------------------------------------------

namespace {

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

}  // namespace

void write_openbf(const Network& net, OutputStream& out, const std::string& inlet_path) {
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
  // openBF's one external pressure: the reference pressure of the vessels whose tube law is
  // given by beta, else what an import from openBF recorded, else 0.
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

  for (std::size_t v = 0; v < nv; ++v) {
    // A tube law given by beta is openBF's thin wall with E h0 = 3 beta A0 / (4 sqrt(pi)) at the
    // vessel's `from` end: h0 is the vessel's (or openBF's law), E follows, or stays the vessel's
    // where beta is that E and h0's (an import from openBF). Along a tapered vessel hemotree's
    // given beta goes as 1 / D^2, as openBF's documented law with h0 and E fixed.
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
    y = "  - label: " + yaml_string(own_label ? (*labels)[v].get<std::string>() : "v" + std::to_string(net.id[v])) + "\n";
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
    out << y;
  }

  OutputStream table(inlet_path);
  for (const auto& [t, q] : inlet_rows(*inflow)) table << yaml_real(t) << ' ' << yaml_real(q) << '\n';
  table.commit();
}

}  // namespace hemotree

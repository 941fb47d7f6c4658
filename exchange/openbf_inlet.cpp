// openBF's inlet table as hemotree's periodic flow waveform.
#include <algorithm>
#include <charconv>
#include <cstdlib>

#include "exchange/openbf_model.hpp"

namespace hemotree::openbf {

namespace {

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
}  // namespace

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
}  // namespace hemotree::openbf

#include "solver/vessel_table.hpp"

#include <charconv>
#include <cmath>
#include <stdexcept>
#include <string_view>

#include "formats/quoting.hpp"

namespace hemotree {

const VesselTable::Column* VesselTable::find(const std::string& name) const {
  for (const Column& c : columns_)
    if (c.name == name) return &c;
  return nullptr;
}

namespace {
void check_size(std::size_t size, std::size_t rows, const std::string& name) {
  if (size != rows)
    throw std::invalid_argument("VesselTable: column " + name + " has " + std::to_string(size) + " rows, not " +
                                std::to_string(rows));
}
}  // namespace

void VesselTable::push(Column c) {
  // Quoted once here, not per row: a name or label may hold anything a user typed.
  c.json_name = json_quoted(c.name);
  for (const std::string& label : c.labels) c.json_labels.push_back(json_quoted(label));
  columns_.push_back(std::move(c));
}

void VesselTable::add_integer(std::string name, std::vector<std::int64_t> values) {
  check_size(values.size(), rows_, name);
  Column c;
  c.name = std::move(name);
  c.kind = Kind::integer;
  c.integer = std::move(values);
  push(std::move(c));
}

void VesselTable::add_number(std::string name, std::vector<double> values) {
  check_size(values.size(), rows_, name);
  Column c;
  c.name = std::move(name);
  c.kind = Kind::number;
  c.number = std::move(values);
  push(std::move(c));
}

void VesselTable::add_text(std::string name, std::vector<std::uint8_t> codes, std::vector<std::string> labels) {
  check_size(codes.size(), rows_, name);
  for (const std::uint8_t k : codes)
    if (k >= labels.size()) throw std::invalid_argument("VesselTable: column " + name + " has a code without a label");
  Column c;
  c.name = std::move(name);
  c.kind = Kind::text;
  c.code = std::move(codes);
  c.labels = std::move(labels);
  push(std::move(c));
}

void write_csv_number(OutputStream& out, double x) {
  if (!std::isfinite(x)) return;
  char text[32];
  out << std::string_view(text, static_cast<std::size_t>(std::to_chars(text, text + sizeof text, x).ptr - text));
}

void write_json_number(OutputStream& out, double x) {
  if (!std::isfinite(x)) {
    out << "null";
    return;
  }
  char text[32];
  const std::string_view s(text, static_cast<std::size_t>(std::to_chars(text, text + sizeof text, x).ptr - text));
  out << s;
  if (s.find_first_of(".e") == std::string_view::npos) out << ".0";
}

void VesselTable::write_json_row(OutputStream& out, std::size_t row) const {
  out << '{';
  for (std::size_t f = 0; f < columns_.size(); ++f) {
    const Column& c = columns_[f];
    out << (f ? "," : "") << c.json_name << ':';
    switch (c.kind) {
      case Kind::integer:
        if (c.integer[row] == null_integer) out << "null";
        else out << std::to_string(c.integer[row]);
        break;
      case Kind::number:
        write_json_number(out, c.number[row]);
        break;
      case Kind::text:
        out << c.json_labels[c.code[row]];
        break;
    }
  }
  out << '}';
}

}  // namespace hemotree

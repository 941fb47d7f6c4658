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
void append_integer(std::string& text, std::int64_t x) {
  char digits[24];
  text.append(digits, std::to_chars(digits, digits + sizeof digits, x).ptr);
}
}  // namespace

void VesselTable::push(Column c) {
  c.rows = rows_;
  // Quoted once here, not per row: a name or label may hold anything a user typed.
  c.json_name = json_quoted(c.name);
  for (const std::string& label : c.labels) {
    c.json_labels.push_back(json_quoted(label));
    c.csv_labels.push_back(csv_field(label));
  }
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

void VesselTable::push_view(std::string name, Kind kind, std::size_t size, const std::byte* first, std::size_t stride) {
  check_size(size, rows_, name);
  Column c;
  c.name = std::move(name);
  c.kind = kind;
  c.view = first;
  c.stride = stride;
  push(std::move(c));
}

void VesselTable::add_integer_view(std::string name, std::span<const std::int64_t> values) {
  push_view(std::move(name), Kind::integer, values.size(), reinterpret_cast<const std::byte*>(values.data()),
            sizeof(std::int64_t));
}

void VesselTable::add_number_view(std::string name, std::span<const double> values) {
  push_view(std::move(name), Kind::number, values.size(), reinterpret_cast<const std::byte*>(values.data()), sizeof(double));
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

void append_csv_number(std::string& text, double x) {
  if (!std::isfinite(x)) return;
  char digits[32];
  text.append(digits, std::to_chars(digits, digits + sizeof digits, x).ptr);
}

void append_json_number(std::string& text, double x) {
  if (!std::isfinite(x)) {
    text += "null";
    return;
  }
  char digits[32];
  const std::string_view s(digits, static_cast<std::size_t>(std::to_chars(digits, digits + sizeof digits, x).ptr - digits));
  text += s;
  if (s.find_first_of(".e") == std::string_view::npos) text += ".0";
}

void VesselTable::append_json_row(std::string& text, std::size_t row) const {
  text += '{';
  for (std::size_t f = 0; f < columns_.size(); ++f) {
    const Column& c = columns_[f];
    if (f) text += ',';
    text += c.json_name;
    text += ':';
    switch (c.kind) {
      case Kind::integer:
        if (const std::int64_t x = c.integer_at(row); x == null_integer) text += "null";
        else append_integer(text, x);
        break;
      case Kind::number:
        append_json_number(text, c.number_at(row));
        break;
      case Kind::text:
        text += c.json_labels[c.code[row]];
        break;
    }
  }
  text += '}';
}

void VesselTable::append_csv_row(std::string& text, std::size_t row) const {
  for (std::size_t f = 0; f < columns_.size(); ++f) {
    if (f) text += ',';
    const Column& c = columns_[f];
    switch (c.kind) {
      case Kind::integer:
        if (const std::int64_t x = c.integer_at(row); x != null_integer) append_integer(text, x);
        break;
      case Kind::number:
        append_csv_number(text, c.number_at(row));  // summary.json's text of the same double
        break;
      case Kind::text:
        text += c.csv_labels[c.code[row]];
        break;
    }
  }
  text += '\n';
}

}  // namespace hemotree

// The per-vessel results of a run as a table of columns (structure of arrays): one row per
// vessel in the network's order, each column a name and its values. A full tree's 3.8 million
// rows are 8 bytes a value here; as JSON objects in memory they were 2.6 kB a vessel, more
// than the whole solver. summary.json, vessels.csv, results.vtp and the group statistics are
// all written from it, so they hold the same values. A column is held by the table, or is a
// view of values that lie elsewhere (the network's diameters, a field of the cycle's
// per-vessel records), read where they are: the table then costs only what it computes.
#pragma once

#include <cstddef>
#include <cstdint>
#include <limits>
#include <span>
#include <string>
#include <vector>


namespace hemotree {

class VesselTable {
 public:
  enum class Kind { integer, number, text };
  static constexpr std::int64_t null_integer = std::numeric_limits<std::int64_t>::min();
  struct Column {
    std::string name;
    Kind kind = Kind::number;
    std::size_t rows = 0;
    std::vector<double> number;         // number, held: NaN (or infinity) is null
    std::vector<std::int64_t> integer;  // integer, held: null_integer is null
    std::vector<std::uint8_t> code;     // text: an index into labels
    std::vector<std::string> labels;
    // A view (number or integer): row r's value at view + r * stride bytes, in storage its
    // maker keeps alive as long as the table; null where the column holds its values.
    const std::byte* view = nullptr;
    std::size_t stride = 0;
    std::string json_name;                // name and labels as JSON strings, quotes included
    std::vector<std::string> json_labels;
    std::vector<std::string> csv_labels;  // labels as CSV fields, quoted where they must be

    double number_at(std::size_t row) const { return at(number, row); }
    std::int64_t integer_at(std::size_t row) const { return at(integer, row); }
    // The whole column in one piece: its own values where they lie so, else copied into scratch.
    std::span<const double> numbers(std::vector<double>& scratch) const { return whole(number, scratch); }
    std::span<const std::int64_t> integers(std::vector<std::int64_t>& scratch) const { return whole(integer, scratch); }

   private:
    template <class T>
    T at(const std::vector<T>& held, std::size_t row) const {
      return view ? *reinterpret_cast<const T*>(view + row * stride) : held[row];
    }
    template <class T>
    std::span<const T> whole(const std::vector<T>& held, std::vector<T>& scratch) const {
      if (!view) return held;
      if (stride == sizeof(T)) return {reinterpret_cast<const T*>(view), rows};
      scratch.resize(rows);
      for (std::size_t r = 0; r < rows; ++r) scratch[r] = at(held, r);
      return scratch;
    }
  };

  explicit VesselTable(std::size_t rows = 0) : rows_(rows) {}
  std::size_t rows() const { return rows_; }
  const std::vector<Column>& columns() const { return columns_; }
  // The column of that name, or null.
  const Column* find(const std::string& name) const;

  // Columns are added whole (their size must be rows(): std::invalid_argument otherwise).
  void add_integer(std::string name, std::vector<std::int64_t> values);
  void add_number(std::string name, std::vector<double> values);
  void add_text(std::string name, std::vector<std::uint8_t> codes, std::vector<std::string> labels);
  // Views: values that must outlive the table, read where they lie.
  void add_integer_view(std::string name, std::span<const std::int64_t> values);
  void add_number_view(std::string name, std::span<const double> values);
  // A member of each record: field of records[v] is row v's value.
  template <class Record>
  void add_number_view(std::string name, std::span<const Record> records, const double Record::*field) {
    push_view(std::move(name), Kind::number, records.size(),
              records.empty() ? nullptr : reinterpret_cast<const std::byte*>(&(records.front().*field)), sizeof(Record));
  }

  // One row appended to text as a JSON object on one line ({"id":3,...}), numbers in their
  // shortest text that reads back to the same double; as a CSV line (its newline included),
  // the same numbers, null an empty field (which pandas and numpy read as NaN).
  void append_json_row(std::string& text, std::size_t row) const;
  void append_csv_row(std::string& text, std::size_t row) const;

 private:
  void push(Column c);
  void push_view(std::string name, Kind kind, std::size_t size, const std::byte* first, std::size_t stride);

  std::size_t rows_;
  std::vector<Column> columns_;
};

// The shortest text that reads back to the same double (as summary.json writes it): with a
// ".0" where it would read as an integer, "null" where not finite (JSON has no NaN).
void append_json_number(std::string& text, double x);
// The same without the ".0" and with nothing for a non-finite value: a CSV field.
void append_csv_number(std::string& text, double x);

}  // namespace hemotree

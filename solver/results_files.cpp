#include "solver/results_files.hpp"

#include <algorithm>
#include <cmath>
#include <exception>
#include <limits>
#include <map>
#include <stdexcept>

#include "formats/hdf5_file.hpp"
#include "formats/output_stream.hpp"

namespace hemotree {

namespace {

constexpr double null_number = std::numeric_limits<double>::quiet_NaN();

// A table's text column as an enumeration of its labels (h5py: h5py.check_enum_dtype; pandas:
// pd.Categorical.from_codes).
hdf5::EnumNames enum_names(const std::vector<std::string>& labels) { return hdf5::EnumNames{labels}; }

void write_vessels(hdf5::File& file, const VesselTable& vessels) {
  // A column a view spaced apart (a field of the cycle's records) is copied whole, one at a time.
  std::vector<double> numbers;
  std::vector<std::int64_t> integers;
  for (const VesselTable::Column& c : vessels.columns()) {
    if (c.name.find('/') != std::string::npos) throw std::logic_error("results.h5: a column named " + c.name);
    const std::string path = "/vessels/" + c.name;
    switch (c.kind) {
      case VesselTable::Kind::number: file.write(path, c.numbers(numbers)); break;
      case VesselTable::Kind::integer: {
        const std::span<const std::int64_t> column = c.integers(integers);
        // With a null, as vessels.csv reads into pandas: reals, NaN for null.
        if (std::find(column.begin(), column.end(), VesselTable::null_integer) == column.end()) {
          file.write(path, column);
          break;
        }
        numbers.resize(column.size());
        for (std::size_t v = 0; v < numbers.size(); ++v)
          numbers[v] = column[v] == VesselTable::null_integer ? null_number : static_cast<double>(column[v]);
        file.write(path, std::span<const double>(numbers));
        break;
      }
      case VesselTable::Kind::text: file.write_enum(path, c.code, enum_names(c.labels)); break;
    }
    std::vector<double>().swap(numbers);
    std::vector<std::int64_t>().swap(integers);
  }
}

// summary.json's list of boundaries as columns, one per member the entries have, in the
// order they first appear (a number column where every value is a number or null, NaN for
// null or absent; an enumeration where every value is text, its labels in the order they
// first appear; integers where every value is one). The entries (two million on a full tree,
// a JSON object each) are read in blocks on every thread and the blocks joined in order: the
// same columns for any count of threads.
struct BoundaryColumn {
  std::string name;
  std::vector<double> number;
  std::vector<std::int64_t> integer;
  std::vector<std::uint8_t> code;
  std::vector<std::string> labels;
  std::size_t present = 0;  // entries that have the member
  bool integers = true, texts = true, numbers = true;
};

// A column of `rows` rows none of whose entries has the member yet.
BoundaryColumn empty_column(const std::string& name, std::size_t rows) {
  BoundaryColumn c;
  c.name = name;
  c.number.assign(rows, null_number);
  c.integer.assign(rows, 0);
  c.code.assign(rows, 0);
  return c;
}

// Entries [first, end) as columns of end - first rows.
std::vector<BoundaryColumn> boundary_block(const SummaryArray& array, std::size_t first, std::size_t end) {
  std::vector<BoundaryColumn> columns;
  const std::size_t rows = end - first;
  for (std::size_t i = first; i < end; ++i) {
    const nlohmann::json entry = array.entry(i);
    for (const auto& [key, value] : entry.items()) {
      auto at = std::find_if(columns.begin(), columns.end(), [&](const BoundaryColumn& c) { return c.name == key; });
      if (at == columns.end()) at = columns.insert(columns.end(), empty_column(key, rows));
      BoundaryColumn& c = *at;
      const std::size_t row = i - first;
      ++c.present;
      c.integers = c.integers && value.is_number_integer();
      c.numbers = c.numbers && (value.is_number() || value.is_null());
      c.texts = c.texts && value.is_string();
      if (value.is_number()) c.number[row] = value.get<double>();
      if (value.is_number_integer()) c.integer[row] = value.get<std::int64_t>();
      if (value.is_string()) {
        const std::string text = value.get<std::string>();
        const auto label = std::find(c.labels.begin(), c.labels.end(), text);
        c.code[row] = static_cast<std::uint8_t>(std::min<std::ptrdiff_t>(label - c.labels.begin(), 255));
        if (label == c.labels.end()) c.labels.push_back(text);
      }
    }
  }
  return columns;
}

void write_boundaries(hdf5::File& file, const SummaryArray& array, int threads) {
  if (array.name.empty() || array.size == 0) return;
  const std::size_t blocks = std::min<std::size_t>(static_cast<std::size_t>(std::max(threads, 1)) * 4, array.size);
  std::vector<std::vector<BoundaryColumn>> parts(blocks);
  std::exception_ptr error;
#pragma omp parallel for schedule(dynamic, 1) num_threads(std::max(threads, 1))
  for (std::size_t b = 0; b < blocks; ++b) {
    try {
      parts[b] = boundary_block(array, b * array.size / blocks, (b + 1) * array.size / blocks);
    } catch (...) {
#pragma omp critical(boundary_block_error)
      if (!error) error = std::current_exception();
    }
  }
  if (error) std::rethrow_exception(error);
  // The blocks joined in order: members and labels in the order of their first appearance.
  std::vector<BoundaryColumn> columns;
  for (std::size_t b = 0; b < blocks; ++b) {
    const std::size_t first = b * array.size / blocks, rows = (b + 1) * array.size / blocks - first;
    for (BoundaryColumn& part : parts[b]) {
      auto at = std::find_if(columns.begin(), columns.end(), [&](const BoundaryColumn& c) { return c.name == part.name; });
      if (at == columns.end()) at = columns.insert(columns.end(), empty_column(part.name, array.size));
      BoundaryColumn& c = *at;
      c.present += part.present;
      c.integers = c.integers && part.integers;
      c.numbers = c.numbers && part.numbers;
      c.texts = c.texts && part.texts;
      std::copy(part.number.begin(), part.number.end(), c.number.begin() + static_cast<std::ptrdiff_t>(first));
      std::copy(part.integer.begin(), part.integer.end(), c.integer.begin() + static_cast<std::ptrdiff_t>(first));
      std::vector<std::uint8_t> global(part.labels.size());
      for (std::size_t k = 0; k < part.labels.size(); ++k) {
        const auto label = std::find(c.labels.begin(), c.labels.end(), part.labels[k]);
        global[k] = static_cast<std::uint8_t>(std::min<std::ptrdiff_t>(label - c.labels.begin(), 255));
        if (label == c.labels.end()) c.labels.push_back(part.labels[k]);
      }
      for (std::size_t row = 0; row < rows; ++row)
        if (!part.labels.empty()) c.code[first + row] = global[std::min<std::size_t>(part.code[row], global.size() - 1)];
    }
    std::vector<BoundaryColumn>().swap(parts[b]);  // joined: freed
  }
  for (const BoundaryColumn& c : columns) {
    const bool complete = c.present == array.size;
    const std::string path = "/" + array.name + "/" + c.name;
    if (c.texts && complete && c.labels.size() <= 255) file.write_enum(path, c.code, enum_names(c.labels));
    else if (c.integers && complete) file.write(path, std::span<const std::int64_t>(c.integer));
    else if (c.numbers) file.write(path, std::span<const double>(c.number));
    else throw std::logic_error("results.h5: the boundaries' member " + c.name + " is neither numbers nor texts");
  }
}

void write_probes(hdf5::File& file, const ProbeRecorder& probes) {
  const std::vector<std::string> names = probes.column_names();
  const std::vector<double> values = probes.values();
  file.write_text("/probes/columns", nlohmann::json(names).dump());
  file.write_matrix("/probes/values", values.size() / names.size(), names.size(), values);
}

}  // namespace

void write_results_hdf5(const std::filesystem::path& path, const RunResults& results) {
  OutputStream out(path.string());
  hdf5::write_through(out, [&](hdf5::File& file) {
    file.set_threads(results.threads);
    file.write_attribute("format", "hemotree-results");
    file.write_attribute("version", std::int64_t{1});
    constexpr auto replace = nlohmann::json::error_handler_t::replace;
    file.write_text("/summary", summary_facts(results.run, results.cycle).dump(1, ' ', false, replace));
    write_vessels(file, results.vessels);
    write_boundaries(file, results.boundaries, results.threads);
    if (results.probes && !results.probes->empty()) write_probes(file, *results.probes);
  });
  out.commit();
}

void write_results(const std::filesystem::path& dir, const RunResults& results, ResultsFormat format) {
  if (format == ResultsFormat::text) {
    write_summary(dir / "summary.json", results.run, results.vessels, results.cycle, results.boundaries,
                  results.threads);
    write_vessel_table(dir / "vessels.csv", results.vessels, results.threads);
    if (results.probes) results.probes->write(dir / "probes.csv");
    return;
  }
  write_results_hdf5(dir / "results.h5", results);
  // summary.json keeps the run's facts, the first thing a person or a script looks at, and
  // says where the rest is.
  nlohmann::json facts = summary_facts(results.run, results.cycle);
  facts["results"] = {{"file", "results.h5"}, {"vessels", results.vessels.rows()}};
  constexpr auto replace = nlohmann::json::error_handler_t::replace;
  OutputStream out((dir / "summary.json").string());
  out << facts.dump(1, ' ', false, replace) << "\n";
  out.commit();
}

}  // namespace hemotree

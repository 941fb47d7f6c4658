#include "solver/results_files.hpp"

#include <algorithm>
#include <cmath>
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
  for (const VesselTable::Column& c : vessels.columns()) {
    if (c.name.find('/') != std::string::npos) throw std::logic_error("results.h5: a column named " + c.name);
    const std::string path = "/vessels/" + c.name;
    switch (c.kind) {
      case VesselTable::Kind::number: file.write(path, std::span<const double>(c.number)); break;
      case VesselTable::Kind::integer: {
        // With a null, as vessels.csv reads into pandas: reals, NaN for null.
        if (std::find(c.integer.begin(), c.integer.end(), VesselTable::null_integer) == c.integer.end()) {
          file.write(path, std::span<const std::int64_t>(c.integer));
          break;
        }
        std::vector<double> values(c.integer.size());
        for (std::size_t v = 0; v < values.size(); ++v)
          values[v] = c.integer[v] == VesselTable::null_integer ? null_number : static_cast<double>(c.integer[v]);
        file.write(path, std::span<const double>(values));
        break;
      }
      case VesselTable::Kind::text: file.write_enum(path, c.code, enum_names(c.labels)); break;
    }
  }
}

// summary.json's list of boundaries as columns, one per member the entries have (a number
// column where every value is a number or null, NaN for null or absent; an enumeration where
// every value is text; integers where every value is one).
void write_boundaries(hdf5::File& file, const SummaryArray& array) {
  if (array.name.empty() || array.size == 0) return;
  struct Column {
    std::vector<double> number;
    std::vector<std::int64_t> integer;
    std::vector<std::uint8_t> code;
    std::vector<std::string> labels;
    bool integers = true, texts = true, numbers = true;
  };
  std::vector<std::pair<std::string, Column>> columns;  // in the first entry's order
  auto column = [&](const std::string& key) -> Column& {
    for (auto& [name, c] : columns)
      if (name == key) return c;
    Column& c = columns.emplace_back(key, Column{}).second;
    return c;
  };
  for (std::size_t i = 0; i < array.size; ++i) {
    const nlohmann::json entry = array.entry(i);
    for (const auto& [key, value] : entry.items()) {
      Column& c = column(key);
      c.number.resize(i, null_number);
      c.integer.resize(i, 0);
      c.code.resize(i, 0);
      c.integers = c.integers && value.is_number_integer();
      c.numbers = c.numbers && (value.is_number() || value.is_null());
      c.texts = c.texts && value.is_string();
      c.number.push_back(value.is_number() ? value.get<double>() : null_number);
      c.integer.push_back(value.is_number_integer() ? value.get<std::int64_t>() : 0);
      std::uint8_t code = 0;
      if (value.is_string()) {
        const std::string text = value.get<std::string>();
        const auto at = std::find(c.labels.begin(), c.labels.end(), text);
        code = static_cast<std::uint8_t>(at - c.labels.begin());
        if (at == c.labels.end()) c.labels.push_back(text);
        c.texts = c.texts && c.labels.size() <= 255;
      }
      c.code.push_back(code);
    }
  }
  for (auto& [name, c] : columns) {
    const bool complete = c.number.size() == array.size;
    c.number.resize(array.size, null_number);
    const std::string path = "/" + array.name + "/" + name;
    if (c.texts && complete) file.write_enum(path, c.code, enum_names(c.labels));
    else if (c.integers && complete) file.write(path, std::span<const std::int64_t>(c.integer));
    else if (c.numbers) file.write(path, std::span<const double>(c.number));
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
    file.write_attribute("format", "hemotree-results");
    file.write_attribute("version", std::int64_t{1});
    constexpr auto replace = nlohmann::json::error_handler_t::replace;
    file.write_text("/summary", summary_facts(results.run, results.cycle).dump(1, ' ', false, replace));
    write_vessels(file, results.vessels);
    write_boundaries(file, results.boundaries);
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

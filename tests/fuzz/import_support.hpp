// What the importer harnesses (fuzz_import_*.cpp) share: a reader's outcome where only its
// refusal (InputError) is allowed, the network compared field by field, and the round trip
// through the vnet format that vimport makes of every accepted file.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include <omp.h>

#include "exchange/foreign_format.hpp"
#include "formats/network_io.hpp"
#include "formats/output_stream.hpp"
#include "fuzz_support.hpp"
#include "network_difference.hpp"

namespace hemotree::fuzz {

inline void init_import_harness() {
  keep_report_channel();
  omp_set_num_threads(1);  // one core is the fuzzer's share
}

// Runs a reader (or a writer): its value, or nullopt when it refused with InputError (and
// IoError where allow_io: the openBF inlet file a model names may be missing or a device).
// Anything else is a finding: another exception reaches vimport's user as an internal error.
template <class F>
auto refused_or(const std::string& stage, F f, bool allow_io = false) -> std::optional<decltype(f())> {
  try {
    return f();
  } catch (const InputError&) {
    return std::nullopt;
  } catch (const IoError& e) {
    if (allow_io) return std::nullopt;
    finding(stage + ": IoError on a readable file: " + e.what());
  } catch (const std::exception& e) {
    finding(stage + ": an exception that is not InputError (internal error, exit 70): " + e.what());
  } catch (...) {
    finding(stage + ": a non-standard exception");
  }
}

// Runs what must succeed: any exception at all is a finding.
template <class F>
auto must(const std::string& stage, F f) -> decltype(f()) {
  try {
    return f();
  } catch (const std::exception& e) {
    finding(stage + ": " + e.what());
  } catch (...) {
    finding(stage + ": a non-standard exception");
  }
}

inline ImportOptions quiet_options() {
  ImportOptions options;
  options.note = [](const std::string&) {};
  return options;
}

// What vimport writes of an accepted network: write_network must take it, the vnet reader
// must accept the file and read the same network back (reals to the writer's 9 digits).
inline void check_vnet_round_trip(Network net, const std::string& format) {
  stamp_import_provenance(net, format, "fuzz-input");  // as vimport does
  const auto path = scratch() / "imported.json";
  must("write_network refused what the " + format + " reader accepted", [&] {
    OutputStream out(path.string());
    write_network(net, out);
    out.commit();
    return true;
  });
  const std::string text = read_file(path);
  const Network back = must("the vnet reader refuses what vimport " + format + " wrote",
                            [&] { return parse_network(text, "imported.json"); });
  if (const std::string d = vnet_difference(net, back, 1e-8); !d.empty())
    finding("vimport " + format + ": written as vnet and read back, the network changed: " + d);
}

}  // namespace hemotree::fuzz

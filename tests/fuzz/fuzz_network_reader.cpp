// The network reader on hostile bytes: read from memory and streamed through a tiny buffer
// (1 to 7 bytes, so that every token crosses refills), the two must agree, on the network
// or on the error message; a network read must survive write_network and a second read.
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <string>
#include <string_view>

#include <omp.h>

#include "formats/network_io.hpp"
#include "fuzz_support.hpp"
#include "network_difference.hpp"

using namespace hemotree;
using hemotree::fuzz::finding;

namespace {

std::string shown(const fuzz::Refusal& r) { return r.kind + " \"" + r.message + "\""; }

std::string write_to_text(const Network& net, const std::filesystem::path& path) {
  auto written_result = fuzz::outcome("write_network", [&] {
    OutputStream out(path.string());
    write_network(net, out);
    out.commit();
    return true;
  });
  auto& written = written_result.first;
  auto& refusal = written_result.second;
  if (!written) finding("write_network refused a network the reader accepted: " + shown(refusal));
  return fuzz::read_file(path);
}

}  // namespace

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  fuzz::keep_report_channel();
  omp_set_num_threads(1);  // the writer's blocks: one core is the fuzzer's share
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  const std::string source = "fuzz.json";

  auto in_memory_result = fuzz::outcome("parse_network", [&] { return parse_network(text, source); });
  auto& in_memory = in_memory_result.first;
  auto& memory_error = in_memory_result.second;

  const std::size_t buffer = 1 + size % 7;
  auto streamed_result = fuzz::outcome("read_network (streamed)", [&] {
    std::string copy(text);  // fmemopen wants a writable buffer, and no zero size
    std::FILE* in = size ? fmemopen(copy.data(), copy.size(), "rb") : std::tmpfile();
    if (!in) finding("the harness cannot open its input as a stream");
    struct Closer {
      std::FILE* f;
      ~Closer() { std::fclose(f); }
    } closer{in};
    return read_network(in, source, buffer);
  });
  auto& streamed = streamed_result.first;
  auto& stream_error = streamed_result.second;

  if (in_memory.has_value() != streamed.has_value())
    finding("in memory " + (in_memory ? std::string("accepted") : shown(memory_error)) +
            ", streamed through " + std::to_string(buffer) + " bytes " +
            (streamed ? std::string("accepted") : shown(stream_error)));
  if (!in_memory) {
    if (!(memory_error == stream_error))
      finding("different errors: in memory " + shown(memory_error) + ", streamed through " +
              std::to_string(buffer) + " bytes " + shown(stream_error));
    return 0;
  }
  if (const std::string d = fuzz::vnet_difference(*in_memory, *streamed, 0.0); !d.empty())
    finding("in memory and streamed through " + std::to_string(buffer) + " bytes read different networks: " + d);

  // Round trip: what the reader accepts the writer writes, the reader reads back the same
  // network, and a second write gives the same bytes (9 digits are a fixed point).
  const auto file = fuzz::scratch() / "network.json";
  const std::string first = write_to_text(*in_memory, file);
  auto again_result = fuzz::outcome("read back", [&] { return parse_network(first, source); });
  auto& again = again_result.first;
  auto& again_error = again_result.second;
  if (!again) finding("the reader refuses what write_network wrote: " + shown(again_error));
  if (const std::string d = fuzz::vnet_difference(*in_memory, *again, 1e-8); !d.empty())  // the writer's 9 digits
    finding("written and read back, the network changed: " + d);
  if (write_to_text(*again, file) != first) finding("a second write gives different bytes");
  return 0;
}

// The vnet network as HDF5: every member survives JSON -> HDF5 -> JSON byte for byte, the
// file is the same bytes for the same network, a pipe reads it as a path does, and a damaged,
// truncated or foreign file is refused in one line naming the dataset (never a crash).
#include <algorithm>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>

#include <sys/wait.h>
#include <unistd.h>

#include <gtest/gtest.h>

#include "core/errors.hpp"
#include "formats/hdf5_file.hpp"
#include "formats/network_io.hpp"
#include "generator/growth_rules.hpp"
#include "generator/tree_growth.hpp"
#include "generator/tree_layout.hpp"
#include "scratch_path.hpp"

using namespace hemotree;
namespace fs = std::filesystem;

namespace {

// This process's scratch folder, removed when it ends (tests/scratch_path.hpp).
fs::path temp_path(const std::string& name) { return scratch_path(name); }

std::string slurp(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

void put(const fs::path& p, std::string_view bytes) {
  std::ofstream out(p, std::ios::binary);
  out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
}

template <class Write>
std::string written(const Network& net, const std::string& name, Write write) {
  const fs::path path = temp_path(name);
  {
    OutputStream out(path.string());
    write(net, out);
    out.commit();
  }
  std::string bytes = slurp(path);
  fs::remove(path);
  return bytes;
}
std::string as_json(const Network& net) { return written(net, "net.json", write_network); }
std::string as_hdf5(const Network& net) { return written(net, "net.h5", write_network_hdf5); }

Network read_bytes(const std::string& bytes, const std::string& name = "net.h5") {
  const fs::path path = temp_path(name);
  put(path, bytes);
  struct Remove {
    fs::path p;
    ~Remove() { fs::remove(p); }
  } remove{path};
  return read_network(path.string());
}

// Every member of the format: tree-form blood, inlet and outlets of each model, boundaries at
// nodes (flow with a hematocrit, pressure, a table), a tapered vessel, direct tube laws on some
// vessels, missing wall data, coordinates, members passed through, provenance.
const char* everything = R"({"format": "vnet", "version": 2,
 "provenance": {"tool": "test", "note": "caf\u00e9"},
 "blood": {"mean_cell_volume": 55e-18, "plasma_viscosity": 1.0466e-3, "hematocrit": 0.42},
 "inlet": {"vessel": 1, "waveform": {"shape": "half_sine", "period": 0.9, "mean": 2e-9, "systole": 0.3}},
 "boundaries": [
  {"node": 21, "type": "pressure", "pressure": 1333.22},
  {"node": 22, "type": "flow", "waveform": {"shape": "table", "period": 1, "time": [0, 0.5], "flow": [2e-12, -1e-12]}, "hematocrit": 0.3}],
 "later_stage": {"kept": [1, 2, 3]},
 "nodes": [{"id": 10, "x": 0, "y": 0, "z": 0}, {"id": 11, "x": 0.01, "y": 0, "z": 0},
           {"id": 12, "x": 0.02, "y": 0.01, "z": 0}, {"id": 13, "x": 0.02, "y": -0.01, "z": 0},
           {"id": 14, "x": 0.03, "y": 0, "z": 0.001}, {"id": 21, "x": 0.04, "y": 0, "z": 0},
           {"id": 22, "x": 0.05, "y": 0, "z": 0}],
 "vessels": [
  {"id": 1, "from": 10, "to": 11, "length": 0.01, "diameter": 1e-3, "distal_diameter": 9e-4,
   "wall_thickness": 1e-4, "youngs_modulus": 4e5},
  {"id": 2, "from": 11, "to": 12, "length": 0.012, "diameter": 6e-4, "wall_thickness": 8e-5,
   "youngs_modulus": 4e5, "outlet": {"type": "RCR", "R1": 1e9, "C": 1e-12, "R2": 4e9, "p_out": 500}},
  {"id": 3, "from": 11, "to": 13, "length": 0.011, "diameter": 5e-5, "beta": 3e7, "reference_pressure": 1000,
   "outlet": {"type": "R", "R": 2e12}},
  {"id": 4, "from": 11, "to": 14, "length": 0.009, "diameter": 7e-6, "wall_thickness": 1e-6,
   "youngs_modulus": 2e5, "outlet": {"type": "reflection", "coefficient": 0.25}},
  {"id": 5, "from": 14, "to": 21, "length": 0.002, "diameter": 6e-6},
  {"id": 6, "from": 22, "to": 14, "length": 0.002, "diameter": 6e-6}]})";

Network grown_tree() {
  GrowthParameters p;
  p.root_diameter = 120e-6;
  p.min_diameter = 7e-6;
  Network net = grow_tree(default_rules(), p);
  lay_out_tree(net);
  net.provenance = {{"tool", "test"}, {"seed", 1}};
  return net;
}

// Expects reading bytes to throw an InputError whose message holds every fragment.
void expect_refusal(const std::string& bytes, std::initializer_list<std::string> fragments) {
  try {
    read_bytes(bytes);
  } catch (const InputError& e) {
    for (const std::string& fragment : fragments)
      EXPECT_NE(std::string(e.what()).find(fragment), std::string::npos)
          << "message: " << e.what() << "\nwanted: " << fragment;
    EXPECT_EQ(std::string(e.what()).find('\n'), std::string::npos) << e.what();
    return;
  }
  ADD_FAILURE() << "accepted";
}

// A file of the reference network with one dataset replaced (or removed: an empty writer).
template <class Change>
std::string changed(const std::string& path_to_change, Change change) {
  const Network net = parse_network(everything);
  const std::string reference_bytes = as_hdf5(net);
  hdf5::File reference =
      hdf5::File::open_image(std::vector<char>(reference_bytes.begin(), reference_bytes.end()), "reference");
  hdf5::File file = hdf5::File::create("net.h5");
  file.write_attribute("format", "vnet");
  file.write_attribute("version", std::int64_t{2});
  const char* reals[] = {"/nodes/x", "/nodes/y", "/nodes/z", "/vessels/length", "/vessels/diameter",
                         "/vessels/distal_diameter", "/vessels/wall_thickness", "/vessels/youngs_modulus",
                         "/vessels/beta", "/vessels/reference_pressure", "/outlets/R1", "/outlets/C",
                         "/outlets/R2", "/outlets/R", "/outlets/p_out", "/outlets/coefficient"};
  const char* integers[] = {"/nodes/id", "/vessels/id", "/vessels/from_node", "/vessels/to_node",
                            "/vessels/generation", "/outlets/vessel"};
  const char* texts[] = {"/provenance", "/blood", "/inlet", "/boundaries", "/extra"};
  for (const char* p : reals)
    if (p == path_to_change) change(file, p);
    else file.write(p, std::span<const double>(reference.read_reals(p)));
  for (const char* p : integers)
    if (p == path_to_change) change(file, p);
    else file.write(p, std::span<const std::int64_t>(reference.read_integers(p)));
  for (const char* p : texts)
    if (p == path_to_change) change(file, p);
    else file.write_text(p, reference.read_text(p));
  const hdf5::EnumNames classes{{"artery", "small_artery", "arteriole", "capillary"}};
  const hdf5::EnumNames types{{"RCR", "R", "reflection"}};
  if (path_to_change == "/vessels/class") change(file, "/vessels/class");
  else file.write_enum("/vessels/class", reference.read_enum("/vessels/class", classes), classes);
  if (path_to_change == "/outlets/type") change(file, "/outlets/type");
  else file.write_enum("/outlets/type", reference.read_enum("/outlets/type", types), types);
  const std::vector<char> bytes = file.bytes();
  return std::string(bytes.begin(), bytes.end());
}

}  // namespace

TEST(NetworkHdf5, EveryMemberSurvivesJsonToHdf5ToJsonByteForByte) {
  const Network net = parse_network(everything);
  const std::string json = as_json(net);
  const std::string h5 = as_hdf5(net);
  ASSERT_TRUE(hdf5::has_signature(std::span<const char>(h5.data(), h5.size())));
  const Network back = read_bytes(h5);
  EXPECT_EQ(as_json(back), json);
  // Written again, the same bytes: no times or addresses that vary between runs.
  EXPECT_EQ(as_hdf5(back), h5);
  EXPECT_EQ(back.outlets.size(), 3u);
  EXPECT_EQ(back.boundaries.size(), 2u);
  EXPECT_EQ(back.extra.at("later_stage").at("kept").size(), 3u);
  EXPECT_EQ(back.provenance.at("note"), "caf\u00e9");
}

TEST(NetworkHdf5, AGrownTreeKeepsEveryDoubleExactly) {
  const Network net = grown_tree();
  const Network back = read_bytes(as_hdf5(net));
  ASSERT_EQ(back.vessel_count(), net.vessel_count());
  EXPECT_EQ(back.length, net.length);  // bit for bit: HDF5 holds the doubles, not 9 digits
  EXPECT_EQ(back.diameter, net.diameter);
  EXPECT_EQ(back.x, net.x);
  EXPECT_EQ(back.from, net.from);
  EXPECT_EQ(back.generation, net.generation);
  EXPECT_EQ(as_json(back), as_json(net));
}

TEST(NetworkHdf5, APipeReadsWhatAPathReads) {
  const Network net = parse_network(everything);
  const std::string h5 = as_hdf5(net);
  std::FILE* pipe = std::tmpfile();
  ASSERT_NE(pipe, nullptr);
  std::fwrite(h5.data(), 1, h5.size(), pipe);
  std::rewind(pipe);
  const Network back = read_network(pipe, "standard input");
  std::fclose(pipe);
  EXPECT_EQ(as_json(back), as_json(net));
}

TEST(NetworkHdf5, ContentErrorsNameTheDatasetTheRowAndTheVessel) {
  auto reals = [](std::vector<double> v) {
    return [v](hdf5::File& f, const char* p) { f.write(p, std::span<const double>(v)); };
  };
  auto integers = [](std::vector<std::int64_t> v) {
    return [v](hdf5::File& f, const char* p) { f.write(p, std::span<const std::int64_t>(v)); };
  };
  auto absent = [](hdf5::File&, const char*) {};
  expect_refusal(changed("/vessels/length", reals({0.01, 0.012, 20, 0.009, 0.002, 0.002})),
                 {"net.h5: /vessels/length: row 2 (vessel 3): \"length\" must lie in [1e-7, 10] m (got 20)"});
  expect_refusal(changed("/vessels/length", absent), {"/vessels/length: missing"});
  expect_refusal(changed("/vessels/length", reals({0.01, 0.012})), {"/vessels/length: must have 6 rows"});
  expect_refusal(changed("/vessels/length", integers({1, 1, 1, 1, 1, 1})),
                 {"/vessels/length: must hold floating-point numbers (it holds integers)"});
  expect_refusal(changed("/vessels/id", integers({1, 2, 3, 2, 5, 6})), {"/vessels/id: vessel id 2 appears twice"});
  expect_refusal(changed("/vessels/to_node", integers({1, 2, 3, 9, 5, 1})),
                 {"/vessels/to_node: row 3 (vessel 4): a row of /nodes, in [0, 6] (got 9)"});
  expect_refusal(changed("/vessels/to_node", integers({1, 2, 3, 4, 5, 6})),
                 {"/vessels/to_node: row 5 (vessel 6): begins and ends at the same node"});
  expect_refusal(changed("/vessels/diameter", reals({1e-3, 6e-4, 5e-5, 7e-6, 6e-6, 2e-5})),
                 {"/vessels/class: row 5 (vessel 6): class \"capillary\" does not match its diameter (arteriole)"});
  expect_refusal(changed("/vessels/generation", integers({0, 1, 1, 1, 2, 6})),
                 {"/vessels/generation: row 5 (vessel 6)", "[0, 5]"});
  // An unused parameter (C at an R or a reflection outlet) is not read.
  EXPECT_EQ(read_bytes(changed("/outlets/C", reals({1e-12, 7, 2}))).outlets[2].c, 0.0);
  expect_refusal(changed("/outlets/C", reals({-1, 0, 0})), {"/outlets/C: row 0 (vessel 2): \"C\" must lie in"});
  expect_refusal(changed("/outlets/vessel", integers({3, 1, 2})), {"/outlets/vessel: row 1: outlets are sorted"});
  expect_refusal(changed("/blood", [](hdf5::File& f, const char* p) { f.write_text(p, "{\"hematocrit\": 2}"); }),
                 {"/blood: ", "hematocrit"});
  expect_refusal(changed("/inlet", [](hdf5::File& f, const char* p) { f.write_text(p, "{not json"); }),
                 {"/inlet: not JSON text"});
  expect_refusal(changed("/boundaries",
                         [](hdf5::File& f, const char* p) {
                           f.write_text(p, R"([{"node": 99, "type": "pressure", "pressure": 0}])");
                         }),
                 {"/boundaries: boundaries[0]: unknown node 99"});
  expect_refusal(changed("/vessels/class",
                         [](hdf5::File& f, const char* p) {
                           const hdf5::EnumNames other{{"artery", "vein"}};
                           const std::vector<std::uint8_t> v(6, 1);
                           f.write_enum(p, v, other);
                         }),
                 {"/vessels/class: unknown value \"vein\""});
}

TEST(NetworkHdf5, TheFileMustSayItIsAVnetNetworkOfAKnownVersion) {
  auto with_attributes = [](auto set) {
    hdf5::File f = hdf5::File::create("net.h5");
    set(f);
    const std::int64_t ids[] = {0, 1};
    f.write("/nodes/id", std::span<const std::int64_t>(ids));
    const std::vector<char> bytes = f.bytes();
    return std::string(bytes.begin(), bytes.end());
  };
  expect_refusal(with_attributes([](hdf5::File&) {}), {"net.h5: /: the attribute \"format\" must be \"vnet\""});
  expect_refusal(with_attributes([](hdf5::File& f) {
                   f.write_attribute("format", "vnet");
                   f.write_attribute("version", std::int64_t{3});
                 }),
                 {"network format version 3 is not supported"});
}

TEST(NetworkHdf5, TruncatedEmptyAndForeignFilesAreRefusedInOneLine) {
  const std::string h5 = as_hdf5(parse_network(everything));
  for (std::size_t keep : {std::size_t{8}, std::size_t{100}, std::size_t{800}, h5.size() / 2, h5.size() - 1})
    expect_refusal(h5.substr(0, keep), {"net.h5: not a complete HDF5 file (truncated or damaged)"});
  expect_refusal("\x89PNG\r\n\x1a\n rest", {"net.h5: not an HDF5 file"});
  // Without HDF5's first byte a file is read as JSON, and refused as such.
  EXPECT_THROW(read_bytes(""), JsonError);
}

// Bytes of a small file flipped (every second one of the first 3000, where the library keeps
// its headers, then every 41st), each read in a child process: each read ends in the file's
// network or in a refusal, never a crash (nor the crash guard's line: on files of ours the
// library finds every damage by its checksums before it could crash), and never in other
// vessel values than the file's (a flip inside the data is caught by the chunks' checksums).
TEST(NetworkHdf5, FlippedBytesAreReadOrRefusedNeverCrashNorChangeAValue) {
  const Network net = parse_network(everything);
  const std::string h5 = as_hdf5(net);
  const fs::path path = temp_path("flipped.h5");
  struct Remove {
    fs::path p;
    ~Remove() { fs::remove(p); }
  } remove{path};
  std::size_t refused = 0, read = 0, crashed = 0, changed_values = 0;
  for (std::size_t at = 0; at < h5.size(); at += at < 3000 ? 2 : 41) {
    std::string damaged = h5;
    damaged[at] = static_cast<char>(damaged[at] ^ 0x5a);
    put(path, damaged);
    const pid_t child = ::fork();
    ASSERT_GE(child, 0);
    if (child == 0) {
      std::freopen("/dev/null", "w", stderr);
      try {
        const Network back = read_network(path.string());
        // Bit for bit (NaN marks a missing wall thickness).
        auto same_bits = [](const auto& a, const auto& b) {
          return a.size() == b.size() && std::memcmp(a.data(), b.data(), a.size() * sizeof a[0]) == 0;
        };
        const bool same = same_bits(back.length, net.length) && same_bits(back.diameter, net.diameter) &&
                          same_bits(back.from, net.from) && same_bits(back.to, net.to) &&
                          same_bits(back.wall_thickness, net.wall_thickness) && same_bits(back.beta, net.beta);
        ::_exit(same ? 0 : 3);
      } catch (const std::exception&) {  // InputError, JsonError (first byte), IoError
        ::_exit(4);
      }
    }
    int status = 0;
    ::waitpid(child, &status, 0);
    if (WIFSIGNALED(status) || WEXITSTATUS(status) == 2) {
      ++crashed;
      ADD_FAILURE() << "byte " << at << ": " << (WIFSIGNALED(status) ? "signal" : "the crash guard's exit");
    } else if (WEXITSTATUS(status) == 4) {
      ++refused;
    } else if (WEXITSTATUS(status) == 3) {
      ++changed_values;
      ADD_FAILURE() << "byte " << at << ": read with other values";
    } else {
      ++read;
    }
  }
  EXPECT_EQ(crashed, 0u);
  EXPECT_EQ(changed_values, 0u);
  EXPECT_GT(refused, 100u);
  RecordProperty("refused", static_cast<int>(refused));
  RecordProperty("read", static_cast<int>(read));
}

// Columns are filtered here, chunk by chunk on every thread, and handed to the library as it
// would store them (H5Dwrite_chunk): the library reads them back through its own filters
// (shuffle, deflate, Fletcher-32 checked) to the same values, for every size around a chunk's
// 65,536 rows and every width. (Byte for byte the same file as the library's own filters gave,
// checked on vgen's full tree, while every column took zlib's default strategy.)
TEST(Hdf5File, ColumnsFilteredHereReadBackThroughTheLibrarysFilters) {
  for (const std::size_t rows : {std::size_t{1}, std::size_t{65535}, std::size_t{65536}, std::size_t{65537},
                                 std::size_t{200001}}) {
    std::vector<double> reals(rows);
    std::vector<std::int64_t> wide(rows);
    std::vector<std::int32_t> narrow(rows);
    std::vector<std::uint8_t> codes(rows);
    for (std::size_t i = 0; i < rows; ++i) {
      reals[i] = std::sin(0.001 * static_cast<double>(i)) * 1e-3 + static_cast<double>(i % 7);
      wide[i] = static_cast<std::int64_t>(i * i) - 5;
      narrow[i] = static_cast<std::int32_t>(i % 1000) - 500;
      codes[i] = static_cast<std::uint8_t>(i % 3);
    }
    const hdf5::EnumNames names{{"a", "b", "c"}};
    hdf5::File file = hdf5::File::create("columns.h5");
    file.write("/reals", std::span<const double>(reals));
    file.write("/wide", std::span<const std::int64_t>(wide));
    file.write("/narrow", std::span<const std::int32_t>(narrow));
    file.write_enum("/codes", codes, names);
    hdf5::File back = hdf5::File::open_image(file.bytes(), "columns.h5");
    EXPECT_EQ(back.read_reals("/reals"), reals) << rows;
    EXPECT_EQ(back.read_integers("/wide"), wide) << rows;
    const std::vector<std::int64_t> narrow_back = back.read_integers("/narrow");
    EXPECT_TRUE(std::equal(narrow_back.begin(), narrow_back.end(), narrow.begin(), narrow.end())) << rows;
    EXPECT_EQ(back.read_enum("/codes", names), codes) << rows;
  }
}

// The guard over the library: a crash while a file is open is one line and exit status 2;
// once the guard is gone, a crash is a crash again (the handlers before are restored).
TEST(Hdf5CrashGuard, ACrashWhileGuardedIsOneLineAndStatusTwo) {
  int error_pipe[2];
  ASSERT_EQ(::pipe(error_pipe), 0);
  const pid_t child = ::fork();
  ASSERT_GE(child, 0);
  if (child == 0) {
    ::dup2(error_pipe[1], STDERR_FILENO);
    hdf5::CrashGuard guard("damaged.h5");
    std::raise(SIGSEGV);
    ::_exit(0);
  }
  ::close(error_pipe[1]);
  // Until the child's end closes the pipe: the handler writes the line in two pieces.
  std::string line;
  char text[512];
  for (ssize_t got; (got = ::read(error_pipe[0], text, sizeof text)) > 0;) line.append(text, static_cast<std::size_t>(got));
  ::close(error_pipe[0]);
  int status = 0;
  ::waitpid(child, &status, 0);
  ASSERT_TRUE(WIFEXITED(status));
  EXPECT_EQ(WEXITSTATUS(status), 2);
  EXPECT_NE(line.find(": error: damaged.h5: damaged HDF5 file (the HDF5 library failed reading it: signal 11)\n"),
            std::string::npos)
      << line;
  EXPECT_EQ(std::count(line.begin(), line.end(), '\n'), 1);

  const pid_t after = ::fork();
  ASSERT_GE(after, 0);
  if (after == 0) {
    std::freopen("/dev/null", "w", stderr);
    { hdf5::CrashGuard guard("read.h5"); }
    std::raise(SIGSEGV);
    ::_exit(0);
  }
  ::waitpid(after, &status, 0);
  // The crash is no longer the guard's (a signal, or a sanitizer's own report and exit).
  EXPECT_FALSE(WIFEXITED(status) && WEXITSTATUS(status) == 2);
}

// A checkpoint holds the solver's evolving state bit for bit: a solver restored from it goes
// on exactly as the one that wrote it (every scheme, with RCR capacitors, after a compliance
// balance), and a file that is not such a checkpoint, or one changed after it was written
// (any byte of it), is refused with a clear message.
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "core/errors.hpp"
#include "network_builders.hpp"
#include "formats/checkpoint_file.hpp"
#include "pulse/pulse_solver.hpp"

namespace hemotree {
namespace {

using namespace test_networks;

TEST(Checkpoint, ValuesComeBackBitForBit) {
  CheckpointWriter out;
  out.section("a");
  out.put(0.1);
  out.put(std::nextafter(1.0, 2.0));
  out.put(std::uint64_t{18446744073709551615ull});
  out.put(std::string("x\0y", 3));
  out.put(std::vector<double>{1e-300, -0.0, 3});
  Eigen::MatrixXd m(2, 3);
  m << 1, 2, 3, 4, 5, std::nan("");
  out.put(m);
  CheckpointReader in(out.bytes(), "test");
  in.section("a");
  EXPECT_EQ(in.get_double(), 0.1);
  EXPECT_EQ(in.get_double(), std::nextafter(1.0, 2.0));
  EXPECT_EQ(in.get_u64(), 18446744073709551615ull);
  EXPECT_EQ(in.get_string(), std::string("x\0y", 3));
  const std::vector<double> v = in.get_vector();
  ASSERT_EQ(v.size(), 3u);
  EXPECT_TRUE(std::signbit(v[1]));
  const Eigen::MatrixXd back = in.get_matrix();
  EXPECT_EQ(back.rows(), 2);
  EXPECT_EQ(back(1, 1), 5);
  EXPECT_TRUE(std::isnan(back(1, 2)));
  EXPECT_TRUE(in.at_end());
}

TEST(Checkpoint, RefusesWhatIsNotOne) {
  EXPECT_THROW(CheckpointReader("{\"format\": \"vnet\"}", "net.json"), InputError);
  CheckpointWriter out;
  out.section("run");
  out.put(std::vector<double>(100, 1.0));
  // Truncated anywhere: a clear refusal, never a read past the end.
  for (std::size_t cut : {std::size_t{25}, out.bytes().size() / 2, out.bytes().size() - 1}) {
    try {
      CheckpointReader in(out.bytes().substr(0, cut), "cut");
      in.section("run");
      in.get_vector();
      FAIL() << "read a truncated checkpoint cut at " << cut;
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find("cut: "), std::string::npos) << e.what();
    }
  }
  CheckpointReader other(out.bytes(), "other");
  EXPECT_THROW(other.section("pulse solver"), InputError);
}

TEST(Checkpoint, FileIsReplacedWhole) {
  const auto file = std::filesystem::temp_directory_path() / ("checkpoint-test-" + std::to_string(::getpid()));
  CheckpointWriter a, b;
  a.section("a");
  a.put(1.0);
  b.section("b");
  b.put(2.0);
  write_checkpoint_file(file, a.bytes());
  write_checkpoint_file(file, b.bytes());
  EXPECT_EQ(read_checkpoint_file(file), b.bytes());
  EXPECT_FALSE(std::filesystem::exists(file.string() + ".tmp"));
  std::filesystem::remove(file);
}

// Written straight to a file, section by section, a checkpoint has the bytes the writer in
// memory gives (the file's checksum carried across the sections), and a vector given in parts
// reads back as one; promoted, it replaces the checkpoint whole.
TEST(Checkpoint, AFileWrittenBySectionsIsTheSameBytes) {
  const auto dir = std::filesystem::temp_directory_path() / ("checkpoint-sections-" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  auto fill = [](CheckpointWriter& out) {
    out.section("first");
    out.put(0.25);
    out.put(std::string("name"));
    out.section("parts");
    out.begin_vector(5);
    out.put_part(std::vector<double>{1, 2});
    out.put_part(std::vector<double>{});
    out.put_part(std::vector<double>{3, 4, 5});
    out.put(std::uint64_t{7});
    // A section larger than the writer's pieces (4 MB out, 1 MB read back for the checksum),
    // given in parts that cross them: streamed, its length and checksum written after.
    out.section("large");
    out.begin_vector(1'300'001);
    std::vector<double> part(100'000);
    for (std::size_t k = 0; k < 13; ++k) {
      for (std::size_t i = 0; i < part.size(); ++i) part[i] = static_cast<double>(k * part.size() + i) * 0.5;
      out.put_part(part);
    }
    out.put_part(std::vector<double>{-1});
    // One array larger than a piece, written at once: straight to the file after the buffer.
    out.section("whole");
    std::vector<double> whole(700'000);
    for (std::size_t i = 0; i < whole.size(); ++i) whole[i] = static_cast<double>(i) * 0.25;
    out.put(whole);
    out.put(std::uint64_t{9});
    out.section("end");
  };
  CheckpointWriter memory;
  fill(memory);
  {
    CheckpointWriter file(dir / "snapshot");
    fill(file);
    file.finish();
  }
  EXPECT_EQ(read_checkpoint_file(dir / "snapshot"), memory.bytes());
  CheckpointReader in(read_checkpoint_file(dir / "snapshot"), "snapshot");
  in.section("first");
  EXPECT_EQ(in.get_double(), 0.25);
  EXPECT_EQ(in.get_string(), "name");
  in.section("parts");
  EXPECT_EQ(in.get_vector(), (std::vector<double>{1, 2, 3, 4, 5}));
  EXPECT_EQ(in.get_u64(), 7u);
  in.section("large");
  const std::vector<double> large = in.get_vector();
  ASSERT_EQ(large.size(), 1'300'001u);
  EXPECT_EQ(large[1'234'567], 1'234'567 * 0.5);
  EXPECT_EQ(large.back(), -1);
  in.section("whole");
  const std::vector<double> whole = in.get_vector();
  ASSERT_EQ(whole.size(), 700'000u);
  EXPECT_EQ(whole[654'321], 654'321 * 0.25);
  EXPECT_EQ(in.get_u64(), 9u);
  write_checkpoint_file(dir / "checkpoint.bin", "old");
  promote_checkpoint_file(dir / "snapshot", dir / "checkpoint.bin");
  EXPECT_EQ(read_checkpoint_file(dir / "checkpoint.bin"), memory.bytes());
  EXPECT_FALSE(std::filesystem::exists(dir / "snapshot"));
  // A vector given short or long is the writer's caller's error, caught before a file is written.
  CheckpointWriter shortened;
  shortened.section("a");
  shortened.begin_vector(2);
  shortened.put_part(std::vector<double>{1});
  EXPECT_THROW(shortened.section("b"), std::logic_error);
  CheckpointWriter lengthened;
  lengthened.section("a");
  lengthened.begin_vector(1);
  EXPECT_THROW(lengthened.put_part(std::vector<double>{1, 2}), std::logic_error);
  // Where the file cannot be written, the error names it.
  try {
    CheckpointWriter nowhere(dir / "no such folder" / "snapshot");
    FAIL() << "opened a file in a missing folder";
  } catch (const IoError& e) {
    EXPECT_NE(std::string(e.what()).find("no such folder/snapshot"), std::string::npos) << e.what();
  }
  std::filesystem::remove_all(dir);
}

// A file's sections read back from the file in order, without the file in memory: values
// as written, what is not read skipped and still checked against its checksum, a changed
// byte and a section asked for out of order refused, naming the file.
TEST(Checkpoint, AStreamReadsSectionsFromTheFile) {
  const auto dir = std::filesystem::temp_directory_path() / ("checkpoint-stream-" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  const auto file = dir / "snapshot";
  std::vector<double> large(300'000);
  for (std::size_t i = 0; i < large.size(); ++i) large[i] = static_cast<double>(i) / 3;
  {
    CheckpointWriter out(file);
    out.section("identity");
    out.put(std::string("a network"));
    out.section("large");
    out.put(large);
    out.put(std::uint64_t{11});
    out.section("last");
    out.put(std::vector<double>{2.5, -1});
    out.section("end");
    out.finish();
  }
  {
    CheckpointStream in(file);
    in.section("identity");  // not read: skipped, and checked
    in.section("large");
    ASSERT_EQ(in.get_u64(), large.size());
    std::vector<double> first(3);
    in.get_doubles(first);
    EXPECT_EQ(first, (std::vector<double>{0.0, 1.0 / 3, 2.0 / 3}));
    in.section("last");  // the rest of "large" skipped, and checked
    ASSERT_EQ(in.get_u64(), 2u);
    std::vector<double> last(2);
    in.get_doubles(last);
    EXPECT_EQ(last, (std::vector<double>{2.5, -1}));
    EXPECT_THROW(in.get_u64(), InputError);  // past the section's end
    in.finish();
  }
  {
    CheckpointStream in(file);
    EXPECT_THROW(in.section("large"), InputError);  // "identity" comes first
  }
  // One byte of "large" changed: found when the section is left.
  std::string bytes = read_checkpoint_file(file);
  bytes[bytes.size() / 2] ^= 0x10;
  write_checkpoint_file(file, bytes);
  {
    CheckpointStream in(file);
    in.section("identity");
    in.section("large");
    try {
      in.section("last");
      FAIL() << "a changed byte went unnoticed";
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find("checksum"), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find(file.string()), std::string::npos) << e.what();
    }
  }
  std::filesystem::remove_all(dir);
}

TEST(Checkpoint, RefusesAnEmptyFileAndAnEarlierFormat) {
  const auto file = std::filesystem::temp_directory_path() / ("checkpoint-empty-" + std::to_string(::getpid()));
  { std::ofstream touch(file); }
  // Resuming nothing would start the run again from its first cycle, as if resumed.
  try {
    read_checkpoint_file(file);
    FAIL() << "read an empty checkpoint";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("empty checkpoint"), std::string::npos) << e.what();
  }
  std::filesystem::remove(file);
  EXPECT_THROW(CheckpointReader("", "empty"), InputError);
  // Format 4: the same magic line, sections without lengths or checksums.
  std::string old = "hemotree checkpoint\n";
  const std::uint64_t four = 4;
  old.append(reinterpret_cast<const char*>(&four), sizeof four);
  old.append(std::string(64, '\0'));
  try {
    CheckpointReader in(old, "old.bin");
    FAIL() << "read a format 4 checkpoint";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("old.bin: checkpoint format 4 of an earlier hemosolve"), std::string::npos)
        << e.what();
  }
}

TEST(Checkpoint, ASectionIsReadWholeOrRefused) {
  CheckpointWriter out;
  out.section("a");
  out.put(1.0);
  out.put(2.0);
  out.section("b");
  CheckpointReader in(out.bytes(), "file");
  in.section("a");
  in.get_double();
  // A build that reads less of "a" than was written reads another layout.
  EXPECT_THROW(in.section("b"), InputError);
  CheckpointReader again(out.bytes(), "file");
  again.section("a");
  again.get_double();
  again.get_double();
  EXPECT_THROW(again.get_double(), InputError);  // past the section's end, not into the next
  again.section("b");
  EXPECT_TRUE(again.at_end());
}

// A chain of three vessels fed by a pulse, ending in an RCR outlet.
Network pulsed_chain() {
  const double d = 3e-3, a = std::numbers::pi / 4 * d * d;
  Network net = chain(3, 0.3, d, beta_for_wave_speed(5.0, a), 1e4, newtonian(4e-3));
  auto inflow = [](double t) { return 5e-6 + 3e-6 * std::sin(2 * std::numbers::pi * t / 0.8); };
  net.inlet = Inlet{0, tabulate(inflow, 0.8, 801, 0.8)};
  net.outlets.push_back(rcr_outlet(2, 2e8, 2e-10, 1.6e9, 0));
  return net;
}

class ResumedSolver : public ::testing::TestWithParam<TimeScheme> {};

TEST_P(ResumedSolver, GoesOnBitForBit) {
  const Network net = pulsed_chain();
  SolverOptions options;
  options.degree = 3;
  options.elements = 2;
  options.scheme = GetParam();
  PulseSolver first(net, options);
  first.balance_compliances(0.8);
  for (int k = 0; k < 300; ++k) first.step();
  first.balance_compliances(0.8);  // a move: the multistep history restarts
  for (int k = 0; k < 7; ++k) first.step();
  CheckpointWriter out;
  first.save(out);
  for (int k = 0; k < 200; ++k) first.step();

  PulseSolver second(net, options);
  CheckpointReader in(out.bytes(), "memory");
  second.restore(in);
  EXPECT_TRUE(in.at_end());
  for (int k = 0; k < 200; ++k) second.step();
  EXPECT_EQ(second.time(), first.time());
  EXPECT_EQ(second.steps(), first.steps());
  EXPECT_TRUE((second.state().area.array() == first.state().area.array()).all());
  EXPECT_TRUE((second.state().flow.array() == first.state().flow.array()).all());
  EXPECT_TRUE((second.state().capacitor.array() == first.state().capacitor.array()).all());
  EXPECT_EQ(second.exchanged_volumes(), first.exchanged_volumes());
}

// A bit changed anywhere in a checkpoint (a disk's, a copy's, a person's) is refused before
// anything is read: the solver's state, the 0D vessels, the framing, the format, the
// checksums themselves. A change inside a section names it.
TEST(ResumedSolver, RefusesEveryFlippedByte) {
  const Network net = pulsed_chain();
  SolverOptions options;
  options.degree = 2;
  options.elements = 2;
  PulseSolver writer(net, options);
  for (int k = 0; k < 20; ++k) writer.step();
  CheckpointWriter out;
  out.section("run");
  out.put(std::string("options"));
  writer.save(out);
  out.section("end");
  const std::string bytes = out.bytes();
  std::size_t refused = 0, named = 0;
  const std::size_t solver_at = bytes.find("pulse solver");
  for (std::size_t i = 0; i < bytes.size(); ++i)
    for (const unsigned char bit : {0x01, 0x04, 0x80}) {
      std::string changed = bytes;
      changed[i] = static_cast<char>(changed[i] ^ bit);
      try {
        CheckpointReader in(changed, "c.bin");
        in.section("run");
        in.get_string();
        PulseSolver reader(net, options);
        reader.restore(in);
        in.section("end");
        ADD_FAILURE() << "byte " << i << " ^ " << int{bit} << " accepted";
      } catch (const InputError& e) {
        ++refused;
        const std::string message = e.what();
        EXPECT_EQ(message.rfind("c.bin: ", 0), 0u) << message;
        // A byte of the solver's state, well inside its section (not in its name or length).
        if (i > solver_at + 20 && i + 100 < bytes.size() && i < bytes.find("0D vessels") - 30) {
          EXPECT_NE(message.find("section \"pulse solver\" does not match its checksum"), std::string::npos) << message;
          ++named;
        }
      }
    }
  EXPECT_EQ(refused, 3 * bytes.size());
  EXPECT_GT(named, 3 * 200u);
  // Cut anywhere: refused.
  for (std::size_t cut = 0; cut < bytes.size(); cut += 7) EXPECT_THROW(CheckpointReader(bytes.substr(0, cut), "c"), InputError);
}

// Read from its file (held open, read in pieces) a checkpoint gives the values it gives from
// memory, and a damaged one the same refusal word for word: cut anywhere, or a byte changed.
TEST(Checkpoint, ReadFromItsFileAsFromMemory) {
  CheckpointWriter out;
  out.section("small");
  for (int i = 0; i < 40000; ++i) out.put(static_cast<double>(i) / 7);  // across the reader's 1 MiB pieces
  out.section("large");
  std::vector<double> large(300000);
  for (std::size_t i = 0; i < large.size(); ++i) large[i] = std::sin(static_cast<double>(i));
  out.put(large);
  out.put(std::string("after"));
  const std::string bytes = out.bytes();
  const std::filesystem::path file = std::filesystem::temp_directory_path() / "hemotree-checkpoint-file-test.bin";
  auto write = [&](const std::string& b) { std::ofstream(file, std::ios::binary).write(b.data(), static_cast<std::streamsize>(b.size())); };
  write(bytes);
  {
    CheckpointReader in(file);
    EXPECT_EQ(in.source(), file.string());
    in.section("small");
    for (int i = 0; i < 40000; ++i) ASSERT_EQ(in.get_double(), static_cast<double>(i) / 7);
    in.section("large");
    EXPECT_EQ(in.get_vector(), large);
    EXPECT_EQ(in.get_string(), "after");
    EXPECT_TRUE(in.at_end());
    const std::filesystem::path copy = file.string() + ".copy";
    std::filesystem::remove(file);  // held open: its copy is still whole
    in.write_copy(copy);
    EXPECT_EQ(read_checkpoint_file(copy), bytes);
    std::filesystem::remove(copy);
  }
  auto refusal = [](auto&& read) -> std::string {
    try {
      read();
    } catch (const InputError& e) {
      return e.what();
    }
    return "accepted";
  };
  std::size_t compared = 0;
  auto same = [&](const std::string& b) {
    write(b);
    const std::string from_memory = refusal([&] { CheckpointReader in(b, file.string()); });
    EXPECT_EQ(refusal([&] { CheckpointReader in(file); }), from_memory);
    EXPECT_NE(from_memory, "accepted");
    ++compared;
  };
  for (std::size_t cut = 0; cut < bytes.size(); cut += bytes.size() / 97) same(bytes.substr(0, cut));
  for (std::size_t i = 0; i < bytes.size(); i += bytes.size() / 89 + 1) {
    std::string changed = bytes;
    changed[i] = static_cast<char>(changed[i] ^ 0x10);
    same(changed);
  }
  for (const std::size_t i : {std::size_t{3}, bytes.size() - 1}) {  // the magic line, the file's checksum
    std::string changed = bytes;
    changed[i] = static_cast<char>(changed[i] ^ 0x10);
    same(changed);
  }
  EXPECT_GT(compared, 180u);
  std::filesystem::remove(file);
  EXPECT_THROW(CheckpointReader{file}, IoError);  // none there
}

INSTANTIATE_TEST_SUITE_P(Schemes, ResumedSolver,
                         ::testing::Values(TimeScheme::exponential_ab2, TimeScheme::adams_bashforth2,
                                           TimeScheme::runge_kutta4));

TEST(ResumedSolver, RefusesAnotherDiscretisation) {
  const Network net = pulsed_chain();
  SolverOptions options;
  options.degree = 3;
  PulseSolver writer(net, options);
  CheckpointWriter out;
  writer.save(out);
  options.degree = 4;
  options.dt = writer.dt();
  PulseSolver reader(net, options);
  CheckpointReader in(out.bytes(), "memory");
  EXPECT_THROW(reader.restore(in), InputError);
}

// The volumes exchanged at the inlet and the outlets, integrated by the scheme itself,
// balance the change of the volume in the vessels to round-off: the mass balance that
// summary.json reports is the scheme's, not an interpolation of end values.
class ExchangedVolumes : public ::testing::TestWithParam<TimeScheme> {};

TEST_P(ExchangedVolumes, BalanceTheStoredVolume) {
  const Network net = pulsed_chain();
  SolverOptions options;
  options.degree = 4;
  options.elements = 3;
  options.scheme = GetParam();
  PulseSolver s(net, options);
  const double start = s.network_volume();
  double inflow = 0;
  const Waveform& w = net.inlet->waveform;
  const int steps = 2000;
  for (int k = 0; k < steps; ++k) {
    inflow += s.dt() * w(s.time() + 0.5 * s.dt());  // midpoint: the prescribed inflow, to O(dt^2)
    s.step();
  }
  const Eigen::Vector2d exchanged = s.exchanged_volumes();
  const double stored = s.network_volume() - start;
  EXPECT_GT(exchanged(1), 0);
  EXPECT_NEAR(exchanged(0) - exchanged(1), stored, 1e-12 * exchanged(0));
  // The inlet passes the prescribed flow.
  EXPECT_NEAR(exchanged(0), inflow, 1e-5 * inflow);
}

INSTANTIATE_TEST_SUITE_P(Schemes, ExchangedVolumes,
                         ::testing::Values(TimeScheme::exponential_ab2, TimeScheme::adams_bashforth2,
                                           TimeScheme::runge_kutta4));

}  // namespace
}  // namespace hemotree

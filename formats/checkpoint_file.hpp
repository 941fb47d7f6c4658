// A run's checkpoint: the solver's evolving state and the run's progress, as one binary
// file written atomically (a temporary beside it, flushed to disk, then renamed over the
// old one), so that a kill at any moment leaves the previous checkpoint or the new one.
// Numbers are stored as their bytes (a checkpoint resumes a run on the same kind of
// machine; nothing is rounded, so the resumed run continues bit for bit). Named sections
// let the reader refuse, with a clear line, a file of another kind or version instead of
// reading it as garbage, and checksums a file changed after it was written: a flipped bit
// in a stored state would otherwise resume as a plausible run with wrong numbers.
//
// The file (format 8):
//   "hemotree checkpoint\n", u64 format
//   each section: u64 name length, name, u64 payload length, payload,
//                 u64 checksum of the section (its name, length and payload)
//   u64 checksum of everything before it
// Checksums are 64-bit FNV-1a: every step of it is a bijection of the state, so any change
// of a single byte changes it; a random change passes with odds 2^-64.
#pragma once

#include <cstdint>
#include <cstdio>
#include <span>
#include <filesystem>
#include <functional>
#include <string>
#include <string_view>
#include <vector>

#include <Eigen/Dense>

namespace hemotree {

class CheckpointWriter {
 public:
  CheckpointWriter();  // in memory (bytes()); starts with the file's magic line and format version
  // Straight to `file` (created or truncated), IoError naming it where it cannot be written:
  // the bytes go out in pieces of a few megabytes as they come, and a section's length and
  // checksum are written when it closes (its length in place, its bytes read back for the
  // checksum), so the writer holds neither the file nor a whole section (the 0D vessels' of
  // a full tree are 0.9 GB). finish() ends the file; it is not synced to disk
  // (promote_checkpoint_file does that).
  explicit CheckpointWriter(const std::filesystem::path& file);
  ~CheckpointWriter();
  CheckpointWriter(const CheckpointWriter&) = delete;
  CheckpointWriter& operator=(const CheckpointWriter&) = delete;
  // Closes the section before (its length and checksum) and opens one; every value is in one.
  void section(std::string_view name);
  void put(double x);
  void put(std::uint64_t x);
  void put(bool x) { put(std::uint64_t{x}); }
  void put(const std::string& text);
  void put(const std::vector<double>& values);
  void put(const Eigen::MatrixXd& m);
  void put(const Eigen::VectorXd& v);
  // A vector of `count` doubles given in parts (put_part, in order, `count` in all), so that
  // one assembled from per-vessel records need not be held whole: get_vector() reads it.
  void begin_vector(std::uint64_t count);
  void put_part(std::span<const double> values);
  // In memory: the whole file, the open section closed and the file's checksum appended.
  std::string bytes() const;
  // To a file: the open section and the file's checksum written, the file closed.
  void finish();

 private:
  void raw(const void* data, std::size_t size);
  static void close_section(std::string& bytes, std::size_t start);
  void spill();               // to the file: bytes_ out as they are
  void close_file_section();  // to the file: the open section's length and checksum
  std::string bytes_;
  // The open section's start (in the file mode, its offset in the file) and its name's size.
  std::size_t section_start_ = std::string::npos, section_name_size_ = 0;
  std::uint64_t vector_left_ = 0;  // of a vector being given in parts
  // The file mode: its descriptor (-1: in memory), name, the bytes written, and the file's
  // checksum of the bytes before hashed_ (every section closed).
  int fd_ = -1;
  std::filesystem::path file_;
  std::uint64_t written_ = 0, hashed_ = 0, written_hash_ = 0;
};

// Reads what a CheckpointWriter wrote, in the same order; InputError naming the file at the
// first thing that is not what the run expects (another kind of file, a truncated one, a
// section or size of another run).
class CheckpointReader {
 public:
  // Checks the whole file before anything is read from it: an empty or truncated file, one
  // of another format, a section whose bytes do not match its checksum (named) are refused.
  CheckpointReader(std::string bytes, std::string source);
  // The same from the file itself, held open, not in memory: a resume of the full tree held
  // its 0.67 GB checkpoint as bytes (twice, at a moment) beside the state made from them, on
  // every rank (3.5 GB, the run itself 1.8 GB). IoError where it cannot be opened or read; the file is read in pieces, once
  // for the checks and once as the values are asked for. It must not change in place
  // meanwhile (a run writes its checkpoints to a temporary renamed over the old, and holds
  // its folder's lock): a copy (write_copy) checks it again, the values read do not.
  explicit CheckpointReader(const std::filesystem::path& file);
  ~CheckpointReader();
  CheckpointReader(const CheckpointReader&) = delete;
  CheckpointReader& operator=(const CheckpointReader&) = delete;
  const std::string& source() const { return source_; }  // what its messages name
  // Its bytes as a checkpoint file at `to` (as write_checkpoint_file writes one), copied in
  // pieces from the file it reads (which may have been removed since: it is held open).
  void write_copy(const std::filesystem::path& to) const;
  // Whether `file` names the very file it reads (the same device and inode: moved there,
  // say), where it reads one.
  bool reads(const std::filesystem::path& file) const;
  // The next section, which must be this one; the one before must have been read whole.
  void section(std::string_view name);
  double get_double();
  std::uint64_t get_u64();
  bool get_bool() { return get_u64() != 0; }
  std::string get_string();
  std::vector<double> get_vector();
  // A vector (put or given in parts) read in parts, so that one taken apart into per-item
  // records, or only partly kept, need not be held whole: its length, then get_part() in
  // order; or passed over whole (its length returned).
  std::uint64_t begin_vector();
  void get_part(std::span<double> values);
  std::uint64_t skip_vector();
  Eigen::MatrixXd get_matrix();
  Eigen::VectorXd get_eigen_vector();
  // The matrix or vector read must have these dimensions (the run's discretisation).
  void get_into(Eigen::MatrixXd& m, const char* what);
  void get_into(Eigen::VectorXd& v, const char* what);
  bool at_end() const { return next_ == sections_.size() && at_ == end_; }
  [[noreturn]] void fail(const std::string& message) const;

 private:
  struct Section {
    std::string name;
    std::size_t begin, end;  // of the payload
  };
  void raw(void* data, std::size_t size);
  std::size_t left() const { return end_ - at_; }
  void check_header();
  void index_sections();
  // size bytes at offset `at` (within size_), from memory or the file.
  void read_at(std::size_t at, void* data, std::size_t size) const;
  std::uint64_t word_at(std::size_t at) const;
  // f(bytes, n) for [begin, end) in pieces of at most a MiB, in order.
  void for_each_piece(std::size_t begin, std::size_t end, const std::function<void(const char*, std::size_t)>& f) const;
  std::string bytes_, source_;  // bytes_: in memory; empty where read from a file
  int fd_ = -1;                 // the file read from, or -1
  std::size_t size_ = 0;        // of the checkpoint
  // The file's bytes [window_at_, window_at_ + window_.size()): small values are read from
  // there, a piece at a time, large ones straight into their place.
  mutable std::vector<char> window_;
  mutable std::size_t window_at_ = 0;
  std::vector<Section> sections_;
  std::size_t next_ = 0;          // the section that section() opens next
  std::size_t at_ = 0, end_ = 0;  // where reading is, and the open section's end
};

// bytes: a CheckpointWriter's bytes().
void write_checkpoint_file(const std::filesystem::path& file, const std::string& bytes);
// A finished file of a CheckpointWriter(file) made the checkpoint `to`: synced to disk, then
// renamed over it, so that `to` holds the old checkpoint or the new one whatever happens.
void promote_checkpoint_file(const std::filesystem::path& from, const std::filesystem::path& to);
// An empty file is refused here (InputError): it holds no run, and resuming nothing would
// silently start again from the first cycle.
std::string read_checkpoint_file(const std::filesystem::path& file);

// FNV-1a over bytes: a fingerprint of what a checkpoint belongs to (the network's arrays).
class Fingerprint {
 public:
  Fingerprint() = default;
  // Carried on from a value(): FNV-1a goes byte by byte, so the bytes in parts hash as a whole.
  explicit Fingerprint(std::uint64_t carried) : hash_(carried) {}
  void add(const void* data, std::size_t size);
  template <class T>
  void add(const std::vector<T>& values) {
    add(values.data(), values.size() * sizeof(T));
  }
  void add(double x) { add(&x, sizeof x); }
  void add(std::string_view text) { add(text.data(), text.size()); }
  std::uint64_t value() const { return hash_; }

 private:
  std::uint64_t hash_ = 14695981039346656037ull;
};

// Sections of a checkpoint file read from the file itself, in order, without the file in
// memory (a full tree's is a gigabyte): for what a run wants back from its own snapshot (the
// last cycle's results, solver/pulsatile_run). Each section is checked against its checksum
// when the next is opened or finish() is called; the file's own checksum is not (it needs the
// whole file). InputError naming the file at anything else than what is asked for.
class CheckpointStream {
 public:
  explicit CheckpointStream(const std::filesystem::path& file);
  ~CheckpointStream();
  CheckpointStream(const CheckpointStream&) = delete;
  CheckpointStream& operator=(const CheckpointStream&) = delete;
  // The next section, which must be this one; what was left of the one before is skipped.
  void section(std::string_view name);
  std::uint64_t get_u64();
  void get_doubles(std::span<double> out);
  void finish();  // what is left of the open section skipped, and its checksum checked

 private:
  void read(void* data, std::size_t size, bool hashed = true);
  void close_section();
  [[noreturn]] void fail(const std::string& message) const;
  std::FILE* file_ = nullptr;
  std::filesystem::path path_;
  Fingerprint hash_;            // of the open section's bytes so far
  std::uint64_t left_ = 0;      // of its payload
  bool open_ = false;
};

}  // namespace hemotree

// A run's checkpoint: the solver's evolving state and the run's progress, as one binary
// file written atomically (a temporary beside it, flushed to disk, then renamed over the
// old one), so that a kill at any moment leaves the previous checkpoint or the new one.
// Numbers are stored as their bytes (a checkpoint resumes a run on the same kind of
// machine; nothing is rounded, so the resumed run continues bit for bit). Named sections
// let the reader refuse, with a clear line, a file of another kind or version instead of
// reading it as garbage.
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

#include <Eigen/Dense>

namespace hemotree {

class CheckpointWriter {
 public:
  CheckpointWriter();  // starts with the file's magic line and format version
  void section(std::string_view name);
  void put(double x);
  void put(std::uint64_t x);
  void put(bool x) { put(std::uint64_t{x}); }
  void put(const std::string& text);
  void put(const std::vector<double>& values);
  void put(const Eigen::MatrixXd& m);
  void put(const Eigen::VectorXd& v);
  const std::string& bytes() const { return bytes_; }

 private:
  void raw(const void* data, std::size_t size);
  std::string bytes_;
};

// Reads what a CheckpointWriter wrote, in the same order; InputError naming the file at the
// first thing that is not what the run expects (another kind of file, a truncated one, a
// section or size of another run).
class CheckpointReader {
 public:
  CheckpointReader(std::string bytes, std::string source);
  void section(std::string_view name);
  double get_double();
  std::uint64_t get_u64();
  bool get_bool() { return get_u64() != 0; }
  std::string get_string();
  std::vector<double> get_vector();
  Eigen::MatrixXd get_matrix();
  Eigen::VectorXd get_eigen_vector();
  // The matrix or vector read must have these dimensions (the run's discretisation).
  void get_into(Eigen::MatrixXd& m, const char* what);
  void get_into(Eigen::VectorXd& v, const char* what);
  bool at_end() const { return at_ == bytes_.size(); }
  [[noreturn]] void fail(const std::string& message) const;

 private:
  void raw(void* data, std::size_t size);
  std::string bytes_, source_;
  std::size_t at_ = 0;
};

void write_checkpoint_file(const std::filesystem::path& file, const CheckpointWriter& checkpoint);
std::string read_checkpoint_file(const std::filesystem::path& file);

// FNV-1a over bytes: a fingerprint of what a checkpoint belongs to (the network's arrays).
class Fingerprint {
 public:
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

}  // namespace hemotree

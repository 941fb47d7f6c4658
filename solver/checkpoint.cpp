#include "solver/checkpoint.hpp"

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <fcntl.h>
#include <fstream>
#include <iterator>
#include <unistd.h>

#include "cli/errors.hpp"

namespace hemotree {

namespace {
constexpr std::string_view magic = "hemotree checkpoint\n";
constexpr std::uint64_t format_version = 4;  // 2: the 0D vessels keep their previous pressures; 3: their volumes above c; 4: face volumes
}  // namespace

CheckpointWriter::CheckpointWriter() {
  bytes_.append(magic);
  put(format_version);
}

void CheckpointWriter::raw(const void* data, std::size_t size) {
  if (size == 0) return;  // an empty matrix's data() is null, which memcpy must not see
  bytes_.append(static_cast<const char*>(data), size);
}

void CheckpointWriter::section(std::string_view name) { put(std::string(name)); }
void CheckpointWriter::put(double x) { raw(&x, sizeof x); }
void CheckpointWriter::put(std::uint64_t x) { raw(&x, sizeof x); }

void CheckpointWriter::put(const std::string& text) {
  put(static_cast<std::uint64_t>(text.size()));
  raw(text.data(), text.size());
}

void CheckpointWriter::put(const std::vector<double>& values) {
  put(static_cast<std::uint64_t>(values.size()));
  raw(values.data(), values.size() * sizeof(double));
}

void CheckpointWriter::put(const Eigen::MatrixXd& m) {
  put(static_cast<std::uint64_t>(m.rows()));
  put(static_cast<std::uint64_t>(m.cols()));
  raw(m.data(), static_cast<std::size_t>(m.size()) * sizeof(double));
}

void CheckpointWriter::put(const Eigen::VectorXd& v) {
  put(static_cast<std::uint64_t>(v.size()));
  raw(v.data(), static_cast<std::size_t>(v.size()) * sizeof(double));
}

CheckpointReader::CheckpointReader(std::string bytes, std::string source)
    : bytes_(std::move(bytes)), source_(std::move(source)) {
  if (bytes_.compare(0, magic.size(), magic) != 0) fail("not a hemosolve checkpoint");
  at_ = magic.size();
  const std::uint64_t version = get_u64();
  if (version != format_version)
    fail("checkpoint format " + std::to_string(version) + ", this build reads format " +
         std::to_string(format_version));
}

void CheckpointReader::fail(const std::string& message) const {
  throw InputError(source_ + ": " + message);
}

void CheckpointReader::raw(void* data, std::size_t size) {
  if (size > bytes_.size() - at_) fail("truncated checkpoint");
  if (size == 0) return;  // an empty matrix's data() is null, which memcpy must not see
  std::memcpy(data, bytes_.data() + at_, size);
  at_ += size;
}

void CheckpointReader::section(std::string_view name) {
  const std::string found = get_string();
  if (found != name) fail("checkpoint of another kind or version (expected section \"" + std::string(name) + "\")");
}

double CheckpointReader::get_double() {
  double x;
  raw(&x, sizeof x);
  return x;
}

std::uint64_t CheckpointReader::get_u64() {
  std::uint64_t x;
  raw(&x, sizeof x);
  return x;
}

std::string CheckpointReader::get_string() {
  const std::uint64_t size = get_u64();
  if (size > bytes_.size() - at_) fail("truncated checkpoint");
  std::string text(bytes_.data() + at_, size);
  at_ += size;
  return text;
}

std::vector<double> CheckpointReader::get_vector() {
  const std::uint64_t size = get_u64();
  if (size > (bytes_.size() - at_) / sizeof(double)) fail("truncated checkpoint");
  std::vector<double> values(size);
  raw(values.data(), size * sizeof(double));
  return values;
}

Eigen::MatrixXd CheckpointReader::get_matrix() {
  const std::uint64_t rows = get_u64(), cols = get_u64();
  if (cols != 0 && rows > (bytes_.size() - at_) / sizeof(double) / cols) fail("truncated checkpoint");
  Eigen::MatrixXd m(static_cast<Eigen::Index>(rows), static_cast<Eigen::Index>(cols));
  raw(m.data(), static_cast<std::size_t>(m.size()) * sizeof(double));
  return m;
}

Eigen::VectorXd CheckpointReader::get_eigen_vector() {
  const std::uint64_t size = get_u64();
  if (size > (bytes_.size() - at_) / sizeof(double)) fail("truncated checkpoint");
  Eigen::VectorXd v(static_cast<Eigen::Index>(size));
  raw(v.data(), size * sizeof(double));
  return v;
}

void CheckpointReader::get_into(Eigen::MatrixXd& m, const char* what) {
  Eigen::MatrixXd read = get_matrix();
  if (read.rows() != m.rows() || read.cols() != m.cols())
    fail(std::string(what) + " of " + std::to_string(read.rows()) + " x " + std::to_string(read.cols()) +
         " where this run has " + std::to_string(m.rows()) + " x " + std::to_string(m.cols()) +
         ": the checkpoint belongs to another discretisation");
  m = std::move(read);
}

void CheckpointReader::get_into(Eigen::VectorXd& v, const char* what) {
  Eigen::VectorXd read = get_eigen_vector();
  if (read.size() != v.size())
    fail(std::string(what) + " of " + std::to_string(read.size()) + " where this run has " +
         std::to_string(v.size()) + ": the checkpoint belongs to another discretisation");
  v = std::move(read);
}

void write_checkpoint_file(const std::filesystem::path& file, const CheckpointWriter& checkpoint) {
  const std::filesystem::path temp = file.string() + ".tmp";
  const int fd = ::open(temp.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (fd < 0) throw IoError("cannot write " + temp.string() + ": " + std::strerror(errno));
  const std::string& bytes = checkpoint.bytes();
  std::size_t written = 0;
  while (written < bytes.size()) {
    const ssize_t n = ::write(fd, bytes.data() + written, bytes.size() - written);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) {
      const int error = errno;
      ::close(fd);
      ::unlink(temp.c_str());
      throw IoError("cannot write " + temp.string() + ": " + std::strerror(error));
    }
    written += static_cast<std::size_t>(n);
  }
  // On disk before the rename: after a crash the name holds a whole checkpoint or the old one.
  if (::fsync(fd) != 0 || ::close(fd) != 0) {
    ::unlink(temp.c_str());
    throw IoError("cannot write " + temp.string() + ": " + std::strerror(errno));
  }
  if (std::rename(temp.c_str(), file.c_str()) != 0) {
    const int error = errno;
    ::unlink(temp.c_str());
    throw IoError("cannot write " + file.string() + ": " + std::strerror(error));
  }
}

std::string read_checkpoint_file(const std::filesystem::path& file) {
  std::ifstream in(file, std::ios::binary);
  if (!in) throw IoError("cannot open " + file.string());
  std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (in.bad()) throw IoError("cannot read " + file.string());
  return bytes;
}

void Fingerprint::add(const void* data, std::size_t size) {
  const auto* p = static_cast<const unsigned char*>(data);
  for (std::size_t i = 0; i < size; ++i) {
    hash_ ^= p[i];
    hash_ *= 1099511628211ull;
  }
}

}  // namespace hemotree

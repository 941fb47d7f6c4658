#include "formats/checkpoint_file.hpp"

#include <algorithm>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <fcntl.h>
#include <sys/stat.h>
#include <fstream>
#include <functional>
#include <stdexcept>
#include <unistd.h>

#include "core/errors.hpp"

namespace hemotree {

namespace {
constexpr std::string_view magic = "hemotree checkpoint\n";
// 2: the 0D vessels keep their previous pressures; 3: their volumes above c; 4: face volumes;
// 5: sections framed by their length and checksummed, and the file checksummed.
// 6: the transport's last face volumes; 7: the run's identity in a section of its own (a hash of the
// whole network and the options that shape the state), so that no field is left out of it.
// 8: the last two cycles' results in sections of their own (a writer holds one section at a time).
// 9: of the cycle before the last, its mean pressures alone (what the periodicity test reads).
// 10: no volumes in and out summed over the boundaries (each boundary's volume gives them).
// 11: the red cells in and out per boundary (ranks hold a few each), the faces before the step count.
constexpr std::uint64_t format_version = 11;
constexpr std::size_t word = sizeof(std::uint64_t);
constexpr std::size_t header = magic.size() + word;  // the magic line and the format
constexpr std::size_t piece_bytes = std::size_t{1} << 20;  // what a reader of the file reads at once

std::uint64_t checksum(const std::string& bytes, std::size_t begin, std::size_t end) {
  Fingerprint f;
  f.add(bytes.data() + begin, end - begin);
  return f.value();
}

void append_word(std::string& bytes, std::uint64_t x) { bytes.append(reinterpret_cast<const char*>(&x), word); }

std::uint64_t word_at(const std::string& bytes, std::size_t at) {
  std::uint64_t x;
  std::memcpy(&x, bytes.data() + at, word);
  return x;
}

// A section as a message names it: by its name where that is readable text (a damaged length
// can make it any bytes), else by its place in the file.
std::string describe_section(const std::string& name, std::size_t index) {
  const bool readable = !name.empty() && name.size() <= 40 &&
                        std::all_of(name.begin(), name.end(), [](char c) { return c >= ' ' && c <= '~'; });
  return readable ? "section \"" + name + "\"" : "section " + std::to_string(index + 1);
}

// All of it to fd, IoError naming the file where it cannot.
void write_all(int fd, const char* data, std::size_t size, const std::filesystem::path& file) {
  std::size_t written = 0;
  while (written < size) {
    const ssize_t n = ::write(fd, data + written, size - written);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) throw IoError("cannot write " + file.string() + ": " + std::strerror(errno));
    written += static_cast<std::size_t>(n);
  }
}
}  // namespace

CheckpointWriter::CheckpointWriter() {
  bytes_.append(magic);
  append_word(bytes_, format_version);
}

CheckpointWriter::CheckpointWriter(const std::filesystem::path& file) : CheckpointWriter() {
  file_ = file;
  fd_ = ::open(file.c_str(), O_RDWR | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);  // read: the checksums
  if (fd_ < 0) throw IoError("cannot write " + file.string() + ": " + std::strerror(errno));
  written_hash_ = Fingerprint().value();
}

CheckpointWriter::~CheckpointWriter() {
  if (fd_ >= 0) ::close(fd_);
}

void CheckpointWriter::spill() {
  write_all(fd_, bytes_.data(), bytes_.size(), file_);
  written_ += bytes_.size();
  bytes_.clear();
}

void CheckpointWriter::close_file_section() {
  spill();
  const std::uint64_t start = section_start_, length_at = start + word + section_name_size_;
  const std::uint64_t length = written_ - length_at - word;
  if (::pwrite(fd_, &length, word, static_cast<off_t>(length_at)) != static_cast<ssize_t>(word))
    throw IoError("cannot write " + file_.string() + ": " + std::strerror(errno));
  // The section's checksum, and the file's carried on (FNV-1a goes byte by byte), over its
  // bytes as they now stand in the file (the page cache's: a read at memory speed).
  Fingerprint section, file(written_hash_);
  std::vector<char> piece(std::size_t{1} << 20);
  for (std::uint64_t at = hashed_; at < written_;) {
    const auto want = static_cast<std::size_t>(std::min<std::uint64_t>(piece.size(), written_ - at));
    const ssize_t n = ::pread(fd_, piece.data(), want, static_cast<off_t>(at));
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) throw IoError("cannot read back " + file_.string() + ": " + std::strerror(n < 0 ? errno : EIO));
    file.add(piece.data(), static_cast<std::size_t>(n));
    const std::uint64_t from = std::max(at, start);  // the header before the first section: the file's alone
    if (from < at + static_cast<std::uint64_t>(n))
      section.add(piece.data() + (from - at), static_cast<std::size_t>(at + static_cast<std::uint64_t>(n) - from));
    at += static_cast<std::uint64_t>(n);
  }
  const std::uint64_t sum = section.value();
  file.add(&sum, word);
  append_word(bytes_, sum);
  spill();
  written_hash_ = file.value();
  hashed_ = written_;
  section_start_ = std::string::npos;
}

void CheckpointWriter::finish() {
  if (fd_ < 0) throw std::logic_error("checkpoint: finish() of a writer in memory");
  if (vector_left_ != 0) throw std::logic_error("checkpoint: a vector given in parts is short");
  if (section_start_ != std::string::npos) close_file_section();
  if (hashed_ < written_ + bytes_.size()) {  // no section at all: the header alone
    Fingerprint f(written_hash_);
    f.add(bytes_.data(), bytes_.size());
    written_hash_ = f.value();
    spill();
    hashed_ = written_;
  }
  append_word(bytes_, written_hash_);
  spill();
  const int fd = fd_;
  fd_ = -1;
  if (::close(fd) != 0) throw IoError("cannot write " + file_.string() + ": " + std::strerror(errno));
}

void CheckpointWriter::begin_vector(std::uint64_t count) {
  put(count);
  vector_left_ = count;
}

void CheckpointWriter::put_part(std::span<const double> values) {
  if (values.size() > vector_left_) throw std::logic_error("checkpoint: a vector given in parts is too long");
  vector_left_ -= values.size();
  raw(values.data(), values.size() * sizeof(double));
}

void CheckpointWriter::raw(const void* data, std::size_t size) {
  if (section_start_ == std::string::npos) throw std::logic_error("checkpoint: a value written before any section");
  if (size == 0) return;  // an empty matrix's data() is null, which memcpy must not see
  constexpr std::size_t piece = std::size_t{4} << 20;
  if (fd_ >= 0 && bytes_.size() + size >= piece) {
    // What would fill the buffer goes to the file after it, as it is: the buffer stays below
    // a piece, where it grew to the largest array written (a full tree's are 30 MB).
    spill();
    write_all(fd_, static_cast<const char*>(data), size, file_);
    written_ += size;
    return;
  }
  bytes_.append(static_cast<const char*>(data), size);
}

// The section from start: its payload's length in the word after its name, its checksum after it.
void CheckpointWriter::close_section(std::string& bytes, std::size_t start) {
  const std::size_t length_at = start + word + word_at(bytes, start);
  const std::uint64_t length = bytes.size() - length_at - word;
  std::memcpy(bytes.data() + length_at, &length, word);
  append_word(bytes, checksum(bytes, start, bytes.size()));
}

void CheckpointWriter::section(std::string_view name) {
  if (vector_left_ != 0) throw std::logic_error("checkpoint: a vector given in parts is short");
  if (section_start_ != std::string::npos) {
    if (fd_ >= 0) close_file_section();
    else close_section(bytes_, section_start_);
  }
  section_start_ = written_ + bytes_.size();  // in memory, written_ stays 0
  section_name_size_ = name.size();
  append_word(bytes_, name.size());
  bytes_.append(name);
  append_word(bytes_, 0);  // the payload's length, known when the section closes
}

std::string CheckpointWriter::bytes() const {
  if (!file_.empty()) throw std::logic_error("checkpoint: bytes() of a writer to a file");
  std::string file = bytes_;
  if (section_start_ != std::string::npos) close_section(file, section_start_);
  append_word(file, checksum(file, 0, file.size()));
  return file;
}
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
    : bytes_(std::move(bytes)), source_(std::move(source)), size_(bytes_.size()) {
  check_header();
  index_sections();
}

CheckpointReader::CheckpointReader(const std::filesystem::path& file) : source_(file.string()) {
  fd_ = ::open(file.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd_ < 0) throw IoError("cannot open " + file.string());
  struct stat st {};
  if (::fstat(fd_, &st) != 0) {
    const int error = errno;
    ::close(fd_);
    throw IoError("cannot read " + file.string() + ": " + std::strerror(error));
  }
  size_ = static_cast<std::size_t>(st.st_size);
  try {
    check_header();
    index_sections();
  } catch (...) {
    ::close(fd_);
    throw;
  }
}

bool CheckpointReader::reads(const std::filesystem::path& file) const {
  struct stat mine {}, there {};
  return fd_ >= 0 && ::fstat(fd_, &mine) == 0 && ::stat(file.c_str(), &there) == 0 && mine.st_dev == there.st_dev &&
         mine.st_ino == there.st_ino;
}

CheckpointReader::~CheckpointReader() {
  if (fd_ >= 0) ::close(fd_);
}

void CheckpointReader::read_at(std::size_t at, void* data, std::size_t size) const {
  if (size == 0) return;  // an empty matrix's data() is null, which memcpy must not see
  if (fd_ < 0) {
    std::memcpy(data, bytes_.data() + at, size);
    return;
  }
  auto* out = static_cast<char*>(data);
  if (at >= window_at_ && at + size <= window_at_ + window_.size()) {
    std::memcpy(out, window_.data() + (at - window_at_), size);
    return;
  }
  const bool small = size < piece_bytes / 4;
  char* into = out;
  std::size_t want = size;
  if (small) {  // the window moved here: the values after it come from memory
    window_.resize(std::min(piece_bytes, size_ - at));
    window_at_ = at;
    into = window_.data();
    want = window_.size();
  }
  for (std::size_t done = 0; done < want;) {
    const ssize_t n = ::pread(fd_, into + done, want - done, static_cast<off_t>(at + done));
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) {
      window_.clear();
      throw IoError("cannot read " + source_ + ": " + (n < 0 ? std::strerror(errno) : "it is shorter than it was"));
    }
    done += static_cast<std::size_t>(n);
  }
  if (small) std::memcpy(out, window_.data(), size);
}

void CheckpointReader::for_each_piece(std::size_t begin, std::size_t end,
                                      const std::function<void(const char*, std::size_t)>& f) const {
  std::vector<char> piece(std::min(piece_bytes, end - begin));
  for (std::size_t at = begin; at < end;) {
    const std::size_t n = std::min(piece.size(), end - at);
    read_at(at, piece.data(), n);
    f(piece.data(), n);
    at += n;
  }
}

std::uint64_t CheckpointReader::word_at(std::size_t at) const {
  std::uint64_t x;
  read_at(at, &x, word);
  return x;
}

void CheckpointReader::check_header() {
  std::string start(std::min(size_, magic.size()), '\0');
  read_at(0, start.data(), start.size());
  if (size_ == 0) fail("empty checkpoint (0 bytes): nothing to resume");
  if (start != magic.substr(0, start.size())) fail("not a hemosolve checkpoint");
  if (size_ < header) fail("truncated checkpoint (" + std::to_string(size_) + " bytes)");
  const std::uint64_t version = word_at(magic.size());
  if (version >= 1 && version < format_version)
    fail("checkpoint format " + std::to_string(version) + " of an earlier hemosolve; this build reads format " +
         std::to_string(format_version) + " only: start the run afresh");
  if (version != format_version)
    fail("checkpoint format " + std::to_string(version) + ", this build reads format " +
         std::to_string(format_version) + " (a newer hemosolve's, or a damaged file)");
}

// Walks the sections, checking each against its checksum and the whole file against its
// own, so that nothing is read from a file changed after it was written. One pass: the
// file's checksum (FNV-1a, byte by byte) is carried through the sections' bytes in order.
void CheckpointReader::index_sections() {
  const std::size_t size = size_;
  const std::size_t last = size >= header + word ? size - word : header;  // where the sections end
  Fingerprint file;
  // Adds [begin, end) to the file's checksum (it has every byte before begin) and to `to`.
  auto hash = [&](std::size_t begin, std::size_t end, Fingerprint* to) {
    for_each_piece(begin, end, [&](const char* piece, std::size_t n) {
      file.add(piece, n);
      if (to) to->add(piece, n);
    });
  };
  hash(0, std::min(header, last), nullptr);
  std::size_t at = header;
  std::string before = "the format";  // for a message about what follows it
  auto damaged = [&](const std::string& what) {
    fail("truncated or damaged checkpoint (" + std::to_string(size) + " bytes): " + what +
         "; it cannot be resumed");
  };
  while (at < last) {
    // Each length is checked against what is left before it is used.
    if (last - at < word) damaged("the section after " + before + " is cut short");
    const std::uint64_t name_length = word_at(at);
    if (name_length > last - at - word || last - at - word - name_length < word)
      damaged("the section after " + before + " runs past the end");
    const std::size_t name_at = at + word, length_at = name_at + name_length;
    std::string name(name_length, '\0');
    read_at(name_at, name.data(), name.size());
    const std::uint64_t length = word_at(length_at);
    const std::size_t begin = length_at + word;
    const std::string described = describe_section(name, sections_.size());
    if (length > last - begin || last - begin - length < word) damaged(described + " runs past the end");
    const std::size_t end = begin + length;
    Fingerprint section;
    hash(at, end, &section);
    const std::uint64_t sum = word_at(end);
    if (sum != section.value())
      fail(described + " does not match its checksum: the file was changed or damaged after it was written; "
           "it cannot be resumed");
    file.add(&sum, word);
    before = described;
    sections_.push_back({std::move(name), begin, end});
    at = end + word;
  }
  const bool whole = size >= header + word && at == last && word_at(last) == file.value();
  if (!whole) damaged("the file's checksum does not match (the bytes after " + before + " or the checksum itself)");
  at_ = end_ = header;
}

void CheckpointReader::fail(const std::string& message) const {
  throw InputError(source_ + ": " + message);
}

void CheckpointReader::raw(void* data, std::size_t size) {
  // The checksums held: a section shorter than this build reads was written by another layout.
  if (size > left()) fail("checkpoint of another kind or version (a section ends before this build has read it)");
  read_at(at_, data, size);
  at_ += size;
}

void CheckpointReader::section(std::string_view name) {
  const std::string expected = "(expected section \"" + std::string(name) + "\")";
  if (at_ != end_) fail("checkpoint of another kind or version (section \"" + sections_[next_ - 1].name +
                        "\" holds more than this build reads) " + expected);
  if (next_ == sections_.size()) fail("checkpoint of another kind or version (it ends early) " + expected);
  const Section& s = sections_[next_++];
  if (s.name != name) fail("checkpoint of another kind or version (section \"" + s.name + "\" where this build reads \"" +
                           std::string(name) + "\")");
  at_ = s.begin;
  end_ = s.end;
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
  if (size > left()) fail("checkpoint of another kind or version (a string runs past its section)");
  std::string text(size, '\0');
  read_at(at_, text.data(), size);
  at_ += size;
  return text;
}

std::vector<double> CheckpointReader::get_vector() {
  const std::uint64_t size = get_u64();
  if (size > left() / sizeof(double)) fail("checkpoint of another kind or version (a vector runs past its section)");
  std::vector<double> values(size);
  raw(values.data(), size * sizeof(double));
  return values;
}

std::uint64_t CheckpointReader::begin_vector() {
  const std::uint64_t size = get_u64();
  if (size > left() / sizeof(double)) fail("checkpoint of another kind or version (a vector runs past its section)");
  return size;
}

void CheckpointReader::get_part(std::span<double> values) { raw(values.data(), values.size() * sizeof(double)); }

std::uint64_t CheckpointReader::skip_vector() {
  const std::uint64_t size = begin_vector();
  at_ += size * sizeof(double);
  return size;
}

Eigen::MatrixXd CheckpointReader::get_matrix() {
  const std::uint64_t rows = get_u64(), cols = get_u64();
  if (cols != 0 && rows > left() / sizeof(double) / cols)
    fail("checkpoint of another kind or version (a matrix runs past its section)");
  Eigen::MatrixXd m(static_cast<Eigen::Index>(rows), static_cast<Eigen::Index>(cols));
  raw(m.data(), static_cast<std::size_t>(m.size()) * sizeof(double));
  return m;
}

Eigen::VectorXd CheckpointReader::get_eigen_vector() {
  const std::uint64_t size = get_u64();
  if (size > left() / sizeof(double)) fail("checkpoint of another kind or version (a vector runs past its section)");
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

namespace {
// A checkpoint file written whole by write(fd, temp) to a temporary beside it, then promoted.
template <class Write>
void write_through_temporary(const std::filesystem::path& file, Write&& write) {
  const std::filesystem::path temp = file.string() + ".tmp";
  const int fd = ::open(temp.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (fd < 0) throw IoError("cannot write " + temp.string() + ": " + std::strerror(errno));
  try {
    write(fd, temp);
  } catch (...) {
    ::close(fd);
    ::unlink(temp.c_str());
    throw;
  }
  try {
    if (::close(fd) != 0) throw IoError("cannot write " + temp.string() + ": " + std::strerror(errno));
    promote_checkpoint_file(temp, file);  // synced, then renamed over `file`
  } catch (...) {
    ::unlink(temp.c_str());
    throw;
  }
}
}  // namespace

void write_checkpoint_file(const std::filesystem::path& file, const std::string& bytes) {
  write_through_temporary(file, [&](int fd, const std::filesystem::path& temp) { write_all(fd, bytes.data(), bytes.size(), temp); });
}

void CheckpointReader::write_copy(const std::filesystem::path& to) const {
  if (fd_ < 0) {
    write_checkpoint_file(to, bytes_);
    return;
  }
  write_through_temporary(to, [&](int fd, const std::filesystem::path& temp) {
    // Checked again as it goes: the file's checksum over the bytes copied (index_sections
    // checked the file's own, which the copy ends with).
    Fingerprint file;
    const std::size_t last = size_ - word;
    for_each_piece(0, last, [&](const char* piece, std::size_t n) {
      file.add(piece, n);
      write_all(fd, piece, n, temp);
    });
    const std::uint64_t sum = word_at(last);
    write_all(fd, reinterpret_cast<const char*>(&sum), word, temp);
    if (sum != file.value()) fail("the file changed after it was checked; it cannot be copied as the run's checkpoint");
  });
}

void promote_checkpoint_file(const std::filesystem::path& from, const std::filesystem::path& to) {
  const int fd = ::open(from.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) throw IoError("cannot read " + from.string() + ": " + std::strerror(errno));
  // On disk before the rename: after a crash the name holds a whole checkpoint or the old one.
  if (::fsync(fd) != 0) {
    const int error = errno;
    ::close(fd);
    throw IoError("cannot write " + from.string() + ": " + std::strerror(error));
  }
  ::close(fd);
  if (std::rename(from.c_str(), to.c_str()) != 0)
    throw IoError("cannot write " + to.string() + ": " + std::strerror(errno));
}

std::string read_checkpoint_file(const std::filesystem::path& file) {
  std::ifstream in(file, std::ios::binary | std::ios::ate);
  if (!in) throw IoError("cannot open " + file.string());
  std::string bytes(static_cast<std::size_t>(std::max<std::streamoff>(0, in.tellg())), '\0');  // read once, not grown
  in.seekg(0);
  if (!in.read(bytes.data(), static_cast<std::streamsize>(bytes.size()))) throw IoError("cannot read " + file.string());
  if (bytes.empty()) throw InputError(file.string() + ": empty checkpoint (0 bytes): nothing to resume");
  return bytes;
}

void Fingerprint::add(const void* data, std::size_t size) {
  const auto* p = static_cast<const unsigned char*>(data);
  for (std::size_t i = 0; i < size; ++i) {
    hash_ ^= p[i];
    hash_ *= 1099511628211ull;
  }
}

// ---- reading from the file -------------------------------------------------------------------

CheckpointStream::CheckpointStream(const std::filesystem::path& file) : path_(file) {
  file_ = std::fopen(file.c_str(), "rb");
  if (!file_) throw IoError("cannot read " + file.string() + ": " + std::strerror(errno));
  std::string start(magic.size(), '\0');
  std::uint64_t version = 0;
  if (std::fread(start.data(), 1, start.size(), file_) != start.size() || start != magic) fail("not a hemosolve checkpoint");
  read(&version, word, false);
  if (version != format_version)
    fail("checkpoint format " + std::to_string(version) + ", this build reads format " + std::to_string(format_version));
}

CheckpointStream::~CheckpointStream() {
  if (file_) std::fclose(file_);
}

void CheckpointStream::fail(const std::string& message) const { throw InputError(path_.string() + ": " + message); }

void CheckpointStream::read(void* data, std::size_t size, bool hashed) {
  if (std::fread(data, 1, size, file_) != size) fail("truncated checkpoint");
  if (hashed) hash_.add(data, size);
}

void CheckpointStream::close_section() {
  char skipped[1 << 16];
  while (left_ > 0) {
    const std::size_t n = static_cast<std::size_t>(std::min<std::uint64_t>(left_, sizeof skipped));
    read(skipped, n);
    left_ -= n;
  }
  std::uint64_t sum = 0;
  read(&sum, word, false);
  if (sum != hash_.value()) fail("a section does not match its checksum: the file was changed or damaged");
  hash_ = Fingerprint();
  open_ = false;
}

void CheckpointStream::section(std::string_view name) {
  if (open_) close_section();
  std::uint64_t name_length = 0, length = 0;
  read(&name_length, word);
  if (name_length != name.size()) fail("no section \"" + std::string(name) + "\" where it was written");
  std::string found(name.size(), '\0');
  read(found.data(), found.size());
  if (found != name) fail("no section \"" + std::string(name) + "\" where it was written");
  read(&length, word);
  left_ = length;
  open_ = true;
}

std::uint64_t CheckpointStream::get_u64() {
  std::uint64_t x = 0;
  get_doubles({});  // checks a section is open
  if (left_ < word) fail("a section shorter than this build reads");
  read(&x, word);
  left_ -= word;
  return x;
}

void CheckpointStream::get_doubles(std::span<double> out) {
  if (!open_) throw std::logic_error("CheckpointStream: a value read outside any section");
  const std::size_t size = out.size() * sizeof(double);
  if (left_ < size) fail("a section shorter than this build reads");
  if (size > 0) read(out.data(), size);
  left_ -= size;
}

void CheckpointStream::finish() {
  if (open_) close_section();
}

}  // namespace hemotree

// HDF5 files of columns (docs/network-format.md, "HDF5"): a small owner of the C library's
// handles and the few operations hemotree's layouts need: groups, one-dimensional columns
// (chunked, byte-shuffled and deflated), enumerations, and JSON text. Every failure is one
// InputError naming the file and the dataset ("net.h5: /vessels/length: ..."); the library's
// own error stack is never printed.
//
// A file is written through an OutputStream (write_through), so that it is atomic like every
// other output (complete or absent) and may go to a pipe; it is read from a path in place, or
// from a temporary file that a pipe's bytes are copied to.
#pragma once

#include <cstdint>
#include <cstdio>
#include <functional>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include <hdf5.h>

#include "formats/hdf5_crash_guard.hpp"
#include "formats/output_stream.hpp"

namespace hemotree::hdf5 {

// The eight bytes every HDF5 file begins with (at offset 0 here: no user block).
inline constexpr unsigned char signature[8] = {0x89, 'H', 'D', 'F', '\r', '\n', 0x1a, '\n'};
bool has_signature(std::span<const char> first_bytes);

// One handle of the C library, closed by its own close function.
class Handle {
 public:
  Handle() = default;
  Handle(hid_t id, herr_t (*close)(hid_t)) : id_(id), close_(close) {}
  Handle(Handle&& other) noexcept : id_(std::exchange(other.id_, -1)), close_(other.close_) {}
  Handle& operator=(Handle&& other) noexcept {
    if (this != &other) {
      reset();
      id_ = std::exchange(other.id_, -1);
      close_ = other.close_;
    }
    return *this;
  }
  Handle(const Handle&) = delete;
  Handle& operator=(const Handle&) = delete;
  ~Handle() { reset(); }
  hid_t id() const { return id_; }
  hid_t release() { return std::exchange(id_, -1); }
  explicit operator bool() const { return id_ >= 0; }

 private:
  void reset() {
    if (id_ >= 0 && close_) close_(id_);
    id_ = -1;
  }
  hid_t id_ = -1;
  herr_t (*close_)(hid_t) = nullptr;
};

// An enumeration stored as one byte a row, its names in the file's type (h5py:
// h5py.check_enum_dtype).
struct EnumNames {
  std::vector<std::string> names;  // value k is names[k]
};

class File {
 public:
  // A new, empty file, in a temporary file of its own; bytes() closes it and gives its bytes
  // (once).
  static File create(std::string name);
  // A new, empty file written at path as it is built (name for messages); close() ends it.
  static File create_at(const std::string& path, std::string name);
  void close();
  // An existing file, read-only: from a path (named in messages by name), or from bytes
  // elsewhere (held in memory, or a stream such as standard input), which go to a temporary
  // file first, unlinked once open.
  static File open(const std::string& path);
  static File open(const std::string& path, const std::string& name);
  static File open_image(const std::vector<char>& bytes, std::string name);
  static File open_stream(std::FILE* in, std::string name);

  File(File&& other) noexcept;
  File& operator=(File&&) = delete;
  ~File();

  const std::string& name() const { return name_; }
  // Threads that filter a column's chunks (0, the default: OpenMP's count).
  void set_threads(int threads) { threads_ = threads; }
  // The whole file, closed: nothing can be written after.
  std::vector<char> bytes();

  // Objects are named by absolute paths ("/vessels/length"); the groups above a dataset are
  // made as needed.
  void create_group(const std::string& path);
  bool exists(const std::string& path) const;
  // The number of rows of a one-dimensional dataset (InputError when it is not one).
  std::size_t rows(const std::string& path) const;

  // Columns. Writing: chunked, shuffled and deflated (level 1: the files are read far more
  // often than written, and deflate's higher levels gain a few per cent for several times
  // the time). Reading checks the dataset is one-dimensional, of the right kind (floating
  // point, integer, enumeration) and, where rows is given, of that length.
  void write(const std::string& path, std::span<const double> values);
  void write(const std::string& path, std::span<const std::int64_t> values);
  void write(const std::string& path, std::span<const std::int32_t> values);
  void write_enum(const std::string& path, std::span<const std::uint8_t> values, const EnumNames& names);
  // A table of reals, rows x columns, row by row (values.size() must be their product).
  void write_matrix(const std::string& path, std::size_t rows, std::size_t columns, std::span<const double> values);
  std::vector<double> read_reals(const std::string& path, std::optional<std::size_t> rows = {}) const;
  std::vector<std::int64_t> read_integers(const std::string& path, std::optional<std::size_t> rows = {}) const;
  // Values as written; names are checked against the file's type (a name it lacks, or a
  // value it maps to another name, is refused).
  std::vector<std::uint8_t> read_enum(const std::string& path, const EnumNames& names,
                                      std::optional<std::size_t> rows = {}) const;
  // The same, of the rows `pick` alone (increasing) of a column of `rows` rows: a process
  // that holds part of a network (a rank of a run over MPI) reads only the chunks that hold
  // its rows, a block of chunks at a time, so that neither the time nor the room is the
  // whole column's.
  std::vector<double> read_reals(const std::string& path, std::size_t rows, std::span<const std::int32_t> pick) const;
  std::vector<std::int64_t> read_integers(const std::string& path, std::size_t rows,
                                          std::span<const std::int32_t> pick) const;
  std::vector<std::uint8_t> read_enum(const std::string& path, const EnumNames& names, std::size_t rows,
                                      std::span<const std::int32_t> pick) const;

  // Text (UTF-8, JSON for the small members) as a scalar dataset, and attributes of the root.
  void write_text(const std::string& path, std::string_view text);
  std::string read_text(const std::string& path) const;
  void write_attribute(const std::string& name, std::string_view text);
  void write_attribute(const std::string& name, std::int64_t value);
  std::optional<std::string> text_attribute(const std::string& name) const;
  std::optional<std::int64_t> integer_attribute(const std::string& name) const;

  // "NAME: PATH: what" as an InputError.
  [[noreturn]] void fail(const std::string& path, const std::string& what) const;

 private:
  File(Handle file, std::string name, CrashGuard guard = {})
      : guard_(std::move(guard)), file_(std::move(file)), name_(std::move(name)) {}
  static File open_temporary(std::string name, const std::function<bool(int fd)>& fill);
  Handle open_dataset(const std::string& path) const;
  // The root's attribute `name` and its type, where it exists: of class `kind` and one value
  // (a list would be read over the one value's room), else refused as "must be one `what`".
  struct Attribute {
    Handle attribute, type;
  };
  std::optional<Attribute> root_attribute(const std::string& name, H5T_class_t kind, const char* what) const;
  // Creates the groups above path that do not exist yet; the link list to create it with.
  Handle links_for(const std::string& path);
  void write_column(const std::string& path, hid_t memory_type, hid_t file_type, const void* data,
                    std::size_t rows);
  void read_column(const Handle& dataset, const std::string& path, hid_t memory_type, void* data,
                   std::size_t rows) const;
  void read_picked(const Handle& dataset, const std::string& path, hid_t memory_type, std::size_t element,
                   std::span<const std::int32_t> pick, void* data) const;
  void check_enum_names(const Handle& dataset, const std::string& path, const EnumNames& names) const;
  std::size_t checked_rows(const Handle& dataset, const std::string& path, int type_class,
                           const char* kind, std::optional<std::size_t> rows) const;

  CrashGuard guard_;  // first: it outlives the file's handle, closed before it
  Handle file_;
  std::string name_;
  int backing_ = -1;         // a created file: where the library writes it when it closes
  int threads_ = 0;
};

// A file written through out, as atomic as every output: in place where out is a file (the
// library writes its temporary, which out.commit() then puts at its name), written to an
// unlinked temporary in TMPDIR and copied where out is standard output or a device. fill
// writes the content; the caller commits out.
template <class Fill>
void write_through(OutputStream& out, Fill fill) {
  const std::string path = out.path_for_writer();
  File file = path.empty() ? File::create(out.name()) : File::create_at(path, out.name());
  fill(file);
  if (!path.empty()) return file.close();
  const std::vector<char> bytes = file.bytes();
  out.write(std::string_view(bytes.data(), bytes.size()));
}

}  // namespace hemotree::hdf5

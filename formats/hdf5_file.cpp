#include "formats/hdf5_file.hpp"

#include <algorithm>
#include <bit>
#include <exception>
#include <new>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <utility>
#include <limits>
#include <stdexcept>

#include <fcntl.h>
#include <zlib.h>
#include <omp.h>
#include <sys/stat.h>
#include <unistd.h>

#include "core/errors.hpp"
#include "formats/hdf5_chunk_filters.hpp"

namespace hemotree::hdf5 {

namespace {

// Rows a chunk: 64 Ki doubles are half a megabyte, a unit the deflate filter works through
// quickly and a reader of a slice (a rank of a parallel run) wastes little of.
constexpr hsize_t chunk_rows = 1 << 16;
constexpr unsigned deflate_level = 1;
// The longest text read (a network's list of boundaries at nodes as JSON: about 100 bytes each).
constexpr std::size_t max_text_bytes = std::size_t{1} << 30;

// The library prints its error stack on stderr unless told not to; the messages here are
// built from it instead.
void silence_library() {
  static const bool silenced = [] {
    H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr);
    return true;
  }();
  (void)silenced;
}

// The innermost description on the library's error stack ("truncated file: eof = 96, ..."),
// the most specific thing it knows about what failed.
std::string library_reason() {
  std::string reason;
  H5Ewalk2(
      H5E_DEFAULT, H5E_WALK_UPWARD,
      [](unsigned n, const H5E_error2_t* error, void* data) -> herr_t {
        if (n == 0 && error->desc) *static_cast<std::string*>(data) = error->desc;
        return 0;
      },
      &reason);
  H5Eclear2(H5E_DEFAULT);
  return reason;
}

std::string with_reason(const std::string& what) {
  const std::string reason = library_reason();
  return reason.empty() ? what : what + " (" + reason + ")";
}

Handle property_list(hid_t kind) { return Handle(H5Pcreate(kind), H5Pclose); }

// Objects without their times of creation and change, which the library records by default:
// the same content gives the same bytes (reproducible runs compare files byte for byte).
Handle untimed(hid_t kind) {
  Handle list = property_list(kind);
  H5Pset_obj_track_times(list.id(), 0);
  return list;
}

// A dataset of chunks of these dimensions, each shuffled, deflated and checksummed
// (Fletcher-32: a flipped bit in the data is refused when read, not computed with); untimed.
Handle filtered_chunks(int rank, const hsize_t* chunk) {
  Handle dcpl = untimed(H5P_DATASET_CREATE);
  H5Pset_chunk(dcpl.id(), rank, chunk);
  H5Pset_shuffle(dcpl.id());
  H5Pset_deflate(dcpl.id(), deflate_level);
  H5Pset_fletcher32(dcpl.id());
  return dcpl;
}

// A group (or the root) untimed, whose members are listed in the order they were made (h5py
// iterates them so): a table's columns in the table's order.
Handle ordered(hid_t kind) {
  Handle list = untimed(kind);
  H5Pset_link_creation_order(list.id(), H5P_CRT_ORDER_TRACKED | H5P_CRT_ORDER_INDEXED);
  return list;
}

// Links named in UTF-8.
Handle utf8_links() {
  Handle lcpl = property_list(H5P_LINK_CREATE);
  H5Pset_char_encoding(lcpl.id(), H5T_CSET_UTF8);
  return lcpl;
}

// Fixed-length UTF-8 text (at least one byte). Not variable-length: such strings live in
// the file's global heap, which carries no checksum, and a damaged heap sent HDF5 1.10.8 into
// an endless loop where a damaged fixed-length string is refused or read as damaged text.
Handle text_type(std::size_t size) {
  Handle type(H5Tcopy(H5T_C_S1), H5Tclose);
  H5Tset_size(type.id(), std::max<std::size_t>(size, 1));
  H5Tset_strpad(type.id(), H5T_STR_NULLPAD);
  H5Tset_cset(type.id(), H5T_CSET_UTF8);
  return type;
}

Handle enum_type(const EnumNames& names) {
  Handle type(H5Tenum_create(H5T_NATIVE_UINT8), H5Tclose);
  for (std::size_t k = 0; k < names.names.size(); ++k) {
    const auto value = static_cast<std::uint8_t>(k);
    H5Tenum_insert(type.id(), names.names[k].c_str(), &value);
  }
  return type;
}

const char* class_name(H5T_class_t c) {
  switch (c) {
    case H5T_INTEGER: return "integers";
    case H5T_FLOAT: return "floating-point numbers";
    case H5T_STRING: return "text";
    case H5T_ENUM: return "an enumeration";
    case H5T_COMPOUND: return "a compound type";
    default: return "another type";
  }
}

}  // namespace

bool has_signature(std::span<const char> first_bytes) {
  return first_bytes.size() >= sizeof signature &&
         std::memcmp(first_bytes.data(), signature, sizeof signature) == 0;
}

namespace {

// The newest object versions of HDF5 1.10 (h5py, and every HDF5 since 1.10, read them): their
// headers, chunk indexes and heaps carry checksums, so that a damaged header is refused rather
// than trusted; the data carry their own (fletcher32, below).
Handle newest_objects(Handle fapl) {
  H5Pset_libver_bounds(fapl.id(), H5F_LIBVER_V110, H5F_LIBVER_V110);
  return fapl;
}

}  // namespace

namespace {

// A file of its own in TMPDIR (mkstemp: no other user's link followed), open for writing.
std::pair<std::string, int> temporary_file(const std::string& name) {
  const char* folder = std::getenv("TMPDIR");
  std::string path = std::string(folder && *folder ? folder : "/tmp") + "/hemotree-XXXXXX";
  const int fd = ::mkstemp(path.data());
  if (fd < 0) throw IoError(name + ": cannot create a temporary file in " + path + ": " + std::strerror(errno));
  return {path, fd};
}

bool write_all(int fd, const char* data, std::size_t size) {
  for (std::size_t done = 0; done < size;) {
    const ssize_t wrote = ::write(fd, data + done, size - done);
    if (wrote <= 0) return false;
    done += static_cast<std::size_t>(wrote);
  }
  return true;
}

}  // namespace

File File::create(std::string name) {
  silence_library();
  // Written as create_at writes (the same bytes) to a file in TMPDIR that is unlinked at once:
  // bytes() reads it back through a descriptor of its own, and a writer killed at any moment
  // leaves nothing behind. Not the core driver's H5Fget_file_image: its images of files with
  // checksummed metadata came back with a superblock checksum no reader accepts (1.10.8).
  Handle fapl = newest_objects(property_list(H5P_FILE_ACCESS));
  const auto [path, made] = temporary_file(name);
  ::close(made);
  Handle fcpl = ordered(H5P_FILE_CREATE);  // the root group's
  Handle file(H5Fcreate(path.c_str(), H5F_ACC_TRUNC, fcpl.id(), fapl.id()), H5Fclose);
  if (!file) {
    ::unlink(path.c_str());
    throw IoError(with_reason(name + ": cannot create an HDF5 file (in " + path + ")"));
  }
  const int backing = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  const int open_errno = errno;
  ::unlink(path.c_str());
  if (backing < 0) throw IoError(name + ": cannot open " + path + ": " + std::strerror(open_errno));
  File created(std::move(file), std::move(name));
  created.backing_ = backing;
  return created;
}

File File::create_at(const std::string& path, std::string name) {
  silence_library();
  Handle fapl = newest_objects(property_list(H5P_FILE_ACCESS));
  Handle fcpl = ordered(H5P_FILE_CREATE);
  Handle file(H5Fcreate(path.c_str(), H5F_ACC_TRUNC, fcpl.id(), fapl.id()), H5Fclose);
  if (!file) throw IoError(with_reason(name + ": cannot create the HDF5 file"));
  return File(std::move(file), std::move(name));
}

void File::close() {
  if (H5Fclose(file_.release()) < 0) throw IoError(with_reason(name_ + ": cannot finish the HDF5 file"));
}

File File::open(const std::string& path) { return open(path, path); }

File File::open(const std::string& path, const std::string& name) {
  silence_library();
  std::ifstream probe(path, std::ios::binary);
  if (!probe) throw IoError("cannot open " + name + ": " + std::strerror(errno));
  char first[sizeof signature] = {};
  probe.read(first, sizeof first);
  if (!has_signature(std::span<const char>(first, static_cast<std::size_t>(probe.gcount()))))
    throw InputError(name + ": not an HDF5 file (it does not begin with HDF5's signature)");
  CrashGuard guard(name);
  Handle file(H5Fopen(path.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT), H5Fclose);
  if (!file) throw InputError(with_reason(name + ": not a complete HDF5 file (truncated or damaged)"));
  return File(std::move(file), name, std::move(guard));
}

// Bytes from elsewhere (a pipe, memory) go to a temporary file, opened by path and unlinked at
// once: read as a file is, not held in memory (HDF5-HL's in-memory image also leaked its
// bookkeeping at every open).
File File::open_temporary(std::string name, const std::function<bool(int fd)>& fill) {
  silence_library();
  auto [path, fd] = temporary_file(name);
  const bool filled = fill(fd);
  const int write_errno = errno;
  ::close(fd);
  if (!filled) {
    ::unlink(path.c_str());
    throw IoError("cannot read " + name + " into " + path + ": " + std::strerror(write_errno));
  }
  try {
    File file = open(path, name);
    ::unlink(path.c_str());
    return file;
  } catch (...) {
    ::unlink(path.c_str());
    throw;
  }
}

File File::open_image(const std::vector<char>& bytes, std::string name) {
  return open_temporary(std::move(name), [&](int fd) { return write_all(fd, bytes.data(), bytes.size()); });
}

File File::open_stream(std::FILE* in, std::string name) {
  return open_temporary(std::move(name), [&](int fd) {
    char block[1 << 16];
    for (std::size_t got; (got = std::fread(block, 1, sizeof block, in)) > 0;)
      if (!write_all(fd, block, got)) return false;
    return !std::ferror(in);
  });
}

std::vector<char> File::bytes() {
  if (backing_ < 0) throw IoError(name_ + ": bytes() of a file not created here");
  if (H5Fclose(file_.release()) < 0) throw IoError(with_reason(name_ + ": cannot finish the HDF5 file"));
  struct stat status{};
  if (::fstat(backing_, &status) != 0) throw IoError(name_ + ": cannot read back the HDF5 file: " + std::strerror(errno));
  std::vector<char> bytes(static_cast<std::size_t>(status.st_size));
  for (std::size_t done = 0; done < bytes.size();) {
    const ssize_t got = ::pread(backing_, bytes.data() + done, bytes.size() - done, static_cast<off_t>(done));
    if (got <= 0) throw IoError(name_ + ": cannot read back the HDF5 file: " + std::strerror(errno));
    done += static_cast<std::size_t>(got);
  }
  return bytes;
}

File::~File() {
  if (backing_ >= 0) ::close(backing_);
}

File::File(File&& other) noexcept
    : guard_(std::move(other.guard_)),
      file_(std::move(other.file_)),
      name_(std::move(other.name_)),
      backing_(std::exchange(other.backing_, -1)),
      threads_(other.threads_) {}

void File::fail(const std::string& path, const std::string& what) const {
  throw InputError(name_ + ": " + path + ": " + what);
}

void File::create_group(const std::string& path) {
  Handle lcpl = utf8_links();
  Handle gcpl = ordered(H5P_GROUP_CREATE);
  Handle group(H5Gcreate2(file_.id(), path.c_str(), lcpl.id(), gcpl.id(), H5P_DEFAULT), H5Gclose);
  if (!group) throw IoError(with_reason(name_ + ": " + path + ": cannot create the group"));
}

Handle File::links_for(const std::string& path) {
  for (std::size_t slash = path.find('/', 1); slash != std::string::npos; slash = path.find('/', slash + 1))
    if (!exists(path.substr(0, slash))) create_group(path.substr(0, slash));
  return utf8_links();
}

bool File::exists(const std::string& path) const {
  // Each link of the path in turn: H5Lexists fails (rather than saying no) below a missing group.
  std::size_t end = 0;
  while (end != std::string::npos) {
    end = path.find('/', end + 1);
    const std::string prefix = path.substr(0, end);
    if (prefix.empty() || prefix == "/") continue;
    if (H5Lexists(file_.id(), prefix.c_str(), H5P_DEFAULT) <= 0) {
      H5Eclear2(H5E_DEFAULT);
      return false;
    }
    // Only the file's own objects: a link to another file (or to a pipe, which would hang the
    // read) is not followed.
    H5L_info_t link{};
    if (H5Lget_info(file_.id(), prefix.c_str(), &link, H5P_DEFAULT) < 0 || link.type != H5L_TYPE_HARD)
      fail(prefix, "a link to outside the file, not followed");
  }
  return true;
}

Handle File::open_dataset(const std::string& path) const {
  if (!exists(path)) fail(path, "missing");
  Handle dataset(H5Dopen2(file_.id(), path.c_str(), H5P_DEFAULT), H5Dclose);
  if (!dataset) throw InputError(with_reason(name_ + ": " + path + ": not a dataset"));
  return dataset;
}

std::size_t File::checked_rows(const Handle& dataset, const std::string& path, int type_class,
                               const char* kind, std::optional<std::size_t> rows) const {
  Handle type(H5Dget_type(dataset.id()), H5Tclose);
  const H5T_class_t found = H5Tget_class(type.id());
  if (found != static_cast<H5T_class_t>(type_class))
    fail(path, std::string("must hold ") + kind + " (it holds " + class_name(found) + ")");
  Handle space(H5Dget_space(dataset.id()), H5Sclose);
  if (H5Sget_simple_extent_ndims(space.id()) != 1)
    fail(path, "must be one-dimensional (it has " + std::to_string(H5Sget_simple_extent_ndims(space.id())) +
                   " dimensions)");
  hsize_t n = 0;
  H5Sget_simple_extent_dims(space.id(), &n, nullptr);
  if (found == H5T_INTEGER && H5Tget_sign(type.id()) == H5T_SGN_NONE && H5Tget_size(type.id()) >= 8)
    fail(path, "must hold signed integers (unsigned 64-bit values may not fit)");
  // Before any room is taken for them: rows the file's index could hold (32-bit), and that
  // its stored bytes can hold (deflate shrinks at most about 1032 to 1).
  if (n > static_cast<hsize_t>(std::numeric_limits<std::int32_t>::max()))
    fail(path, "declares " + std::to_string(n) + " rows, more than 2^31 - 1");
  const double declared = static_cast<double>(n) * static_cast<double>(H5Tget_size(type.id()));
  if (declared > 1100.0 * static_cast<double>(H5Dget_storage_size(dataset.id())) + 1e6)
    fail(path, "declares " + std::to_string(n) + " rows, more than its stored " +
                   std::to_string(H5Dget_storage_size(dataset.id())) + " bytes can hold");
  if (rows && n != *rows)
    fail(path, "must have " + std::to_string(*rows) + " rows, one per " +
                   (path.rfind("/nodes/", 0) == 0 ? "node" : path.rfind("/vessels/", 0) == 0 ? "vessel" : "row") +
                   " (it has " + std::to_string(n) + ")");
  return static_cast<std::size_t>(n);
}

std::size_t File::rows(const std::string& path) const {
  Handle dataset = open_dataset(path);
  Handle space(H5Dget_space(dataset.id()), H5Sclose);
  if (H5Sget_simple_extent_ndims(space.id()) != 1) fail(path, "must be one-dimensional");
  hsize_t n = 0;
  H5Sget_simple_extent_dims(space.id(), &n, nullptr);
  return static_cast<std::size_t>(n);
}

void File::write_column(const std::string& path, hid_t memory_type, hid_t file_type, const void* data,
                        std::size_t rows) {
  const hsize_t n = rows;
  Handle space(H5Screate_simple(1, &n, nullptr), H5Sclose);
  const hsize_t chunk = std::max<hsize_t>(1, std::min(n, chunk_rows));
  Handle dcpl = n > 0 ? filtered_chunks(1, &chunk) : untimed(H5P_DATASET_CREATE);
  Handle lcpl = links_for(path);
  Handle dataset(H5Dcreate2(file_.id(), path.c_str(), file_type, space.id(), lcpl.id(), dcpl.id(), H5P_DEFAULT),
                 H5Dclose);
  if (!dataset) throw IoError(with_reason(name_ + ": " + path + ": cannot create the dataset"));
  if (n == 0) return;
  // The filters are the time of writing (deflate about 100 MB/s): every chunk filtered on
  // every thread here, then handed to the library as it would have stored it. The file type
  // is little-endian and the machine's too, so the values go as they lie in memory.
  static_assert(std::endian::native == std::endian::little);
  const std::size_t element = H5Tget_size(memory_type);
  const std::size_t chunks = static_cast<std::size_t>((n + chunk - 1) / chunk);
  std::vector<std::vector<unsigned char>> filtered(chunks);
  // Floating-point columns by runs alone (zlib's Z_RLE): in their shuffled bytes the signs' and
  // exponents' runs are what compresses, and the mantissas' bytes hold no longer repeats for
  // deflate's search to find: the same size within 1 %, three times faster (a full tree's
  // results, bench/README.md). Integer columns keep the search: ids and node rows repeat
  // their byte patterns (0.5 % of their size with it, 13 % by runs).
  const int strategy = H5Tget_class(memory_type) == H5T_FLOAT ? Z_RLE : Z_DEFAULT_STRATEGY;
  std::exception_ptr error;
  const auto* bytes = static_cast<const unsigned char*>(data);
  const int threads = threads_ > 0 ? threads_ : omp_get_max_threads();
#pragma omp parallel num_threads(threads)
  {
    std::unique_ptr<ChunkFilter> filter;
#pragma omp for schedule(dynamic, 1)
    for (std::size_t c = 0; c < chunks; ++c) {
      try {
        if (!filter) filter = std::make_unique<ChunkFilter>(chunk, element, static_cast<int>(deflate_level), strategy);
        const std::size_t first = c * chunk, count = std::min<std::size_t>(chunk, rows - first);
        filtered[c] = (*filter)(bytes + first * element, count);
      } catch (...) {
#pragma omp critical(hdf5_chunk_error)
        if (!error) error = std::current_exception();
      }
    }
  }
  if (error) std::rethrow_exception(error);
  for (std::size_t c = 0; c < chunks; ++c) {
    const hsize_t offset = c * chunk;
    if (H5Dwrite_chunk(dataset.id(), H5P_DEFAULT, 0, &offset, filtered[c].size(), filtered[c].data()) < 0)
      throw IoError(with_reason(name_ + ": " + path + ": cannot write the dataset"));
    std::vector<unsigned char>().swap(filtered[c]);
  }
}

void File::read_column(const Handle& dataset, const std::string& path, hid_t memory_type, void* data,
                       std::size_t rows) const {
  if (rows == 0) return;
  if (H5Dread(dataset.id(), memory_type, H5S_ALL, H5S_ALL, H5P_DEFAULT, data) < 0)
    throw InputError(with_reason(name_ + ": " + path + ": cannot be read (damaged or of values out of range)"));
}

void File::write_matrix(const std::string& path, std::size_t rows, std::size_t columns,
                        std::span<const double> values) {
  if (values.size() != rows * columns) throw std::invalid_argument(path + ": a matrix of the wrong size");
  const hsize_t dims[2] = {rows, columns};
  Handle space(H5Screate_simple(2, dims, nullptr), H5Sclose);
  const hsize_t chunk[2] = {std::min<hsize_t>(rows, std::max<hsize_t>(1, chunk_rows / std::max<std::size_t>(columns, 1))),
                            columns};
  Handle dcpl = rows > 0 && columns > 0 ? filtered_chunks(2, chunk) : untimed(H5P_DATASET_CREATE);
  Handle lcpl = links_for(path);
  Handle dataset(H5Dcreate2(file_.id(), path.c_str(), H5T_IEEE_F64LE, space.id(), lcpl.id(), dcpl.id(), H5P_DEFAULT),
                 H5Dclose);
  if (!dataset) throw IoError(with_reason(name_ + ": " + path + ": cannot create the dataset"));
  if (!values.empty() && H5Dwrite(dataset.id(), H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, values.data()) < 0)
    throw IoError(with_reason(name_ + ": " + path + ": cannot write the dataset"));
}

void File::write(const std::string& path, std::span<const double> values) {
  write_column(path, H5T_NATIVE_DOUBLE, H5T_IEEE_F64LE, values.data(), values.size());
}
void File::write(const std::string& path, std::span<const std::int64_t> values) {
  write_column(path, H5T_NATIVE_INT64, H5T_STD_I64LE, values.data(), values.size());
}
void File::write(const std::string& path, std::span<const std::int32_t> values) {
  write_column(path, H5T_NATIVE_INT32, H5T_STD_I32LE, values.data(), values.size());
}
void File::write_enum(const std::string& path, std::span<const std::uint8_t> values, const EnumNames& names) {
  Handle type = enum_type(names);
  write_column(path, type.id(), type.id(), values.data(), values.size());
}

std::vector<double> File::read_reals(const std::string& path, std::optional<std::size_t> rows) const {
  Handle dataset = open_dataset(path);
  const std::size_t n = checked_rows(dataset, path, H5T_FLOAT, "floating-point numbers", rows);
  std::vector<double> values(n);
  read_column(dataset, path, H5T_NATIVE_DOUBLE, values.data(), n);
  return values;
}

std::vector<std::int64_t> File::read_integers(const std::string& path, std::optional<std::size_t> rows) const {
  Handle dataset = open_dataset(path);
  const std::size_t n = checked_rows(dataset, path, H5T_INTEGER, "integers", rows);
  std::vector<std::int64_t> values(n);
  read_column(dataset, path, H5T_NATIVE_INT64, values.data(), n);
  return values;
}

void File::read_picked(const Handle& dataset, const std::string& path, hid_t memory_type, std::size_t element,
                       std::span<const std::int32_t> pick, void* data) const {
  // Blocks of whole chunks: each chunk read is decompressed once, and one that holds none of
  // the rows not at all.
  constexpr std::size_t block = 16 * chunk_rows;
  std::vector<unsigned char> buffer;
  Handle file_space(H5Dget_space(dataset.id()), H5Sclose);
  auto* out = static_cast<unsigned char*>(data);
  for (std::size_t k = 0; k < pick.size();) {
    const std::size_t first = static_cast<std::size_t>(pick[k]) / block * block;
    std::size_t end = k;
    while (end < pick.size() && static_cast<std::size_t>(pick[end]) < first + block) ++end;
    // The block's span of rows from its first picked row's chunk to its last's.
    const std::size_t lo = static_cast<std::size_t>(pick[k]) / chunk_rows * chunk_rows;
    const std::size_t hi = static_cast<std::size_t>(pick[end - 1]) + 1;
    const hsize_t start = lo, count = hi - lo;
    buffer.resize(count * element);
    Handle memory_space(H5Screate_simple(1, &count, nullptr), H5Sclose);
    if (H5Sselect_hyperslab(file_space.id(), H5S_SELECT_SET, &start, nullptr, &count, nullptr) < 0 ||
        H5Dread(dataset.id(), memory_type, memory_space.id(), file_space.id(), H5P_DEFAULT, buffer.data()) < 0)
      throw InputError(with_reason(name_ + ": " + path + ": cannot be read (damaged or of values out of range)"));
    for (; k < end; ++k) std::memcpy(out + k * element, buffer.data() + (static_cast<std::size_t>(pick[k]) - lo) * element, element);
  }
}

std::vector<double> File::read_reals(const std::string& path, std::size_t rows,
                                     std::span<const std::int32_t> pick) const {
  Handle dataset = open_dataset(path);
  checked_rows(dataset, path, H5T_FLOAT, "floating-point numbers", rows);
  std::vector<double> values(pick.size());
  read_picked(dataset, path, H5T_NATIVE_DOUBLE, sizeof(double), pick, values.data());
  return values;
}

std::vector<std::int64_t> File::read_integers(const std::string& path, std::size_t rows,
                                              std::span<const std::int32_t> pick) const {
  Handle dataset = open_dataset(path);
  checked_rows(dataset, path, H5T_INTEGER, "integers", rows);
  std::vector<std::int64_t> values(pick.size());
  read_picked(dataset, path, H5T_NATIVE_INT64, sizeof(std::int64_t), pick, values.data());
  return values;
}

std::vector<std::uint8_t> File::read_enum(const std::string& path, const EnumNames& names, std::size_t rows,
                                          std::span<const std::int32_t> pick) const {
  Handle dataset = open_dataset(path);
  checked_rows(dataset, path, H5T_ENUM, "an enumeration", rows);
  check_enum_names(dataset, path, names);
  std::vector<std::uint8_t> values(pick.size());
  Handle memory_type = enum_type(names);
  read_picked(dataset, path, memory_type.id(), 1, pick, values.data());
  for (std::size_t i = 0; i < values.size(); ++i)
    if (values[i] >= names.names.size())
      fail(path, "row " + std::to_string(pick[i]) + ": a value that names none of the enumeration's");
  return values;
}

void File::check_enum_names(const Handle& dataset, const std::string& path, const EnumNames& names) const {
  // The file's names, each one of ours (its values may differ: the library converts by name).
  Handle file_type(H5Dget_type(dataset.id()), H5Tclose);
  const int members = H5Tget_nmembers(file_type.id());
  for (int m = 0; m < members; ++m) {
    char* member = H5Tget_member_name(file_type.id(), static_cast<unsigned>(m));
    const std::string found = member ? member : "";
    H5free_memory(member);
    if (std::find(names.names.begin(), names.names.end(), found) == names.names.end()) {
      std::string known;
      for (const std::string& name : names.names) known += (known.empty() ? "" : ", ") + name;
      fail(path, "unknown value \"" + found + "\" (expected one of " + known + ")");
    }
  }
}

std::vector<std::uint8_t> File::read_enum(const std::string& path, const EnumNames& names,
                                          std::optional<std::size_t> rows) const {
  Handle dataset = open_dataset(path);
  const std::size_t n = checked_rows(dataset, path, H5T_ENUM, "an enumeration", rows);
  check_enum_names(dataset, path, names);
  std::vector<std::uint8_t> values(n);
  Handle memory_type = enum_type(names);
  read_column(dataset, path, memory_type.id(), values.data(), n);
  for (std::size_t i = 0; i < n; ++i)
    if (values[i] >= names.names.size())
      fail(path, "row " + std::to_string(i) + ": a value that names none of the enumeration's");
  return values;
}

void File::write_text(const std::string& path, std::string_view text) {
  // One row of one string, chunked, so that the text carries a checksum as the columns do
  // (and is deflated: a list of boundaries may be long).
  Handle type = text_type(text.size());
  const hsize_t one = 1;
  Handle space(H5Screate_simple(1, &one, nullptr), H5Sclose);
  Handle dcpl = untimed(H5P_DATASET_CREATE);
  H5Pset_chunk(dcpl.id(), 1, &one);
  H5Pset_deflate(dcpl.id(), deflate_level);
  H5Pset_fletcher32(dcpl.id());
  Handle lcpl = links_for(path);
  Handle dataset(H5Dcreate2(file_.id(), path.c_str(), type.id(), space.id(), lcpl.id(), dcpl.id(), H5P_DEFAULT),
                 H5Dclose);
  std::string padded(text);
  padded.resize(std::max<std::size_t>(text.size(), 1), '\0');
  if (!dataset || H5Dwrite(dataset.id(), type.id(), H5S_ALL, H5S_ALL, H5P_DEFAULT, padded.data()) < 0)
    throw IoError(with_reason(name_ + ": " + path + ": cannot write the text"));
}

namespace {

// A fixed-length or variable-length string, of a dataset or an attribute.
template <class Read>
std::string read_string(hid_t stored_type, Read read) {
  if (H5Tis_variable_str(stored_type) > 0) {
    Handle memory(H5Tcopy(H5T_C_S1), H5Tclose);
    H5Tset_size(memory.id(), H5T_VARIABLE);
    H5Tset_cset(memory.id(), H5Tget_cset(stored_type));
    char* text = nullptr;
    if (read(memory.id(), &text) < 0) return {};
    std::string result = text ? text : "";
    H5free_memory(text);
    return result;
  }
  const std::size_t size = H5Tget_size(stored_type);
  std::string text(size, '\0');
  Handle memory(H5Tcopy(stored_type), H5Tclose);
  if (read(memory.id(), text.data()) < 0) return {};
  text.resize(std::strlen(text.c_str()));  // fixed-length strings are padded with nulls
  return text;
}

}  // namespace

std::string File::read_text(const std::string& path) const {
  Handle dataset = open_dataset(path);
  Handle type(H5Dget_type(dataset.id()), H5Tclose);
  if (H5Tget_class(type.id()) != H5T_STRING) fail(path, "must be text");
  Handle space(H5Dget_space(dataset.id()), H5Sclose);
  // One text: a scalar, or one row (as written here).
  if (H5Sget_simple_extent_npoints(space.id()) != 1) fail(path, "must hold one text");
  if (H5Tis_variable_str(type.id()) <= 0 && H5Tget_size(type.id()) > max_text_bytes)
    fail(path, "is longer than " + std::to_string(max_text_bytes) + " bytes");
  bool failed = false;
  std::string text = read_string(type.id(), [&](hid_t memory, void* into) {
    const herr_t status = H5Dread(dataset.id(), memory, H5S_ALL, H5S_ALL, H5P_DEFAULT, into);
    failed = status < 0;
    return status;
  });
  if (failed) throw InputError(with_reason(name_ + ": " + path + ": cannot be read (damaged)"));
  return text;
}

void File::write_attribute(const std::string& name, std::string_view text) {
  Handle type = text_type(text.size());
  Handle space(H5Screate(H5S_SCALAR), H5Sclose);
  Handle attribute(H5Acreate2(file_.id(), name.c_str(), type.id(), space.id(), H5P_DEFAULT, H5P_DEFAULT), H5Aclose);
  std::string padded(text);
  padded.resize(std::max<std::size_t>(text.size(), 1), '\0');
  if (!attribute || H5Awrite(attribute.id(), type.id(), padded.data()) < 0)
    throw IoError(with_reason(name_ + ": /: cannot write the attribute " + name));
}

void File::write_attribute(const std::string& name, std::int64_t value) {
  Handle space(H5Screate(H5S_SCALAR), H5Sclose);
  Handle attribute(H5Acreate2(file_.id(), name.c_str(), H5T_STD_I64LE, space.id(), H5P_DEFAULT, H5P_DEFAULT),
                   H5Aclose);
  if (!attribute || H5Awrite(attribute.id(), H5T_NATIVE_INT64, &value) < 0)
    throw IoError(with_reason(name_ + ": /: cannot write the attribute " + name));
}

std::optional<File::Attribute> File::root_attribute(const std::string& name, H5T_class_t kind, const char* what) const {
  if (H5Aexists(file_.id(), name.c_str()) <= 0) return std::nullopt;
  Attribute a{Handle(H5Aopen(file_.id(), name.c_str(), H5P_DEFAULT), H5Aclose), {}};
  a.type = Handle(H5Aget_type(a.attribute.id()), H5Tclose);
  Handle space(H5Aget_space(a.attribute.id()), H5Sclose);
  if (H5Tget_class(a.type.id()) != kind || H5Sget_simple_extent_npoints(space.id()) != 1)
    fail("/", "the attribute \"" + name + "\" must be one " + what);
  return a;
}

std::optional<std::string> File::text_attribute(const std::string& name) const {
  const std::optional<Attribute> a = root_attribute(name, H5T_STRING, "text");
  if (!a) return std::nullopt;
  const hid_t attribute = a->attribute.id(), type = a->type.id();
  if (H5Tis_variable_str(type) <= 0 && H5Tget_size(type) > max_text_bytes)
    fail("/", "the attribute \"" + name + "\" is longer than " + std::to_string(max_text_bytes) + " bytes");
  bool failed = false;
  std::string text = read_string(type, [&](hid_t memory, void* into) {
    const herr_t status = H5Aread(attribute, memory, into);
    failed = status < 0;
    return status;
  });
  if (failed) throw InputError(with_reason(name_ + ": /: the attribute \"" + name + "\" cannot be read"));
  return text;
}

std::optional<std::int64_t> File::integer_attribute(const std::string& name) const {
  const std::optional<Attribute> a = root_attribute(name, H5T_INTEGER, "integer");
  if (!a) return std::nullopt;
  std::int64_t value = 0;
  if (H5Aread(a->attribute.id(), H5T_NATIVE_INT64, &value) < 0)
    throw InputError(with_reason(name_ + ": /: the attribute \"" + name + "\" cannot be read"));
  return value;
}

}  // namespace hemotree::hdf5

#include "mpi/session.hpp"

#include <exception>
#include <limits>
#include <new>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "core/errors.hpp"
#include "core/setting_error.hpp"

namespace hemotree {

namespace {
bool initialised_here = false;
std::vector<std::function<void()>> session_end;
}  // namespace

void at_session_end(std::function<void()> step) { session_end.push_back(std::move(step)); }

MpiSession::MpiSession(int& argc, char**& argv) {
  int provided = 0;
  if (MPI_Init_thread(&argc, &argv, MPI_THREAD_FUNNELED, &provided) != MPI_SUCCESS)
    throw std::runtime_error("MPI could not be initialised");
  initialised_here = true;
}

MpiSession::~MpiSession() {
  for (auto step = session_end.rbegin(); step != session_end.rend(); ++step) (*step)();
  session_end.clear();
  if (initialised_here) MPI_Finalize();
  initialised_here = false;
}

int world_size() {
  if (!initialised_here) return 1;
  int size = 1;
  MPI_Comm_size(MPI_COMM_WORLD, &size);
  return size;
}

int world_rank() {
  if (!initialised_here) return 0;
  int rank = 0;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  return rank;
}

namespace {

// A failure as the ranks pass it on: its kind, and for a SettingError its setting.
struct Failure {
  enum Kind : int { none, input, refused_setting, io, memory, other };
  int kind = none;
  std::string setting, message;
};

Failure caught(const std::function<void()>& step) {
  Failure f;
  try {
    step();
  } catch (const SettingError& e) {
    f = {Failure::refused_setting, e.setting(), e.message()};
  } catch (const InputError& e) {
    f = {Failure::input, "", e.what()};
  } catch (const IoError& e) {
    f = {Failure::io, "", e.what()};
  } catch (const std::bad_alloc&) {
    f = {Failure::memory, "", "out of memory"};
  } catch (const std::exception& e) {
    f = {Failure::other, "", e.what()};
  }
  return f;
}

// The failure of rank `from` on every rank: the same kind, the same words.
[[noreturn]] void thrown_everywhere(Failure f, int from) {
  MPI_Bcast(&f.kind, 1, MPI_INT, from, MPI_COMM_WORLD);
  for (std::string* text : {&f.setting, &f.message}) {
    int length = static_cast<int>(text->size());
    MPI_Bcast(&length, 1, MPI_INT, from, MPI_COMM_WORLD);
    text->resize(static_cast<std::size_t>(length));
    MPI_Bcast(text->data(), length, MPI_CHAR, from, MPI_COMM_WORLD);
  }
  if (from != 0) f.message = "rank " + std::to_string(from) + ": " + f.message;
  mark_collective_failure();
  switch (f.kind) {
    case Failure::input: throw InputError(f.message);
    case Failure::refused_setting: throw SettingError(f.setting, f.message);
    case Failure::io: throw IoError(f.message);
    case Failure::memory: throw std::bad_alloc();
    default: throw std::runtime_error(f.message);
  }
}

bool collective_failure = false;

}  // namespace

void mark_collective_failure() { collective_failure = true; }

void end_every_rank(int status) {
  if (world_size() > 1) MPI_Abort(MPI_COMM_WORLD, status);
}
bool failure_is_collective() { return collective_failure; }

void on_lead_rank(const std::function<void()>& step) {
  if (world_size() == 1) {
    step();
    return;
  }
  Failure f;
  if (world_rank() == 0) f = caught(step);
  int kind = f.kind;
  MPI_Bcast(&kind, 1, MPI_INT, 0, MPI_COMM_WORLD);
  if (kind != Failure::none) thrown_everywhere(std::move(f), 0);
}

void on_every_rank(const std::function<void()>& step) {
  if (world_size() == 1) {
    step();
    return;
  }
  Failure f = caught(step);
  const int mine = f.kind != Failure::none ? world_rank() : std::numeric_limits<int>::max();
  int first = mine;
  MPI_Allreduce(&mine, &first, 1, MPI_INT, MPI_MIN, MPI_COMM_WORLD);
  if (first != std::numeric_limits<int>::max()) thrown_everywhere(std::move(f), first);
}

}  // namespace hemotree

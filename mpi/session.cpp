#include "mpi/session.hpp"

#include <exception>
#include <initializer_list>
#include <limits>
#include <new>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include <pthread.h>
#include <signal.h>

#include "core/errors.hpp"
#include "core/setting_error.hpp"

namespace hemotree {

namespace {
bool initialised_here = false;
std::vector<std::function<void()>> session_end;
}  // namespace

void at_session_end(std::function<void()> step) { session_end.push_back(std::move(step)); }

MpiSession::MpiSession(int& argc, char**& argv) {
  // MPI's own threads inherit this mask: they never take the run's signals, which its main
  // thread answers (blocked and polled while a run lives: cli/interrupt.hpp).
  sigset_t run_signals, before;
  sigemptyset(&run_signals);
  for (const int signal_number : {SIGINT, SIGTERM, SIGHUP}) sigaddset(&run_signals, signal_number);
  pthread_sigmask(SIG_BLOCK, &run_signals, &before);
  int provided = 0;
  const int started = MPI_Init_thread(&argc, &argv, MPI_THREAD_FUNNELED, &provided);
  pthread_sigmask(SIG_SETMASK, &before, nullptr);
  if (started != MPI_SUCCESS) throw std::runtime_error("MPI could not be initialised");
  initialised_here = true;
}

MpiSession::~MpiSession() {
  for (auto step = session_end.rbegin(); step != session_end.rend(); ++step) (*step)();
  session_end.clear();
  if (initialised_here) MPI_Finalize();
  initialised_here = false;
}

namespace {
// MPI in use: initialised (by a session, or by whoever calls this library) and not finalised.
bool mpi_in_use() {
  int initialised = 0, finalised = 0;
  MPI_Initialized(&initialised);
  if (!initialised) return false;
  MPI_Finalized(&finalised);
  return !finalised;
}
}  // namespace

int world_size() {
  if (!mpi_in_use()) return 1;
  int size = 1;
  MPI_Comm_size(MPI_COMM_WORLD, &size);
  return size;
}

int world_rank() {
  if (!mpi_in_use()) return 0;
  int rank = 0;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  return rank;
}

namespace {

// A failure as the ranks pass it on: its kind, and for a SettingError its setting.
struct Failure {
  enum Kind : int { none, input, refused_setting, json, io, memory, other };
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
  } catch (const JsonError& e) {
    f = {Failure::json, "", e.what()};
  } catch (const IoError& e) {
    f = {Failure::io, "", e.what()};
  } catch (const std::bad_alloc&) {
    f = {Failure::memory, "", "out of memory"};
  } catch (const std::exception& e) {
    f = {Failure::other, "", e.what()};
  } catch (...) {  // an interrupt's exit (cli/interrupt.hpp) or anything else: never left half-agreed
    f = {Failure::other, "", "stopped"};
  }
  return f;
}

void broadcast(std::string& text, int from) {
  int length = static_cast<int>(text.size());
  MPI_Bcast(&length, 1, MPI_INT, from, MPI_COMM_WORLD);
  text.resize(static_cast<std::size_t>(length));
  MPI_Bcast(text.data(), length, MPI_CHAR, from, MPI_COMM_WORLD);
}

// The failure of rank `from` on every rank: the same kind, the same words.
[[noreturn]] void thrown_everywhere(Failure f, int from) {
  MPI_Bcast(&f.kind, 1, MPI_INT, from, MPI_COMM_WORLD);
  broadcast(f.setting, from);
  broadcast(f.message, from);
  if (from != 0) f.message = "rank " + std::to_string(from) + ": " + f.message;
  switch (f.kind) {
    case Failure::input: throw Collective<InputError>(f.message);
    case Failure::refused_setting: throw Collective<SettingError>(f.setting, f.message);
    case Failure::json: throw Collective<JsonError>(f.message);
    case Failure::io:
    case Failure::memory: throw Collective<IoError>(f.message);
    default: throw Collective<std::runtime_error>(f.message);
  }
}

bool left = false;

}  // namespace

std::string words_of(int from, std::string words) {
  if (world_size() == 1) return words;
  broadcast(words, from);
  return from != 0 ? "rank " + std::to_string(from) + ": " + words : words;
}

bool lead_answer(bool answer) {
  if (world_size() == 1) return answer;
  int value = answer ? 1 : 0;
  MPI_Bcast(&value, 1, MPI_INT, 0, MPI_COMM_WORLD);
  return value != 0;
}

void leave_collectives() { left = true; }
bool left_collectives() { return left; }

void end_every_rank(int status) {
  if (world_size() > 1) MPI_Abort(MPI_COMM_WORLD, status);
}

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

#include "mpi/session.hpp"

#include <exception>
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

void on_lead_rank(const std::function<void()>& step) {
  if (world_size() == 1) {
    step();
    return;
  }
  // kind: 0 none, 1 InputError, 2 SettingError, 3 IoError, 4 any other
  int kind = 0;
  std::string setting, message;
  if (world_rank() == 0) {
    try {
      step();
    } catch (const SettingError& e) {
      kind = 2, setting = e.setting(), message = e.message();
    } catch (const InputError& e) {
      kind = 1, message = e.what();
    } catch (const IoError& e) {
      kind = 3, message = e.what();
    } catch (const std::exception& e) {
      kind = 4, message = e.what();
    }
  }
  MPI_Bcast(&kind, 1, MPI_INT, 0, MPI_COMM_WORLD);
  if (kind == 0) return;
  for (std::string* text : {&setting, &message}) {
    int length = static_cast<int>(text->size());
    MPI_Bcast(&length, 1, MPI_INT, 0, MPI_COMM_WORLD);
    text->resize(static_cast<std::size_t>(length));
    MPI_Bcast(text->data(), length, MPI_CHAR, 0, MPI_COMM_WORLD);
  }
  switch (kind) {
    case 1: throw InputError(message);
    case 2: throw SettingError(setting, message);
    case 3: throw IoError(message);
    default: throw std::runtime_error(message);
  }
}

}  // namespace hemotree

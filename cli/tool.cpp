#include "cli/tool.hpp"

#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <initializer_list>
#include <cstring>
#include <iostream>
#include <new>
#include <optional>
#include <string>
#include <string_view>
#include <unistd.h>

#ifdef __GLIBC__
#include <malloc.h>
#endif

#include "core/errors.hpp"
#include "core/setting_error.hpp"
#include "cli/interrupt.hpp"
#include "mpi/session.hpp"

namespace hemotree {

namespace {
std::string tool_name = "hemotree";

void say(const std::string& kind, const std::string& message) {
  std::fprintf(stderr, "%s: %s%s\n", tool_name.c_str(), kind.c_str(), message.c_str());
}
}  // namespace

namespace {
// An MPI launcher's environment (Open MPI's mpirun, a PMI launcher such as Slurm's srun, MPICH's
// Hydra): the number of ranks and this one's, without initialising MPI. 1 and 0 without one.
int environment_number(std::initializer_list<const char*> names, int otherwise) {
  for (const char* name : names)
    if (const char* value = std::getenv(name); value && *value) return std::atoi(value);
  return otherwise;
}
}  // namespace

// Slurm's srun last: its PMIx plugin may not export PMIX_SIZE, and Open MPI's own variables
// appear only once MPI starts; SLURM_STEP_NUM_TASKS is the step's, not the allocation's.
int launched_ranks() {
  return environment_number({"OMPI_COMM_WORLD_SIZE", "PMI_SIZE", "PMIX_SIZE", "SLURM_STEP_NUM_TASKS"}, 1);
}
int launched_rank() { return environment_number({"OMPI_COMM_WORLD_RANK", "PMI_RANK", "PMIX_RANK", "SLURM_PROCID"}, 0); }

// Over several MPI ranks every rank runs the same command: its notes and warnings are said
// once, by rank 0.
void warn(const std::string& message) {
  if (world_rank() == 0) say("warning: ", message);
}
void note(const std::string& message) {
  if (world_rank() == 0) say("", message);
}

std::string standard_output_error() {
  std::cout.flush();
  errno = 0;
  if (std::fflush(stdout) != 0 || std::ferror(stdout) || std::cout.fail())
    return errno != 0 ? std::strerror(errno) : "an earlier write failed";
  return "";
}

bool stderr_is_terminal() { return ::isatty(STDERR_FILENO) == 1; }

namespace {
// What a tool printed outside an OutputStream (help, a table) must have reached its
// destination before the tool says it succeeded: a full disk is exit 1, not 0.
int checked_success(int status) {
  if (status != 0) return status;
  if (const std::string why = standard_output_error(); !why.empty()) {
    say("error: ", "cannot write standard output: " + why);
    return 1;
  }
  return 0;
}
}  // namespace

int run_tool(CLI::App& app, int argc, char** argv, const std::function<int()>& body) {
  return run_tool(app, argc, argv, SettingWords{}, body);
}

int run_tool(CLI::App& app, int argc, char** argv, const SettingWords& words, const std::function<int()>& body) {
  return run_tool(app, argc, argv, words, body, {});
}

int run_tool(CLI::App& app, int argc, char** argv, const SettingWords& words, const std::function<int()>& body,
             const std::function<std::string()>& over_ranks) {
  tool_name = app.get_name();
#ifdef __GLIBC__
  // Blocks of a megabyte or more mapped on their own, and given back to the system when
  // freed. Left to itself glibc raises this threshold to the largest block freed (up to
  // 32 MB: a full tree's per-vessel arrays), keeps what each phase of a run frees in its
  // heap, and the resident size never falls below the largest phase so far.
  mallopt(M_MMAP_THRESHOLD, 1 << 20);
#endif
  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp& e) {
    return checked_success(app.exit(e));
  } catch (const CLI::CallForAllHelp& e) {
    return checked_success(app.exit(e));
  } catch (const CLI::CallForVersion& e) {
    return checked_success(app.exit(e));
  } catch (const CLI::ParseError& e) {
    // One line, not CLI11's usage dump: the user sees what is wrong at once.
    say("error: ", std::string(e.what()) + " (see --help)");
    return 2;  } catch (const std::exception&) {
    // CLI11 2.1 reads a flag's "=value" with std::stoll and lets its out_of_range escape
    // (found by fuzzing: hemosolve --no-balance-compliances=99999999999999999999 aborted).
    std::string culprit;
    for (int i = 1; i < argc && culprit.empty(); ++i) {
      const std::string_view arg(argv[i]);
      if (arg.size() > 1 && arg[0] == '-' && arg.find('=') != std::string_view::npos) culprit = arg;
    }
    say("error: ", culprit.empty() ? std::string("an argument's value is out of range (see --help)")
                                   : "'" + culprit + "': the value is out of range for that option (see --help)");
    return 2;
  }
  // Started by an MPI launcher on several ranks, a command that does not run over them would
  // run whole on every rank and write the same outputs: refused on every rank, said once.
  const int ranks = launched_ranks();
  std::optional<MpiSession> session;
  if (ranks > 1) {
    const std::string refusal =
        over_ranks ? over_ranks()
                   : tool_name + " runs as one process (each rank would run the whole command and write the same "
                                 "outputs)";
    if (!refusal.empty()) {
      if (launched_rank() == 0)
        say("error: ", "started on " + std::to_string(ranks) + " MPI ranks: " + refusal +
                           "; run it without mpirun, or with -np 1");
      return 2;
    }
    try {
      session.emplace(argc, argv);
    } catch (const std::exception& e) {
      say("error: ", e.what());
      return 1;
    }
  }
  // Over several ranks a failure made every rank's (mpi/session.hpp's Collective: reading,
  // checks, the distributed solve's status) is said by rank 0 alone, and every rank ends
  // alike. So is one of a rank that has left every collective call (rank 0 writing the
  // results: the others have finished). Any other is one rank's own: said by it, naming it,
  // and the run ends on every rank (no rank is left waiting in a collective call for it; the
  // output folder stays DIR.partial).
  auto said = [&](const std::string& kind, const std::string& message, int status, const std::exception* e) {
    if (world_size() == 1 || left_collectives()) {
      say(kind, message);
      return status;
    }
    if (e && dynamic_cast<const CollectiveFailure*>(e)) {
      if (world_rank() == 0) say(kind, message);
      return status;
    }
    say(kind, "rank " + std::to_string(world_rank()) + ": " + message);
    std::fflush(stderr);
    end_every_rank(status);
    return status;
  };
  try {
    return checked_success(body());
  } catch (const InterruptedExit& e) {
    if (!left_collectives()) end_every_rank(e.status);  // the others may wait for this one
    return e.status;
  } catch (const SettingError& e) {
    return said("error: ", e.in_words(words), 2, &e);
  } catch (const InputError& e) {
    return said("error: ", e.what(), 2, &e);
  } catch (const JsonError& e) {
    return said("error: ", e.what(), 2, &e);
  } catch (const IoError& e) {
    return said("error: ", e.what(), 1, &e);
  } catch (const std::bad_alloc& e) {
    return said("error: ", "out of memory", 1, &e);
  } catch (const std::exception& e) {
    return said("internal error: ", e.what(), 70, &e);
  }
}

}  // namespace hemotree

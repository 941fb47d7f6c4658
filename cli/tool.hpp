// The common frame of every hemotree command: one clear line on stderr and a non-zero exit
// for anything that goes wrong, never an uncaught exception.
#pragma once

#include <functional>
#include <string>

#include <CLI/CLI.hpp>

#include "core/setting_error.hpp"

namespace hemotree {

// Parses the command line with app, then runs body. Exit status: 0 success, 2 bad input
// (flags, values, file contents), 1 input/output failure, 70 internal error.
// A library's message that names settings (core/setting_error.hpp) is shown in words, the
// tool's flags (cli/setting_words.hpp).
int run_tool(CLI::App& app, int argc, char** argv, const SettingWords& words, const std::function<int()>& body);
// The same for a tool whose libraries name no setting of its own.
int run_tool(CLI::App& app, int argc, char** argv, const std::function<int()>& body);
// The same for a tool that runs some of its commands over MPI ranks (issue 24): over_ranks,
// asked once the command line is parsed, returns "" where this command runs over the
// ranks a launcher started, else the refusal's words. Started on several ranks, the body
// then runs inside an MPI session (mpi/session.hpp) on every rank, and an error
// every rank meets alike (bad input: every rank reads the same) is said once, by rank 0.
int run_tool(CLI::App& app, int argc, char** argv, const SettingWords& words, const std::function<int()>& body,
             const std::function<std::string()>& over_ranks);

// The ranks an MPI launcher started (1 without one) and this process's (0 without one), from
// the launcher's environment: run_tool refuses more than one rank, said by rank 0, for a
// command that does not run over them.
int launched_ranks();
int launched_rank();

// "vgen: warning: ..." / "vgen: ..." on stderr.
void warn(const std::string& message);
void note(const std::string& message);

// Flushes standard output (and std::cout) and returns "" when everything written to it
// reached its destination, else the reason. A tool that printed to standard output outside
// an OutputStream (help, version, a table) calls it before exiting 0.
std::string standard_output_error();

// True when stderr is a terminal: progress lines are shown only then.
bool stderr_is_terminal();

}  // namespace hemotree

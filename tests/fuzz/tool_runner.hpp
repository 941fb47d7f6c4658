// Runs a tool's main in process (its source compiled with -Dmain=tool_main) in a scratch
// folder that holds small valid inputs under fixed names, and checks the promise of
// cli/tool.hpp: exit status 0, 1 or 2, never 70 (internal error), an escaped exception or a
// sanitizer report.
#pragma once

#include <filesystem>
#include <iostream>
#include <string>
#include <vector>
#include <unistd.h>

#include <omp.h>

#include "fuzz_support.hpp"

int tool_main(int argc, char** argv);

namespace hemotree::fuzz {

// The inputs a command line may name, as files in the current folder (tests/fuzz/fixtures):
// tree.json (13 vessels, as vgen grows them), net.json (3 vessels with blood, inlet and
// outlets; 45 steps per cycle, so hemosolve runs in a millisecond), rules.json (vgen
// --print-rules), inflow.csv (a table for vprune --inflow-table).
class ToolRunner {
 public:
  ToolRunner() {
    omp_set_num_threads(1);
    for (const char* name : {"tree.json", "net.json", "rules.json", "inflow.csv"})
      fixtures_.push_back({name, read_file(std::filesystem::path(HEMOTREE_FUZZ_FIXTURES) / name)});
    work_ = scratch() / "work";
    std::filesystem::create_directories(work_);
    // Relative paths on the command line land in the scratch folder.
    if (::chdir(work_.c_str()) != 0) finding("cannot enter " + work_.string());
  }

  // Empties the folder (a previous run's outputs, a fixture it overwrote) and puts the
  // fixtures back, so that every run starts alike.
  void reset() {
    for (const auto& entry : std::filesystem::directory_iterator(work_)) std::filesystem::remove_all(entry.path());
    for (const auto& [name, bytes] : fixtures_) write_file(work_ / name, bytes);
  }

  // Runs tool_main(tool, args...) and returns its exit status; a finding unless 0, 1 or 2.
  int run(const std::string& tool, const std::vector<std::string>& args) {
    std::vector<std::string> storage{tool};
    storage.insert(storage.end(), args.begin(), args.end());
    std::vector<char*> argv;
    for (auto& a : storage) argv.push_back(a.data());
    argv.push_back(nullptr);
    int status = 0;
    std::cout.clear();  // a previous run's write error must not stick
    try {
      status = tool_main(static_cast<int>(storage.size()), argv.data());
    } catch (const std::exception& e) {
      finding("an exception escaped main (" + std::string(e.what()) + ") in " + shown(storage));
    } catch (...) {
      finding("a non-standard exception escaped main in " + shown(storage));
    }
    if (status != 0 && status != 1 && status != 2)
      finding("exit status " + std::to_string(status) + " (0, 1 or 2 expected) from " + shown(storage));
    return status;
  }

  const std::filesystem::path& folder() const { return work_; }

  static std::string shown(const std::vector<std::string>& argv) {
    std::string s;
    for (const auto& a : argv) s += (s.empty() ? "" : " ") + nlohmann::json(a).dump(-1, ' ', false,
                                                              nlohmann::json::error_handler_t::replace);
    return s;
  }

 private:
  std::vector<std::pair<std::string, std::string>> fixtures_;
  std::filesystem::path work_;
};

}  // namespace hemotree::fuzz

// Ranks of a run over MPI played by the threads of one process (tests of pulse/'s cuts: the
// messages carried in memory between them).
#pragma once

#include <string>
#include <thread>
#include <vector>

#include "pulse/lumped_vessels.hpp"

namespace hemotree::test_networks {

// step(r, its vessels) of every played rank, each on a thread of its own, as ranks run at
// once; per rank the words of what it threw ("" where nothing).
template <class Step>
std::vector<std::string> on_every_played_rank(std::vector<LumpedVessels>& part, Step&& step) {
  std::vector<std::string> said(part.size());
  std::vector<std::thread> threads;
  for (std::size_t r = 0; r < part.size(); ++r)
    threads.emplace_back([&, r] {
      try {
        step(static_cast<int>(r), part[r]);
      } catch (const LumpedVessels::CollapsedNode& c) {
        said[r] = "collapsed at vessel " + std::to_string(c.vessel);
      } catch (const std::exception& e) {
        said[r] = e.what();
      } catch (...) {
        said[r] = "not a std::exception";
      }
    });
  for (std::thread& th : threads) th.join();
  return said;
}

}  // namespace hemotree::test_networks

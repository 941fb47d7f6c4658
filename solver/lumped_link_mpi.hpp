// The messages of a run over ranks' 0D steps (pulse/lumped_cut.hpp's LumpedLink) carried by
// MPI: each step one gather of the shares' root numbers to the top's rank and one scatter of
// its answers back (distributed/root_exchange.hpp's two halves); a failure on any rank is
// refused on every rank alike, as the 0D step's words ("the 0D step: ...").
#pragma once

#include "distributed/root_exchange.hpp"
#include "pulse/lumped_cut.hpp"

namespace hemotree {

// exchange: built with the cut's roots per rank (LumpedCut::roots) and its top's rank; it
// must outlive the link.
LumpedLink mpi_lumped_link(RootExchange& exchange);

}  // namespace hemotree

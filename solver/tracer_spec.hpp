// `hemosolve --tracer SPEC`: an indicator injected as a bolus or a step, where and when.
//
//   SPEC = key=value[,key=value...]
//   name=NAME            its name in probes.csv, summary.json and the VTK (default tracer1, ...)
//   carrier=plasma|cells|blood   what carries it (default plasma: an imaging agent; cells: a
//                        labelled red cell; blood: a marker that moves with the mixture)
//   at=inlet|node:ID|vessel:ID   into the blood entering through every inflow boundary, through
//                        the boundary at node ID, or crossing vessel ID's proximal end
//                        (default inlet)
//   shape=bolus|step     a rectangular bolus over [start, start + duration), or from start on
//   start=T, duration=T  [s] (default 0 and 0.1 s); units accepted: s, ms
//   concentration=C      of the carrier while it is given (default 1: relative units)
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "formats/network.hpp"
#include "transport/tracer_transport.hpp"

namespace hemotree {

struct TracerSpec {
  enum class Place { inlet, node, vessel };
  enum class Shape { bolus, step };
  std::string name;
  TracerCarrier carrier = TracerCarrier::plasma;
  Place place = Place::inlet;
  std::int64_t at = -1;  // node or vessel index (not id)
  Shape shape = Shape::bolus;
  double start = 0, duration = 0.1, concentration = 1;

  // The mean of the injected concentration over [t0, t1] (exact for the rectangle).
  double mean_over(double t0, double t1) const;
  // The moment the injection is centred on (bolus: start + duration / 2; step: start).
  double centre() const { return shape == Shape::bolus ? start + duration / 2 : start; }
};

// Parses SPEC for the network (ids to indices); `ordinal` names it tracerN where no name is
// given. InputError naming the key, the value and what is accepted.
TracerSpec parse_tracer(const std::string& spec, const Network& net, int ordinal);

// Each SPEC parsed (the k-th named tracerk where it names none), and a name given twice refused.
std::vector<TracerSpec> parse_tracers(const std::vector<std::string>& specs, const Network& net);

const char* to_string(TracerCarrier carrier);

}  // namespace hemotree

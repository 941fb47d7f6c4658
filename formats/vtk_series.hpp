// A time series of per-vessel fields for ParaView: one VTK PolyData file per frame and a
// .pvd collection that lists the frames with their times, so ParaView opens the series
// as one animated dataset.
#pragma once

#include <cstddef>
#include <filesystem>
#include <string>
#include <vector>

#include "formats/exports.hpp"
#include "formats/network.hpp"

namespace hemotree {

// Writes DIR/STEM_0000.vtp, DIR/STEM_0001.vtp, ... (4 digits, more past 9999 frames) and,
// on finish(), DIR/STEM.pvd. Frames go through write_vtk, so geometry and the standard cell
// data equal those of `--format vtk`. The .pvd is written last, so an interrupted run never
// leaves a collection that looks complete. The network must outlive the series.
class VtkTimeSeries {
 public:
  // InputError if the network has no node coordinates or the stem is empty or has a path
  // separator; removes a .pvd left by an earlier run, as its frames are about to be replaced.
  // keep: the vessels written (one entry per vessel, 1 = written; empty: all).
  VtkTimeSeries(const Network& net, std::filesystem::path dir, std::string stem, std::vector<std::uint8_t> keep = {});

  // Writes one frame now. Times must be finite and increase at the 9 digits the .pvd keeps
  // (InputError otherwise). IoError if the file cannot be written (e.g. DIR is missing);
  // a frame that failed is not counted and its index is reused.
  void add_frame(double time, const std::vector<CellField>& fields);

  // Writes the .pvd; only then is the series complete. No frames may follow it.
  void finish();

  std::size_t frames() const { return times_.size(); }
  std::filesystem::path collection_path() const;     // DIR/STEM.pvd
  std::string frame_file_name(std::size_t frame) const;  // STEM_0000.vtp, relative to DIR

 private:
  const Network* net_;
  std::vector<std::uint8_t> keep_;
  std::filesystem::path dir_;
  std::string stem_;
  std::vector<double> times_;  // as printed in the .pvd, one per written frame
  bool finished_ = false;
};

}  // namespace hemotree

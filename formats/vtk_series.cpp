#include "formats/vtk_series.hpp"

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <stdexcept>
#include <string_view>
#include <system_error>
#include <utility>

#include "core/errors.hpp"
#include "formats/output_stream.hpp"

namespace hemotree {

namespace {

// A time as the .pvd carries it: 9 significant digits, like every number we write.
std::string time_text(double time) {
  char text[32];
  return std::string(text, format_real(text, time));
}

}  // namespace

VtkTimeSeries::VtkTimeSeries(const Network& net, std::filesystem::path dir, std::string stem,
                             std::vector<std::uint8_t> keep)
    : net_(&net), keep_(std::move(keep)), dir_(std::move(dir)), stem_(std::move(stem)) {
  // Fail before a long simulation starts rather than at its first output.
  if (!net.has_coordinates())
    throw InputError("VTK time series needs node coordinates; this network has none");
  if (stem_.empty() || stem_.find('/') != std::string::npos)
    throw InputError("VTK time series name '" + stem_ + "' must be a plain file name");
  // An old collection would list the old frames as they are overwritten one by one: a
  // series that looks complete but mixes two runs.
  std::error_code ec;
  std::filesystem::remove(collection_path(), ec);
  if (ec)
    throw IoError("cannot remove the old " + collection_path().string() + ": " + ec.message());
}

std::filesystem::path VtkTimeSeries::collection_path() const { return dir_ / (stem_ + ".pvd"); }

std::string VtkTimeSeries::frame_file_name(std::size_t frame) const {
  char number[24];
  std::snprintf(number, sizeof number, "%04zu", frame);
  return stem_ + '_' + number + ".vtp";
}

void VtkTimeSeries::add_frame(double time, const std::vector<CellField>& fields) {
  if (finished_) throw std::logic_error("VTK time series: frame added after finish()");
  if (!std::isfinite(time))
    throw InputError("VTK time series: frame time is not a finite number");
  // ParaView orders frames by time: a repeated or earlier time would hide or reorder one.
  const double time_in_collection = std::strtod(time_text(time).c_str(), nullptr);
  if (!times_.empty() && !(time_in_collection > times_.back()))
    throw InputError("VTK time series: frame time " + time_text(time) +
                     " does not come after the previous one (" + time_text(times_.back()) +
                     ") at 9 significant digits");

  OutputStream out((dir_ / frame_file_name(times_.size())).string());
  write_vtk(*net_, out, fields, keep_);
  out.commit();
  times_.push_back(time_in_collection);
}

void VtkTimeSeries::finish() {
  OutputStream out(collection_path().string());
  out << "<?xml version=\"1.0\"?>\n"
         "<VTKFile type=\"Collection\" version=\"0.1\" byte_order=\"LittleEndian\">\n"
         "  <Collection>\n";
  for (std::size_t frame = 0; frame < times_.size(); ++frame)
    out << "    <DataSet timestep=\"" << times_[frame] << "\" group=\"\" part=\"0\" file=\""
        << xml_attribute(frame_file_name(frame)) << "\"/>\n";
  out << "  </Collection>\n"
         "</VTKFile>\n";
  out.commit();
  finished_ = true;
}

}  // namespace hemotree

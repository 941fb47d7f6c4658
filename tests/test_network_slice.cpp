// A slice of a network (formats/network_slice.hpp): what a rank of a run over MPI reads of an
// HDF5 network, its vessels' rows and the nodes they touch, is the same slice as one taken of
// the network read whole, every member of it; its columns' rows are read only where picked,
// across chunks and blocks of chunks; and a value out of range in a slice's rows is refused
// naming the file's row, as the whole reader names it.
#include <algorithm>
#include <cstdint>
#include <filesystem>
#include <numeric>
#include <random>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "core/errors.hpp"
#include "formats/hdf5_file.hpp"
#include "formats/network_io.hpp"
#include "formats/network_slice.hpp"
#include "generator/growth_rules.hpp"
#include "generator/tree_growth.hpp"
#include "generator/tree_layout.hpp"
#include "scratch_path.hpp"

using namespace hemotree;
namespace fs = std::filesystem;

namespace {

std::string written_hdf5(const Network& net, const std::string& name) {
  const fs::path path = scratch_path(name);
  OutputStream out(path.string());
  write_network_hdf5(net, out);
  out.commit();
  return path.string();
}

std::string as_json(const Network& net) {
  const fs::path path = scratch_path("slice.json");
  {
    OutputStream out(path.string());
    write_network(net, out);
    out.commit();
  }
  const std::string text = [&] {
    std::FILE* f = std::fopen(path.c_str(), "rb");
    std::string s;
    char buffer[65536];
    for (std::size_t got; (got = std::fread(buffer, 1, sizeof buffer, f)) > 0;) s.append(buffer, got);
    std::fclose(f);
    return s;
  }();
  fs::remove(path);
  return text;
}

// A tree in the tree form (an inlet, outlets of both models), every column given.
Network grown_tree() {
  GrowthParameters p;
  p.root_diameter = 150e-6;
  p.min_diameter = 8e-6;
  Network net = grow_tree(default_rules(), p);
  lay_out_tree(net);
  for (std::size_t v = 0; v < net.vessel_count(); ++v) {
    net.wall_thickness[v] = 0.1 * net.diameter[v];
    net.youngs_modulus[v] = 4e5;
  }
  net.inlet = Inlet{net.id[0], Waveform{}};
  net.inlet->waveform.mean = 1e-10;
  std::vector<std::uint8_t> leaves_from(net.node_count(), 0);
  for (std::size_t v = 0; v < net.vessel_count(); ++v) leaves_from[static_cast<std::size_t>(net.from[v])] = 1;
  for (std::size_t v = 0; v < net.vessel_count(); ++v) {
    if (leaves_from[static_cast<std::size_t>(net.to[v])]) continue;
    Outlet o;
    o.vessel = static_cast<std::int32_t>(v);
    if (v % 2) {
      o.type = BoundaryType::rcr;
      o.r1 = 1e12 + static_cast<double>(v);
      o.c = 1e-18;
      o.r2 = 4e12;
    } else {
      o.r = 5e12 + static_cast<double>(v);
    }
    o.p_out = 600;
    net.outlets.push_back(o);
  }
  net.blood = Blood{};
  net.provenance = {{"tool", "test"}};
  return net;
}

// Every member of the slice read from the file against the slice of the whole network, and
// the slice's rows against the whole network's, value by value.
void expect_same_slice(const std::string& path, const Network& whole, const Network& topology,
                       const std::vector<std::int32_t>& rows) {
  const NetworkSlice read = read_network_slice(path, topology, rows);
  const NetworkSlice taken = slice_of(whole, rows);
  EXPECT_EQ(read.vessel_row, rows);
  EXPECT_EQ(read.node_row, taken.node_row);
  EXPECT_EQ(as_json(read.net), as_json(taken.net));
  ASSERT_EQ(read.net.vessel_count(), rows.size());
  std::size_t outlets = 0;
  for (std::size_t k = 0; k < rows.size(); ++k) {
    const auto v = static_cast<std::size_t>(rows[k]);
    EXPECT_EQ(read.net.id[k], whole.id[v]);
    EXPECT_EQ(read.net.length[k], whole.length[v]);
    EXPECT_EQ(read.net.generation[k], whole.generation[v]);
    EXPECT_EQ(read.net.node_id[static_cast<std::size_t>(read.net.from[k])], whole.node_id[static_cast<std::size_t>(whole.from[v])]);
    EXPECT_EQ(read.net.x[static_cast<std::size_t>(read.net.to[k])], whole.x[static_cast<std::size_t>(whole.to[v])]);
    EXPECT_EQ(read.node_at(whole.to[v]), read.net.to[k]);
  }
  for (const Outlet& o : whole.outlets)
    if (std::binary_search(rows.begin(), rows.end(), o.vessel)) {
      ASSERT_LT(outlets, read.net.outlets.size());
      const Outlet& mine = read.net.outlets[outlets++];
      EXPECT_EQ(rows[static_cast<std::size_t>(mine.vessel)], o.vessel);
      EXPECT_EQ(mine.resistance(), o.resistance());
    }
  EXPECT_EQ(read.net.outlets.size(), outlets);
  const bool holds_inlet = std::binary_search(rows.begin(), rows.end(), static_cast<std::int32_t>(whole.index_of(whole.inlet->vessel)));
  EXPECT_EQ(read.net.inlet.has_value(), holds_inlet);
}

}  // namespace

TEST(NetworkSlice, ASliceReadFromTheFileIsTheSliceOfTheWholeNetwork) {
  const Network net = grown_tree();
  ASSERT_GT(net.vessel_count(), 200u);
  const std::string path = written_hdf5(net, "tree.h5");
  const Network whole = read_network(path);
  const Network topology = read_network_topology(path);
  EXPECT_EQ(topology.id, whole.id);
  EXPECT_EQ(topology.node_id, whole.node_id);
  EXPECT_EQ(topology.from, whole.from);
  EXPECT_EQ(topology.to, whole.to);
  EXPECT_TRUE(topology.length.empty());
  EXPECT_TRUE(topology.inlet.has_value());
  const Network taken = topology_of(whole);  // rank 0's, of the network it reads whole
  EXPECT_EQ(taken.id, topology.id);
  EXPECT_EQ(taken.node_id, topology.node_id);
  EXPECT_EQ(taken.from, topology.from);
  EXPECT_EQ(taken.to, topology.to);
  EXPECT_EQ(taken.inlet->vessel, topology.inlet->vessel);
  EXPECT_EQ(taken.provenance, topology.provenance);
  EXPECT_TRUE(taken.length.empty() && taken.outlets.empty());

  const auto n = static_cast<std::int32_t>(whole.vessel_count());
  std::vector<std::int32_t> all(static_cast<std::size_t>(n));
  std::iota(all.begin(), all.end(), 0);
  expect_same_slice(path, whole, topology, all);
  EXPECT_EQ(as_json(read_network_slice(path, topology, all).net), as_json(whole));  // the whole as a slice of itself
  expect_same_slice(path, whole, topology, {0});
  expect_same_slice(path, whole, topology, {n - 1});
  expect_same_slice(path, whole, topology, {});
  std::mt19937 random(7);
  for (int trial = 0; trial < 5; ++trial) {
    std::vector<std::int32_t> rows;
    for (std::int32_t v = 0; v < n; ++v)
      if (std::uniform_real_distribution<double>(0, 1)(random) < 0.3) rows.push_back(v);
    expect_same_slice(path, whole, topology, rows);
  }
  EXPECT_THROW(read_network_slice(path, topology, std::vector<std::int32_t>{3, 2}), std::invalid_argument);
  EXPECT_THROW(read_network_slice(path, topology, std::vector<std::int32_t>{n}), std::invalid_argument);
}

TEST(NetworkSlice, AValueOutOfRangeInASlicesRowsIsNamedByTheFilesRow) {
  Network net = grown_tree();
  net.length[40] = 20;
  const std::string path = written_hdf5(net, "bad.h5");
  const Network topology = read_network_topology(path);
  try {
    read_network_slice(path, topology, std::vector<std::int32_t>{3, 40, 41});
    ADD_FAILURE() << "accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("/vessels/length: row 40 (vessel " + std::to_string(net.id[40]) +
                                         "): \"length\" must lie in [1e-7, 10] m (got 20)"),
              std::string::npos)
        << e.what();
  }
  // A slice without that row does not read it (the whole reader, on the run's lead rank, does).
  EXPECT_EQ(read_network_slice(path, topology, std::vector<std::int32_t>{3, 41}).net.vessel_count(), 2u);
}

TEST(Hdf5File, PickedRowsAcrossChunksAndBlocksAreTheColumnsRows) {
  // More rows than one block of 16 chunks of 65,536 rows: picks on each side of the
  // boundaries of chunks and of blocks, a run of rows, and random rows.
  const std::size_t rows = (std::size_t{1} << 20) + 3 * (std::size_t{1} << 16) + 123;
  std::vector<double> values(rows);
  std::vector<std::int64_t> integers(rows);
  for (std::size_t i = 0; i < rows; ++i) {
    values[i] = 0.5 * static_cast<double>(i) + 1e-3;
    integers[i] = 3 * static_cast<std::int64_t>(i) - 7;
  }
  const fs::path path = scratch_path("columns.h5");
  {
    OutputStream out(path.string());
    hdf5::write_through(out, [&](hdf5::File& f) {
      f.write("/a", std::span<const double>(values));
      f.write("/b", std::span<const std::int64_t>(integers));
    });
    out.commit();
  }
  const hdf5::File file = hdf5::File::open(path.string());
  std::vector<std::int32_t> pick = {0, 1, 65535, 65536, 65537, 1048575, 1048576, 1048577,
                                    static_cast<std::int32_t>(rows - 1)};
  for (std::int32_t r = 200000; r < 200300; ++r) pick.push_back(r);
  std::mt19937 random(3);
  for (int k = 0; k < 2000; ++k)
    pick.push_back(std::uniform_int_distribution<std::int32_t>(0, static_cast<std::int32_t>(rows - 1))(random));
  std::sort(pick.begin(), pick.end());
  pick.erase(std::unique(pick.begin(), pick.end()), pick.end());
  const std::vector<double> a = file.read_reals("/a", rows, pick);
  const std::vector<std::int64_t> b = file.read_integers("/b", rows, pick);
  ASSERT_EQ(a.size(), pick.size());
  for (std::size_t k = 0; k < pick.size(); ++k) {
    EXPECT_EQ(a[k], values[static_cast<std::size_t>(pick[k])]);
    EXPECT_EQ(b[k], integers[static_cast<std::size_t>(pick[k])]);
  }
  EXPECT_THROW(file.read_reals("/a", rows + 1, pick), InputError);  // the column's length is checked
}

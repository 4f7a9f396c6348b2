// Pins the mesher's output: element counts per kind and a hash of the whole mesh (coordinates to
// the bit, connectivity, boundary faces, NC flags) for a few parts at fixed sizes, against
// tests/volume/golden_meshes.json. A change meant to leave meshes unchanged must pass this as is;
// a change meant to move them regenerates the file with scripts/update-golden.sh and says why in
// its commit.
#include <gtest/gtest.h>

#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>

#include "app/part_modal.hpp"
#include "mesher/mesh/mesh_stats.hpp"
#include "mesher/pipeline.hpp"

namespace hexfem {
namespace {

const std::string kGoldenFile = std::string(HEXFEM_SOURCE_DIR) + "/tests/volume/golden_meshes.json";

// FNV-1a over raw bytes: any change of a coordinate bit or an index changes the hash.
struct Fnv1a {
  std::uint64_t h = 1469598103934665603ull;
  template <class T>
  void add(const std::vector<T>& v) {
    const std::uint64_t n = v.size();
    bytes(&n, sizeof n);
    bytes(v.data(), v.size() * sizeof(T));
  }
  void bytes(const void* p, std::size_t n) {
    const auto* c = static_cast<const unsigned char*>(p);
    for (std::size_t i = 0; i < n; ++i) h = (h ^ c[i]) * 1099511628211ull;
  }
};

std::string mesh_hash(const MixedMesh& m) {
  Fnv1a f;
  f.add(m.nodes);
  f.add(m.cell_kind);
  f.add(m.cell_nodes);
  f.add(m.cell_solid);
  f.add(m.bface_nodes);
  f.add(m.bface_cad_face);
  f.add(m.nc_cell);
  f.add(m.nc_local_face);
  if (m.order == 2) {  // the mid-edge nodes (their coordinates are in m.nodes)
    f.add(m.cell_edge_nodes);
    f.add(m.bface_edge_nodes);
  }
  char s[17];
  std::snprintf(s, sizeof s, "%016llx", static_cast<unsigned long long>(f.h));
  return s;
}

struct GoldenPart {
  std::string file;
  double h;
  bool glue;      // --glue: the solids fused into a bonded assembly first
  int order = 1;  // 2: the mid-edge nodes put on the CAD geometry, as `hexfem mesh --order 2`
};

nlohmann::json measure(const GoldenPart& part) {
  const auto& [file, h, glue, order] = part;
  MeshOptions o;
  o.surface.h = h;
  o.read.glue = glue;
  MeshReport report;
  const CadModel cad = read_cad_to_mesh(std::string(HEXFEM_SOURCE_DIR) + "/" + file, o, report);
  MixedMesh m = mesh_part(cad, o, &report);
  if (order == 2) raise_to_order2(m, &cad);
  const MeshStats st = compute_stats(m);
  nlohmann::json j;
  j["file"] = file;
  j["h"] = h;
  if (order == 2) j["order"] = 2;
  j["vertices"] = m.nodes.size();
  for (int k = 0; k < kNumCellKinds; ++k)
    j[kind_name(static_cast<CellKind>(k))] = st.cells_per_kind[k];
  j["boundary_faces"] = m.num_bfaces();
  j["nc_quads"] = m.nc_cell.size();
  j["hash"] = mesh_hash(m);
  return j;
}

// The parts: the demo's steel part, a curved part, the paper's ANC101, a thin-walled part, a
// solid whose lumps touch along an edge, a glued assembly (the last two since session 19; the
// first four's entries did not move when they were added), a part meshed again and a part at
// order 2 (session 36).
const std::vector<GoldenPart> kParts = {
    {"models/steel_part.step", 1.0, false},
    {"tests/data/cylinder.stp", 0.9, false},
    {"tests/data/ANC101.stp", 9.0, false},
    {"tests/data/0049_control_arm.step", 10.1, false},
    {"tests/data/gehause_rohteil.stp", 0.698, false},
    {"tests/data/as1-oc-214.stp", 8.0, true},
    // Meshed again with a curvature bound (-10.6 % off the CAD volume at h), the first
    // attempt's volume never meshed (session 36; its entry made by the code before, which
    // meshed every attempt in full).
    {"tests/data/tie_rod.step", 4.26, false},
    // Order 2 on B-spline blades (session 36; its entry made by the code before the mid-edge
    // nodes were placed on all threads).
    {"tests/data/Propeller.rle", 67.93, false, 2},
};

TEST(Golden, MeshesMatchThePinnedCountsAndHashes) {
  if (std::getenv("HEXFEM_GOLDEN_WRITE")) {  // scripts/update-golden.sh
    nlohmann::json all = nlohmann::json::array();
    for (const GoldenPart& part : kParts) all.push_back(measure(part));
    std::ofstream(kGoldenFile) << all.dump(2) << "\n";
    GTEST_SKIP() << "wrote " << kGoldenFile;
  }
  std::ifstream in(kGoldenFile);
  ASSERT_TRUE(in) << "missing " << kGoldenFile;
  const nlohmann::json golden = nlohmann::json::parse(in);
  ASSERT_EQ(golden.size(), kParts.size());
  for (std::size_t i = 0; i < kParts.size(); ++i) {
    const nlohmann::json got = measure(kParts[i]);
    SCOPED_TRACE(got["file"].get<std::string>());
    for (const auto& [key, value] : golden[i].items()) EXPECT_EQ(got[key], value) << key;
  }
}

}  // namespace
}  // namespace hexfem

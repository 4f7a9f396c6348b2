// Small hand-made meshes with known answers, shared by the mesh tests.
#pragma once

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "mesher/mesh/mixed_mesh.hpp"

namespace hexfem::testing {

// Unit cube hex, nodes in Gmsh order; `shear` adds shear*y to x.
inline MixedMesh unit_hex(double shear = 0.0) {
  MixedMesh m;
  const double p[8][3] = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0},
                          {0, 0, 1}, {1, 0, 1}, {1, 1, 1}, {0, 1, 1}};
  for (const auto& x : p) m.nodes.push_back({x[0] + shear * x[1], x[1], x[2]});
  m.add_cell(CellKind::Hex8, {0, 1, 2, 3, 4, 5, 6, 7});
  return m;
}

// A hex with two tets on its top face (4,5,6,7) split along the diagonal 4-6: one NC quad.
inline MixedMesh hex_with_split_top() {
  MixedMesh m = unit_hex();
  m.nodes.push_back({0.5, 0.5, 1.5});  // node 8, apex of both tets
  m.add_cell(CellKind::Tet4, {4, 5, 6, 8});
  m.add_cell(CellKind::Tet4, {4, 6, 7, 8});
  return m;
}

// One cell of every kind in two solids, with boundary faces and physical tags.
inline MixedMesh mixed_sample() {
  MixedMesh m;
  for (int k = 0; k < 3; ++k)
    for (int j = 0; j < 2; ++j)
      for (int i = 0; i < 2; ++i) m.nodes.push_back({1.0 * i, 1.0 * j, 1.0 * k});
  // nodes: z=0: 0..3, z=1: 4..7, z=2: 8..11 (index = 4k + 2j + i)
  m.nodes.push_back({0.5, 0.5, 2.7});  // 12: pyramid apex
  m.nodes.push_back({2.0, 0.0, 0.0});  // 13
  m.nodes.push_back({2.0, 0.0, 1.0});  // 14
  m.nodes.push_back({1.3, 1.4, 1.2});  // 15
  m.add_cell(CellKind::Hex8, {0, 1, 3, 2, 4, 5, 7, 6}, 1, 10);
  m.add_cell(CellKind::Hex8, {4, 5, 7, 6, 8, 9, 11, 10}, 1, 10);
  m.add_cell(CellKind::Pyramid5, {8, 9, 11, 10, 12}, 2, 20);
  m.add_cell(CellKind::Wedge6, {1, 13, 3, 5, 14, 7}, 2, 20);
  m.add_cell(CellKind::Tet4, {5, 14, 7, 15}, 2, 20);
  m.add_bface(0, 2, 3, 1, 1, 100);
  m.add_bface(8, 9, 12, -1, 2, 0);
  m.physical_names[{3, 10}] = "steel";
  m.physical_names[{2, 100}] = "bottom face";
  return m;
}

inline std::filesystem::path work_path(const std::string& name) {
  return std::filesystem::path(HEXFEM_WORK_DIR) / name;
}

// Runs a shell command, returns its exit status and captures stdout+stderr.
inline int run(const std::string& command, std::string* output = nullptr) {
  const std::string cmd = command + " 2>&1";
  FILE* pipe = popen(cmd.c_str(), "r");
  if (!pipe) return -1;
  std::string out;
  char buf[4096];
  while (std::fgets(buf, sizeof buf, pipe)) out += buf;
  const int status = pclose(pipe);
  if (output) *output = out;
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

inline std::string hexfem_cli() {
  return std::string(HEXFEM_BINARY);
}

inline void write_file(const std::filesystem::path& p, const std::string& text) {
  std::ofstream(p, std::ios::binary) << text;
}

}  // namespace hexfem::testing

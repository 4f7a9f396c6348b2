// Reading and writing the mixed mesh: Gmsh MSH 4.1 (ASCII/binary) and 2.2 (ASCII) in,
// MSH 4.1, VTK XML .vtu and Abaqus/CalculiX .inp out. Every write is atomic (temp + rename).
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>
#include <utility>
#include <vector>

#include "mesher/mesh/mixed_mesh.hpp"

namespace hexfem {

// MSH 4.1 written by hexfem carries the NC quad faces (mesh.nc_cell) as quads (quad8 at order 2)
// on a surface entity of their own in the physical group of this name; the reader skips them.
inline constexpr const char* kNonconformalGroup = "nonconformal";

// Reads a .msh file (format detected from its header). Throws hexfem::Error naming the file
// and line on a corrupt or truncated file. Fills nc_cell/nc_local_face (flag_nonconformal_quads).
MixedMesh read_msh(const std::filesystem::path& path);

// A node whose displacement is a weighted sum of other nodes' (each component): at order 2 the
// mid-diagonal node of an NC quad face, tied to the quad8's trace (fem/nc_ties.hpp). The .inp
// writes each as three *EQUATIONs, so CalculiX sees the same tie as hexfem's solver.
struct NodeTie {
  std::int32_t node = -1;
  std::vector<std::pair<std::int32_t, double>> masters;  // (node, weight)
};

struct MeshWriteOptions {
  MeshWriteOptions(bool binary_msh = false) : binary(binary_msh) {}  // NOLINT: {binary} reads well
  bool binary = false;                                               // .msh: MSH 4.1 binary
  std::vector<NodeTie> inp_ties;  // .inp: written as *EQUATION; other formats cannot carry them
  bool inp_incompatible_hex8 = false;  // .inp, order 1: hexes as C3D8I instead of C3D8
  // .inp, order 2: per cell, pyramids written as C3D20R instead of C3D20 (ones CalculiX would
  // find inside out as a collapsed C3D20; app/ccx_deck.hpp finds them).
  std::vector<char> inp_reduced_pyramids;
};
void write_msh(const MixedMesh& mesh, const std::filesystem::path& path,
               const MeshWriteOptions& options = {});

// Extra arrays for a .vtu: field data (name, values) and point data with 3 components per node
// (name, 3 * nodes values), e.g. mode shapes. `digits` > 0 rounds the point data to that many
// significant digits (shapes need no more than 7; keeps large files small).
struct VtuExtras {
  std::vector<std::pair<std::string, std::vector<double>>> field_data;
  std::vector<std::pair<std::string, std::vector<double>>> point_vectors;
  int digits = 0;
  bool nc_faces_file = true;  // also write <stem>_nc.vtu
};

// VTK XML unstructured grid. Cell data: kind (VTK type id), solid, quality (min scaled
// Jacobian), nc (number of NC quad faces of the cell). Also writes <stem>_nc.vtu with the NC
// quad faces as polygons, when there are any (unless extras.nc_faces_file is false).
void write_vtu(const MixedMesh& mesh, const std::filesystem::path& path,
               const VtuExtras& extras = {});

// Abaqus/CalculiX input: *NODE (node i -> i+1), *ELEMENT (cell c -> c+1) as C3D8, C3D6, C3D4,
// pyramids as C3D8 with the apex repeated; ELSETs EALL, E_HEX8, E_WEDGE6, E_PYRAMID5, E_TET4,
// SOLID_<id>; NSETs NALL and FACE_<id> for each CAD face with boundary faces; when there are NC
// quad faces, ELSET NC_ELEMENTS (the cells with one) and the element-face SURFACE NONCONFORMAL.
// `ties` go out as *EQUATION (the tied node's DOF first, so CalculiX eliminates it). Mesh and
// constraints only (no material/step), so a deck can *INCLUDE it. incompatible_hex8: order-1
// hexes as C3D8I (incompatible modes, like hexfem's default hex8) instead of C3D8;
// reduced_pyramids (per cell, order 2): those pyramids as C3D20R, ELSET E_PYRAMID13R.
void write_inp(const MixedMesh& mesh, const std::filesystem::path& path,
               const std::vector<NodeTie>& ties = {}, bool incompatible_hex8 = false,
               const std::vector<char>& reduced_pyramids = {});

// A real number as an .inp field: the shortest round-trip form when it fits in 20 characters,
// since ccx 2.20 refuses a longer field ("*ERROR reading *NODE" on 1.7763568394002505E-15, a
// coordinate a glued assembly's fuse left next to zero); else the most digits that fit (14 to
// 16 significant, far below any mesh tolerance).
std::string inp_real(double v);

// Writes by extension: .msh (options.binary), .vtu, .inp. Unknown extension: hexfem::Error.
void write_mesh(const MixedMesh& mesh, const std::filesystem::path& path,
                const MeshWriteOptions& options = {});
// Reads by extension (.msh only for now). Missing file / unknown extension: hexfem::Error.
MixedMesh read_mesh(const std::filesystem::path& path);

}  // namespace hexfem

// VTK XML (.vtu) and Abaqus/CalculiX (.inp) writers, and the by-extension dispatch.
#include <charconv>
#include <set>
#include <string>
#include <type_traits>

#include "mesher/mesh/atomic_file.hpp"
#include "mesher/mesh/element_topology.hpp"
#include "mesher/mesh/error.hpp"
#include "mesher/mesh/face_keys.hpp"
#include "mesher/mesh/mesh_io.hpp"
#include "mesher/mesh/quality.hpp"

namespace hexfem {

namespace {

// VTK cell type ids, and Gmsh -> VTK node order (the VTK wedge's first triangle faces outward).
int vtk_type(CellKind k) {
  switch (k) {
    case CellKind::Tet4:
      return 10;
    case CellKind::Pyramid5:
      return 14;
    case CellKind::Wedge6:
      return 13;
    case CellKind::Hex8:
      return 12;
  }
  return 0;
}
constexpr int kWedgeToVtk[6] = {0, 2, 1, 3, 5, 4};

// Order 2: VTK quadratic tet 24, pyramid 27, wedge 26, hexahedron 25, and for output position i
// the element's (Gmsh-ordered) local node. VTK and Abaqus list the bottom edges, the top edges,
// then the vertical ones; Gmsh lists the edges by their first corner.
constexpr int kVtkOrder2Type[kNumCellKinds] = {24, 27, 26, 25};
constexpr int kVtkOrder2[kNumCellKinds][kMaxElementNodes] = {
    {0, 1, 2, 3, 4, 5, 6, 7, 9, 8},
    {0, 1, 2, 3, 4, 5, 8, 10, 6, 7, 9, 11, 12},
    {0, 2, 1, 3, 5, 4, 7, 9, 6, 13, 14, 12, 8, 11, 10},
    {0, 1, 2, 3, 4, 5, 6, 7, 8, 11, 13, 9, 16, 18, 19, 17, 10, 12, 14, 15}};
// Abaqus/CalculiX C3D10, C3D15 and C3D20; a pyramid13 goes out as a C3D20 collapsed onto its
// apex (corners 0 1 2 3 4 4 4 4, the top edges' nodes at the apex).
constexpr int kInpOrder2[kNumCellKinds][kMaxElementNodes] = {
    {0, 1, 2, 3, 4, 5, 6, 7, 9, 8},
    {0, 1, 2, 3, 4, 4, 4, 4, 5, 8, 10, 6, 4, 4, 4, 4, 7, 9, 11, 12},
    {0, 1, 2, 3, 4, 5, 6, 9, 7, 12, 14, 13, 8, 10, 11},
    {0, 1, 2, 3, 4, 5, 6, 7, 8, 11, 13, 9, 16, 18, 19, 17, 10, 12, 14, 15}};

// A number and a space (shortest round-trip form for doubles).
template <class T>
requires std::is_arithmetic_v<T>
void put(std::string& s, T v) {
  char buf[32];
  auto r = std::to_chars(buf, buf + sizeof buf, v);
  s.append(buf, r.ptr);
  s.push_back(' ');
}

template <class Fn>
void data_array(std::string& s, const char* type, const char* name, int components, std::size_t n,
                Fn value) {
  s += std::string("<DataArray type=\"") + type + "\" Name=\"" + name + "\" NumberOfComponents=\"" +
       std::to_string(components) + "\" format=\"ascii\">\n";
  for (std::size_t i = 0; i < n; ++i) {
    value(i);
    if (i % 8 == 7) s.push_back('\n');
  }
  s += "\n</DataArray>\n";
}

// Writes v into buf (32 chars) as inp_real says; returns the end.
char* inp_real_chars(double v, char* buf) {
  constexpr std::ptrdiff_t kCcxField = 20;
  auto r = std::to_chars(buf, buf + 32, v);
  for (int digits = 16; r.ptr - buf > kCcxField && digits > 1; --digits)
    r = std::to_chars(buf, buf + 32, v, std::chars_format::general, digits);
  return r.ptr;
}

// A real number for CalculiX and a space (no string made: millions of coordinates).
void put_inp_real(std::string& s, double v) {
  char buf[32];
  s.append(buf, inp_real_chars(v, buf));
  s.push_back(' ');
}

// One unstructured grid of `n` cells; `cell(i, ids)` returns the VTK type and fills VTK-ordered
// ids.
void put_rounded(std::string& s, double v, int digits) {
  char buf[32];
  auto r = std::to_chars(buf, buf + sizeof buf, v, std::chars_format::general, digits);
  s.append(buf, r.ptr);
  s.push_back(' ');
}

template <class CellFn, class DataFn>
std::string vtu_text(const std::vector<Vec3>& nodes, std::size_t n, CellFn cell, DataFn cell_data,
                     const VtuExtras& extras = {}) {
  std::string s;
  s.reserve(64 * (nodes.size() + n));
  s += "<?xml version=\"1.0\"?>\n<VTKFile type=\"UnstructuredGrid\" version=\"1.0\" "
       "byte_order=\"LittleEndian\" header_type=\"UInt64\">\n<UnstructuredGrid>\n";
  if (!extras.field_data.empty()) {
    s += "<FieldData>\n";
    for (const auto& [name, values] : extras.field_data) {
      s += "<DataArray type=\"Float64\" Name=\"" + name + "\" NumberOfTuples=\"" +
           std::to_string(values.size()) + "\" format=\"ascii\">\n";
      for (double v : values) put(s, v);
      s += "\n</DataArray>\n";
    }
    s += "</FieldData>\n";
  }
  s += "<Piece NumberOfPoints=\"" + std::to_string(nodes.size()) + "\" NumberOfCells=\"" +
       std::to_string(n) + "\">\n<Points>\n";
  data_array(s, "Float64", "Points", 3, nodes.size(), [&](std::size_t i) {
    for (double x : nodes[i]) put(s, x);
  });
  s += "</Points>\n<Cells>\n";
  std::vector<long long> types(n), offsets(n);
  std::string conn;
  long long offset = 0;
  std::int32_t ids[kMaxElementNodes];
  for (std::size_t i = 0; i < n; ++i) {
    int count = 0;
    types[i] = cell(i, ids, count);
    for (int k = 0; k < count; ++k) put(conn, ids[k]);
    conn.push_back('\n');
    offset += count;
    offsets[i] = offset;
  }
  s += "<DataArray type=\"Int64\" Name=\"connectivity\" format=\"ascii\">\n" + conn +
       "</DataArray>\n";
  data_array(s, "Int64", "offsets", 1, n, [&](std::size_t i) { put(s, offsets[i]); });
  data_array(s, "UInt8", "types", 1, n, [&](std::size_t i) { put(s, types[i]); });
  s += "</Cells>\n<CellData>\n";
  cell_data(s);
  s += "</CellData>\n";
  if (!extras.point_vectors.empty()) {
    s += "<PointData Vectors=\"" + extras.point_vectors.front().first + "\">\n";
    for (const auto& [name, values] : extras.point_vectors) {
      if (values.size() != 3 * nodes.size())
        throw Error("point data '" + name + "' does not match the mesh's nodes");
      data_array(s, "Float64", name.c_str(), 3, nodes.size(), [&](std::size_t i) {
        for (int a = 0; a < 3; ++a) {
          if (extras.digits > 0)
            put_rounded(s, values[3 * i + a], extras.digits);
          else
            put(s, values[3 * i + a]);
        }
      });
    }
    s += "</PointData>\n";
  }
  s += "</Piece>\n</UnstructuredGrid>\n</VTKFile>\n";
  return s;
}

void write_text(const std::filesystem::path& path, const std::string& text) {
  write_atomically(path, false, [&](std::ostream& out) { out << text; });
}

}  // namespace

void write_vtu(const MixedMesh& mesh, const std::filesystem::path& path, const VtuExtras& extras) {
  std::string text;
  if (mesh.num_cells() > 0) {
    std::vector<int> nc_count(mesh.num_cells(), 0);
    for (std::int32_t c : mesh.nc_cell) ++nc_count[c];
    text = vtu_text(
        mesh.nodes, mesh.num_cells(),
        [&](std::size_t c, std::int32_t* ids, int& count) {
          const CellKind k = mesh.cell_kind[c];
          if (mesh.order == 2) {
            std::int32_t all[kMaxElementNodes];
            count = mesh.element_nodes(c, all);
            for (int i = 0; i < count; ++i) ids[i] = all[kVtkOrder2[static_cast<int>(k)][i]];
            return kVtkOrder2Type[static_cast<int>(k)];
          }
          count = num_nodes(k);
          for (int i = 0; i < count; ++i)
            ids[i] = mesh.cell(c)[k == CellKind::Wedge6 ? kWedgeToVtk[i] : i];
          return vtk_type(k);
        },
        [&](std::string& s) {
          const std::size_t n = mesh.num_cells();
          data_array(s, "Int32", "kind", 1, n, [&](std::size_t c) {
            put(s, mesh.order == 2 ? kVtkOrder2Type[static_cast<int>(mesh.cell_kind[c])]
                                   : vtk_type(mesh.cell_kind[c]));
          });
          data_array(s, "Int32", "solid", 1, n, [&](std::size_t c) { put(s, mesh.cell_solid[c]); });
          data_array(s, "Float64", "quality", 1, n,
                     [&](std::size_t c) { put(s, cell_min_scaled_jacobian(mesh, c)); });
          data_array(s, "Int32", "nc", 1, n, [&](std::size_t c) { put(s, nc_count[c]); });
        },
        extras);
  } else {
    // A surface mesh: its boundary faces, tagged by CAD face.
    text = vtu_text(
        mesh.nodes, mesh.num_bfaces(),
        [&](std::size_t f, std::int32_t* ids, int& count) {
          count = mesh.bface_element_nodes(f, ids);  // VTK's quadratic order is Gmsh's
          return count == 4 ? 9 : count == 3 ? 5 : count == 8 ? 23 : 22;
        },
        [&](std::string& s) {
          data_array(s, "Int32", "cad_face", 1, mesh.num_bfaces(),
                     [&](std::size_t f) { put(s, mesh.bface_cad_face[f]); });
        });
  }
  write_text(path, text);

  // The NC quad faces on their own, so they can be shown over the cut mesh in ParaView.
  if (mesh.nc_cell.empty() || !extras.nc_faces_file) return;
  std::filesystem::path nc_path = path;
  nc_path.replace_filename(path.stem().string() + "_nc.vtu");
  const std::string nc_text = vtu_text(
      mesh.nodes, mesh.nc_cell.size(),
      [&](std::size_t i, std::int32_t* ids, int& count) {
        const std::int32_t c = mesh.nc_cell[i];
        const LocalFace& f = faces_of(mesh.cell_kind[c]).face[mesh.nc_local_face[i]];
        count = 4;
        for (int k = 0; k < 4; ++k) ids[k] = mesh.cell(c)[f.v[k]];
        return 9;
      },
      [&](std::string& s) {
        data_array(s, "Int32", "cell", 1, mesh.nc_cell.size(),
                   [&](std::size_t i) { put(s, mesh.nc_cell[i]); });
      });
  write_text(nc_path, nc_text);
}

namespace {

// CalculiX's face numbers S1.. of C3D8/C3D20 and C3D6/C3D15 as corner sets (0-based, the INP
// node order, which is the mesh's); a pyramid is a C3D8 on nodes 0 1 2 3 4 4 4 4: its base is S1.
constexpr std::array<std::array<int, 4>, 6> kCcxHexFaces = {
    {{0, 1, 2, 3}, {4, 7, 6, 5}, {0, 4, 5, 1}, {1, 5, 6, 2}, {2, 6, 7, 3}, {3, 7, 4, 0}}};
constexpr std::array<std::array<int, 4>, 5> kCcxWedgeFaces = {
    {{0, 1, 2, -1}, {3, 4, 5, -1}, {0, 1, 4, 3}, {1, 2, 5, 4}, {2, 0, 3, 5}}};

// The S number of local quad face f of cell c.
int ccx_face_number(const MixedMesh& mesh, std::int32_t c, int f) {
  const CellKind k = mesh.cell_kind[c];
  if (k == CellKind::Pyramid5) return 1;
  const std::int32_t* ids = mesh.cell(c);
  const FaceKey want = face_key(ids, faces_of(k).face[f]);
  auto find = [&](const auto& table) {
    for (std::size_t s = 0; s < table.size(); ++s) {
      if (table[s][3] < 0) continue;
      const LocalFace lf{4, table[s]};
      if (face_key(ids, lf) == want) return static_cast<int>(s) + 1;
    }
    return 0;
  };
  return k == CellKind::Hex8 ? find(kCcxHexFaces) : find(kCcxWedgeFaces);
}

template <class IdList>
void write_inp_nc_sets(const MixedMesh& mesh, std::string& s, IdList id_list) {
  s += "** Non-conformal quad faces (a quad face against two triangles, not an identical quad): "
       "ELSET NC_ELEMENTS\n** holds the elements with one, SURFACE NONCONFORMAL the faces "
       "(element, CalculiX face number)\n";
  std::set<long long> cells(mesh.nc_cell.begin(), mesh.nc_cell.end());
  std::vector<long long> ids;
  for (long long c : cells) ids.push_back(c + 1);
  s += "*ELSET, ELSET=NC_ELEMENTS\n";
  id_list(ids);
  s += "*SURFACE, NAME=NONCONFORMAL, TYPE=ELEMENT\n";
  for (std::size_t i = 0; i < mesh.nc_cell.size(); ++i)
    s += std::to_string(mesh.nc_cell[i] + 1) + ", S" +
         std::to_string(ccx_face_number(mesh, mesh.nc_cell[i], mesh.nc_local_face[i])) + "\n";
}

// u_node,a - sum w_i u_master_i,a = 0 for a = 1..3, at most four terms (12 entries) a line.
void write_inp_ties(const std::vector<NodeTie>& ties, std::string& s) {
  s += "** Order-2 hanging nodes of the NC faces: each mid-diagonal node follows the quad8's "
       "trace\n** (u = sum w_i u_i over the face's 8 nodes), as hexfem's solver ties "
       "it\n*EQUATION\n";
  for (const NodeTie& t : ties) {
    std::vector<std::pair<std::int32_t, double>> terms{{t.node, 1.0}};
    for (const auto& [m, w] : t.masters)
      if (w != 0) terms.emplace_back(m, -w);
    for (int a = 1; a <= 3; ++a) {
      s += std::to_string(terms.size()) + "\n";
      for (std::size_t i = 0; i < terms.size(); ++i) {
        put(s, static_cast<long long>(terms[i].first + 1));
        s.back() = ',';
        put(s, a);
        s.back() = ',';
        put_inp_real(s, terms[i].second);
        s.back() = (i % 4 == 3 || i + 1 == terms.size()) ? '\n' : ',';
      }
    }
  }
}

}  // namespace

std::string inp_real(double v) {
  char buf[32];
  return std::string(buf, inp_real_chars(v, buf));
}

void write_inp(const MixedMesh& mesh, const std::filesystem::path& path,
               const std::vector<NodeTie>& ties, bool incompatible_hex8,
               const std::vector<char>& reduced_pyramids) {
  std::string s;
  s.reserve(80 * (mesh.nodes.size() + mesh.num_cells()));
  s += "** hexfem mixed mesh: node i -> i+1, cell c -> c+1\n";
  if (!mesh.length_unit.empty()) s += "** coordinates in " + mesh.length_unit + "\n";
  s += "*NODE, NSET=NALL\n";
  for (std::size_t i = 0; i < mesh.nodes.size(); ++i) {
    put(s, static_cast<long long>(i + 1));
    for (double x : mesh.nodes[i]) {
      s.back() = ',';
      put_inp_real(s, x);
    }
    s.back() = '\n';
  }
  struct KindOut {
    CellKind kind;
    const char* type;
    const char* elset;
    bool reduced = false;  // the pyramids flagged in reduced_pyramids, and only those
  };
  const bool o2 = mesh.order == 2;
  auto reduced = [&](std::size_t c) {
    return o2 && c < reduced_pyramids.size() && reduced_pyramids[c];
  };
  const KindOut kinds[] = {
      {CellKind::Hex8,
       o2                  ? "C3D20"
       : incompatible_hex8 ? "C3D8I"
                           : "C3D8",
       o2 ? "E_HEX20" : "E_HEX8"},
      {CellKind::Wedge6, o2 ? "C3D15" : "C3D6", o2 ? "E_WEDGE15" : "E_WEDGE6"},
      {CellKind::Pyramid5, o2 ? "C3D20" : "C3D8", o2 ? "E_PYRAMID13" : "E_PYRAMID5"},
      {CellKind::Pyramid5, "C3D20R", "E_PYRAMID13R", true},
      {CellKind::Tet4, o2 ? "C3D10" : "C3D4", o2 ? "E_TET10" : "E_TET4"}};
  std::vector<std::string> used_elsets;
  for (const KindOut& k : kinds) {
    bool any = false;
    for (std::size_t c = 0; c < mesh.num_cells(); ++c) {
      if (mesh.cell_kind[c] != k.kind) continue;
      if (k.kind == CellKind::Pyramid5 && reduced(c) != k.reduced) continue;
      if (!any) {
        if (k.kind == CellKind::Pyramid5 && !o2)
          s += "** CalculiX has no pyramid: each pyramid is a C3D8 with the apex repeated "
               "(nodes 1 2 3 4 5 5 5 5)\n";
        if (k.kind == CellKind::Pyramid5 && o2 && !k.reduced)
          s += "** CalculiX has no pyramid: each pyramid13 is a C3D20 collapsed onto its apex "
               "(corners 1 2 3 4 5 5 5 5, the top edges' mid nodes at the apex too)\n";
        if (k.reduced)
          s += "** These pyramids, collapsed C3D20 too, would be inside out at C3D20's 3x3x3 "
               "points (ccx refuses them): C3D20R, with 2x2x2 points\n";
        s += std::string("*ELEMENT, TYPE=") + k.type + ", ELSET=" + k.elset + "\n";
        used_elsets.push_back(k.elset);
        any = true;
      }
      put(s, static_cast<long long>(c + 1));
      const std::int32_t* ids = mesh.cell(c);
      if (o2) {
        std::int32_t all[kMaxElementNodes];
        mesh.element_nodes(c, all);
        const int n = k.kind == CellKind::Pyramid5 ? 20 : num_nodes(k.kind, 2);
        for (int i = 0; i < n; ++i) {
          // Abaqus lines hold at most 16 entries: a C3D20 continues on a second line.
          s.back() = ',';
          if (i == 15) s += '\n';
          put(s, static_cast<long long>(all[kInpOrder2[static_cast<int>(k.kind)][i]] + 1));
        }
        s.back() = '\n';
        continue;
      }
      const int n = k.kind == CellKind::Pyramid5 ? 8 : num_nodes(k.kind);
      for (int i = 0; i < n; ++i) {
        s.back() = ',';
        put(s, static_cast<long long>(ids[std::min(i, num_nodes(k.kind) - 1)] + 1));
      }
      s.back() = '\n';
    }
  }
  auto id_list = [&](const std::vector<long long>& ids) {
    for (std::size_t i = 0; i < ids.size(); ++i) {
      put(s, ids[i]);
      s.back() = (i % 16 == 15 || i + 1 == ids.size()) ? '\n' : ',';
    }
  };
  s += "*ELSET, ELSET=EALL\n";
  for (std::size_t i = 0; i < used_elsets.size(); ++i)
    s += used_elsets[i] + (i + 1 == used_elsets.size() ? "\n" : ", ");
  std::map<int, std::vector<long long>> by_solid;
  for (std::size_t c = 0; c < mesh.num_cells(); ++c) by_solid[mesh.cell_solid[c]].push_back(c + 1);
  for (const auto& [solid, ids] : by_solid) {
    s += "*ELSET, ELSET=SOLID_" + std::to_string(solid) + "\n";
    id_list(ids);
  }
  std::map<int, std::set<long long>> by_face;
  for (std::size_t f = 0; f < mesh.num_bfaces(); ++f) {
    std::int32_t ids[8];
    for (int i = 0, n = mesh.bface_element_nodes(f, ids); i < n; ++i)
      by_face[mesh.bface_cad_face[f]].insert(ids[i] + 1);
  }
  for (const auto& [face, ids] : by_face) {
    s += "*NSET, NSET=FACE_" + std::to_string(face) + "\n";
    id_list(std::vector<long long>(ids.begin(), ids.end()));
  }
  if (!mesh.nc_cell.empty()) write_inp_nc_sets(mesh, s, id_list);
  if (!ties.empty()) write_inp_ties(ties, s);
  write_text(path, s);
}

void write_mesh(const MixedMesh& mesh, const std::filesystem::path& path,
                const MeshWriteOptions& options) {
  const std::string ext = lower_extension(path);
  if (ext == "msh") return write_msh(mesh, path, options);
  if (ext == "vtu") return write_vtu(mesh, path);
  if (ext == "inp")
    return write_inp(mesh, path, options.inp_ties, options.inp_incompatible_hex8,
                     options.inp_reduced_pyramids);
  throw Error("unknown output format '." + ext + "' for '" + path.string() +
              "' (use .msh, .vtu or .inp)");
}

MixedMesh read_mesh(const std::filesystem::path& path) {
  if (!std::filesystem::exists(path)) throw Error("file not found: '" + path.string() + "'");
  const std::string ext = lower_extension(path);
  if (ext == "msh") return read_msh(path);
  throw Error("unknown mesh format '." + ext + "' for '" + path.string() + "' (hexfem reads .msh)");
}

}  // namespace hexfem

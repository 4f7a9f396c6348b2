#include "fem/mode_shapes_vtu.hpp"

#include <charconv>
#include <cmath>
#include <string>

#include "mesher/mesh/atomic_file.hpp"
#include "mesher/mesh/error.hpp"

namespace hexfem {
namespace {

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
// VTK's wedge lists its first triangle with the normal pointing away from the second.
constexpr int kWedgeToVtk[6] = {0, 2, 1, 3, 5, 4};

void put(std::string& s, double v) {
  char buf[32];
  const auto r = std::to_chars(buf, buf + sizeof buf, v);
  s.append(buf, r.ptr);
  s.push_back(' ');
}
void put(std::string& s, long v) {
  char buf[24];
  const auto r = std::to_chars(buf, buf + sizeof buf, v);
  s.append(buf, r.ptr);
  s.push_back(' ');
}
// Shape values need no more than 7 digits; keeps large files small.
void put_short(std::string& s, double v) {
  char buf[32];
  const auto r = std::to_chars(buf, buf + sizeof buf, v, std::chars_format::general, 7);
  s.append(buf, r.ptr);
  s.push_back(' ');
}

void open_array(std::string& s, const char* type, const std::string& name, int comps) {
  s += std::string("<DataArray type=\"") + type + "\" Name=\"" + name + "\" NumberOfComponents=\"" +
       std::to_string(comps) + "\" format=\"ascii\">\n";
}

}  // namespace

void write_mode_shapes_vtu(const MixedMesh& mesh, const ModalResult& result,
                           const std::filesystem::path& path) {
  const long nn = static_cast<long>(mesh.nodes.size());
  const long nc = static_cast<long>(mesh.num_cells());
  const long k = result.modes.cols();
  if (result.modes.rows() != 3 * nn) throw Error("mode shapes do not match the mesh");
  write_atomically(path, false, [&](std::ostream& out) {
    std::string s;
    s += "<?xml version=\"1.0\"?>\n<VTKFile type=\"UnstructuredGrid\" version=\"1.0\" "
         "byte_order=\"LittleEndian\" header_type=\"UInt64\">\n<UnstructuredGrid>\n<FieldData>\n";
    s += "<DataArray type=\"Float64\" Name=\"frequency_hz\" NumberOfTuples=\"" + std::to_string(k) +
         "\" format=\"ascii\">\n";
    for (double f : result.frequencies) put(s, f);
    s += "\n</DataArray>\n</FieldData>\n";
    s += "<Piece NumberOfPoints=\"" + std::to_string(nn) + "\" NumberOfCells=\"" +
         std::to_string(nc) + "\">\n<Points>\n";
    open_array(s, "Float64", "Points", 3);
    for (const Vec3& p : mesh.nodes) {
      for (double x : p) put(s, x);
      s.back() = '\n';
    }
    s += "</DataArray>\n</Points>\n<Cells>\n";
    open_array(s, "Int64", "connectivity", 1);
    for (long c = 0; c < nc; ++c) {
      const CellKind kind = mesh.cell_kind[c];
      for (int i = 0; i < num_nodes(kind); ++i)
        put(s, static_cast<long>(mesh.cell(c)[kind == CellKind::Wedge6 ? kWedgeToVtk[i] : i]));
      s.back() = '\n';
    }
    s += "</DataArray>\n";
    open_array(s, "Int64", "offsets", 1);
    long offset = 0;
    for (long c = 0; c < nc; ++c) put(s, offset += num_nodes(mesh.cell_kind[c]));
    s += "\n</DataArray>\n";
    open_array(s, "UInt8", "types", 1);
    for (long c = 0; c < nc; ++c) put(s, static_cast<long>(vtk_type(mesh.cell_kind[c])));
    s += "\n</DataArray>\n</Cells>\n<CellData>\n";
    open_array(s, "Int32", "kind", 1);
    for (long c = 0; c < nc; ++c) put(s, static_cast<long>(vtk_type(mesh.cell_kind[c])));
    s += "\n</DataArray>\n</CellData>\n<PointData Vectors=\"mode_1\">\n";
    out << s;
    for (long m = 0; m < k; ++m) {
      s.clear();
      double largest = 0;
      for (long v = 0; v < nn; ++v)
        largest = std::max(largest, result.modes.block(3 * v, m, 3, 1).norm());
      const double scale = largest > 0 ? 1.0 / largest : 0.0;
      open_array(s, "Float64", "mode_" + std::to_string(m + 1), 3);
      for (long v = 0; v < nn; ++v) {
        for (int a = 0; a < 3; ++a) put_short(s, result.modes(3 * v + a, m) * scale);
        s.back() = '\n';
      }
      s += "</DataArray>\n";
      out << s;
    }
    out << "</PointData>\n</Piece>\n</UnstructuredGrid>\n</VTKFile>\n";
  });
}

}  // namespace hexfem

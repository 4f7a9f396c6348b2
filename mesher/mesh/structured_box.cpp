#include "mesher/mesh/structured_box.hpp"

#include <algorithm>
#include <array>
#include <string>

#include "mesher/mesh/element_topology.hpp"
#include "mesher/mesh/error.hpp"

namespace hexfem {
namespace {

Vec3 sub(const Vec3& a, const Vec3& b) {
  return {a[0] - b[0], a[1] - b[1], a[2] - b[2]};
}

double det3(const Vec3& a, const Vec3& b, const Vec3& c) {
  return a[0] * (b[1] * c[2] - b[2] * c[1]) - a[1] * (b[0] * c[2] - b[2] * c[0]) +
         a[2] * (b[0] * c[1] - b[1] * c[0]);
}

// Reorders `ids` so that the cell is positively oriented: the edge triple at corner 0 (as
// element_topology lists it) must be right-handed. The generators below build the cells from
// lattice offsets, so this only ever mirrors a cell, never repairs a bad one.
void orient(CellKind kind, std::int32_t* ids, const std::vector<Vec3>& x) {
  const auto c = corners_of(kind).corner[0];
  const Vec3& o = x[ids[c[0]]];
  if (det3(sub(x[ids[c[1]]], o), sub(x[ids[c[2]]], o), sub(x[ids[c[3]]], o)) > 0) return;
  switch (kind) {
    case CellKind::Tet4:
      std::swap(ids[1], ids[2]);
      break;
    case CellKind::Pyramid5:
      std::swap(ids[1], ids[3]);
      break;
    case CellKind::Wedge6:
      std::swap(ids[1], ids[2]);
      std::swap(ids[4], ids[5]);
      break;
    case CellKind::Hex8:
      std::swap(ids[1], ids[3]);
      std::swap(ids[5], ids[7]);
      break;
  }
}

}  // namespace

MixedMesh make_box_mesh(Vec3 lengths, int nx, int ny, int nz, CellKind kind) {
  CubeSpec spec;
  switch (kind) {
    case CellKind::Hex8:
      spec.fill = CubeFill::Hex;
      break;
    case CellKind::Tet4:
      spec.fill = CubeFill::Tets;
      break;
    case CellKind::Wedge6:
      spec.fill = CubeFill::Wedges;
      break;
    case CellKind::Pyramid5:
      spec = {CubeFill::Pyramids, 0b11};
      break;
  }
  return make_box_mesh(lengths, nx, ny, nz, [spec](int, int, int) { return spec; });
}

MixedMesh make_box_mesh(Vec3 lengths, int nx, int ny, int nz,
                        const std::function<CubeSpec(int i, int j, int k)>& spec) {
  if (nx < 1 || ny < 1 || nz < 1)
    throw Error("box mesh: cell counts must be >= 1 (got " + std::to_string(nx) + "x" +
                std::to_string(ny) + "x" + std::to_string(nz) + ")");
  if (!(lengths[0] > 0 && lengths[1] > 0 && lengths[2] > 0))
    throw Error("box mesh: lengths must be positive");

  MixedMesh mesh;
  const int n[3] = {nx, ny, nz};
  const auto lattice = [&](int i, int j, int k) {
    return static_cast<std::int32_t>(i + (nx + 1) * (j + (ny + 1) * k));
  };
  mesh.nodes.reserve(static_cast<std::size_t>(nx + 1) * (ny + 1) * (nz + 1));
  for (int k = 0; k <= nz; ++k)
    for (int j = 0; j <= ny; ++j)
      for (int i = 0; i <= nx; ++i)
        mesh.nodes.push_back({lengths[0] * i / nx, lengths[1] * j / ny, lengths[2] * k / nz});
  const std::size_t num_lattice = mesh.nodes.size();

  // Cube corner c (Gmsh hex order: bottom ccw from +z, then top) as lattice offsets.
  static constexpr int kCorner[8][3] = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0},
                                        {0, 0, 1}, {1, 0, 1}, {1, 1, 1}, {0, 1, 1}};
  // Cube faces -x, +x, -y, +y, -z, +z as corner cycles starting at the lowest corner, with the
  // highest corner third: splitting along (0,2) is the Kuhn diagonal.
  static constexpr int kFace[6][4] = {{0, 3, 7, 4}, {1, 2, 6, 5}, {0, 1, 5, 4},
                                      {3, 2, 6, 7}, {0, 1, 2, 3}, {4, 5, 6, 7}};
  const auto emit = [&](CellKind k, std::initializer_list<std::int32_t> list) {
    std::array<std::int32_t, kMaxCellNodes> ids{};
    std::copy(list.begin(), list.end(), ids.begin());
    orient(k, ids.data(), mesh.nodes);
    mesh.add_cell(k, ids.data());
  };

  for (int k = 0; k < nz; ++k)
    for (int j = 0; j < ny; ++j)
      for (int i = 0; i < nx; ++i) {
        std::int32_t v[8];
        for (int c = 0; c < 8; ++c)
          v[c] = lattice(i + kCorner[c][0], j + kCorner[c][1], k + kCorner[c][2]);
        const CubeSpec cube = spec(i, j, k);
        switch (cube.fill) {
          case CubeFill::Hex:
            emit(CellKind::Hex8, {v[0], v[1], v[2], v[3], v[4], v[5], v[6], v[7]});
            break;
          case CubeFill::Wedges:
            emit(CellKind::Wedge6, {v[0], v[1], v[2], v[4], v[5], v[6]});
            emit(CellKind::Wedge6, {v[0], v[2], v[3], v[4], v[6], v[7]});
            break;
          case CubeFill::Tets: {
            // Kuhn: walk from corner 0 to corner 6 adding one unit axis at a time.
            static constexpr int kPerm[6][3] = {{0, 1, 2}, {0, 2, 1}, {1, 0, 2},
                                                {1, 2, 0}, {2, 0, 1}, {2, 1, 0}};
            for (const auto& p : kPerm) {
              int o[3] = {0, 0, 0};
              std::int32_t path[4];
              path[0] = lattice(i, j, k);
              for (int s = 0; s < 3; ++s) {
                ++o[p[s]];
                path[s + 1] = lattice(i + o[0], j + o[1], k + o[2]);
              }
              emit(CellKind::Tet4, {path[0], path[1], path[2], path[3]});
            }
            break;
          }
          case CubeFill::Pyramids: {
            const auto centre = static_cast<std::int32_t>(mesh.nodes.size());
            const Vec3& a = mesh.nodes[v[0]];
            const Vec3& b = mesh.nodes[v[6]];
            mesh.nodes.push_back({(a[0] + b[0]) / 2, (a[1] + b[1]) / 2, (a[2] + b[2]) / 2});
            for (int f = 0; f < 6; ++f) {
              const std::int32_t q[4] = {v[kFace[f][0]], v[kFace[f][1]], v[kFace[f][2]],
                                         v[kFace[f][3]]};
              if (cube.split_faces & (1u << f)) {
                emit(CellKind::Tet4, {q[0], q[1], q[2], centre});
                emit(CellKind::Tet4, {q[0], q[2], q[3], centre});
              } else {
                emit(CellKind::Pyramid5, {q[0], q[1], q[2], q[3], centre});
              }
            }
            break;
          }
        }
      }

  // Boundary faces: the cells' own faces whose nodes all lie on one side of the box.
  const auto lattice_coord = [&](std::int32_t node, int axis) {
    int idx = node;
    for (int a = 0; a < axis; ++a) idx /= n[a] + 1;
    return idx % (n[axis] + 1);
  };
  for (std::size_t c = 0; c < mesh.num_cells(); ++c) {
    const CellKind ck = mesh.cell_kind[c];
    const std::int32_t* ids = mesh.cell(c);
    const CellFaces faces = faces_of(ck);
    for (int f = 0; f < faces.count; ++f) {
      const LocalFace& lf = faces.face[f];
      bool lattice_only = true;
      for (int q = 0; q < lf.n; ++q)
        lattice_only = lattice_only && static_cast<std::size_t>(ids[lf.v[q]]) < num_lattice;
      if (!lattice_only) continue;
      for (int axis = 0; axis < 3; ++axis)
        for (int side = 0; side < 2; ++side) {
          const int target = side == 0 ? 0 : n[axis];
          bool on = true;
          for (int q = 0; q < lf.n; ++q) on = on && lattice_coord(ids[lf.v[q]], axis) == target;
          if (on)
            mesh.add_bface(ids[lf.v[0]], ids[lf.v[1]], ids[lf.v[2]], lf.n == 4 ? ids[lf.v[3]] : -1,
                           1 + 2 * axis + side);
        }
    }
  }
  return mesh;
}

}  // namespace hexfem

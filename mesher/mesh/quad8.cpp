#include "mesher/mesh/quad8.hpp"

#include <algorithm>
#include <cmath>
#include <unordered_map>

#include "mesher/mesh/element_topology.hpp"

namespace hexfem {

void quad8_shape(double x, double y, double* N, double (*dN)[2]) {
  static constexpr double c[4][2] = {{-1, -1}, {1, -1}, {1, 1}, {-1, 1}};
  for (int i = 0; i < 4; ++i) {
    const double a = c[i][0], b = c[i][1], fx = 1 + a * x, fy = 1 + b * y, s = a * x + b * y - 1;
    N[i] = fx * fy * s / 4;
    dN[i][0] = (a * fy * s + fx * fy * a) / 4;
    dN[i][1] = (fx * b * s + fx * fy * b) / 4;
  }
  for (int e = 0; e < 4; ++e) {
    const double a = (c[e][0] + c[(e + 1) % 4][0]) / 2, b = (c[e][1] + c[(e + 1) % 4][1]) / 2;
    if (a == 0) {  // edge along x at y = b
      N[4 + e] = (1 - x * x) * (1 + b * y) / 2;
      dN[4 + e][0] = -x * (1 + b * y);
      dN[4 + e][1] = (1 - x * x) * b / 2;
    } else {  // edge along y at x = a
      N[4 + e] = (1 - y * y) * (1 + a * x) / 2;
      dN[4 + e][0] = (1 - y * y) * a / 2;
      dN[4 + e][1] = -y * (1 + a * x);
    }
  }
}

Quad8Nearest quad8_nearest(const MixedMesh& mesh, const std::int32_t* nodes, const Vec3& p) {
  Quad8Nearest q;
  double N[8], dN[8][2];
  for (int it = 0; it < 20; ++it) {
    quad8_shape(q.x, q.y, N, dN);
    double r[3] = {-p[0], -p[1], -p[2]}, J[3][2] = {};
    for (int i = 0; i < 8; ++i)
      for (int a = 0; a < 3; ++a) {
        r[a] += N[i] * mesh.nodes[nodes[i]][a];
        J[a][0] += dN[i][0] * mesh.nodes[nodes[i]][a];
        J[a][1] += dN[i][1] * mesh.nodes[nodes[i]][a];
      }
    double A[2][2] = {}, g[2] = {};
    for (int a = 0; a < 3; ++a)
      for (int u = 0; u < 2; ++u) {
        g[u] += J[a][u] * r[a];
        for (int v = 0; v < 2; ++v) A[u][v] += J[a][u] * J[a][v];
      }
    const double det = A[0][0] * A[1][1] - A[0][1] * A[1][0];
    if (!(det > 0)) break;
    const double dx = (A[1][1] * g[0] - A[0][1] * g[1]) / det;
    const double dy = (A[0][0] * g[1] - A[1][0] * g[0]) / det;
    q.x = std::clamp(q.x - dx, -1.0, 1.0);
    q.y = std::clamp(q.y - dy, -1.0, 1.0);
    if (std::abs(dx) + std::abs(dy) < 1e-14) break;
  }
  quad8_shape(q.x, q.y, q.w, dN);
  double dist = 0, size = 0;
  for (int a = 0; a < 3; ++a) {
    double xa = 0;
    for (int i = 0; i < 8; ++i) xa += q.w[i] * mesh.nodes[nodes[i]][a];
    q.at[a] = xa;
    dist += (xa - p[a]) * (xa - p[a]);
    const double d = mesh.nodes[nodes[2]][a] - mesh.nodes[nodes[0]][a];
    size += d * d;
  }
  q.distance = std::sqrt(dist);
  q.size = std::sqrt(size);
  return q;
}

std::vector<NcQuad8> nc_quad8_faces(const MixedMesh& mesh) {
  std::vector<NcQuad8> out;
  if (mesh.order != 2 || mesh.nc_cell.empty()) return out;
  const auto key = [](std::int32_t a, std::int32_t b) {
    if (a > b) std::swap(a, b);
    return (static_cast<std::uint64_t>(static_cast<std::uint32_t>(a)) << 32) |
           static_cast<std::uint32_t>(b);
  };
  std::unordered_map<std::uint64_t, std::int32_t> mid;  // every edge's mid-edge node
  mid.reserve(2 * mesh.num_cells());
  for (std::size_t c = 0; c < mesh.num_cells(); ++c) {
    const CellKind k = mesh.cell_kind[c];
    const std::int32_t* v = mesh.cell(c);
    const std::int32_t* e = mesh.cell_edges(c);
    for (int i = 0; i < num_edges(k); ++i)
      mid.emplace(key(v[edges_of(k)[i][0]], v[edges_of(k)[i][1]]), e[i]);
  }
  const auto find = [&](std::int32_t a, std::int32_t b) {
    const auto it = mid.find(key(a, b));
    return it == mid.end() ? -1 : it->second;
  };
  for (std::size_t f = 0; f < mesh.nc_cell.size(); ++f) {
    const std::size_t c = static_cast<std::size_t>(mesh.nc_cell[f]);
    const LocalFace& lf = faces_of(mesh.cell_kind[c]).face[mesh.nc_local_face[f]];
    if (lf.n != 4) continue;
    NcQuad8 q;
    for (int i = 0; i < 4; ++i) q.nodes[i] = mesh.cell(c)[lf.v[i]];
    bool ok = true;
    for (int i = 0; i < 4; ++i)
      ok = ok && (q.nodes[4 + i] = find(q.nodes[i], q.nodes[(i + 1) % 4])) >= 0;
    if (!ok) continue;
    for (int d = 0; d < 2; ++d) q.diagonal[d] = find(q.nodes[d], q.nodes[d + 2]);
    out.push_back(q);
  }
  return out;
}

}  // namespace hexfem

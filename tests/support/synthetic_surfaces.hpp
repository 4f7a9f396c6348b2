// Surface meshes built without CAD, for testing the volume mesher on known shapes: a box with a
// structured right-triangle grid (frames = axes) and a cylinder (lateral grid + ring-triangulated
// disks, frames radial / tangential / axial). Shared by tests/volume and validation/bench_volume.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <numbers>
#include <vector>

#include "mesher/surface_mesh.hpp"

namespace hexfem::synthetic {

inline Vec3 sub3(const Vec3& a, const Vec3& b) {
  return {a[0] - b[0], a[1] - b[1], a[2] - b[2]};
}
inline Vec3 cross3(const Vec3& a, const Vec3& b) {
  return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
}
inline double dot3(const Vec3& a, const Vec3& b) {
  return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

// Appends triangle (a,b,c) to `s`, flipped if needed so that its normal points along `out`.
inline void add_oriented(SurfaceMesh& s, int a, int b, int c, const Vec3& out, int cad_face) {
  const auto& x = s.mesh.nodes;
  const Vec3 n = cross3(sub3(x[b], x[a]), sub3(x[c], x[a]));
  if (dot3(n, out) < 0) std::swap(b, c);
  s.mesh.add_bface(a, b, c, -1, cad_face);
}

// Box [0,L0]x[0,L1]x[0,L2] with n[d] lattice steps per axis; every grid square is split into two
// right triangles (diagonal alternating when `alternate`). CAD faces 1..6 = x0, x1, y0, y1, z0, z1.
inline SurfaceMesh box_surface(Vec3 L, std::array<int, 3> n, bool alternate = true) {
  SurfaceMesh s;
  std::map<std::array<int, 3>, int> id;  // lattice index -> node
  auto node = [&](std::array<int, 3> ijk) {
    auto it = id.find(ijk);
    if (it != id.end()) return it->second;
    const int v = static_cast<int>(s.mesh.nodes.size());
    Vec3 p;
    int extremes = 0;
    for (int d = 0; d < 3; ++d) {
      p[d] = L[d] * ijk[d] / n[d];
      extremes += (ijk[d] == 0 || ijk[d] == n[d]);
    }
    s.mesh.nodes.push_back(p);
    int nd = 0;  // the first axis on which the node is extreme gives the normal
    while (ijk[nd] != 0 && ijk[nd] != n[nd]) ++nd;
    Vec3 normal{0, 0, 0};
    normal[nd] = ijk[nd] == 0 ? -1 : 1;
    Vec3 d1{0, 0, 0}, d2{0, 0, 0};
    d1[(nd + 1) % 3] = 1;
    d2[(nd + 2) % 3] = 1;
    s.frame.push_back({d1, d2, normal});
    s.size.push_back(L[0] / n[0]);
    s.on_edge.push_back(extremes >= 2);
    id.emplace(ijk, v);
    return v;
  };
  for (int axis = 0; axis < 3; ++axis) {
    const int u = (axis + 1) % 3, w = (axis + 2) % 3;
    for (int side = 0; side < 2; ++side) {
      const int cad = 1 + 2 * axis + side;
      Vec3 out{0, 0, 0};
      out[axis] = side ? 1 : -1;
      for (int i = 0; i < n[u]; ++i) {
        for (int j = 0; j < n[w]; ++j) {
          auto at = [&](int di, int dj) {
            std::array<int, 3> ijk{};
            ijk[axis] = side ? n[axis] : 0;
            ijk[u] = i + di;
            ijk[w] = j + dj;
            return node(ijk);
          };
          const int a = at(0, 0), b = at(1, 0), c = at(1, 1), d = at(0, 1);
          if (!alternate || (i + j) % 2 == 0) {
            add_oriented(s, a, b, c, out, cad);
            add_oriented(s, a, c, d, out, cad);
          } else {
            add_oriented(s, a, b, d, out, cad);
            add_oriented(s, b, c, d, out, cad);
          }
        }
      }
    }
  }
  s.faces_of_solid = {{}, {1, 2, 3, 4, 5, 6}};
  return s;
}

// Cylinder of radius R and height H around the z axis, target size h. CAD faces: 1 lateral,
// 2 bottom (z=0), 3 top (z=H). Lateral nodes on a (theta, z) grid; disks by concentric rings.
inline SurfaceMesh cylinder_surface(double R, double H, double h) {
  SurfaceMesh s;
  const double pi = std::numbers::pi;
  const int nt = std::max(8, static_cast<int>(std::lround(2 * pi * R / h)));
  const int nz = std::max(1, static_cast<int>(std::lround(H / h)));
  const int nr = std::max(1, static_cast<int>(std::lround(R / h)));
  auto add_node = [&](Vec3 p, std::array<Vec3, 3> f, bool edge) {
    s.mesh.nodes.push_back(p);
    s.frame.push_back(f);
    s.size.push_back(h);
    s.on_edge.push_back(edge);
    return static_cast<int>(s.mesh.nodes.size()) - 1;
  };
  // Lateral grid: node (i, j) at angle 2 pi i / nt, height H j / nz.
  std::vector<int> lat((nz + 1) * nt);
  for (int j = 0; j <= nz; ++j) {
    for (int i = 0; i < nt; ++i) {
      const double t = 2 * pi * i / nt;
      const Vec3 radial{std::cos(t), std::sin(t), 0}, tang{-std::sin(t), std::cos(t), 0};
      lat[j * nt + i] = add_node({R * radial[0], R * radial[1], H * j / nz},
                                 {tang, Vec3{0, 0, 1}, radial}, j == 0 || j == nz);
    }
  }
  for (int j = 0; j < nz; ++j) {
    for (int i = 0; i < nt; ++i) {
      const int i1 = (i + 1) % nt;
      const int a = lat[j * nt + i], b = lat[j * nt + i1], c = lat[(j + 1) * nt + i1],
                d = lat[(j + 1) * nt + i];
      const double t = 2 * pi * (i + 0.5) / nt;
      const Vec3 out{std::cos(t), std::sin(t), 0};
      add_oriented(s, a, b, c, out, 1);
      add_oriented(s, a, c, d, out, 1);
    }
  }
  // Disks: ring m (1..nr) at radius R m / nr; ring nr is the lateral boundary circle.
  for (int side = 0; side < 2; ++side) {
    const double z = side ? H : 0;
    const Vec3 normal{0, 0, side ? 1.0 : -1.0};
    const int cad = 2 + side;
    std::vector<std::vector<int>> ring(nr + 1);
    std::vector<std::vector<double>> angle(nr + 1);
    ring[0] = {add_node({0, 0, z}, {Vec3{1, 0, 0}, Vec3{0, 1, 0}, normal}, false)};
    angle[0] = {0};
    for (int m = 1; m <= nr; ++m) {
      const int count =
          m == nr ? nt : std::max(6, static_cast<int>(std::lround(2 * pi * R * m / nr / h)));
      const double shift = m == nr ? 0.0 : 0.5 * (m % 2);
      for (int i = 0; i < count; ++i) {
        const double t = 2 * pi * (i + shift) / count;
        angle[m].push_back(t);
        if (m == nr) {
          ring[m].push_back(lat[(side ? nz : 0) * nt + i]);
          continue;
        }
        const Vec3 radial{std::cos(t), std::sin(t), 0}, tang{-std::sin(t), std::cos(t), 0};
        const double r = R * m / nr;
        ring[m].push_back(
            add_node({r * radial[0], r * radial[1], z}, {radial, tang, normal}, false));
      }
    }
    for (int i = 0; i < static_cast<int>(ring[1].size()); ++i) {
      const int n1 = static_cast<int>(ring[1].size());
      add_oriented(s, ring[0][0], ring[1][i], ring[1][(i + 1) % n1], normal, cad);
    }
    // Zip rings m-1 and m together, always advancing the one whose next node comes first.
    for (int m = 2; m <= nr; ++m) {
      const auto &in = ring[m - 1], &outr = ring[m];
      const int ni = static_cast<int>(in.size()), no = static_cast<int>(outr.size());
      auto ang = [&](int mm, int k) {
        const int cnt = static_cast<int>(angle[mm].size());
        return angle[mm][k % cnt] + 2 * pi * (k / cnt);
      };
      int a = 0, b = 0;
      // Start both rings at angles near zero (ring m-1 may be shifted by half a step).
      while (a < ni + 0 && b < no + 0) {
        if (a == ni && b == no) break;
        const double na = ang(m - 1, a + 1), nb = ang(m, b + 1);
        if (nb <= na) {
          add_oriented(s, in[a % ni], outr[b % no], outr[(b + 1) % no], normal, cad);
          ++b;
        } else {
          add_oriented(s, in[a % ni], outr[b % no], in[(a + 1) % ni], normal, cad);
          ++a;
        }
      }
      while (a < ni) {
        add_oriented(s, in[a % ni], outr[b % no], in[(a + 1) % ni], normal, cad);
        ++a;
      }
      while (b < no) {
        add_oriented(s, in[a % ni], outr[b % no], outr[(b + 1) % no], normal, cad);
        ++b;
      }
    }
  }
  s.faces_of_solid = {{}, {1, 2, 3}};
  return s;
}

}  // namespace hexfem::synthetic

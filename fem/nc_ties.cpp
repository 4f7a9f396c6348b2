#include "fem/nc_ties.hpp"

#include <algorithm>
#include <cmath>

#include "mesher/mesh/element_topology.hpp"
#include "mesher/mesh/quad8.hpp"

namespace hexfem {

namespace {

// The quad8 face's reference point nearest to p (Gauss-Newton from the centre): the hanging
// node's displacement is the face's trace there, so a linear field stays linear across it. On
// a parallelogram that is the centre (weights -1/4, 1/2); on a distorted quad it is not.
// Returns false when p is not on the face (farther than 1e-6 of its size, or outside).
bool face_weights(const MixedMesh& mesh, const std::int32_t* nodes, const Vec3& p, double* w) {
  const Quad8Nearest q = quad8_nearest(mesh, nodes, p);
  std::copy(q.w, q.w + 8, w);
  return std::abs(q.x) < 0.999 && std::abs(q.y) < 0.999 && q.distance <= 1e-6 * q.size;
}

}  // namespace

NodeTies nc_face_ties(const MixedMesh& mesh, const std::vector<std::uint8_t>& fixed) {
  NodeTies t;
  if (mesh.order != 2 || mesh.nc_cell.empty()) return t;
  t.slot.assign(mesh.nodes.size(), -1);
  std::vector<std::int32_t> candidates;
  for (const NcQuad8& q : nc_quad8_faces(mesh)) {
    for (const std::int32_t h : q.diagonal) {
      if (h < 0 || t.slot[h] >= 0) continue;
      bool is_fixed = false;
      for (int a = 0; a < 3 && !fixed.empty(); ++a) is_fixed = is_fixed || fixed[3 * h + a];
      if (is_fixed) {
        ++t.refused;
        continue;
      }
      double w[8];
      if (!face_weights(mesh, q.nodes.data(), mesh.nodes[h], w)) {
        ++t.refused;
        continue;
      }
      t.slot[h] = static_cast<std::int32_t>(t.count++);
      candidates.push_back(h);
      for (int i = 0; i < 8; ++i) {
        t.master.push_back(q.nodes[i]);
        t.weight.push_back(w[i]);
      }
    }
  }
  // A master tied itself (two NC faces sharing an edge as diagonal and side): left free.
  for (std::int32_t h : candidates) {
    const std::int32_t s = t.slot[h];
    bool nested = false;
    for (int i = 0; i < kTieMasters; ++i) nested = nested || t.tied(t.master[kTieMasters * s + i]);
    if (nested) {
      for (int i = 0; i < kTieMasters; ++i) t.weight[kTieMasters * s + i] = 0;
      t.slot[h] = -1;
      ++t.refused;
    }
  }
  long live = 0;
  for (std::int32_t v : t.slot) live += v >= 0;
  t.count = live;
  if (live == 0) t.slot.clear();
  return t;
}

std::vector<NodeTie> node_tie_list(const NodeTies& ties) {
  std::vector<NodeTie> out;
  for (std::size_t v = 0; v < ties.slot.size(); ++v) {
    const std::int32_t s = ties.slot[v];
    if (s < 0) continue;
    NodeTie& t = out.emplace_back();
    t.node = static_cast<std::int32_t>(v);
    for (int j = 0; j < kTieMasters; ++j)
      t.masters.emplace_back(ties.master[kTieMasters * s + j], ties.weight[kTieMasters * s + j]);
  }
  return out;
}

int tied_element_nodes(const NodeTies& ties, const std::int32_t* ids, int n, std::int32_t* out,
                       double* C) {
  if (ties.slot.empty()) return -1;
  bool any = false;
  for (int i = 0; i < n && !any; ++i) any = ties.tied(ids[i]);
  if (!any) return -1;
  int k = 0;
  const auto index = [&](std::int32_t v) {
    for (int j = 0; j < k; ++j)
      if (out[j] == v) return j;
    out[k] = v;
    return k++;
  };
  // Columns first (the untied nodes keep their order), then C.
  int col[kMaxElementNodes];
  for (int i = 0; i < n; ++i) col[i] = ties.tied(ids[i]) ? -1 : index(ids[i]);
  int mcol[kMaxElementNodes][kTieMasters];
  for (int i = 0; i < n; ++i)
    if (col[i] < 0) {
      const std::int32_t s = ties.slot[ids[i]];
      for (int j = 0; j < kTieMasters; ++j) mcol[i][j] = index(ties.master[kTieMasters * s + j]);
    }
  std::fill(C, C + n * k, 0.0);
  for (int i = 0; i < n; ++i) {
    if (col[i] >= 0) {
      C[i * k + col[i]] = 1;
      continue;
    }
    const std::int32_t s = ties.slot[ids[i]];
    for (int j = 0; j < kTieMasters; ++j) C[i * k + mcol[i][j]] += ties.weight[kTieMasters * s + j];
  }
  return k;
}

void tie_element_matrices(const double* C, int n, int k, const double* K, const double* m,
                          double* K_out, double* m_out) {
  const int nd = 3 * n, kd = 3 * k;
  // m' = Cᵀ m C, via T = m C (n x k).
  std::vector<double> T(static_cast<std::size_t>(n) * k, 0.0);
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j)
      if (const double v = m[i * n + j])
        for (int q = 0; q < k; ++q) T[i * k + q] += v * C[j * k + q];
  std::fill(m_out, m_out + k * k, 0.0);
  for (int i = 0; i < n; ++i)
    for (int p = 0; p < k; ++p)
      if (const double c = C[i * k + p])
        for (int q = 0; q < k; ++q) m_out[p * k + q] += c * T[i * k + q];
  // K' = (C ⊗ I)ᵀ K (C ⊗ I), per component pair (a, b), via U = K (C ⊗ I) (nd x kd).
  std::vector<double> U(static_cast<std::size_t>(nd) * kd, 0.0);
  for (int r = 0; r < nd; ++r)
    for (int j = 0; j < n; ++j)
      for (int b = 0; b < 3; ++b)
        if (const double v = K[r * nd + 3 * j + b])
          for (int q = 0; q < k; ++q) U[r * kd + 3 * q + b] += v * C[j * k + q];
  std::fill(K_out, K_out + kd * kd, 0.0);
  for (int i = 0; i < n; ++i)
    for (int a = 0; a < 3; ++a)
      for (int p = 0; p < k; ++p)
        if (const double c = C[i * k + p])
          for (int s = 0; s < kd; ++s) K_out[(3 * p + a) * kd + s] += c * U[(3 * i + a) * kd + s];
}

void fill_tied_nodes(const NodeTies& ties, double* u) {
  for (std::size_t v = 0; v < ties.slot.size(); ++v) {
    const std::int32_t s = ties.slot[v];
    if (s < 0) continue;
    for (int a = 0; a < 3; ++a) {
      double sum = 0;
      for (int j = 0; j < kTieMasters; ++j)
        sum += ties.weight[kTieMasters * s + j] * u[3 * ties.master[kTieMasters * s + j] + a];
      u[3 * v + a] = sum;
    }
  }
}

}  // namespace hexfem

#include "fem/assembly.hpp"

#include <algorithm>
#include <atomic>
#include <limits>
#include <string>

#include "fem/element.hpp"
#include "fem/hex8_incompatible.hpp"
#include "mesher/mesh/error.hpp"

namespace hexfem {

namespace {

// The nodes carrying cell c's DOFs (its own, tied ones replaced by their masters) into `out`
// (kMaxTiedElementNodes slots); C, if given, receives the tie matrix when some node is tied.
int dof_nodes(const MixedMesh& mesh, const NodeTies* ties, long c, std::int32_t* out,
              double* C = nullptr, bool* tied = nullptr) {
  std::int32_t ids[kMaxElementNodes] = {};
  const int n = mesh.element_nodes(c, ids);
  double scratch[kMaxElementNodes * kMaxTiedElementNodes];
  const int k = ties ? tied_element_nodes(*ties, ids, n, out, C ? C : scratch) : -1;
  if (tied) *tied = k >= 0;
  if (k >= 0) return k;
  std::copy(ids, ids + n, out);
  return n;
}

}  // namespace

NodeGraph node_graph(const MixedMesh& mesh, const NodeTies* ties) {
  const long nn = static_cast<long>(mesh.nodes.size());
  const long nc = static_cast<long>(mesh.num_cells());
  // Node -> cells, CSR (every node of the element: the mid-edge nodes too at order 2).
  std::vector<long> cptr(nn + 1, 0);
  std::int32_t ids[kMaxTiedElementNodes];
  for (long c = 0; c < nc; ++c)
    for (int k = 0, n = dof_nodes(mesh, ties, c, ids); k < n; ++k) ++cptr[ids[k] + 1];
  for (long i = 0; i < nn; ++i) cptr[i + 1] += cptr[i];
  std::vector<std::int32_t> cells(cptr[nn]);
  {
    std::vector<long> fill(cptr.begin(), cptr.end() - 1);
    for (long c = 0; c < nc; ++c)
      for (int k = 0, n = dof_nodes(mesh, ties, c, ids); k < n; ++k)
        cells[fill[ids[k]]++] = static_cast<std::int32_t>(c);
  }
  std::vector<std::vector<std::int32_t>> lists(nn);
#pragma omp parallel for schedule(dynamic, 1024)
  for (long i = 0; i < nn; ++i) {
    auto& l = lists[i];
    std::int32_t en[kMaxTiedElementNodes];
    for (long p = cptr[i]; p < cptr[i + 1]; ++p)
      for (int k = 0, n = dof_nodes(mesh, ties, cells[p], en); k < n; ++k)
        if (en[k] != i) l.push_back(en[k]);
    std::sort(l.begin(), l.end());
    l.erase(std::unique(l.begin(), l.end()), l.end());
  }
  NodeGraph g;
  g.ptr.assign(nn + 1, 0);
  for (long i = 0; i < nn; ++i) g.ptr[i + 1] = g.ptr[i] + static_cast<long>(lists[i].size());
  g.adj.reserve(g.ptr[nn]);
  for (auto& l : lists) {
    g.adj.insert(g.adj.end(), l.begin(), l.end());
    std::vector<std::int32_t>().swap(l);
  }
  return g;
}

namespace {

// The common pattern of the lower triangles: column (v,a) holds (v,b>=a) first, then the free
// DOFs of the neighbours ranked after v, ascending.
void build_pattern(const MixedMesh& mesh, const DofMap& dofs, SparseMatrix& K) {
  const NodeGraph g = node_graph(mesh, &dofs.ties);
  const long nn = static_cast<long>(mesh.nodes.size());
  const long n = dofs.num_free;
  std::vector<long> colptr(n + 1, 0);
  const auto later = [&](long v, std::int32_t m) { return dofs.node_rank[m] > dofs.node_rank[v]; };
  for (long v = 0; v < nn; ++v) {
    long others = 0;
    for (long p = g.ptr[v]; p < g.ptr[v + 1]; ++p)
      if (later(v, g.adj[p]))
        for (int b = 0; b < 3; ++b) others += dofs.dof[3 * g.adj[p] + b] >= 0;
    for (int a = 0; a < 3; ++a) {
      const std::int32_t col = dofs.dof[3 * v + a];
      if (col < 0) continue;
      long self = 0;
      for (int b = a; b < 3; ++b) self += dofs.dof[3 * v + b] >= 0;
      colptr[col + 1] = self + others;
    }
  }
  for (long c = 0; c < n; ++c) colptr[c + 1] += colptr[c];
  K.resize(n, n);
  K.resizeNonZeros(colptr[n]);
  std::copy(colptr.begin(), colptr.end(), K.outerIndexPtr());
  long* rows = K.innerIndexPtr();
#pragma omp parallel for schedule(dynamic, 1024)
  for (long v = 0; v < nn; ++v)
    for (int a = 0; a < 3; ++a) {
      const std::int32_t col = dofs.dof[3 * v + a];
      if (col < 0) continue;
      long pos = colptr[col];
      for (int b = a; b < 3; ++b)
        if (dofs.dof[3 * v + b] >= 0) rows[pos++] = dofs.dof[3 * v + b];
      const long first_other = pos;
      for (long p = g.ptr[v]; p < g.ptr[v + 1]; ++p)
        if (later(v, g.adj[p]))
          for (int b = 0; b < 3; ++b)
            if (dofs.dof[3 * g.adj[p] + b] >= 0) rows[pos++] = dofs.dof[3 * g.adj[p] + b];
      std::sort(rows + first_other, rows + pos);
    }
  std::fill(K.valuePtr(), K.valuePtr() + colptr[n], 0.0);
}

inline void atomic_add(double& target, double value) {
#pragma omp atomic
  target += value;
}

}  // namespace

std::vector<const Material*> cell_materials(const MixedMesh& mesh, const SolidMaterials& mats) {
  if (mesh.cell_solid.size() != mesh.num_cells())
    return std::vector<const Material*>(mesh.num_cells(), &mats.base);
  const std::int32_t max_solid =
      mesh.cell_solid.empty() ? 0
                              : *std::max_element(mesh.cell_solid.begin(), mesh.cell_solid.end());
  const std::vector<const Material*> table = mats.table(max_solid);
  std::vector<const Material*> out(mesh.num_cells());
  for (std::size_t c = 0; c < out.size(); ++c)
    out[c] =
        mesh.cell_solid[c] >= 0 ? table[static_cast<std::size_t>(mesh.cell_solid[c])] : &mats.base;
  return out;
}

SystemMatrices assemble_system(const MixedMesh& mesh, const SolidMaterials& mats,
                               const DofMap& dofs, double length_scale, bool incompatible_hex) {
  validate(mats);
  const std::vector<const Material*> cell_mat = cell_materials(mesh, mats);
  if (dofs.dof.size() != 3 * mesh.nodes.size())
    throw Error("assemble_system: DOF map does not match the mesh");
  SystemMatrices sys;
  build_pattern(mesh, dofs, sys.K);
  sys.M = sys.K;  // same pattern, zero values
  const long* colptr = sys.K.outerIndexPtr();
  const long* rows = sys.K.innerIndexPtr();
  double* kv = sys.K.valuePtr();
  double* mv = sys.M.valuePtr();

  const long nc = static_cast<long>(mesh.num_cells());
  std::atomic<long> bad_cell{std::numeric_limits<long>::max()};
  double mass = 0, volume = 0;
#pragma omp parallel reduction(+ : mass, volume)
  {
    constexpr int kMaxDofs = 3 * kMaxElementNodes, kMaxTiedDofs = 3 * kMaxTiedElementNodes;
    std::vector<double> Kbuf(kMaxDofs * kMaxDofs), mbuf(kMaxElementNodes * kMaxElementNodes);
    std::vector<double> Kt(kMaxTiedDofs * kMaxTiedDofs),
        mt(kMaxTiedElementNodes * kMaxTiedElementNodes), C(kMaxElementNodes * kMaxTiedElementNodes);
    Vec3 x[kMaxElementNodes];
    std::int32_t ids[kMaxTiedElementNodes];
#pragma omp for schedule(dynamic, 256)
    for (long c = 0; c < nc; ++c) {
      const CellKind kind = mesh.cell_kind[c];
      const ReferenceElement& ref = reference_element(kind, mesh.order);
      const Material& mat = *cell_mat[c];
      int n = ref.n, nd = 3 * n;
      double *Ke = Kbuf.data(), *me = mbuf.data();
      mesh.element_nodes(c, ids);
      for (int i = 0; i < n; ++i)
        for (int d = 0; d < 3; ++d) x[i][d] = mesh.nodes[ids[i]][d] * length_scale;
      // Incompatible modes enrich the trilinear hex only; hex20 needs none.
      const bool bad = !(element_matrices(ref, x, mat, Ke, me) > 0) ||
                       (incompatible_hex && kind == CellKind::Hex8 && mesh.order == 1 &&
                        !(hex8_incompatible_stiffness(x, mat, Ke) > 0));
      if (bad) {
        long expected = bad_cell.load();
        while (c < expected && !bad_cell.compare_exchange_weak(expected, c)) {
        }
        continue;
      }
      double cell_mass = 0;
      for (int i = 0; i < n * n; ++i) cell_mass += me[i];
      mass += cell_mass;
      volume += cell_mass / mat.rho;
      bool tied = false;
      const int k = dof_nodes(mesh, &dofs.ties, c, ids, C.data(), &tied);
      if (tied) {  // a hanging node of an NC face: the matrices move onto its masters
        tie_element_matrices(C.data(), n, k, Ke, me, Kt.data(), mt.data());
        Ke = Kt.data();
        me = mt.data();
        n = k;
        nd = 3 * k;
      }
      for (int p = 0; p < n; ++p) {
        const std::int32_t np = ids[p];
        for (int q = 0; q < n; ++q) {
          const std::int32_t nq = ids[q];
          if (dofs.node_rank[nq] < dofs.node_rank[np]) continue;
          // First free DOF of nq; the free DOFs of a node are consecutive rows of a column.
          int b0 = 0;
          while (b0 < 3 && dofs.dof[3 * nq + b0] < 0) ++b0;
          if (b0 == 3) continue;
          for (int a = 0; a < 3; ++a) {
            const std::int32_t col = dofs.dof[3 * np + a];
            if (col < 0) continue;
            long pos;
            int bstart;
            if (nq == np) {  // self block: rows (np, b >= a) open the column
              pos = colptr[col];
              bstart = a;
            } else {
              pos = std::lower_bound(rows + colptr[col], rows + colptr[col + 1],
                                     static_cast<long>(dofs.dof[3 * nq + b0])) -
                    rows;
              bstart = b0;
            }
            for (int b = bstart; b < 3; ++b) {
              if (dofs.dof[3 * nq + b] < 0) continue;
              atomic_add(kv[pos], Ke[(3 * q + b) * nd + 3 * p + a]);
              if (a == b) atomic_add(mv[pos], me[q * n + p]);
              ++pos;
            }
          }
        }
      }
    }
  }
  if (bad_cell.load() != std::numeric_limits<long>::max()) {
    const long c = bad_cell.load();
    throw Error("cell " + std::to_string(c + 1) + " (" + kind_name(mesh.cell_kind[c], mesh.order) +
                ") has a non-positive Jacobian determinant: it is inverted or degenerate");
  }
  sys.mass = mass;
  sys.volume = volume;
  return sys;
}

}  // namespace hexfem

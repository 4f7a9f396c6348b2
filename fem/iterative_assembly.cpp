#include "fem/iterative_assembly.hpp"

#include <algorithm>
#include <cmath>
#include <string>

#include "fem/assembly.hpp"
#include "fem/block_csr.hpp"
#include "fem/element.hpp"
#include "fem/hex8_incompatible.hpp"
#include "fem/petsc_env.hpp"
#include "mesher/mesh/error.hpp"

namespace hexfem {
namespace {

constexpr int kMaxDofs = 3 * kMaxElementNodes;

std::uint64_t spread_bits(std::uint64_t v) {  // 21 bits -> every third bit of 63
  v &= 0x1fffff;
  v = (v | v << 32) & 0x1f00000000ffffULL;
  v = (v | v << 16) & 0x1f0000ff0000ffULL;
  v = (v | v << 8) & 0x100f00f00f00f00fULL;
  v = (v | v << 4) & 0x10c30c30c30c30c3ULL;
  v = (v | v << 2) & 0x1249249249249249ULL;
  return v;
}

// A cell is assembled by the rank owning its first-ordered node; cells without equations
// (every node clamped) only add their mass, on rank c % size.
int cell_owner(const MixedMesh& mesh, const DofLayout& L, long c, int size) {
  long first = -1;
  std::int32_t ids[kMaxElementNodes];
  const int n = mesh.element_nodes(c, ids);
  for (int k = 0; k < n; ++k)
    if (const long p = L.pos[ids[k]]; p >= 0 && (first < 0 || p < first)) first = p;
  return first < 0 ? static_cast<int>(c % size) : L.owner(first);
}

Mat create_matrix(MatType type, long local_rows) {
  Mat A;
  HEXFEM_PETSC(MatCreate(PETSC_COMM_WORLD, &A));
  HEXFEM_PETSC(MatSetSizes(A, 3 * local_rows, 3 * local_rows, PETSC_DETERMINE, PETSC_DETERMINE));
  HEXFEM_PETSC(MatSetType(A, type));
  HEXFEM_PETSC(MatSetBlockSize(A, 3));
  return A;
}

// PETSc's K (full rows) and M (upper rows), preallocated for exactly the owned rows' patterns.
void create_matrices(const BlockCsr& Kb, const BlockCsr& Mb, const DofLayout& L, Matrices& mats) {
  std::vector<PetscInt> d, o, du, ou;
  count_blocks(Kb, L, d, o);
  count_blocks(Mb, L, du, ou);
  mats.K = create_matrix(MATAIJ, L.end - L.begin);
  mats.M = create_matrix(MATSBAIJ, L.end - L.begin);
  HEXFEM_PETSC(MatXAIJSetPreallocation(mats.K, 3, d.data(), o.data(), nullptr, nullptr));
  HEXFEM_PETSC(MatXAIJSetPreallocation(mats.M, 3, d.data(), o.data(), du.data(), ou.data()));
  HEXFEM_PETSC(MatSetOption(mats.M, MAT_IGNORE_LOWER_TRIANGULAR, PETSC_TRUE));
}

// The element's rows of nodes another rank owns go to that rank through PETSc's stash (within
// its pattern: the node graph is global); idx: the nodes' positions.
void add_off_rank_rows(const DofLayout& L, int n, const PetscInt* idx, const double* Ke,
                       const double* Me, Matrices& mats) {
  const int nd = 3 * n;
  for (int i = 0; i < n; ++i) {
    if (idx[i] < 0 || (idx[i] >= L.begin && idx[i] < L.end)) continue;
    HEXFEM_PETSC(MatSetValuesBlocked(mats.K, 1, &idx[i], n, idx, Ke + 3 * i * nd, ADD_VALUES));
    HEXFEM_PETSC(MatSetValuesBlocked(mats.M, 1, &idx[i], n, idx, Me + 3 * i * nd, ADD_VALUES));
  }
}

}  // namespace

// Nodes of any element (corners and, at order 2, mid-edge nodes).
std::vector<std::uint8_t> element_node_mask(const MixedMesh& mesh) {
  std::vector<std::uint8_t> used(mesh.nodes.size(), 0);
  for (std::int32_t v : mesh.cell_nodes)
    if (v >= 0) used[v] = 1;
  for (std::int32_t v : mesh.cell_edge_nodes)
    if (v >= 0) used[v] = 1;
  return used;
}

// The nodes that carry equations (used by a cell, not fixed in all three components) in a
// Morton (Z-curve) order of their coordinates: neighbours stay close in memory, and cutting the
// order into contiguous ranges gives compact per-rank parts.
// Nodes tied to others (order-2 NC faces, fem/nc_ties.hpp) carry no equation either.
DofLayout make_layout(const MixedMesh& mesh, const std::vector<std::uint8_t>& fixed,
                      const NodeTies& ties, int rank, int size) {
  const long nn = static_cast<long>(mesh.nodes.size());
  const std::vector<std::uint8_t> used = element_node_mask(mesh);
  Vec3 lo{1e300, 1e300, 1e300}, hi{-1e300, -1e300, -1e300};
  for (long v = 0; v < nn; ++v)
    if (used[v])
      for (int d = 0; d < 3; ++d) {
        lo[d] = std::min(lo[d], mesh.nodes[v][d]);
        hi[d] = std::max(hi[d], mesh.nodes[v][d]);
      }
  const double extent = std::max({hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2], 1e-300});
  std::vector<std::pair<std::uint64_t, std::int32_t>> keyed;
  for (long v = 0; v < nn; ++v) {
    if (!used[v] || ties.tied(static_cast<std::int32_t>(v)) ||
        (fixed[3 * v] && fixed[3 * v + 1] && fixed[3 * v + 2]))
      continue;
    std::uint64_t code = 0;
    for (int d = 0; d < 3; ++d) {
      const double t = (mesh.nodes[v][d] - lo[d]) / extent;
      code |= spread_bits(static_cast<std::uint64_t>(t * 2097151.0)) << d;
    }
    keyed.emplace_back(code, static_cast<std::int32_t>(v));
  }
  std::sort(keyed.begin(), keyed.end());
  DofLayout L;
  L.pos.assign(nn, -1);
  L.order.reserve(keyed.size());
  for (const auto& [code, v] : keyed) {
    L.pos[v] = static_cast<std::int32_t>(L.order.size());
    L.order.push_back(v);
  }
  const long n = static_cast<long>(L.order.size());
  if (n < 2L * size)
    throw Error("mpirun -n " + std::to_string(size) + ": the model has only " + std::to_string(n) +
                " free nodes; use at most " + std::to_string(n / 2) + " ranks");
  for (int r = 0; r <= size; ++r) L.starts.push_back(n * r / size);
  L.begin = L.starts[rank];
  L.end = L.starts[rank + 1];
  return L;
}

// Typical K_ii / M_ii from the element matrices of a sample of cells (the same on every rank):
// the scale of the shift, the zero-eigenvalue floor and the spurious eigenvalue.
double stiffness_scale(const MixedMesh& mesh, const std::vector<const Material*>& cell_mat,
                       double length_scale) {
  const long nc = static_cast<long>(mesh.num_cells());
  const long step = std::max(1L, nc / 2000);
  double log_sum = 0;
  long count = 0;
  std::vector<double> Ke(kMaxDofs * kMaxDofs), me(kMaxElementNodes * kMaxElementNodes);
  Vec3 x[kMaxElementNodes];
  std::int32_t ids[kMaxElementNodes];
  for (long c = 0; c < nc; c += step) {
    const ReferenceElement& ref = reference_element(mesh.cell_kind[c], mesh.order);
    mesh.element_nodes(c, ids);
    for (int i = 0; i < ref.n; ++i)
      for (int d = 0; d < 3; ++d) x[i][d] = mesh.nodes[ids[i]][d] * length_scale;
    if (!(element_matrices(ref, x, *cell_mat[c], Ke.data(), me.data()) > 0)) continue;
    for (int i = 0; i < 3 * ref.n; ++i) {
      const double m = me[(i / 3) * ref.n + i / 3];
      if (m > 0 && Ke[i * 3 * ref.n + i] > 0) {
        log_sum += std::log(Ke[i * 3 * ref.n + i] / m);
        ++count;
      }
    }
  }
  return count ? std::exp(log_sum / count) : 1.0;
}

// Assembles K - σM (positive definite also for a free structure) and M over this rank's cells.
// DOFs fixed on partly free nodes are decoupled, with K_ii / M_ii = λ_spurious.
// Returns the mass of the whole mesh; `volume` gets its volume.
double assemble(const MixedMesh& mesh, const std::vector<std::uint8_t>& fixed, const NodeTies& ties,
                const DofLayout& L, double length_scale, bool incompatible_hex,
                const std::vector<const Material*>& cell_mat, double sigma, double lambda_spurious,
                Matrices& mats, double& volume) {
  const int rank = mpi_rank(), size = mpi_size();
  BlockCsr Kb, Mb;  // the owned rows, accumulated here and handed to PETSc at the end
  {
    const NodeGraph g = node_graph(mesh, &ties);
    Kb = block_pattern(g, L, false, 9);
    Mb = block_pattern(g, L, true, 3);
  }
  create_matrices(Kb, Mb, L, mats);
  constexpr int kTiedDofs = 3 * kMaxTiedElementNodes;
  std::vector<double> Kv(kTiedDofs * kTiedDofs), mv(kMaxTiedElementNodes * kMaxTiedElementNodes),
      Mv(kTiedDofs * kTiedDofs), Kt(kTiedDofs * kTiedDofs),
      mt(kMaxTiedElementNodes * kMaxTiedElementNodes), Cv(kMaxElementNodes * kMaxTiedElementNodes);
  double *Ke = Kv.data(), *me = mv.data(), *Me = Mv.data();
  Vec3 x[kMaxElementNodes];
  std::int32_t ids[kMaxTiedElementNodes], tied_ids[kMaxTiedElementNodes];
  PetscInt idx[kMaxTiedElementNodes];
  double mass = 0, vol = 0, mdiag_sum = 0;
  long mdiag_count = 0, bad = 0;
  const long nc = static_cast<long>(mesh.num_cells());
  for (long c = 0; c < nc; ++c) {
    if (cell_owner(mesh, L, c, size) != rank) continue;
    const CellKind kind = mesh.cell_kind[c];
    const ReferenceElement& ref = reference_element(kind, mesh.order);
    int n = ref.n, nd = 3 * n;
    const Material& mat = *cell_mat[c];
    mesh.element_nodes(c, ids);
    for (int i = 0; i < n; ++i)
      for (int d = 0; d < 3; ++d) x[i][d] = mesh.nodes[ids[i]][d] * length_scale;
    if (!(element_matrices(ref, x, mat, Ke, me) > 0) ||
        (incompatible_hex && kind == CellKind::Hex8 && mesh.order == 1 &&
         !(hex8_incompatible_stiffness(x, mat, Ke) > 0))) {
      ++bad;
      continue;
    }
    double cell_mass = 0;
    for (int i = 0; i < n * n; ++i) cell_mass += me[i];
    mass += cell_mass;
    vol += cell_mass / mat.rho;
    // A tied node's DOFs become its masters': K' = Cᵀ K C, m' = Cᵀ m C on the masters.
    if (const int k = tied_element_nodes(ties, ids, n, tied_ids, Cv.data()); k >= 0) {
      tie_element_matrices(Cv.data(), n, k, Ke, me, Kt.data(), mt.data());
      std::copy_n(Kt.data(), 9 * k * k, Ke);
      std::copy_n(mt.data(), k * k, me);
      std::copy_n(tied_ids, k, ids);
      n = k;
      nd = 3 * k;
    }
    for (int i = 0; i < nd; ++i)
      for (int j = 0; j < nd; ++j) {
        const bool free = !fixed[3 * ids[i / 3] + i % 3] && !fixed[3 * ids[j / 3] + j % 3];
        const double m = i % 3 == j % 3 ? me[(i / 3) * n + j / 3] : 0.0;
        Me[i * nd + j] = free ? m : 0.0;
        Ke[i * nd + j] = free ? Ke[i * nd + j] - sigma * m : 0.0;
      }
    for (int i = 0; i < nd; ++i)
      if (Me[i * nd + i] > 0) {
        mdiag_sum += Me[i * nd + i];
        ++mdiag_count;
      }
    for (int i = 0; i < n; ++i) idx[i] = L.pos[ids[i]];  // -1: no equation
    add_element(idx, n, Ke, Me, Kb, Mb);
    add_off_rank_rows(L, n, idx, Ke, Me, mats);
  }
  // Whole rows, columns ascending, into an exactly preallocated AIJ: PETSc's sorted-full path
  // copies them instead of searching for each entry (sequential AIJ; MPIAIJ ignores it). Off
  // again before the fixed DOFs and the other ranks' rows are added.
  HEXFEM_PETSC(MatSetOption(mats.K, MAT_SORTED_FULL, PETSC_TRUE));
  add_rows(Kb, mats.K);
  HEXFEM_PETSC(MatSetOption(mats.K, MAT_SORTED_FULL, PETSC_FALSE));
  Kb = BlockCsr();  // one copy of K at a time
  add_rows(Mb, mats.M);
  Mb = BlockCsr();
  double local[5] = {mass, mdiag_sum, static_cast<double>(mdiag_count), static_cast<double>(bad),
                     vol};
  double global[5];
  MPI_Allreduce(local, global, 5, MPI_DOUBLE, MPI_SUM, PETSC_COMM_WORLD);
  volume = global[4];
  if (global[3] > 0)
    throw Error(std::to_string(static_cast<long>(global[3])) +
                " cell(s) have a non-positive Jacobian determinant: inverted or degenerate");
  // Partly fixed nodes: the fixed DOF keeps its row, decoupled, with a typical mass (a tiny one
  // would make LOBPCG's M-Gram matrices ill-conditioned) and eigenvalue λ_spurious.
  const double m_typical = global[2] > 0 ? global[1] / global[2] : 1.0;
  for (long p = L.begin; p < L.end; ++p)
    for (int a = 0; a < 3; ++a)
      if (fixed[3 * L.order[p] + a]) {
        const PetscInt row = 3 * p + a;
        HEXFEM_PETSC(MatSetValue(mats.K, row, row, lambda_spurious * m_typical, ADD_VALUES));
        HEXFEM_PETSC(MatSetValue(mats.M, row, row, m_typical, ADD_VALUES));
      }
  for (Mat A : {mats.K, mats.M}) {
    HEXFEM_PETSC(MatAssemblyBegin(A, MAT_FINAL_ASSEMBLY));
    HEXFEM_PETSC(MatAssemblyEnd(A, MAT_FINAL_ASSEMBLY));
  }
  return global[0];
}

}  // namespace hexfem

#include "fem/p_multigrid.hpp"

#include <array>

#include "fem/gamg.hpp"
#include "fem/petsc_env.hpp"
#include "mesher/mesh/element_topology.hpp"

namespace hexfem {

OrderOneCoarse::~OrderOneCoarse() {
  MatDestroy(&P);
  MatDestroy(&A);
}

void make_order_one_coarse(const MixedMesh& mesh, const std::vector<std::uint8_t>& fixed,
                           const DofLayout& L, double length_scale, Mat K, OrderOneCoarse& out) {
  const std::size_t nn = mesh.nodes.size();
  std::vector<std::uint8_t> corner(nn, 0);
  std::vector<std::array<std::int32_t, 2>> ends(nn, {-1, -1});  // a mid-edge node's corners
  for (std::size_t c = 0; c < mesh.num_cells(); ++c) {
    const CellKind kind = mesh.cell_kind[c];
    const std::int32_t* v = mesh.cell(c);
    for (int i = 0; i < num_nodes(kind); ++i) corner[v[i]] = 1;
    for (int e = 0; e < num_edges(kind); ++e) {
      const std::int32_t m = mesh.cell_edge_nodes[kMaxCellEdges * c + e];
      if (m >= 0 && ends[m][0] < 0) ends[m] = {v[edges_of(kind)[e][0]], v[edges_of(kind)[e][1]]};
    }
  }
  // Coarse numbering: the corners in layout order; every rank computes it all.
  const long n = static_cast<long>(L.order.size());
  std::vector<long> coarse(n, -1);
  long count = 0, begin = 0, end = 0;
  for (long p = 0; p < n; ++p) {
    if (p == L.begin) begin = count;
    if (corner[L.order[p]]) coarse[p] = count++;
    if (p + 1 == L.end) end = count;
  }

  HEXFEM_PETSC(MatCreate(PETSC_COMM_WORLD, &out.P));
  HEXFEM_PETSC(MatSetSizes(out.P, 3 * (L.end - L.begin), 3 * (end - begin), PETSC_DETERMINE,
                           PETSC_DETERMINE));
  HEXFEM_PETSC(MatSetBlockSizes(out.P, 3, 3));
  HEXFEM_PETSC(MatSetType(out.P, MATAIJ));
  HEXFEM_PETSC(MatSeqAIJSetPreallocation(out.P, 2, nullptr));
  HEXFEM_PETSC(MatMPIAIJSetPreallocation(out.P, 2, nullptr, 2, nullptr));
  for (long p = L.begin; p < L.end; ++p) {
    const std::int32_t v = L.order[p];
    for (int d = 0; d < 3; ++d) {
      const PetscInt row = static_cast<PetscInt>(3 * p + d);
      if (coarse[p] >= 0) {
        const PetscInt col = static_cast<PetscInt>(3 * coarse[p] + d);
        HEXFEM_PETSC(MatSetValue(out.P, row, col, 1.0, INSERT_VALUES));
        continue;
      }
      if (fixed[3 * v + d] || ends[v][0] < 0) continue;
      for (const std::int32_t e : ends[v]) {
        const long q = L.pos[e];
        if (q < 0 || coarse[q] < 0 || fixed[3 * e + d]) continue;
        const PetscInt col = static_cast<PetscInt>(3 * coarse[q] + d);
        HEXFEM_PETSC(MatSetValue(out.P, row, col, 0.5, INSERT_VALUES));
      }
    }
  }
  HEXFEM_PETSC(MatAssemblyBegin(out.P, MAT_FINAL_ASSEMBLY));
  HEXFEM_PETSC(MatAssemblyEnd(out.P, MAT_FINAL_ASSEMBLY));
  HEXFEM_PETSC(MatPtAP(K, out.P, MAT_INITIAL_MATRIX, 2.0, &out.A));
  HEXFEM_PETSC(MatSetBlockSize(out.A, 3));

  std::vector<double> coords;
  coords.reserve(3 * (end - begin));
  for (long p = L.begin; p < L.end; ++p)
    if (coarse[p] >= 0)
      for (int d = 0; d < 3; ++d) coords.push_back(mesh.nodes[L.order[p]][d] * length_scale);
  set_rigid_body_near_null_space(out.A, coords);
}

}  // namespace hexfem

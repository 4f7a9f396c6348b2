// The rows a rank owns of a node-block matrix (3x3 blocks, one per pair of neighbour nodes),
// accumulated element by element in our own CSR and handed to PETSc one sorted row at a time:
// PETSc's insertion of unsorted element blocks searches and shifts its rows on every new entry
// (validation/solver.md §21: 0.5-1 s less of a ~5 s assembly at 317k DOF).
#pragma once

#include <petscmat.h>

#include <cstdint>
#include <vector>

#include "fem/assembly.hpp"
#include "fem/dof_layout.hpp"

namespace hexfem {

struct BlockCsr {
  long first = 0;                 // position of row 0: the rank's first owned node
  int width = 9;                  // doubles a block: 9 (3x3, row-major) or 3 (its diagonal)
  std::vector<long> ptr;          // row r's blocks are [ptr[r], ptr[r + 1])
  std::vector<std::int32_t> col;  // their column positions, ascending, the diagonal included
  std::vector<double> val;        // `width` doubles a block, zero to start with
  long rows() const { return static_cast<long>(ptr.size()) - 1; }
};

// The pattern of the owned rows [L.begin, L.end): each node's neighbours in `g` that have a
// position, and itself. `upper` keeps the columns q >= p only (a symmetric matrix's stored half).
BlockCsr block_pattern(const NodeGraph& g, const DofLayout& L, bool upper, int width);

// Adds an element's matrices to the rows this rank owns: Ke (nd x nd, nd = 3n, row-major) to K
// (width 9, full rows) and the diagonals of Me's 3x3 blocks to M (width 3, upper rows; the mass
// couples equal components only). pos: the nodes' positions, -1 for none.
void add_element(const PetscInt* pos, int n, const double* Ke, const double* Me, BlockCsr& K,
                 BlockCsr& M);

// Per owned row, the blocks inside [L.begin, L.end) and outside it (PETSc's preallocation).
void count_blocks(const BlockCsr& A, const DofLayout& L, std::vector<PetscInt>& diag,
                  std::vector<PetscInt>& off);

// Adds the rows to A (block size 3), one MatSetValuesBlocked per row with ascending columns.
void add_rows(const BlockCsr& A, Mat mat);

}  // namespace hexfem

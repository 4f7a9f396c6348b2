// The iterative path of solve_modal (--solver iterative): K and M in distributed PETSc matrices
// (block size 3, one block per node, nodes in a space-filling-curve order cut into one
// contiguous range per MPI rank), the six rigid-body motions from the coordinates as GAMG's
// near-null space, our block LOBPCG (lobpcg.cpp) with a block V-cycle over GAMG (block_vcycle.cpp)
// for the lowest modes, SLEPc Krylov-Schur as the fallback (krylov_schur.cpp). Settings:
// iterative_settings.hpp.
//
// One process, or `mpirun -n N hexfem ...`: rank 0 reads the input, meshes, writes every
// output; the other ranks wait in MpiSession::serve() and take part in each solve.
#pragma once

#include <cstdint>
#include <vector>

#include "fem/modal_solver.hpp"

namespace hexfem {

// Called by solve_modal (rank 0, or the only process) after its input checks; `fixed` is the
// per-DOF mask of select_fixed_dofs. Throws hexfem::Error on non-convergence, naming the residual
// reached.
ModalResult solve_modal_iterative(const MixedMesh& mesh, const ModalOptions& options,
                                  const std::vector<std::uint8_t>& fixed);

// The process side of MPI in main(): under a launcher, MPI and PETSc start here on every rank;
// ranks > 0 then call serve() and never run the command themselves.
class MpiSession {
 public:
  MpiSession();
  ~MpiSession();  // rank 0: releases the serving ranks
  MpiSession(const MpiSession&) = delete;
  MpiSession& operator=(const MpiSession&) = delete;
  bool is_root() const;
  int serve();  // ranks > 0: solve with rank 0 until it ends; returns the exit code
};

}  // namespace hexfem

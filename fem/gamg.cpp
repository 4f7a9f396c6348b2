#include "fem/gamg.hpp"

#include <algorithm>

#include "fem/petsc_env.hpp"

namespace hexfem {

void configure_gamg(KSP ksp, const IterativeSettings& s) {
  PC pc;
  HEXFEM_PETSC(KSPGetPC(ksp, &pc));
  HEXFEM_PETSC(PCSetType(pc, PCGAMG));
  HEXFEM_PETSC(PCGAMGSetType(pc, PCGAMGAGG));
  HEXFEM_PETSC(PCGAMGSetNSmooths(pc, s.gamg_smooths));
  PetscReal threshold[1] = {s.gamg_threshold};
  HEXFEM_PETSC(PCGAMGSetThreshold(pc, threshold, 1));
  HEXFEM_PETSC(PCGAMGSetCoarseEqLim(pc, s.gamg_coarse_eq_limit));
}

void set_rigid_body_near_null_space(Mat A, const std::vector<double>& local_coords) {
  Vec coords;
  HEXFEM_PETSC(VecCreate(PETSC_COMM_WORLD, &coords));
  HEXFEM_PETSC(VecSetSizes(coords, static_cast<PetscInt>(local_coords.size()), PETSC_DETERMINE));
  HEXFEM_PETSC(VecSetBlockSize(coords, 3));
  HEXFEM_PETSC(VecSetFromOptions(coords));
  PetscScalar* c;
  HEXFEM_PETSC(VecGetArray(coords, &c));
  std::copy(local_coords.begin(), local_coords.end(), c);
  HEXFEM_PETSC(VecRestoreArray(coords, &c));
  MatNullSpace nsp;
  HEXFEM_PETSC(MatNullSpaceCreateRigidBody(coords, &nsp));
  HEXFEM_PETSC(MatSetNearNullSpace(A, nsp));
  HEXFEM_PETSC(MatNullSpaceDestroy(&nsp));
  HEXFEM_PETSC(VecDestroy(&coords));
}

void drop_galerkin_intermediates(PC pc) {
  PetscInt n;
  HEXFEM_PETSC(PCMGGetLevels(pc, &n));
  for (PetscInt l = 0; l < n; ++l) {
    KSP smoother;
    Mat A;
    HEXFEM_PETSC(PCMGGetSmoother(pc, l, &smoother));
    HEXFEM_PETSC(KSPGetOperators(smoother, &A, nullptr));
    HEXFEM_PETSC(MatProductClear(A));
    if (l == 0) continue;
    Mat P;
    HEXFEM_PETSC(PCMGGetInterpolation(pc, l, &P));
    HEXFEM_PETSC(MatProductClear(P));
  }
}

}  // namespace hexfem

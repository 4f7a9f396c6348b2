#include "fem/gamg.hpp"

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

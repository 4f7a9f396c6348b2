#include "fem/krylov_schur.hpp"

#include <algorithm>
#include <chrono>
#include <cstdio>

#include "fem/gamg.hpp"
#include "fem/petsc_env.hpp"
#include "mesher/mesh/error.hpp"
#include "mesher/mesh/progress.hpp"

namespace hexfem {
namespace {

// Progress on stderr (rank 0, terminals only) and the residual reached, for the error message.
struct Monitor {
  int nev = 0;
  double worst = 0;  // largest error estimate among the wanted pairs at the last iteration
  long iterations = 0;
};
PetscErrorCode monitor(EPS, PetscInt its, PetscInt nconv, PetscScalar*, PetscScalar*,
                       PetscReal* errest, PetscInt nest, void* ctx) {
  auto* m = static_cast<Monitor*>(ctx);
  m->iterations = its;
  m->worst = 0;
  for (PetscInt i = 0; i < std::min<PetscInt>(nest, m->nev); ++i)
    m->worst = std::max(m->worst, static_cast<double>(errest[i]));
  if (mpi_rank() == 0)
    show_progress("eigensolver iteration " + std::to_string(its) + ": " + std::to_string(nconv) +
                  " of " + std::to_string(m->nev) + " modes converged");
  return 0;
}

std::string failure_message(EPS eps, int nev, const Monitor& mon, long n, bool breakdown) {
  PetscInt nconv = 0, its = 0, max_its = 0;
  PetscReal tol = 0;
  EPSConvergedReason reason;
  EPSType type = nullptr;
  EPSGetConverged(eps, &nconv);
  EPSGetIterationNumber(eps, &its);
  EPSGetConvergedReason(eps, &reason);
  EPSGetTolerances(eps, &tol, &max_its);  // PETSC_OPTIONS may have changed them
  EPSGetType(eps, &type);
  char buf[400];
  std::snprintf(buf, sizeof buf,
                "the iterative eigensolver (%s + GAMG) %s: %ld of %d modes converged after "
                "%ld iterations, residual reached %.3g (tolerance %.3g, %ld DOFs); try "
                "--solver direct",
                type ? type : "krylovschur",
                breakdown || reason == EPS_DIVERGED_BREAKDOWN ? "broke down" : "did not converge",
                static_cast<long>(std::min<PetscInt>(nconv, nev)), nev,
                std::max(static_cast<long>(its), mon.iterations), mon.worst,
                static_cast<double>(tol), n);
  return buf;
}

// The fallback: Krylov-Schur on (K - σM)^-1 M, each solve by CG + GAMG. K - σM is positive
// definite, so target 0 and the largest |θ| = 1 / (λ - σ).
PetscErrorCode apply_shell(PC pc, Vec x, Vec y) {
  void* ctx = nullptr;
  PCShellGetContext(pc, &ctx);
  try {  // no exception may cross PETSc's C frames
    (*static_cast<const VectorPreconditioner*>(ctx))(x, y);
  } catch (const std::exception& e) {
    return PetscError(PETSC_COMM_SELF, __LINE__, "apply_shell", __FILE__, PETSC_ERR_LIB,
                      PETSC_ERROR_INITIAL, "%s", e.what());
  }
  return 0;
}

void configure_krylov_schur(EPS eps, int nev, const IterativeSettings& s, Monitor* mon,
                            const VectorPreconditioner& precondition) {
  HEXFEM_PETSC(EPSSetProblemType(eps, EPS_GHEP));
  HEXFEM_PETSC(EPSSetDimensions(eps, nev, PETSC_DEFAULT, PETSC_DEFAULT));
  HEXFEM_PETSC(EPSMonitorSet(eps, monitor, mon, nullptr));
  // Its own options prefix: PETSC_OPTIONS="-ks_eps_ncv 40 -ks_st_ksp_rtol 1e-12" tunes it
  // apart from LOBPCG's preconditioner ("-st_...").
  HEXFEM_PETSC(EPSSetOptionsPrefix(eps, "ks_"));
  HEXFEM_PETSC(EPSSetType(eps, EPSKRYLOVSCHUR));
  HEXFEM_PETSC(EPSSetWhichEigenpairs(eps, EPS_TARGET_MAGNITUDE));
  HEXFEM_PETSC(EPSSetTarget(eps, 0.0));
  HEXFEM_PETSC(EPSSetTolerances(eps, s.krylov_schur_tolerance, s.krylov_schur_max_iterations));
  ST st;
  KSP ksp;
  HEXFEM_PETSC(EPSGetST(eps, &st));
  HEXFEM_PETSC(STSetType(st, STSINVERT));
  HEXFEM_PETSC(STGetKSP(st, &ksp));
  HEXFEM_PETSC(KSPSetType(ksp, KSPCG));
  HEXFEM_PETSC(KSPSetTolerances(ksp, s.cg_tolerance, PETSC_DEFAULT, PETSC_DEFAULT, 1000));
  if (precondition) {
    PC pc;
    HEXFEM_PETSC(KSPGetPC(ksp, &pc));
    HEXFEM_PETSC(PCSetType(pc, PCSHELL));
    HEXFEM_PETSC(PCShellSetContext(pc, const_cast<VectorPreconditioner*>(&precondition)));
    HEXFEM_PETSC(PCShellSetApply(pc, apply_shell));
  } else {
    configure_gamg(ksp, s);
  }
  HEXFEM_PETSC(EPSSetFromOptions(eps));  // PETSC_OPTIONS overrides
}

}  // namespace

KrylovSchurRun krylov_schur(EPS eps, Mat K, Mat M, std::vector<Vec>& deflation, int nev,
                            const IterativeSettings& s, long n,
                            const VectorPreconditioner& precondition) {
  KrylovSchurRun run;
  Monitor mon{nev};
  HEXFEM_PETSC(EPSSetOperators(eps, K, M));
  if (!deflation.empty())
    HEXFEM_PETSC(
        EPSSetDeflationSpace(eps, static_cast<PetscInt>(deflation.size()), deflation.data()));
  configure_krylov_schur(eps, nev, s, &mon, precondition);
  const auto t_setup = std::chrono::steady_clock::now();
  HEXFEM_PETSC(EPSSetUp(eps));
  run.setup_seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - t_setup).count();
  const PetscErrorCode solved = EPSSolve(eps);
  if (mpi_rank() == 0) end_progress();
  if (solved != 0) {  // a breakdown (e.g. an indefinite Gram matrix): say how far it got
    std::string detail;
    try {
      HEXFEM_PETSC(solved);
    } catch (const Error& e) {
      detail = e.what();
    }
    run.iterations = mon.iterations;
    run.failure = failure_message(eps, nev, mon, n, true) + " [" + detail + "]";
    return run;
  }
  PetscInt nconv = 0, its = 0;
  HEXFEM_PETSC(EPSGetConverged(eps, &nconv));
  HEXFEM_PETSC(EPSGetIterationNumber(eps, &its));
  run.iterations = its;
  if (nconv < nev) run.failure = failure_message(eps, nev, mon, n, false);
  return run;
}

}  // namespace hexfem

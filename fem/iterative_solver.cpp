#include "fem/iterative_solver.hpp"

#include <petscksp.h>
#include <slepceps.h>

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <functional>
#include <memory>
#include <numeric>
#include <string>

#include "fem/assembly.hpp"
#include "fem/block_vcycle.hpp"
#include "fem/boundary.hpp"
#include "fem/dof_layout.hpp"
#include "fem/element.hpp"
#include "fem/gamg.hpp"
#include "fem/iterative_assembly.hpp"
#include "fem/krylov_schur.hpp"
#include "fem/lobpcg.hpp"
#include "fem/nc_ties.hpp"
#include "fem/p_multigrid.hpp"
#include "fem/petsc_env.hpp"
#include "mesher/mesh/error.hpp"
#include "mesher/mesh/progress.hpp"

namespace hexfem {
namespace {

using Clock = std::chrono::steady_clock;
double seconds_since(Clock::time_point t0) {
  return std::chrono::duration<double>(Clock::now() - t0).count();
}

enum Command : int { kQuit = 0, kSolve = 1 };

// Everything but the mesh, the fixed mask and the materials that every rank needs for a solve
// (plain data, broadcast as bytes).
struct JobParams {
  int num_modes = 10;
  int incompatible_hex = 0;
  double length_scale = 1;
  IterativeSettings settings;
};

// What rank 0 gets back (the other ranks discard theirs).
struct JobOutput {
  std::vector<double> eigenvalues;
  Eigen::MatrixXd modes;  // 3 * nodes x modes
  Eigen::MatrixXd effective_mass_fraction;
  double free_mass[3] = {0, 0, 0};
  double total_mass = 0;
  double total_volume = 0;  // Σ ∫ dV (the mass over each cell's own density)
  double sigma = 0;         // the shift of K - σM
  double assemble_seconds = 0, setup_seconds = 0, solve_seconds = 0;
  long iterations = 0;
  std::string algorithm;  // LOBPCG, or the fallback and why
  double max_residual = 0;
  double peak_memory_bytes = 0;
  double peak_after_assembly = 0, peak_after_setup = 0;  // this rank's, summed at the end
  long num_free = 0, num_fixed = 0;
  long stiffness_nnz = 0;  // entries of K over all ranks (decoupled fixed rows included)
};

// The six rigid-body motions of the owned nodes, for GAMG's aggregates.
void attach_near_null_space(const MixedMesh& mesh, const DofLayout& L, double length_scale, Mat K) {
  std::vector<double> coords;
  coords.reserve(3 * (L.end - L.begin));
  for (long p = L.begin; p < L.end; ++p)
    for (int d = 0; d < 3; ++d) coords.push_back(mesh.nodes[L.order[p]][d] * length_scale);
  set_rigid_body_near_null_space(K, coords);
}

// The settings of our own LOBPCG and V-cycle, overridable at run time like PETSc's:
// PETSC_OPTIONS="-lobpcg_extra_columns 4 -lobpcg_chebyshev_steps 1 -lobpcg_block_vcycle 0"
// (-lobpcg_max_iterations, -lobpcg_krylov_schur 0 and -lobpcg_shift_fraction are for studies).
IterativeSettings with_option_overrides(IterativeSettings s) {
  PetscBool set = PETSC_FALSE, flag = PETSC_FALSE;
  PetscInt v = 0;
  HEXFEM_PETSC(PetscOptionsGetInt(nullptr, nullptr, "-lobpcg_extra_columns", &v, &set));
  if (set) s.extra_block_columns = static_cast<int>(std::max<PetscInt>(0, v));
  HEXFEM_PETSC(PetscOptionsGetInt(nullptr, nullptr, "-lobpcg_chebyshev_steps", &v, &set));
  if (set) s.chebyshev_steps = static_cast<int>(std::max<PetscInt>(1, v));
  PetscReal r = 0;
  HEXFEM_PETSC(PetscOptionsGetReal(nullptr, nullptr, "-lobpcg_chebyshev_low", &r, &set));
  if (set) s.chebyshev_low = r;
  HEXFEM_PETSC(PetscOptionsGetReal(nullptr, nullptr, "-lobpcg_tolerance", &r, &set));
  if (set) s.tolerance = r;
  HEXFEM_PETSC(PetscOptionsGetBool(nullptr, nullptr, "-lobpcg_block_vcycle", &flag, &set));
  if (set) s.block_vcycle = flag;
  HEXFEM_PETSC(PetscOptionsGetBool(nullptr, nullptr, "-lobpcg_p_multigrid", &flag, &set));
  if (set) s.p_multigrid = flag;
  HEXFEM_PETSC(PetscOptionsGetInt(nullptr, nullptr, "-lobpcg_max_iterations", &v, &set));
  if (set) s.max_iterations = static_cast<int>(std::max<PetscInt>(1, v));
  HEXFEM_PETSC(PetscOptionsGetBool(nullptr, nullptr, "-lobpcg_krylov_schur", &flag, &set));
  if (set) s.krylov_schur_fallback = flag;
  HEXFEM_PETSC(PetscOptionsGetReal(nullptr, nullptr, "-lobpcg_shift_fraction", &r, &set));
  if (set) s.shift_fraction = r;
  return s;
}

long lo_block(const IterativeSettings& s, int nev) {
  return s.block_size > 0 ? s.block_size : nev + s.extra_block_columns;
}

// Unit translation along d on the free DOFs.
void translation(const DofLayout& L, const std::vector<std::uint8_t>& fixed, int d, Vec r) {
  PetscScalar* a;
  HEXFEM_PETSC(VecGetArray(r, &a));
  for (long p = L.begin; p < L.end; ++p)
    for (int b = 0; b < 3; ++b)
      a[3 * (p - L.begin) + b] = (b == d && !fixed[3 * L.order[p] + b]) ? 1.0 : 0.0;
  HEXFEM_PETSC(VecRestoreArray(r, &a));
}

// The rigid motions no fixed DOF holds (all six for a free structure), as vectors of this
// rank's rows, M-orthonormal Ritz vectors of (K - σM, M) on their span. They are exact
// zero-energy modes, so LOBPCG is deflated by them instead of converging to λ ≈ 0, where its
// Gram matrices lose definiteness.
struct RigidModes {
  std::vector<Vec> vectors;
  Eigen::VectorXd mu;
  ~RigidModes() {
    for (Vec& v : vectors) VecDestroy(&v);
  }
};
void rigid_modes(const MixedMesh& mesh, const DofLayout& L, const std::vector<std::uint8_t>& fixed,
                 const Matrices& mats, RigidModes& out) {
  const UnheldRigidMotions u = unheld_rigid_motions(mesh, fixed);
  const int k = static_cast<int>(u.coefficients.cols());
  if (k == 0) return;
  std::vector<Vec> basis(k);
  for (int j = 0; j < k; ++j) {
    HEXFEM_PETSC(MatCreateVecs(mats.K, &basis[j], nullptr));
    PetscScalar* a;
    HEXFEM_PETSC(VecGetArray(basis[j], &a));
    for (long p = L.begin; p < L.end; ++p) {
      const Vec3& x = mesh.nodes[L.order[p]];
      const Eigen::Vector3d d = (Eigen::Vector3d(x[0], x[1], x[2]) - u.centre) / u.length;
      for (int b = 0; b < 3; ++b) {
        double v = u.coefficients(b, j);
        for (int r = 0; r < 3; ++r)
          v += u.coefficients(3 + r, j) * Eigen::Vector3d::Unit(r).cross(d)[b];
        a[3 * (p - L.begin) + b] = fixed[3 * L.order[p] + b] ? 0.0 : v;
      }
    }
    HEXFEM_PETSC(VecRestoreArray(basis[j], &a));
  }
  Eigen::MatrixXd A(k, k), B(k, k);
  Vec w;
  HEXFEM_PETSC(MatCreateVecs(mats.K, &w, nullptr));
  for (int j = 0; j < k; ++j) {
    HEXFEM_PETSC(MatMult(mats.K, basis[j], w));
    for (int i = 0; i < k; ++i) HEXFEM_PETSC(VecDot(basis[i], w, &A(i, j)));
    HEXFEM_PETSC(MatMult(mats.M, basis[j], w));
    for (int i = 0; i < k; ++i) HEXFEM_PETSC(VecDot(basis[i], w, &B(i, j)));
  }
  HEXFEM_PETSC(VecDestroy(&w));
  const Eigen::GeneralizedSelfAdjointEigenSolver<Eigen::MatrixXd> ges(0.5 * (A + A.transpose()),
                                                                      0.5 * (B + B.transpose()));
  out.mu = ges.eigenvalues();
  for (int i = 0; i < k; ++i) {
    Vec v;
    HEXFEM_PETSC(VecDuplicate(basis[0], &v));
    HEXFEM_PETSC(VecSet(v, 0.0));
    for (int j = 0; j < k; ++j) HEXFEM_PETSC(VecAXPY(v, ges.eigenvectors()(j, i), basis[j]));
    out.vectors.push_back(v);
  }
  for (Vec& v : basis) VecDestroy(&v);
}

// Eigenpairs back to λ = μ + σ, M-normalized; residuals with the unshifted K; effective masses;
// the vectors gathered on rank 0 in node order.
// mode(i, x) writes eigenvector i into x and returns its eigenvalue μ of (K - σM, M).
void collect(const std::function<double(int, Vec)>& mode, const Matrices& mats, const DofLayout& L,
             const std::vector<std::uint8_t>& fixed, const NodeTies& ties, const JobParams& job,
             double sigma, double lambda_spurious, long num_nodes, JobOutput& out) {
  const int k = job.num_modes;
  Vec x, kx, mx, r[3], mr[3], x0;
  HEXFEM_PETSC(MatCreateVecs(mats.K, &x, &kx));
  HEXFEM_PETSC(VecDuplicate(x, &mx));
  for (int d = 0; d < 3; ++d) {
    HEXFEM_PETSC(VecDuplicate(x, &r[d]));
    HEXFEM_PETSC(VecDuplicate(x, &mr[d]));
    translation(L, fixed, d, r[d]);
    HEXFEM_PETSC(MatMult(mats.M, r[d], mr[d]));
    HEXFEM_PETSC(VecDot(r[d], mr[d], &out.free_mass[d]));
  }
  VecScatter to_zero;
  HEXFEM_PETSC(VecScatterCreateToZero(x, &to_zero, &x0));
  const bool root = mpi_rank() == 0;
  if (root) out.modes = Eigen::MatrixXd::Zero(3 * num_nodes, k);
  out.effective_mass_fraction.resize(k, 3);
  std::vector<double> rel_residual(k);
  for (int i = 0; i < k; ++i) {
    const double mu = mode(i, x);
    if (mu > 0.5 * lambda_spurious)
      throw Error("mode " + std::to_string(i + 1) +
                  " reaches the eigenvalue given to DOFs fixed on partly free nodes; ask for "
                  "fewer modes or use --solver direct");
    out.eigenvalues.push_back(mu + sigma);
    PetscScalar xmx;
    HEXFEM_PETSC(MatMult(mats.M, x, mx));
    HEXFEM_PETSC(VecDot(x, mx, &xmx));
    HEXFEM_PETSC(VecScale(x, 1.0 / std::sqrt(xmx)));
    HEXFEM_PETSC(VecScale(mx, 1.0 / std::sqrt(xmx)));
    HEXFEM_PETSC(MatMult(mats.K, x, kx));  // (K - σM)x - μMx = Kx - λMx
    HEXFEM_PETSC(VecAXPY(kx, -mu, mx));
    PetscReal rn, mn;
    HEXFEM_PETSC(VecNorm(kx, NORM_2, &rn));
    HEXFEM_PETSC(VecNorm(mx, NORM_2, &mn));
    rel_residual[i] = rn / mn;
    for (int d = 0; d < 3; ++d) {
      PetscScalar gamma;
      HEXFEM_PETSC(VecDot(x, mr[d], &gamma));
      out.effective_mass_fraction(i, d) = gamma * gamma / out.total_mass;
    }
    HEXFEM_PETSC(VecScatterBegin(to_zero, x, x0, INSERT_VALUES, SCATTER_FORWARD));
    HEXFEM_PETSC(VecScatterEnd(to_zero, x, x0, INSERT_VALUES, SCATTER_FORWARD));
    if (root) {
      const PetscScalar* a;
      HEXFEM_PETSC(VecGetArrayRead(x0, &a));
      for (std::size_t p = 0; p < L.order.size(); ++p)
        for (int b = 0; b < 3; ++b)
          if (!fixed[3 * L.order[p] + b]) out.modes(3 * L.order[p] + b, i) = a[3 * p + b];
      HEXFEM_PETSC(VecRestoreArrayRead(x0, &a));
      fill_tied_nodes(ties, out.modes.col(i).data());
    }
  }
  // As the direct path: against the top of the computed spectrum (or |σ|).
  const double top = std::max(std::abs(out.eigenvalues.back()), std::abs(sigma));
  for (double rr : rel_residual) out.max_residual = std::max(out.max_residual, rr / top);
  VecScatterDestroy(&to_zero);
  for (Vec* v : {&x, &kx, &mx, &x0, &r[0], &r[1], &r[2], &mr[0], &mr[1], &mr[2]}) VecDestroy(v);
}

// The collective solve: every rank calls it with the same mesh, mask and parameters.
JobOutput solve_distributed(const MixedMesh& mesh, const std::vector<std::uint8_t>& fixed,
                            const SolidMaterials& materials, const JobParams& job) {
  const int rank = mpi_rank(), size = mpi_size();
  const IterativeSettings s = with_option_overrides(job.settings);
  JobOutput out;
  auto t0 = Clock::now();
  const NodeTies ties = nc_face_ties(mesh, fixed);  // the same on every rank
  const DofLayout L = make_layout(mesh, fixed, ties, rank, size);
  // Tied DOFs are neither free nor fixed.
  const std::vector<std::uint8_t> used = element_node_mask(mesh);
  for (std::size_t i = 0; i < fixed.size(); ++i)
    if (used[i / 3] && !ties.tied(static_cast<std::int32_t>(i / 3)))
      ++(fixed[i] ? out.num_fixed : out.num_free);
  const long n = 3 * static_cast<long>(L.order.size());
  if (job.num_modes >= n)
    throw Error("requested " + std::to_string(job.num_modes) + " modes but the model has only " +
                std::to_string(n) + " DOFs");
  const std::vector<const Material*> cell_mat = cell_materials(mesh, materials);
  const double lambda_scale = stiffness_scale(mesh, cell_mat, job.length_scale);
  const double sigma = -s.shift_fraction * lambda_scale;
  const double lambda_spurious = s.spurious_factor * lambda_scale;
  out.sigma = sigma;
  Matrices mats;
  out.total_mass = assemble(mesh, fixed, ties, L, job.length_scale, job.incompatible_hex, cell_mat,
                            sigma, lambda_spurious, mats, out.total_volume);
  attach_near_null_space(mesh, L, job.length_scale, mats.K);
  out.assemble_seconds = seconds_since(t0);
  out.peak_after_assembly = peak_rss_bytes();
  MatInfo info;
  HEXFEM_PETSC(MatGetInfo(mats.K, MAT_GLOBAL_SUM, &info));
  out.stiffness_nnz = static_cast<long>(info.nz_used);

  RigidModes rigid;
  rigid_modes(mesh, L, fixed, mats, rigid);
  const int num_rigid = static_cast<int>(rigid.vectors.size());
  const int nev = job.num_modes - std::min(num_rigid, job.num_modes);
  t0 = Clock::now();
  const SingleThreadedBlas one_blas_thread;  // LOBPCG's dgemm, SLEPc's dense work
  // Declared before eps: SLEPc applies the fallback's preconditioner again when it hands out the
  // eigenvectors (EPSGetEigenpair, in collect below), so the V-cycle, the GAMG it runs on
  // (pc_ksp: its levels' solvers are reset with it) and the shell must outlive it.
  KSP pc_ksp = nullptr;
  struct KspGuard {
    KSP& k;
    ~KspGuard() { KSPDestroy(&k); }
  } ksp_guard{pc_ksp};
  std::unique_ptr<BlockVcycle> vcycle;
  VectorPreconditioner precondition;
  EPS eps = nullptr;
  LobpcgResult lob;
  bool used_eps = false;  // the Krylov-Schur fallback ran (the modes are eps's)
  struct EpsGuard {
    EPS& e;
    ~EpsGuard() { EPSDestroy(&e); }
  } guard{eps};
  if (nev > 0) {
    std::string brief;  // how LOBPCG ended, in a few words
    // LOBPCG (fem/lobpcg.cpp), preconditioned by one GAMG V-cycle on K - σM.
    HEXFEM_PETSC(KSPCreate(PETSC_COMM_WORLD, &pc_ksp));
    HEXFEM_PETSC(KSPSetOptionsPrefix(pc_ksp, "st_"));  // as SLEPc's: -st_mg_levels_ksp_max_it ...
    const auto t_setup = Clock::now();
    // Order 2: GAMG on the order-1 space of the same mesh, K smoothed above it (p_multigrid.hpp).
    OrderOneCoarse coarse;
    const bool p_multigrid = mesh.order == 2 && s.block_vcycle && s.p_multigrid;
    if (p_multigrid) make_order_one_coarse(mesh, fixed, L, job.length_scale, mats.K, coarse);
    Mat amg_operator = p_multigrid ? coarse.A : mats.K;
    HEXFEM_PETSC(KSPSetOperators(pc_ksp, amg_operator, amg_operator));
    HEXFEM_PETSC(KSPSetType(pc_ksp, KSPPREONLY));
    configure_gamg(pc_ksp, s);
    HEXFEM_PETSC(KSPSetFromOptions(pc_ksp));
    HEXFEM_PETSC(KSPSetUp(pc_ksp));
    PC pc;
    HEXFEM_PETSC(KSPGetPC(pc_ksp, &pc));
    drop_galerkin_intermediates(pc);
    if (s.block_vcycle)
      vcycle = std::make_unique<BlockVcycle>(pc, s.chebyshev_steps, s.chebyshev_low);
    if (p_multigrid) vcycle->add_finer_level(mats.K, coarse.P);
    out.setup_seconds += seconds_since(t_setup);
    out.peak_after_setup = peak_rss_bytes();
    LobpcgProblem problem{mats.K, mats.M, nullptr, nullptr, rigid.vectors};
    if (vcycle) {
      problem.precondition = [&](Mat in, Mat o) { vcycle->apply(in, o); };
      problem.multiply_a = [&](Mat in, Mat o) { vcycle->multiply_finest(in, o); };  // K
    } else
      problem.precondition = [&](Mat in, Mat o) { HEXFEM_PETSC(KSPMatSolve(pc_ksp, in, o)); };
    LobpcgOptions lo;
    lo.nev = nev;
    lo.block = lo_block(s, nev);
    lo.tolerance = s.tolerance;
    lo.max_iterations = s.max_iterations;
    lo.progress_window = s.progress_window;
    lo.max_iterations_progressing = s.max_iterations_progressing;
    lo.stall_iterations = s.stall_iterations;
    // The test of a pair (x M-normalized): |Kx - λMx| / (max(|λ|, floor) sqrt(mass per DOF)),
    // about |r|_{M^-1} / λ, dimensionless; a floor for λ ≈ 0.
    lo.floor = s.floor_fraction * lambda_scale;
    lo.mass_per_dof = out.total_mass / std::max(1L, n);
    PetscBool log_iterations = PETSC_FALSE;  // PETSC_OPTIONS="-lobpcg_monitor": one line each
    HEXFEM_PETSC(
        PetscOptionsGetBool(nullptr, nullptr, "-lobpcg_monitor", &log_iterations, nullptr));
    if (rank == 0)
      lo.monitor = [nev, log_iterations](int its, int nconv, double worst) {
        if (log_iterations)
          std::fprintf(stderr, "lobpcg iteration %d: %d of %d converged, largest error %.3g\n", its,
                       nconv, nev, worst);
        show_progress("eigensolver iteration " + std::to_string(its) + ": " +
                      std::to_string(nconv) + " of " + std::to_string(nev) + " modes converged");
      };
    lob = lobpcg(problem, lo);
    if (rank == 0) end_progress();
    out.iterations += lob.iterations;
    out.algorithm = p_multigrid ? "LOBPCG, order 2 over order 1" : "LOBPCG";
    std::string failed;
    if (!lob.failure.empty()) {
      char buf[400];
      std::snprintf(buf, sizeof buf,
                    "the iterative eigensolver (LOBPCG + GAMG) %s: %d of %d modes converged "
                    "after %d iterations, residual reached %.3g (tolerance %.3g, %ld DOFs); try "
                    "--solver direct",
                    lob.failure.c_str(), lob.converged, nev, lob.iterations, lob.worst, s.tolerance,
                    n);
      failed = buf;
      brief = std::to_string(lob.converged) + " of " + std::to_string(nev) +
              " modes converged after " + std::to_string(lob.iterations) + " iterations";
    }
    if (!failed.empty() && s.krylov_schur_fallback) {
      // LOBPCG stalls where a cluster of modes straddles its block; shift-and-invert does not.
      HEXFEM_PETSC(EPSCreate(PETSC_COMM_WORLD, &eps));
      // Its CG takes LOBPCG's V-cycle: at order 2 the p-multigrid (GAMG on K crawled there), at
      // order 1 GAMG's hierarchy with our smoother (PETSc's own broke down as indefinite at
      // round-off on tie_rod, solver.md §17).
      if (vcycle) precondition = [&](Vec x, Vec y) { vcycle->apply(x, y); };
      const KrylovSchurRun ks =
          krylov_schur(eps, mats.K, mats.M, rigid.vectors, nev, s, n, precondition);
      out.setup_seconds += ks.setup_seconds;
      out.iterations += ks.iterations;
      const std::string lobpcg_brief = brief, ks_failed = ks.failure;
      used_eps = true;
      out.algorithm = std::string("SLEPc Krylov-Schur shift-invert, CG + ") +
                      (p_multigrid ? "order 2 over order 1" : "GAMG") +
                      " (LOBPCG: " + lobpcg_brief + ")";
      failed = ks_failed.empty() ? "" : ks_failed + " (after LOBPCG: " + failed + ")";
    }
    if (!failed.empty()) throw Error(failed);
    out.solve_seconds = seconds_since(t0) - out.setup_seconds;
  }
  const auto mode = [&](int i, Vec x) -> double {
    if (i < num_rigid) {
      HEXFEM_PETSC(VecCopy(rigid.vectors[i], x));
      return rigid.mu[i];
    }
    if (!used_eps) {
      PetscScalar* a;
      HEXFEM_PETSC(VecGetArray(x, &a));
      std::copy_n(lob.vectors.col(i - num_rigid).data(), lob.vectors.rows(), a);
      HEXFEM_PETSC(VecRestoreArray(x, &a));
      return lob.values[i - num_rigid];
    }
    PetscScalar mu;
    HEXFEM_PETSC(EPSGetEigenpair(eps, i - num_rigid, &mu, nullptr, x, nullptr));
    return mu;
  };
  collect(mode, mats, L, fixed, ties, job, sigma, lambda_spurious,
          static_cast<long>(mesh.nodes.size()), out);
  const double peak = peak_rss_bytes();
  const double local[3] = {peak, out.peak_after_assembly,
                           std::max(out.peak_after_setup, out.peak_after_assembly)};
  double sum[3];
  MPI_Allreduce(local, sum, 3, MPI_DOUBLE, MPI_SUM, PETSC_COMM_WORLD);
  out.peak_memory_bytes = sum[0];
  out.peak_after_assembly = sum[1];
  out.peak_after_setup = sum[2];
  return out;
}

// The materials as plain numbers for a broadcast: base E, nu, rho, then solid, E, nu, rho per
// solid listed.
std::vector<double> pack_materials(const SolidMaterials& m) {
  std::vector<double> v{m.base.E, m.base.nu, m.base.rho};
  for (const auto& [solid, mat] : m.by_solid)
    v.insert(v.end(), {static_cast<double>(solid), mat.E, mat.nu, mat.rho});
  return v;
}

SolidMaterials unpack_materials(const std::vector<double>& v) {
  SolidMaterials m(Material{"", v[0], v[1], v[2]});
  for (std::size_t i = 3; i + 3 < v.size(); i += 4)
    m.by_solid.emplace_back(static_cast<std::int32_t>(v[i]),
                            Material{"", v[i + 1], v[i + 2], v[i + 3]});
  return m;
}

// Everything solve_distributed reads from the mesh, shared from rank 0: on the root MPI_Bcast
// reads the buffers, elsewhere it fills them. One list for both sides, so they cannot drift (the
// NC faces were once left out: the other ranks then had no order-2 ties, laid out other DOFs,
// and the first collective deadlocked).
void share_job(MixedMesh& mesh, std::vector<std::uint8_t>& fixed, JobParams& job,
               std::vector<double>& materials) {
  broadcast_vector(mesh.nodes);
  broadcast_vector(mesh.cell_kind);
  broadcast_vector(mesh.cell_nodes);
  broadcast_vector(mesh.cell_edge_nodes);
  broadcast_bytes(&mesh.order, sizeof mesh.order);
  broadcast_vector(mesh.cell_solid);
  broadcast_vector(mesh.nc_cell);
  broadcast_vector(mesh.nc_local_face);
  broadcast_vector(fixed);
  broadcast_bytes(&job, sizeof job);
  broadcast_vector(materials);
}

}  // namespace

ModalResult solve_modal_iterative(const MixedMesh& mesh, const ModalOptions& options,
                                  const std::vector<std::uint8_t>& fixed) {
  ensure_petsc();
  JobParams job;
  job.num_modes = options.num_modes;
  job.incompatible_hex = options.incompatible_hex;
  job.length_scale = options.length_scale;
  job.settings = options.iterative;
  if (mpi_size() > 1) {
    int cmd = kSolve;
    broadcast_bytes(&cmd, sizeof cmd);
    std::vector<double> materials = pack_materials(options.material);
    share_job(const_cast<MixedMesh&>(mesh), const_cast<std::vector<std::uint8_t>&>(fixed), job,
              materials);
  }
  JobOutput o = solve_distributed(mesh, fixed, options.material, job);

  ModalResult r;
  r.num_free_dofs = o.num_free;
  r.num_fixed_dofs = o.num_fixed;
  r.num_cells = static_cast<long>(mesh.num_cells());
  r.num_nodes = static_cast<long>(mesh.nodes.size());
  r.total_mass = o.total_mass;
  r.volume = o.total_volume;
  for (int d = 0; d < 3; ++d) r.free_mass[d] = o.free_mass[d];
  r.assemble_seconds = o.assemble_seconds;
  r.stiffness_nnz = o.stiffness_nnz;
  r.eigenvalues = o.eigenvalues;
  for (double lam : o.eigenvalues)
    r.frequencies.push_back(std::copysign(std::sqrt(std::abs(lam)) / (2 * M_PI), lam));
  r.modes = std::move(o.modes);
  r.effective_mass_fraction = std::move(o.effective_mass_fraction);
  EigenResult& e = r.eigen;
  e.method = "iterative";
  e.algorithm = o.algorithm;
  e.eigenvalues = Eigen::Map<const Eigen::VectorXd>(o.eigenvalues.data(), o.eigenvalues.size());
  e.sigma = o.sigma;
  e.setup_seconds = o.setup_seconds;
  e.solve_seconds = o.solve_seconds;
  e.iterations = o.iterations;
  e.max_residual = o.max_residual;
  e.peak_memory_bytes = o.peak_memory_bytes;
  e.peak_memory_assembly_bytes = o.peak_after_assembly;
  e.peak_memory_setup_bytes = o.peak_after_setup;
  e.ranks = mpi_size();
  return r;
}

MpiSession::MpiSession() {
  if (!under_mpi_launcher()) return;
  try {
    ensure_petsc();
  } catch (const Error& e) {
    std::fprintf(stderr, "hexfem: error: %s\n", e.what());
    std::exit(1);
  }
}

MpiSession::~MpiSession() {
  if (mpi_size() > 1 && mpi_rank() == 0) {
    int cmd = kQuit;
    broadcast_bytes(&cmd, sizeof cmd);
  }
}

bool MpiSession::is_root() const {
  return mpi_rank() == 0;
}

int MpiSession::serve() {
  for (;;) {
    int cmd = kQuit;
    broadcast_bytes(&cmd, sizeof cmd);
    if (cmd != kSolve) return 0;
    MixedMesh mesh;
    std::vector<std::uint8_t> fixed;
    JobParams job;
    std::vector<double> materials;
    share_job(mesh, fixed, job, materials);
    try {
      solve_distributed(mesh, fixed, unpack_materials(materials), job);
    } catch (const std::exception&) {
      // Rank 0 meets the same failure and reports it.
    }
  }
}

}  // namespace hexfem

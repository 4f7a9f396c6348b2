// Natural frequencies and mode shapes: K φ = ω² M φ with Spectra's shift-invert Lanczos, the
// shifted matrix K - σM factorized once (CHOLMOD supernodal LLᵀ).
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

#include "fem/assembly.hpp"
#include "fem/iterative_settings.hpp"
#include "fem/material.hpp"
#include "mesher/mesh/error.hpp"
#include "mesher/mesh/mixed_mesh.hpp"

namespace hexfem {

struct EigenOptions {
  int num_modes = 10;
  double tolerance = 1e-10;  // Spectra's relative tolerance on the Ritz values
  // Shift σ = -shift_fraction * median_i(K_ii / M_ii): slightly below zero so K - σM is positive
  // definite for free structures (rigid-body modes come out near zero) and far enough below the
  // elastic spectrum of any practical mesh not to slow the iteration.
  double shift_fraction = 1e-8;
  // K and M are already in a fill-reducing order (solve_modal numbers the DOFs that way);
  // otherwise CHOLMOD orders them with METIS.
  bool preordered = false;
  // Lanczos basis size; 0 = automatic (see solve_eigen).
  int ncv = 0;
  // Known zero-energy modes (columns over the DOFs, e.g. rigid_motions_of_parts): returned first
  // as Ritz pairs of their span, and projected out of the Lanczos iteration.
  Eigen::MatrixXd deflation;
  // Largest factor the direct path may allocate [bytes]; 0 = 90 % of the memory available when
  // it is about to factorize (MemAvailable). CHOLMOD's symbolic analysis gives the exact size
  // first, so a model too big for the machine is refused instead of killed for want of memory.
  double max_factor_bytes = 0;
};

// The direct path's factor would not fit in memory (EigenOptions::max_factor_bytes).
struct FactorTooLarge : Error {
  using Error::Error;
};

struct EigenResult {
  Eigen::VectorXd eigenvalues;  // ω² ascending [rad²/s²]
  Eigen::MatrixXd vectors;      // free DOFs x modes, M-orthonormal
  double sigma = 0;
  long factor_nnz = 0;      // entries of the Cholesky factor
  double factor_bytes = 0;  // the factor's memory (values, indices, update workspace)
  double factor_flops = 0;  // CHOLMOD's flop count of the factorization
  long iterations = 0;      // Lanczos restarts
  long operations = 0;      // applications of (K - σM)^-1
  double factor_seconds = 0, solve_seconds = 0;
  double max_residual = 0;  // max over modes of |Kφ - λMφ| / (λ_top |Mφ|), λ_top the largest found
  // Common to both paths: "direct" or "iterative", the setup (factorization or AMG hierarchy),
  // the peak resident memory of the solving processes (summed over MPI ranks) and their count.
  std::string method = "direct";
  std::string algorithm;  // iterative: "LOBPCG", or the Krylov-Schur fallback and why
  double setup_seconds = 0;
  double peak_memory_bytes = 0;
  // iterative: the peak (summed over ranks) reached by the end of assembly and of the AMG setup
  // (resident memory never falls from a peak, so the solve's own is peak_memory_bytes).
  double peak_memory_assembly_bytes = 0, peak_memory_setup_bytes = 0;
  int ranks = 1;
};

// Lowest `num_modes` eigenpairs of (K, M) given as lower triangles. Throws hexfem::Error when
// the request exceeds the size or the iteration does not converge.
EigenResult solve_eigen(const SparseMatrix& K, const SparseMatrix& M, const EigenOptions& options);

// --solver: direct (CHOLMOD + Spectra), iterative (LOBPCG + PETSc GAMG, MPI-capable), or auto
// (by DOF count and the estimated factor memory against the free memory).
enum class SolverChoice { Direct, Iterative, Auto };
inline constexpr long kAutoDirectMaxDofs = 100000;
// At order 2 (more nonzeros per row, a weaker AMG) the direct path stays faster longer: steel
// part, 152k DOF 26.5 s direct / 57.6 s iterative, 431k DOF 160 s (10.2 GB) / 102 s (2.1 GB).
inline constexpr long kAutoDirectMaxDofsOrder2 = 300000;
SolverChoice solver_choice_from_option(const std::string& value);  // throws on a bad value

struct ModalOptions {
  // The material of every cell, or per CAD solid (each listed solid must be in the mesh).
  SolidMaterials material;
  std::vector<std::string> fix;  // --fix specs (boundary.hpp); empty = free-free
  int num_modes = 10;
  double length_scale = 1.0;  // mesh coordinates * length_scale = metres
  // Hexes with incompatible modes (bending-accurate, C3D8I-like) instead of the fully
  // integrated trilinear hex (= CalculiX C3D8, which locks in bending).
  bool incompatible_hex = false;
  EigenOptions eigen;  // num_modes is taken from above
  SolverChoice solver = SolverChoice::Direct;
  // --solver auto: the largest DOF count solved directly (-1: kAutoDirectMaxDofs, or
  // kAutoDirectMaxDofsOrder2 at order 2); tests set 0 to take the iterative path first.
  long auto_direct_max_dofs = -1;
  IterativeSettings iterative;
};

struct ModalResult {
  std::vector<double> eigenvalues;  // ω² [rad²/s²], ascending
  std::vector<double> frequencies;  // Hz; a round-off negative eigenvalue gives a negative value
  Eigen::MatrixXd modes;            // 3*nodes x modes, M-orthonormal, zero at fixed DOFs
  // Effective modal mass fraction per mode and direction (x,y,z): (φᵀ M r_d)² / total mass.
  Eigen::MatrixXd effective_mass_fraction;
  double total_mass = 0;  // kg, ρ·V of the whole mesh
  // r_dᵀ M r_d over the free DOFs per direction: what all modes together can reach (= total_mass
  // for a free structure, less when DOFs are fixed).
  double free_mass[3] = {0, 0, 0};
  double volume = 0;  // m³
  long num_free_dofs = 0, num_fixed_dofs = 0;
  long num_cells = 0, num_nodes = 0;
  long stiffness_nnz = 0;    // entries of the assembled K (both triangles), as the solver holds it
  double order_seconds = 0;  // fill-reducing order of the nodes
  double assemble_seconds = 0;  // DOF selection and numbering, K and M
  EigenResult eigen;            // solver figures (vectors moved into `modes`)
  std::string solver_reason;    // why this path was taken (--solver auto explains its pick)
};

// Checks the input (material, cells, inverted cells, fixed-DOF selection, mode count), then
// assembles and solves. Every failure is a hexfem::Error naming the problem.
ModalResult solve_modal(const MixedMesh& mesh, const ModalOptions& options);

}  // namespace hexfem

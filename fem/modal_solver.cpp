#include "fem/modal_solver.hpp"

#include <Spectra/MatOp/SparseSymMatProd.h>
#include <Spectra/SymGEigsShiftSolver.h>

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <string>

#include "fem/boundary.hpp"
#include "fem/iterative_solver.hpp"
#include "fem/petsc_env.hpp"
#include "mesher/mesh/error.hpp"
#include "mesher/mesh/quality.hpp"
#include "mesher/mesh/system_memory.hpp"

#ifdef HEXFEM_HAVE_CHOLMOD
#include <Eigen/CholmodSupport>
#else
#include <Eigen/SparseCholesky>
#endif

namespace hexfem {
namespace {

// Largest relative residual |Kφ - λMφ| / (λ_top |Mφ|) the direct path reports (it reaches 1e-9
// to 1e-13 at tolerance 1e-10).
constexpr double kMaxDirectResidual = 1e-6;
// --solver auto: the direct path takes over from a LOBPCG with no converged pair whose rate would
// need more than twice this many iterations (it converges in 20-100 where it does; solver.md §10,
// §20).
constexpr int kAutoStallIterations = 60;

double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

// y = (K - σM)^-1 x for Spectra, factorized once per shift. K and M share one pattern, so
// K - σM is formed on the values alone. With set_scale(s) it acts for the scaled pencil (K/s, M):
// Spectra then sees Ritz values 1/(λ/s - σ') of order one. Its tests have absolute floors
// (a restart when ‖f‖ < ε√n, convergence to tol·max(ε^(2/3), |θ|)), so an unscaled 1 mm part
// (λ ~ 1e14, θ ~ 1e-14) came out with wrong frequencies and residuals of order one.
class ShiftInvertOp {
 public:
  using Scalar = double;

  ShiftInvertOp(const SparseMatrix& K, const SparseMatrix& M, bool preordered,
                double max_factor_bytes)
      : K_(K), M_(M), max_factor_bytes_(max_factor_bytes) {
#ifdef HEXFEM_HAVE_CHOLMOD
    // One ordering, chosen here: CHOLMOD's default suite can settle for AMD, which on slender
    // 3D meshes costs tens of times METIS's flops.
    cholmod_common& cm = solver_.cholmod();
    cm.nmethods = 1;
    cm.method[0].ordering = preordered ? CHOLMOD_NATURAL : CHOLMOD_METIS;
    cm.postorder = 1;
#else
    (void)preordered;
#endif
  }
  Eigen::Index rows() const {
    return K_.rows();
  }
  Eigen::Index cols() const {
    return K_.cols();
  }

  void set_scale(double s) {
    scale_ = s;
  }
  // sigma is the shift of the scaled pencil: K - sigma*s*M is factorized.
  void set_shift(double scaled_sigma) {
    const double sigma = scaled_sigma * scale_;
    // A second Lanczos run at the same shift (the search for missed copies) reuses the factor.
    if (factored_ && sigma == factored_sigma_) return;
    const auto t0 = std::chrono::steady_clock::now();
    A_ = K_;
    Eigen::Map<Eigen::VectorXd>(A_.valuePtr(), A_.nonZeros()) -=
        sigma * Eigen::Map<const Eigen::VectorXd>(M_.valuePtr(), M_.nonZeros());
    if (!analyzed_) {
      solver_.analyzePattern(A_);
      analyzed_ = true;
      check_factor_fits();
    }
    solver_.factorize(A_);
    if (solver_.info() != Eigen::Success)
      throw Error("factorization of K - sigma*M failed (sigma = " + std::to_string(sigma) +
                  "): the model is not positive definite after the shift");
#ifdef HEXFEM_HAVE_CHOLMOD
    factor_nnz_ = static_cast<long>(solver_.cholmod().lnz);
    factor_flops_ = solver_.cholmod().fl;
#else
    factor_nnz_ = static_cast<long>(solver_.matrixL().nestedExpression().nonZeros());
#endif
    A_ = SparseMatrix();  // the factor holds what is needed
    factor_seconds_ = seconds_since(t0);
    factored_ = true;
    factored_sigma_ = sigma;
  }

  void perform_op(const double* x_in, double* y_out) const {
    Eigen::Map<const Eigen::VectorXd> x(x_in, rows());
    Eigen::Map<Eigen::VectorXd> y(y_out, rows());
    y = scale_ * solver_.solve(x);
    project(y_out);
  }

  // Removes the M-orthonormal columns of Z from every result: y -= Z (Zᵀ M y).
  void set_deflation(const Eigen::MatrixXd* Z) {
    Z_ = Z;
  }
  void project(double* v) const {
    if (!Z_ || Z_->cols() == 0) return;
    Eigen::Map<Eigen::VectorXd> y(v, rows());
    const Eigen::VectorXd my = M_.selfadjointView<Eigen::Lower>() * y;
    y -= *Z_ * (Z_->transpose() * my);
  }

  long factor_nnz() const {
    return factor_nnz_;
  }
  double factor_bytes() const {
    return factor_bytes_;
  }
  double factor_flops() const {
    return factor_flops_;
  }
  double factor_seconds() const {
    return factor_seconds_;
  }

 private:
#ifdef HEXFEM_HAVE_CHOLMOD
  // Eigen keeps CHOLMOD's factor to itself; its symbolic part tells the numeric size.
  struct Supernodal : Eigen::CholmodSupernodalLLT<SparseMatrix, Eigen::Lower> {
    const cholmod_factor* factor() const { return m_cholmodFactor; }
  };
#endif

  // After the symbolic analysis: the numeric factor's values and indices plus the largest
  // supernodal update (CHOLMOD's workspace), against the limit. A compact 3D part at order 2
  // needs several times what a slender one of the same DOF count does (ANC101, 589k DOF: over
  // 24 GB), so no formula in the DOF count can stand in for this.
  void check_factor_fits() {
#ifdef HEXFEM_HAVE_CHOLMOD
    const cholmod_factor* L = solver_.factor();
    if (!L) return;
    const double values = L->is_super ? static_cast<double>(L->xsize + L->maxcsize)
                                      : static_cast<double>(solver_.cholmod().lnz);
    factor_bytes_ = 8.0 * values + 8.0 * static_cast<double>(L->is_super ? L->ssize : 0);
    double limit = max_factor_bytes_;
    if (!(limit > 0)) limit = 0.9 * available_memory_bytes();
    if (limit > 0 && factor_bytes_ > limit) {
      char buf[200];
      std::snprintf(buf, sizeof buf,
                    "the direct solver's factor needs %.3g GB, more than the %.3g GB available "
                    "(%ld DOFs): use --solver iterative, or a larger --h",
                    factor_bytes_ / 1e9, limit / 1e9, static_cast<long>(K_.rows()));
      throw FactorTooLarge(buf);
    }
#endif
  }

  const SparseMatrix& K_;
  const SparseMatrix& M_;
  double max_factor_bytes_ = 0;
  bool analyzed_ = false;
  bool factored_ = false;
  double factored_sigma_ = 0;
  double factor_bytes_ = 0;
  SparseMatrix A_;
  const Eigen::MatrixXd* Z_ = nullptr;
  double scale_ = 1;
#ifdef HEXFEM_HAVE_CHOLMOD
  Supernodal solver_;
#else
  Eigen::SimplicialLDLT<SparseMatrix, Eigen::Lower> solver_;
#endif
  long factor_nnz_ = 0;
  double factor_flops_ = 0;
  double factor_seconds_ = 0;
};

using MassOp = Spectra::SparseSymMatProd<double, Eigen::Lower, Eigen::ColMajor, long>;

struct LanczosPairs {
  Eigen::VectorXd values;   // of the scaled pencil (K/s, M), ascending
  Eigen::MatrixXd vectors;  // M-orthonormal, and M-orthogonal to the operator's deflation
  long iterations = 0, operations = 0;
  bool converged = false;  // else values/vectors hold only the pairs that did
};

// The nev eigenpairs of the scaled pencil nearest its shift, by Spectra's shift-invert Lanczos
// from a fixed pseudo-random start vector (`seed` picks it) with the deflated part removed.
// Does not throw when the iteration stops unconverged: `converged` says so.
LanczosPairs lanczos_nearest_shift(ShiftInvertOp& op, MassOp& bop, long nev, long ncv,
                                   double scaled_sigma, double seed, double tolerance) {
  Spectra::SymGEigsShiftSolver<ShiftInvertOp, MassOp, Spectra::GEigsMode::ShiftInvert> eigs(
      op, bop, nev, ncv, scaled_sigma);
  const long n = op.rows();
  Eigen::VectorXd v0(n);
  for (long i = 0; i < n; ++i) v0[i] = std::sin(seed * static_cast<double>(i + 1)) + 0.5;
  op.project(v0.data());
  eigs.init(v0.data());
  eigs.compute(Spectra::SortRule::LargestMagn, 1000, tolerance, Spectra::SortRule::SmallestAlge);
  return {eigs.eigenvalues(), eigs.eigenvectors(), eigs.num_iterations(), eigs.num_operations(),
          eigs.info() == Spectra::CompInfo::Successful};
}

// Lanczos from one start vector sees one copy of each eigenvalue in exact arithmetic; round-off
// brings the other copies in late or never. On a cube's structured mesh (a triple eigenvalue)
// `--modes 10` gave the triple once and the next frequency in place of its other two copies. So
// the complement of the pairs found (and of Z) is searched once more from another start vector,
// to a loose tolerance (a Ritz value's error is about the square of its residual): if it holds
// an eigenvalue below the highest kept, a full-tolerance run there brings the missed pairs in,
// they replace the highest, and the complement is searched again. `pairs` keeps its size.
void add_missed_copies(ShiftInvertOp& op, MassOp& bop, const Eigen::MatrixXd& Z,
                       double scaled_sigma, double tolerance, LanczosPairs& pairs) {
  const long n = op.rows(), nl = pairs.values.size();
  // A value this far below the highest kept is a different eigenvalue; closer, a copy of it,
  // and which copy is kept does not change the list.
  constexpr double kDistinct = 1e-8;
  constexpr long kSearchNcv = 10;
  constexpr double kSearchTolerance = 1e-4;
  for (int round = 0; round < nl; ++round) {
    Eigen::MatrixXd D(n, Z.cols() + nl);
    D << Z, pairs.vectors;
    op.set_deflation(&D);
    const long left = n - D.cols();
    if (left < 2) break;
    const double top = pairs.values[nl - 1], below_top = top - kDistinct * std::abs(top);
    const LanczosPairs probe =
        lanczos_nearest_shift(op, bop, 1, std::min(left, kSearchNcv), scaled_sigma, 78.233 + round,
                              std::max(tolerance, kSearchTolerance));
    pairs.iterations += probe.iterations;
    pairs.operations += probe.operations;
    // A search that does not converge leaves the list as the first run found it.
    if (!probe.converged || probe.values.size() == 0 || !(probe.values[0] < below_top)) break;
    const long k = std::min<long>({nl, 3, left - 1});
    const LanczosPairs more = lanczos_nearest_shift(op, bop, k, std::min<long>(left, 20),
                                                    scaled_sigma, 4.1414 + round, tolerance);
    pairs.iterations += more.iterations;
    pairs.operations += more.operations;
    // Merge, ascending, and keep the nl lowest.
    std::vector<std::pair<double, long>> all;  // value, column (>= nl: from `more`)
    for (long j = 0; j < nl; ++j) all.emplace_back(pairs.values[j], j);
    for (long j = 0; j < more.values.size(); ++j)
      if (more.values[j] < below_top) all.emplace_back(more.values[j], nl + j);
    if (static_cast<long>(all.size()) == nl) break;  // the probe's value not confirmed
    std::stable_sort(all.begin(), all.end(),
                     [](const auto& x, const auto& y) { return x.first < y.first; });
    LanczosPairs merged = pairs;
    for (long j = 0; j < nl; ++j) {
      merged.values[j] = all[j].first;
      const long c = all[j].second;
      if (c < nl)
        merged.vectors.col(j) = pairs.vectors.col(c);
      else
        merged.vectors.col(j) = more.vectors.col(c - nl);
    }
    pairs = std::move(merged);
  }
  op.set_deflation(&Z);
}

#ifdef HEXFEM_HAVE_CHOLMOD
// METIS nested dissection of the node graph: 3x fewer vertices and 9x fewer edges than the DOF
// graph, so ordering costs a fraction of CHOLMOD's own METIS call on K, for the same fill (the 3
// DOFs of a node are interchangeable). Empty on failure: CHOLMOD then orders K itself.
std::vector<std::int32_t> fill_reducing_node_order(const MixedMesh& mesh) {
  const NodeGraph g = node_graph(mesh);
  const long n = static_cast<long>(mesh.nodes.size());
  cholmod_common cm;
  cholmod_l_start(&cm);
  cm.print = 0;
  std::vector<std::int32_t> order;
  // Upper triangle (stype 1), column j: neighbours i < j then the diagonal, sorted.
  long nnz = n;
  for (long j = 0; j < n; ++j)
    for (long p = g.ptr[j]; p < g.ptr[j + 1] && g.adj[p] < j; ++p) ++nnz;
  cholmod_sparse* A = cholmod_l_allocate_sparse(n, n, nnz, 1, 1, 1, CHOLMOD_PATTERN, &cm);
  if (A) {
    auto* ap = static_cast<SuiteSparse_long*>(A->p);
    auto* ai = static_cast<SuiteSparse_long*>(A->i);
    long k = 0;
    for (long j = 0; j < n; ++j) {
      ap[j] = k;
      for (long p = g.ptr[j]; p < g.ptr[j + 1] && g.adj[p] < j; ++p) ai[k++] = g.adj[p];
      ai[k++] = j;
    }
    ap[n] = k;
    std::vector<SuiteSparse_long> perm(n);
    if (cholmod_l_metis(A, nullptr, 0, 1, perm.data(), &cm)) order.assign(perm.begin(), perm.end());
    cholmod_l_free_sparse(&A, &cm);
  }
  cholmod_l_finish(&cm);
  return order;
}
#endif

// Inverted cells have negative stiffness and flat ones (volume ~0) a stiffness ~1/volume that
// swamps the spectrum; either makes the frequencies meaningless, so both are refused.
void reject_invalid_cells(const MixedMesh& mesh) {
  long inverted = 0, degenerate = 0, first_inverted = -1, first_degenerate = -1;
  for (std::size_t c = 0; c < mesh.num_cells(); ++c) {
    if (cell_is_inverted(mesh, c)) {
      if (inverted++ == 0) first_inverted = static_cast<long>(c);
    } else if (cell_min_scaled_jacobian(mesh, c) < kDegenerateScaledJacobian) {
      if (degenerate++ == 0) first_degenerate = static_cast<long>(c);
    }
  }
  auto first = [&](long c) {
    return "(first: cell " + std::to_string(c + 1) + ", " + kind_name(mesh.cell_kind[c]) + ")";
  };
  if (inverted > 0)
    throw Error("the mesh has " + std::to_string(inverted) + " inverted cell(s) " +
                first(first_inverted) + "; fix the mesh before a modal analysis");
  if (degenerate > 0)
    throw Error("the mesh has " + std::to_string(degenerate) +
                " degenerate (flat) cell(s) with scaled Jacobian below 1e-6 " +
                first(first_degenerate) + "; fix the mesh before a modal analysis");
}

// --solver auto: the direct path while it is fast and its factor fits, the iterative one
// beyond. Factor memory ~ 157 n^(4/3) bytes fits the cantilevers of solver.md §8 (0.79 / 3.4 /
// 16.5 GB measured at 94.5k / 305k / 1.05M DOFs); nested dissection on compact 3D meshes
// grows as n^(4/3) too. On one process the two paths take the same time at 94.5k DOFs (8.7 s),
// where the iterative one needs 2.4x less memory, and the iterative one is 1.5x faster at 305k
// and 3.4x at 1.05M (solver.md §10, session 13); 100k sits at the break-even. At order 2 the
// break-even is near 300k (kAutoDirectMaxDofsOrder2; order2.md section 4).
// *direct_fits: the direct path's estimated factor fits in half the available memory (one rank).
SolverChoice pick_solver(long free_dofs, int order, long max_direct, std::string& reason,
                         bool* direct_fits) {
  const double factor_bytes = 157.0 * std::pow(static_cast<double>(free_dofs), 4.0 / 3.0);
  const double available = available_memory_bytes();
  char buf[300];
  if (mpi_size() > 1) {
    std::snprintf(buf, sizeof buf, "auto: iterative (%d MPI ranks; the direct path is serial)",
                  mpi_size());
    reason = buf;
    *direct_fits = false;
    return SolverChoice::Iterative;
  }
  const bool fits = available <= 0 || factor_bytes < 0.5 * available;
  *direct_fits = fits;
  const long limit = max_direct >= 0 ? max_direct
                     : order == 2    ? kAutoDirectMaxDofsOrder2
                                     : kAutoDirectMaxDofs;
  const bool small = free_dofs <= limit;
  std::snprintf(buf, sizeof buf,
                "auto: %s (%ld DOFs %s %ld at order %d; estimated factor %.2g GB %s half of the "
                "%.3g GB available)",
                small && fits ? "direct" : "iterative", free_dofs, small ? "<=" : ">", limit, order,
                factor_bytes / 1e9, fits ? "<" : ">=", available / 1e9);
  reason = buf;
  return small && fits ? SolverChoice::Direct : SolverChoice::Iterative;
}

}  // namespace

SolverChoice solver_choice_from_option(const std::string& value) {
  if (value == "direct") return SolverChoice::Direct;
  if (value == "iterative") return SolverChoice::Iterative;
  if (value == "auto") return SolverChoice::Auto;
  throw Error("--solver must be direct, iterative or auto (got '" + value + "')");
}

EigenResult solve_eigen(const SparseMatrix& K, const SparseMatrix& M, const EigenOptions& options) {
  const long n = K.rows();
  const long nev = options.num_modes;
  if (nev < 1)
    throw Error("the number of modes must be at least 1 (got " + std::to_string(nev) + ")");
  if (nev >= n)
    throw Error("requested " + std::to_string(nev) + " modes but the model has only " +
                std::to_string(n) + " free DOFs (at most " + std::to_string(n - 1) + " modes)");
  // Shift scale: the median diagonal ratio K_ii/M_ii, about (wave speed / element size)^2. Not
  // the largest: one sliver tet has a huge ratio, and a shift that far below zero leaves the
  // elastic modes unresolved next to |sigma| (seen on hex-dominant meshes: modes at 2 MHz).
  std::vector<double> ratio;
  ratio.reserve(n);
  for (long c = 0; c < n; ++c) {
    const double kd = K.valuePtr()[K.outerIndexPtr()[c]];  // the diagonal opens each column
    const double md = M.valuePtr()[M.outerIndexPtr()[c]];
    if (md > 0) ratio.push_back(kd / md);
  }
  std::nth_element(ratio.begin(), ratio.begin() + ratio.size() / 2, ratio.end());
  const double lambda_scale = ratio.empty() ? 1.0 : ratio[ratio.size() / 2];
  EigenResult res;
  res.sigma = -options.shift_fraction * lambda_scale;

  // Known zero-energy modes first: Ritz pairs of (K, M) on their span, M-orthonormal.
  Eigen::MatrixXd Z;
  Eigen::VectorXd zero_values;
  const long nz = std::min<long>(options.deflation.cols(), nev);
  if (options.deflation.cols() > 0) {
    const Eigen::MatrixXd& R = options.deflation;
    const Eigen::MatrixXd KR = K.selfadjointView<Eigen::Lower>() * R,
                          MR = M.selfadjointView<Eigen::Lower>() * R;
    const Eigen::MatrixXd A = R.transpose() * KR, B = R.transpose() * MR;
    const Eigen::GeneralizedSelfAdjointEigenSolver<Eigen::MatrixXd> ges(0.5 * (A + A.transpose()),
                                                                        0.5 * (B + B.transpose()));
    if (ges.info() != Eigen::Success)
      throw Error("the rigid-body modes are not independent (a part with a single node?)");
    Z = R * ges.eigenvectors();
    zero_values = ges.eigenvalues();
  }
  const long nl = nev - nz;  // modes left to the Lanczos iteration

  ShiftInvertOp op(K, M, options.preordered, options.max_factor_bytes);
  op.set_deflation(&Z);
  op.set_scale(lambda_scale);
  MassOp bop(M);
  const long nfree = n - Z.cols();  // the dimension left after the deflation
  const long ncv = options.ncv > nl ? std::min<long>(nfree, options.ncv)
                                    : std::min(nfree, std::max(2 * nl + 1, 20L));
  const auto t0 = std::chrono::steady_clock::now();
  Eigen::VectorXd lambda = zero_values.head(nz);
  Eigen::MatrixXd phi = Z.leftCols(nz);
  if (nl > 0) {
    if (nl >= nfree)
      throw Error("requested " + std::to_string(nev) + " modes but the model has only " +
                  std::to_string(n) + " free DOFs and " + std::to_string(Z.cols()) +
                  " rigid-body modes");
    // The same start as Spectra's default (a fixed pseudo-random vector), without its rigid part.
    const double scaled_sigma = res.sigma / lambda_scale;
    LanczosPairs pairs =
        lanczos_nearest_shift(op, bop, nl, ncv, scaled_sigma, 12.9898, options.tolerance);
    if (!pairs.converged)
      throw Error("the eigenvalue iteration did not converge (" + std::to_string(nev) + " modes, " +
                  std::to_string(n) + " DOFs)");
    add_missed_copies(op, bop, Z, scaled_sigma, options.tolerance, pairs);
    res.iterations = pairs.iterations;
    res.operations = pairs.operations;
    lambda.conservativeResize(nev);
    lambda.tail(nl) = lambda_scale * pairs.values;
    phi.conservativeResize(n, nev);
    phi.rightCols(nl) = pairs.vectors;
  }
  res.factor_seconds = op.factor_seconds();
  res.solve_seconds = seconds_since(t0) - res.factor_seconds;
  res.factor_nnz = op.factor_nnz();
  res.factor_bytes = op.factor_bytes();
  res.factor_flops = op.factor_flops();
  res.eigenvalues = std::move(lambda);
  res.vectors = std::move(phi);
  // Residuals against the top of the computed spectrum, so rigid-body modes (λ ≈ 0, Kφ ≈ 0) are
  // judged by how small Kφ is, not by a ratio of two round-off quantities. The rigid-body modes
  // come from the geometry, not the iteration: their Kφ is round-off in K's own scale (about
  // 1e-13 of the median K_ii/M_ii), which on a slender free part at fine h is 1e6-1e7 times its
  // first elastic eigenvalue; judged against that, exact modes were refused (tie_rod, h 12).
  const double scale = std::max(std::abs(res.eigenvalues.maxCoeff()), std::abs(res.sigma));
  for (long k = 0; k < res.vectors.cols(); ++k) {
    const Eigen::VectorXd kx = K.selfadjointView<Eigen::Lower>() * res.vectors.col(k);
    const Eigen::VectorXd mx = M.selfadjointView<Eigen::Lower>() * res.vectors.col(k);
    const double mode_scale = k < nz ? std::max(scale, lambda_scale) : scale;
    const double r = (kx - res.eigenvalues[k] * mx).norm() / (mode_scale * mx.norm());
    res.max_residual = std::max(res.max_residual, r);
  }
  // Never report frequencies the iteration did not resolve (10^4 above what it usually reaches).
  if (!(res.max_residual < kMaxDirectResidual))
    throw Error("the direct eigenvalue solve did not resolve the modes (relative residual " +
                std::to_string(res.max_residual) + "); try --solver iterative");
  return res;
}

namespace {

// The direct path: CHOLMOD + Spectra shift-invert on the assembled K and M. Throws
// FactorTooLarge before allocating a factor the machine cannot hold.
ModalResult solve_modal_direct(const MixedMesh& mesh, const ModalOptions& options,
                               const std::vector<std::uint8_t>& fixed, const std::string& reason,
                               std::chrono::steady_clock::time_point t0) {
  const auto t_order = std::chrono::steady_clock::now();
#ifdef HEXFEM_HAVE_CHOLMOD
  const std::vector<std::int32_t> order = fill_reducing_node_order(mesh);
#else
  const std::vector<std::int32_t> order;  // SimplicialLDLT orders by itself (AMD)
#endif
  const double order_seconds = seconds_since(t_order);
  const DofMap dofs = number_free_dofs(mesh, fixed, order);
  if (dofs.num_free == 0) throw Error("every DOF is fixed: nothing to analyse");
  if (options.num_modes >= dofs.num_free)
    throw Error("requested " + std::to_string(options.num_modes) + " modes but the model has " +
                std::to_string(dofs.num_free) + " free DOFs (at most " +
                std::to_string(dofs.num_free - 1) + " modes)");
  const SystemMatrices sys =
      assemble_system(mesh, options.material, dofs, options.length_scale, options.incompatible_hex);

  ModalResult out;
  out.assemble_seconds = seconds_since(t0) - order_seconds;
  out.order_seconds = order_seconds;
  out.total_mass = sys.mass;
  out.volume = sys.volume;
  out.num_free_dofs = dofs.num_free;
  out.num_fixed_dofs = dofs.num_fixed;
  out.stiffness_nnz = 2 * static_cast<long>(sys.K.nonZeros()) - dofs.num_free;  // lower -> full
  out.num_cells = static_cast<long>(mesh.num_cells());
  out.num_nodes = static_cast<long>(mesh.nodes.size());

  EigenOptions eo = options.eigen;
  eo.num_modes = options.num_modes;
  eo.preordered = !order.empty();
  eo.deflation = rigid_motions_of_parts(mesh, dofs);
  out.eigen = solve_eigen(sys.K, sys.M, eo);
  out.eigen.setup_seconds = out.eigen.factor_seconds;
  out.eigen.peak_memory_bytes = peak_rss_bytes();
  out.solver_reason = reason;
  const Eigen::MatrixXd& phi = out.eigen.vectors;
  const long k = phi.cols();

  // Γ_d = φᵀ M r_d with r_d the unit rigid translation along d (free DOFs only).
  out.effective_mass_fraction.resize(k, 3);
  for (int d = 0; d < 3; ++d) {
    Eigen::VectorXd r = Eigen::VectorXd::Zero(dofs.num_free);
    for (std::size_t v = 0; v < mesh.nodes.size(); ++v)
      if (dofs.dof[3 * v + d] >= 0) r[dofs.dof[3 * v + d]] = 1;
    const Eigen::VectorXd mr = sys.M.selfadjointView<Eigen::Lower>() * r;
    out.free_mass[d] = r.dot(mr);
    const Eigen::VectorXd gamma = phi.transpose() * mr;
    out.effective_mass_fraction.col(d) = gamma.array().square() / sys.mass;
  }
  out.modes.resize(3 * static_cast<long>(mesh.nodes.size()), k);
  for (long j = 0; j < k; ++j) {
    const double lam = out.eigen.eigenvalues[j];
    out.eigenvalues.push_back(lam);
    out.frequencies.push_back(std::copysign(std::sqrt(std::abs(lam)) / (2 * M_PI), lam));
    out.modes.col(j) = expand_to_nodes(dofs, phi.col(j));
  }
  out.eigen.vectors.resize(0, 0);
  return out;
}

// A material given to a solid that the mesh does not have is a typo: an error naming the solids
// there are.
void check_material_solids(const MixedMesh& mesh, const SolidMaterials& mats) {
  if (mats.by_solid.empty()) return;
  std::vector<std::int32_t> solids = mesh.cell_solid;
  std::sort(solids.begin(), solids.end());
  solids.erase(std::unique(solids.begin(), solids.end()), solids.end());
  for (const auto& [solid, m] : mats.by_solid) {
    if (std::binary_search(solids.begin(), solids.end(), solid)) continue;
    std::string have;
    for (std::size_t i = 0; i < solids.size() && i < 20; ++i)
      have += (i ? ", " : "") + std::to_string(solids[i]);
    if (solids.size() > 20) have += ", ...";
    throw Error("a material is given to solid " + std::to_string(solid) +
                ", but the mesh has no such solid (its solids: " + have + ")");
  }
}

}  // namespace

ModalResult solve_modal(const MixedMesh& mesh, const ModalOptions& options) {
  validate(options.material);
  check_material_solids(mesh, options.material);
  if (!(options.length_scale > 0) || !std::isfinite(options.length_scale))
    throw Error("length scale must be positive");
  if (mesh.num_cells() == 0) throw Error("the mesh has no volume cells");
  if (options.num_modes < 1)
    throw Error("the number of modes must be at least 1 (got " + std::to_string(options.num_modes) +
                ")");
  reject_invalid_cells(mesh);

  const auto t0 = std::chrono::steady_clock::now();
  const std::vector<std::uint8_t> fixed = select_fixed_dofs(mesh, options.fix);
  check_every_part_is_held(mesh, fixed);
  SolverChoice path = options.solver;
  std::string reason = path == SolverChoice::Direct ? "--solver direct" : "--solver iterative";
  if (path != SolverChoice::Direct) {
    std::vector<std::uint8_t> used(mesh.nodes.size(), 0);
    for (const auto* list : {&mesh.cell_nodes, &mesh.cell_edge_nodes})
      for (std::int32_t v : *list)
        if (v >= 0) used[v] = 1;
    long free_dofs = 0;
    for (std::size_t i = 0; i < fixed.size(); ++i) free_dofs += used[i / 3] && !fixed[i];
    if (free_dofs == 0) throw Error("every DOF is fixed: nothing to analyse");
    if (options.num_modes >= free_dofs)
      throw Error("requested " + std::to_string(options.num_modes) + " modes but the model has " +
                  std::to_string(free_dofs) + " free DOFs (at most " +
                  std::to_string(free_dofs - 1) + " modes)");
    bool direct_fits = false, iterative_failed = false;
    const bool automatic = path == SolverChoice::Auto;
    if (automatic)
      path = pick_solver(free_dofs, mesh.order, options.auto_direct_max_dofs, reason, &direct_fits);
    if (path == SolverChoice::Iterative && automatic && direct_fits) {
      // LOBPCG + GAMG stalls on some parts (40mm_capot at order 2, 411k DOF: 0 of 2 modes after
      // 200 iterations, then Krylov-Schur past 10 min; the direct path takes 72 s, 5.4 GB).
      // Where the factor fits, a LOBPCG that has converged nothing and will not by twice
      // kAutoStallIterations hands over to the direct path instead of to Krylov-Schur.
      ModalOptions first = options;
      first.iterative.krylov_schur_fallback = false;
      first.iterative.stall_iterations = kAutoStallIterations;
      try {
        ModalResult r = solve_modal_iterative(mesh, first, fixed);
        r.solver_reason = reason;
        return r;
      } catch (const Error& e) {
        reason += std::string("; then direct, since the iterative path failed: ") + e.what();
        path = SolverChoice::Direct;
        iterative_failed = true;
      }
    }
    if (path == SolverChoice::Iterative) {
      ModalResult r = solve_modal_iterative(mesh, options, fixed);
      r.solver_reason = reason;
      return r;
    }
    if (automatic) {  // direct by the estimate; CHOLMOD's analysis has the last word
      try {
        return solve_modal_direct(mesh, options, fixed, reason, t0);
      } catch (const FactorTooLarge& e) {
        if (iterative_failed) throw Error(reason + "; " + e.what());
        ModalResult r = solve_modal_iterative(mesh, options, fixed);
        r.solver_reason = reason + "; then iterative, since " + e.what();
        return r;
      }
    }
  }
  return solve_modal_direct(mesh, options, fixed, reason, t0);
}

}  // namespace hexfem
